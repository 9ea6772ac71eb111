//! Part renders: a render of one sample range, stored with its exact sums so that parts rendered
//! on different machines merge into the one-machine render bit for bit (`lapidary render
//! --samples A..B`, `lapidary merge`; docs/farm.md).
//!
//! A part file is the ordinary render EXR of its own samples (colour, AOVs, metadata: it opens
//! in any viewer and `lapidary compare` reads it) plus:
//! - the film's fixed-point sums ([`super::fixed`]) as 32-bit unsigned integer channels named
//!   `raw.*`, exact: an `i128` is four words, least significant first (`raw.sum.R.0` … `.3`);
//! - with `--stokes`, the Stokes vector's sums the same way (`raw.stokes.*`, [`stokes`]);
//! - `lapidary.samples` (the range rendered, `A..B`; shorter than requested if a time limit
//!   stopped it), `lapidary.samples_requested`, `lapidary.strategy` and `lapidary.exposure`.
//!
//! [`Part::read`] believes nothing it can check ([`check`]): the file's type before it is opened,
//! every attribute the merge uses against the range `lapidary render` accepts, and every pixel's
//! sums against the part's sample range (kept + dropped samples = the range's length, and sums
//! no such count of samples can exceed).
//!
//! [`merge`] checks that parts belong together — the same values of every key in
//! [`MUST_AGREE`] and the same size — and that their ranges are disjoint and cover `0..spp`,
//! naming the files that overlap and the ranges that are missing.

use super::film::{Film, PixelSums};
use crate::image::{ExrImage, RawChannel};
use std::ops::Range;
use std::path::{Path, PathBuf};

mod check;
mod range;
pub mod stokes;

pub use self::check::{MAX_RENDER_TIME, check};
pub use self::range::{MAX_SPP, format_range, parse_range};

/// Attributes every part of one render must share.
pub const MUST_AGREE: [&str; 11] = [
    "lapidary.version",
    "lapidary.recipe_hash",
    "lapidary.seed",
    "lapidary.spp",
    "lapidary.sampler",
    "lapidary.max_depth",
    "lapidary.accuracy",
    "lapidary.medium",
    "lapidary.materials",
    "lapidary.strategy",
    "lapidary.exposure",
];

/// Attributes only a part has; a merged image drops them.
pub const PART_ONLY: [&str; 4] = [
    "lapidary.samples",
    "lapidary.samples_requested",
    "lapidary.strategy",
    "lapidary.exposure",
];

/// One named word of a pixel's sums.
type Word = (String, fn(&PixelSums) -> u32);

/// Splits a 128-bit value into 4 words, least significant first.
fn word128(v: u128, k: u32) -> u32 {
    (v >> (32 * k)) as u32
}

/// The raw channels' names and how each word is read from a pixel, in a fixed order.
fn words() -> Vec<Word> {
    let mut out: Vec<Word> = Vec::with_capacity(46);
    macro_rules! wide {
        ($name:expr, $get:expr, $n:expr) => {
            for k in 0..$n {
                let f: fn(&PixelSums) -> u32 = match k {
                    0 => |p| word128($get(p), 0),
                    1 => |p| word128($get(p), 1),
                    2 => |p| word128($get(p), 2),
                    _ => |p| word128($get(p), 3),
                };
                out.push((format!("{}.{k}", $name), f));
            }
        };
    }
    wide!("raw.sum.R", |p: &PixelSums| p.sum[0] as u128, 4);
    wide!("raw.sum.G", |p: &PixelSums| p.sum[1] as u128, 4);
    wide!("raw.sum.B", |p: &PixelSums| p.sum[2] as u128, 4);
    wide!("raw.sum_sq.R", |p: &PixelSums| p.sum_sq[0], 4);
    wide!("raw.sum_sq.G", |p: &PixelSums| p.sum_sq[1], 4);
    wide!("raw.sum_sq.B", |p: &PixelSums| p.sum_sq[2], 4);
    wide!(
        "raw.albedo.R",
        |p: &PixelSums| p.albedo[0] as u64 as u128,
        2
    );
    wide!(
        "raw.albedo.G",
        |p: &PixelSums| p.albedo[1] as u64 as u128,
        2
    );
    wide!(
        "raw.albedo.B",
        |p: &PixelSums| p.albedo[2] as u64 as u128,
        2
    );
    wide!(
        "raw.normal.X",
        |p: &PixelSums| p.normal[0] as u64 as u128,
        2
    );
    wide!(
        "raw.normal.Y",
        |p: &PixelSums| p.normal[1] as u64 as u128,
        2
    );
    wide!(
        "raw.normal.Z",
        |p: &PixelSums| p.normal[2] as u64 as u128,
        2
    );
    wide!("raw.depth", |p: &PixelSums| p.depth as u128, 4);
    wide!("raw.rays", |p: &PixelSums| u128::from(p.rays), 2);
    out.push(("raw.n".into(), |p| p.n));
    out.push(("raw.dropped".into(), |p| p.dropped));
    out.push(("raw.depth_n".into(), |p| p.depth_n));
    out.push(("raw.material".into(), |p| p.material as u32));
    out
}

