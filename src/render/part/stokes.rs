//! The Stokes sums of a part render (`--stokes --samples A..B`): like the radiance sums, exact
//! fixed-point integers ([`crate::render::fixed`]) stored as 32-bit words, so that parts merge into
//! the one-machine render's Stokes AOVs bit for bit. Channels `raw.stokes.S{k}.{R,G,B}.{w}`, the
//! four Stokes components per colour channel, each `i128` as four words, least significant first;
//! present exactly when the render measured the Stokes vector.

use crate::image::RawChannel;
use crate::render::film::{Film, StokesSums};
use crate::render::fixed;

/// Colour channels' names, in the order of a sum's inner index.
const COLOURS: [&str; 3] = ["R", "G", "B"];

/// The name of word `w` of Stokes component `k`, colour channel `c`.
fn name(k: usize, c: usize, w: u32) -> String {
    format!("raw.stokes.S{k}.{}.{w}", COLOURS[c])
}

/// The film's Stokes sums as exact integer channels (none when the film has none).
pub fn raw_channels(film: &Film) -> Vec<RawChannel> {
    let mut out = Vec::new();
    if film.stokes.is_empty() {
        return out;
    }
    for k in 0..4 {
        for c in 0..3 {
            for w in 0..4 {
                out.push(RawChannel {
                    name: name(k, c, w),
                    data: film
                        .stokes
                        .iter()
                        .map(|s| (s.0[k][c] as u128 >> (32 * w)) as u32)
                        .collect(),
                });
            }
        }
    }
    out
}

/// The Stokes sums of a part's `n` pixels, read back from its raw channels: empty when the part
/// has none, an error naming a missing or short channel when it has some but not all.
pub fn from_raw(n: usize, raw: &[RawChannel]) -> Result<Vec<StokesSums>, String> {
    if !raw.iter().any(|c| c.name.starts_with("raw.stokes.")) {
        return Ok(Vec::new());
    }
    let mut out = vec![StokesSums::default(); n];
    for k in 0..4 {
        for c in 0..3 {
            for w in 0..4 {
                let want = name(k, c, w);
                let channel = raw
                    .iter()
                    .find(|ch| ch.name == want)
                    .ok_or_else(|| format!("no channel `{want}` beside the other Stokes sums"))?;
                if channel.data.len() != n {
                    return Err(format!(
                        "channel `{want}` has {} values, not {n}",
                        channel.data.len()
                    ));
                }
                for (s, &v) in out.iter_mut().zip(&channel.data) {
                    let bits = s.0[k][c] as u128 | u128::from(v) << (32 * w);
                    s.0[k][c] = bits as i128;
                }
            }
        }
    }
    Ok(out)
}

/// What a part's Stokes sums say that its kept samples cannot make: each sample adds a component
/// clamped to ±2⁶⁰ ([`StokesSums::add`]), so no sum exceeds `n` times that. The first pixel that
/// breaks it and how many more do, or `None`.
pub fn check(film: &Film) -> Option<String> {
    if film.stokes.is_empty() {
        return None;
    }
    let limit = fixed::radiance(fixed::RADIANCE_LIMIT) as u128;
    let broken = film
        .pixels
        .iter()
        .zip(&film.stokes)
        .enumerate()
        .filter(|(_, (p, s))| {
            let most = u128::from(p.n).saturating_mul(limit);
            s.0.iter().flatten().any(|v| v.unsigned_abs() > most)
        })
        .map(|(i, (p, _))| {
            let m = format!(
                "`raw.stokes` beyond what {} kept samples of at most 2^60 can add up to",
                p.n
            );
            (i, m)
        });
    super::check::first_broken(film, broken)
}

/// Adds `other`'s Stokes sums to `sums` (exact: the order of parts does not matter).
pub fn merge(sums: &mut [StokesSums], other: &[StokesSums]) {
    for (a, b) in sums.iter_mut().zip(other) {
        a.merge(b);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every word survives the channels, negative sums included; a film without Stokes sums has
    /// no channels; a missing word is named.
    #[test]
    fn stokes_sums_round_trip_exactly() {
        let mut film = Film::new(2, 1);
        film.pixels[0].n = 3;
        film.stokes = vec![StokesSums::default(); 2];
        film.stokes[0].0[0] = [-(1i128 << 100) - 7, 1, 5];
        film.stokes[1].0[3] = [i128::MIN + 1, -1, 1i128 << 70];
        let raw = raw_channels(&film);
        assert_eq!(raw.len(), 48);
        assert_eq!(from_raw(2, &raw), Ok(film.stokes.clone()));
        assert!(raw_channels(&Film::new(2, 1)).is_empty());
        assert_eq!(from_raw(2, &[]), Ok(Vec::new()));
        let err = from_raw(2, &raw[1..]).unwrap_err();
        assert!(err.contains("raw.stokes.S0.R.0"), "{err}");
    }

    /// Sums that many samples can make pass; one beyond `n` clamped samples is named.
    #[test]
    fn impossible_stokes_sums_are_named() {
        let mut film = Film::new(2, 1);
        film.pixels[0].n = 2;
        film.stokes = vec![StokesSums::default(); 2];
        let one = fixed::radiance(fixed::RADIANCE_LIMIT);
        film.stokes[0].0[1][2] = -2 * one;
        assert_eq!(check(&film), None);
        film.stokes[0].0[1][2] = -2 * one - 1;
        let e = check(&film).unwrap();
        assert!(
            e.contains("pixel (0, 0)") && e.contains("raw.stokes"),
            "{e}"
        );
        // A pixel that kept no samples can hold no Stokes sum.
        film.stokes[0].0[1][2] = 0;
        film.stokes[1].0[0][0] = 1;
        assert!(check(&film).unwrap().contains("pixel (1, 0)"));
    }

    #[test]
    fn merging_adds_every_component() {
        let mut a = vec![StokesSums([[1, 2, 3], [4, 5, 6], [7, 8, 9], [-1, -2, -3]])];
        merge(&mut a, &[StokesSums([[10; 3], [20; 3], [30; 3], [40; 3]])]);
        assert_eq!(
            a[0].0,
            [[11, 12, 13], [24, 25, 26], [37, 38, 39], [39, 38, 37]]
        );
    }
}
