//! What a part file says of itself that can be checked, checked: every attribute the merge uses
//! lies in the range `lapidary render` accepts, the counts agree with the sample range, and every
//! pixel's sums are ones that many samples can make. A part that fails is refused by
//! [`super::Part::read`] with every problem listed.

use super::range::{MAX_SPP, format_range, parse_range};
use crate::image::ExrImage;
use crate::render::film::{Film, PixelSums};
use crate::render::fixed;
use std::ops::Range;

/// Longest render time a part may record, in seconds (about 32 years).
pub const MAX_RENDER_TIME: f64 = 1e9;

/// What is wrong with a part's attributes and sums (nothing believed that can be checked): every
/// attribute the merge uses lies in the range `lapidary render` accepts, the counts agree with
/// the sample range, and every pixel's sums are ones `samples` samples can make.
pub fn check(image: &ExrImage, film: &Film, samples: &Range<u32>) -> Vec<String> {
    let mut out = Vec::new();
    let taken = u64::from(samples.end - samples.start);
    let mut need = |key: &str, expected: &str, ok: &dyn Fn(&str) -> bool| match image.attribute(key)
    {
        None => out.push(format!("no `{key}` attribute (expected {expected})")),
        Some(v) if !ok(v) => out.push(format!("`{key}` is {}, not {expected}", shown(v))),
        Some(_) => {}
    };
    let count =
        |lo: u64, hi: u64| move |v: &str| v.parse::<u64>().is_ok_and(|n| (lo..=hi).contains(&n));
    need(
        "lapidary.spp",
        &format!("a count of samples in 1..={MAX_SPP}"),
        &count(1, MAX_SPP.into()),
    );
    need(
        "lapidary.seed",
        "a seed in 0..=18446744073709551615",
        &count(0, u64::MAX),
    );
    need("lapidary.max_depth", "a depth in 1..=1024", &count(1, 1024));
    need("lapidary.recipe_hash", "16 hex digits", &|v| {
        v.len() == 16 && v.bytes().all(|c| c.is_ascii_hexdigit())
    });
    need("lapidary.sampler", "sobol or independent", &|v| {
        ["sobol", "independent"].contains(&v)
    });
    need("lapidary.strategy", "mis, light or bsdf", &|v| {
        ["mis", "light", "bsdf"].contains(&v)
    });
    need("lapidary.partial", "true or false", &|v| {
        ["true", "false"].contains(&v)
    });
    need("lapidary.exposure", "stops in -30..=30", &|v| {
        v.parse::<f32>().is_ok_and(|e| (-30.0..=30.0).contains(&e))
    });
    need(
        "lapidary.render_time",
        &format!("seconds in 0..={MAX_RENDER_TIME:e}"),
        &|v| {
            v.parse::<f64>()
                .is_ok_and(|t| (0.0..=MAX_RENDER_TIME).contains(&t))
        },
    );
    need(
        "lapidary.spp_complete",
        &format!("{taken}, the length of its range {}", format_range(samples)),
        &|v| v.parse::<u64>() == Ok(taken),
    );
    need(
        "lapidary.samples_requested",
        &format!(
            "a range A..B with A = {} and B ≥ {}",
            samples.start, samples.end
        ),
        &|v| parse_range(v).is_ok_and(|r| r.start == samples.start && r.end >= samples.end),
    );
    // Dropped samples: at most the samples taken, and the sum of the raw counts.
    let total = u64::from(image.width) * u64::from(image.height) * taken;
    let dropped = film.dropped();
    match image
        .attribute("lapidary.dropped")
        .map(|v| (v, v.parse::<u64>()))
    {
        None => out.push(format!(
            "no `lapidary.dropped` attribute (expected {dropped})"
        )),
        Some((_, Ok(d))) if d > total => out.push(format!(
            "`lapidary.dropped` is {d}, beyond the {total} samples taken ({taken} a pixel)"
        )),
        Some((_, Ok(d))) if d == dropped => {}
        Some((v, _)) => out.push(format!(
            "`lapidary.dropped` is {}, not {dropped}, the sum of its `raw.dropped`",
            shown(v)
        )),
    }
    out.extend(check_sums(film, samples));
    out
}

/// An attribute's value as shown in a message: quoted with escapes, at most 40 characters.
fn shown(v: &str) -> String {
    let short: String = v.chars().take(40).collect();
    let more = if short.len() < v.len() { "…" } else { "" };
    format!("{:?}{more}", short)
}

/// What a pixel's sums say that `taken` samples cannot make, if anything.
type Rule = fn(&PixelSums, u64) -> Option<String>;

/// The invariants of a pixel's sums over `taken` samples ([`PixelSums::add`]).
const RULES: [Rule; 6] = [
    |p, taken| {
        let got = u64::from(p.n) + u64::from(p.dropped);
        (got != taken).then(|| {
            format!(
                "`raw.n` + `raw.dropped` = {} + {}, not the {taken} samples of its range",
                p.n, p.dropped
            )
        })
    },
    |p, _| {
        let all = u64::from(p.n) + u64::from(p.dropped);
        (u64::from(p.depth_n) > all)
            .then(|| format!("`raw.depth_n` = {}, more than its {all} samples", p.depth_n))
    },
    |p, _| {
        let most = u128::from(p.n).saturating_mul(fixed::radiance(fixed::RADIANCE_LIMIT) as u128);
        p.sum.iter().any(|s| s.unsigned_abs() > most).then(|| {
            format!(
                "`raw.sum` beyond what {} kept samples of at most 2^60 can add up to",
                p.n
            )
        })
    },
    |p, _| {
        let all = u64::from(p.n) + u64::from(p.dropped);
        let most = u128::from(all) * fixed::aov(fixed::AOV_LIMIT) as u128;
        let big = |v: &i64| u128::from(v.unsigned_abs()) > most;
        (p.albedo.iter().any(big) || p.normal.iter().any(big)).then(|| {
            format!(
                "`raw.albedo` or `raw.normal` beyond what {all} samples of at most 256 add up to"
            )
        })
    },
    |p, _| {
        let most = u128::from(p.depth_n) * fixed::depth(fixed::DEPTH_LIMIT) as u128;
        (p.depth < 0 || p.depth.unsigned_abs() > most).then(|| {
            format!(
                "`raw.depth` outside what {} hits at depths in [0, 2^60] add up to",
                p.depth_n
            )
        })
    },
    |p, _| {
        (p.material < -2).then(|| format!("`raw.material` = {}, below −2 (nothing)", p.material))
    },
];

/// Every rule a pixel of `film` breaks: the first such pixel and how many more break it.
fn check_sums(film: &Film, samples: &Range<u32>) -> Vec<String> {
    let taken = u64::from(samples.end - samples.start);
    let mut out = Vec::new();
    for rule in RULES {
        let broken = film
            .pixels
            .iter()
            .enumerate()
            .filter_map(|(i, p)| rule(p, taken).map(|m| (i, m)));
        out.extend(first_broken(film, broken));
    }
    out
}

/// The first pixel of `broken` (index and what is wrong) with how many more there are, or `None`.
pub(super) fn first_broken(
    film: &Film,
    mut broken: impl Iterator<Item = (usize, String)>,
) -> Option<String> {
    let (i, m) = broken.next()?;
    let w = film.width.max(1) as usize;
    let more = broken.count();
    let others = if more > 0 {
        format!(" (and {more} more pixels)")
    } else {
        String::new()
    };
    Some(format!("pixel ({}, {}){others}: {m}", i % w, i / w))
}