/// The film's sums (and its Stokes sums, if it has them) as exact integer channels.
pub fn raw_channels(film: &Film) -> Vec<RawChannel> {
    let mut out: Vec<RawChannel> = words()
        .into_iter()
        .map(|(name, get)| RawChannel {
            name,
            data: film.pixels.iter().map(get).collect(),
        })
        .collect();
    out.extend(stokes::raw_channels(film));
    out
}

/// Rebuilds a film from its raw channels; the error names a missing or short channel.
pub fn film_from_raw(width: u32, height: u32, raw: &[RawChannel]) -> Result<Film, String> {
    let n = width as usize * height as usize;
    let get = |name: &str| -> Result<&[u32], String> {
        let c = raw.iter().find(|c| c.name == name).ok_or_else(|| {
            format!("no channel `{name}`: not a part file (render one with --samples)")
        })?;
        if c.data.len() != n {
            return Err(format!(
                "channel `{name}` has {} values, not {n}",
                c.data.len()
            ));
        }
        Ok(&c.data)
    };
    let wide = |name: &str, words: u32| -> Result<Vec<u128>, String> {
        let mut out = vec![0u128; n];
        for k in 0..words {
            for (o, &w) in out.iter_mut().zip(get(&format!("{name}.{k}"))?) {
                *o |= u128::from(w) << (32 * k);
            }
        }
        Ok(out)
    };
    let mut film = Film::new(width, height);
    for (c, ch) in ["R", "G", "B"].iter().enumerate() {
        let sum = wide(&format!("raw.sum.{ch}"), 4)?;
        let sq = wide(&format!("raw.sum_sq.{ch}"), 4)?;
        let albedo = wide(&format!("raw.albedo.{ch}"), 2)?;
        for (i, p) in film.pixels.iter_mut().enumerate() {
            p.sum[c] = sum[i] as i128;
            p.sum_sq[c] = sq[i];
            p.albedo[c] = albedo[i] as u64 as i64;
        }
    }
    for (c, ch) in ["X", "Y", "Z"].iter().enumerate() {
        let normal = wide(&format!("raw.normal.{ch}"), 2)?;
        for (p, v) in film.pixels.iter_mut().zip(normal) {
            p.normal[c] = v as u64 as i64;
        }
    }
    let depth = wide("raw.depth", 4)?;
    let rays = wide("raw.rays", 2)?;
    let (count, dropped) = (get("raw.n")?, get("raw.dropped")?);
    let (depth_n, material) = (get("raw.depth_n")?, get("raw.material")?);
    for (i, p) in film.pixels.iter_mut().enumerate() {
        p.depth = depth[i] as i128;
        p.rays = rays[i] as u64;
        p.n = count[i];
        p.dropped = dropped[i];
        p.depth_n = depth_n[i];
        p.material = material[i] as i32;
    }
    film.stokes = stokes::from_raw(n, raw)?;
    Ok(film)
}

/// How a part was rendered beyond its [`Metadata`](super::Metadata).
#[derive(Clone, Debug, PartialEq)]
pub struct PartSettings {
    /// The samples asked for.
    pub requested: Range<u32>,
    /// Direct-light estimators (`mis`, `light`, `bsdf`).
    pub strategy: String,
    /// PNG exposure in stops, for the merged PNG.
    pub exposure: f32,
}

/// The EXR of a part render: the render's image with the part attributes, and its raw sums.
pub fn part_image(
    rendered: &super::Rendered,
    meta: &super::Metadata,
    part: &PartSettings,
) -> (ExrImage, Vec<RawChannel>) {
    let mut img = super::exr_image(rendered, meta);
    let start = part.requested.start;
    let done = start..start + rendered.stats.spp_complete;
    img.attributes.extend([
        ("lapidary.samples".to_string(), format_range(&done)),
        (
            "lapidary.samples_requested".to_string(),
            format_range(&part.requested),
        ),
        ("lapidary.strategy".to_string(), part.strategy.clone()),
        ("lapidary.exposure".to_string(), part.exposure.to_string()),
    ]);
    (img, raw_channels(&rendered.film))
}

/// A part file read back.
#[derive(Clone, Debug)]
pub struct Part {
    /// Where it was read from.
    pub path: PathBuf,
    /// Its attributes (sorted by key) and display channels.
    pub image: ExrImage,
    /// Its exact sums.
    pub film: Film,
    /// The samples it holds.
    pub samples: Range<u32>,
}

impl Part {
    /// Reads and checks a part file: a regular file (checked before it is opened: a FIFO would
    /// block), readable, with raw channels and a sample range, whose attributes lie in their
    /// ranges and agree with its sums ([`check`]). The error lists every problem, one a line.
    pub fn read(path: &Path) -> Result<Part, String> {
        let at = |e: String| format!("{}: {e}", path.display());
        crate::image::input_kind::regular_file(path).map_err(|e| at(e.to_string()))?;
        let (image, raw) = crate::image::read_exr_raw(path).map_err(|e| e.to_string())?;
        let samples = image
            .attribute("lapidary.samples")
            .ok_or_else(|| {
                at(
                    "no `lapidary.samples` attribute: not a part file (render one with --samples)"
                        .into(),
                )
            })
            .and_then(|s| parse_range(s).map_err(at))?;
        let film = film_from_raw(image.width, image.height, &raw).map_err(at)?;
        let mut problems = check(&image, &film, &samples);
        problems.extend(stokes::check(&film));
        if !problems.is_empty() {
            return Err(problems.into_iter().map(at).collect::<Vec<_>>().join("\n"));
        }
        Ok(Part {
            path: path.to_path_buf(),
            image,
            film,
            samples,
        })
    }

    /// The value of an attribute ("(none)" when absent).
    pub fn attr(&self, key: &str) -> &str {
        self.image.attribute(key).unwrap_or("(none)")
    }

    /// Whether this part holds every sample it was asked for.
    pub fn complete(&self) -> bool {
        self.image
            .attribute("lapidary.samples_requested")
            .and_then(|s| parse_range(s).ok())
            .is_some_and(|r| r == self.samples)
    }
}

/// Parts merged into one render.
#[derive(Clone, Debug)]
pub struct Merged {
    /// The summed film, equal to the one-machine render's.
    pub film: Film,
    /// Total samples per pixel (`lapidary.spp`).
    pub spp: u32,
    /// Attributes of the merged render (the lowest part's, less [`PART_ONLY`], with
    /// `spp_complete`, `partial`, `dropped` and `render_time` (the parts' sum) set for the whole).
    pub attributes: Vec<(String, String)>,
    /// Sum of the parts' render times in seconds.
    pub render_time: f64,
    /// The parts' PNG exposure in stops.
    pub exposure: f32,
}

/// Merges parts: checks they belong together and cover `0..spp` exactly once, then adds their
/// sums (exact, so the order of `parts` does not matter). The error lists every problem found.
pub fn merge(mut parts: Vec<Part>) -> Result<Merged, String> {
    let Some(first) = parts.first() else {
        return Err("no part files given".into());
    };
    let mut problems = Vec::new();
    for p in &parts[1..] {
        if (p.image.width, p.image.height) != (first.image.width, first.image.height) {
            problems.push(format!(
                "{} is {}x{} but {} is {}x{}",
                p.path.display(),
                p.image.width,
                p.image.height,
                first.path.display(),
                first.image.width,
                first.image.height
            ));
        }
        for key in MUST_AGREE {
            if p.attr(key) != first.attr(key) {
                problems.push(format!(
                    "`{key}` is {} in {} but {} in {}",
                    p.attr(key),
                    p.path.display(),
                    first.attr(key),
                    first.path.display()
                ));
            }
        }
    }
    for p in &parts[1..] {
        if p.film.stokes.is_empty() != first.film.stokes.is_empty() {
            let (with, without) = if p.film.stokes.is_empty() {
                (first, p)
            } else {
                (p, first)
            };
            problems.push(format!(
                "{} holds the Stokes sums (rendered with --stokes) but {} does not",
                with.path.display(),
                without.path.display()
            ));
        }
    }
    let spp: u32 = first
        .attr("lapidary.spp")
        .parse()
        .map_err(|_| format!("{}: `lapidary.spp` is not a count", first.path.display()))?;
    parts.sort_by_key(|p| (p.samples.start, p.samples.end));
    let mut covered = 0u32;
    let mut last: Option<&Part> = None;
    for p in &parts {
        if p.samples.end > spp {
            problems.push(format!(
                "{} holds samples {} beyond the render's {spp} spp",
                p.path.display(),
                format_range(&p.samples)
            ));
        }
        if p.samples.start > covered {
            problems.push(format!(
                "samples {} are missing",
                format_range(&(covered..p.samples.start))
            ));
        } else if p.samples.start < covered {
            let prev = last.map_or_else(String::new, |l| l.path.display().to_string());
            problems.push(format!(
                "{} (samples {}) overlaps {prev} at samples {}",
                p.path.display(),
                format_range(&p.samples),
                format_range(&(p.samples.start..covered.min(p.samples.end)))
            ));
        }
        covered = covered.max(p.samples.end);
        last = Some(p);
    }
    if covered < spp {
        problems.push(format!(
            "samples {} are missing",
            format_range(&(covered..spp))
        ));
    }
    if !problems.is_empty() {
        return Err(problems.join("\n"));
    }
    // Rays are the one sum no range bounds: forged counts must not overflow.
    let rays = |i: usize| {
        parts
            .iter()
            .try_fold(0u64, |a, p| a.checked_add(p.film.pixels[i].rays))
    };
    if let Some(i) = (0..parts[0].film.pixels.len()).find(|&i| rays(i).is_none()) {
        return Err(format!(
            "the parts' `raw.rays` of pixel {i} add up to more than 2^64: not rays a render traced"
        ));
    }
    let mut film = parts[0].film.clone();
    for p in &parts[1..] {
        for (a, b) in film.pixels.iter_mut().zip(&p.film.pixels) {
            a.merge(b);
        }
        stokes::merge(&mut film.stokes, &p.film.stokes);
    }
    let render_time: f64 = parts
        .iter()
        .filter_map(|p| {
            p.image
                .attribute("lapidary.render_time")?
                .parse::<f64>()
                .ok()
        })
        .sum();
    let dropped = film.dropped();
    let attributes = parts[0]
        .image
        .attributes
        .iter()
        .filter(|(k, _)| !PART_ONLY.contains(&k.as_str()))
        .map(|(k, v)| {
            let v = match k.as_str() {
                "lapidary.spp_complete" => spp.to_string(),
                "lapidary.partial" => "false".to_string(),
                "lapidary.dropped" => dropped.to_string(),
                "lapidary.render_time" => format!("{render_time:.3}"),
                _ => v.clone(),
            };
            (k.clone(), v)
        })
        .collect();
    let exposure = parts[0].attr("lapidary.exposure").parse().unwrap_or(0.0);
    Ok(Merged {
        film,
        spp,
        attributes,
        render_time,
        exposure,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_parse_and_refuse_nonsense() {
        assert_eq!(parse_range("0..64"), Ok(0..64));
        assert_eq!(parse_range(" 3 .. 5 "), Ok(3..5));
        for bad in [
            "5..5",
            "6..2",
            "1-4",
            "..3",
            "a..b",
            "+1..3",
            "0..4294967296",
        ] {
            assert!(parse_range(bad).is_err(), "{bad}");
        }
        assert_eq!(parse_range("0..1048576"), Ok(0..MAX_SPP));
        for big in [
            "0..18446744073709551615",
            "0..1048577",
            "99999999999999999999999..3",
        ] {
            let e = parse_range(big).unwrap_err();
            assert!(
                e.contains("is too large") && e.contains("0..1048576"),
                "{e}"
            );
        }
    }

    /// Every word of every field survives the raw channels, including negative sums.
    #[test]
    fn raw_channels_round_trip_exactly() {
        let mut film = Film::new(2, 1);
        film.pixels[0] = PixelSums {
            sum: [-(1i128 << 100) - 7, 1, i128::MAX],
            sum_sq: [u128::MAX, 0, 1u128 << 96],
            n: 9,
            dropped: 2,
            albedo: [-5, i64::MIN, i64::MAX],
            normal: [1, -1, 1 << 40],
            depth: -(1i128 << 90),
            depth_n: 7,
            material: -2,
            rays: u64::MAX - 3,
        };
        let raw = raw_channels(&film);
        assert_eq!(raw.len(), 46);
        assert_eq!(film_from_raw(2, 1, &raw), Ok(film));
        let err = film_from_raw(2, 1, &raw[1..]).unwrap_err();
        assert!(err.contains("raw.sum.R.0"), "{err}");
    }
}
