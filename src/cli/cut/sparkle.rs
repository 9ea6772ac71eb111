//! The cut report's spot lighting and what it measures: fire and scintillation (docs/cuts.md).
//!
//! **The spots**: a black sky holding small white discs of angular radius [`SPOT_HALF_ANGLE`],
//! [`SPOT_SPACING`] apart in rings of elevation from the horizon up to the head shadow
//! ([`super::report::HEAD_HALF_ANGLE`]) — a ceiling of point-like lamps, as the fire and
//! scintillation of a cut are judged (GIA's fire metric: "dispersed colored light return" under
//! spot lighting, Reinitz et al., Gems & Gemology 37(3) 2001; scintillation as the sparkles that
//! flash on and off as the stone moves, Moses et al., Gems & Gemology 40(3) 2004; Sasian et al.,
//! Optical Engineering 46(9) 2007). Each disc has radiance 1, so a pixel's luminance is the share
//! of a spot's light the stone returns to it. The face-up view is orthographic, so all the pixels
//! of a facet's path see one direction: a sparkle is such a region whose direction meets a spot.
//!
//! - **Fire**: dispersion fans a white ray into colours, so a pixel that sees a spot through the
//!   stone sees only part of the spectrum. A pixel's colour `c` departs from the body's tint `t`
//!   by `c − Y(c) t` (`Y` the luminance, `t` the stone's mean colour per unit luminance: white for
//!   a colourless stone; summed over the pixels, dispersion's colours give back the tint). The
//!   fire is the root mean square of that departure over the stone's pixels, in units of a
//!   spot's radiance — the coloured light dispersion returns. A stone without dispersion has
//!   none. The mean square is estimated without the bias of render noise (a noisy grey pixel
//!   looks coloured): the view is rendered as two independent halves and each pixel contributes
//!   the dot product of the two halves' departures, whose expectation is the noise-free
//!   departure's squared length.
//! - **Scintillation**: a pixel *sparkles* when its luminance is at least [`SPARKLE`] of a
//!   spot's. The report counts the sparkles (4-connected groups of sparkling pixels) and renders
//!   the stone again [`TILT_STEP`] further tilted: the scintillation is the share of the stone's
//!   pixels that turn on or off, per degree of tilt.

use super::report::{Estimate, jackknife, luminance};
use crate::image::RgbImage;
use crate::render::film::Film;
use glam::DVec3;

/// Angular radius of each spot, degrees (GUESS: a 7 cm lamp 2 m away).
pub const SPOT_HALF_ANGLE: f64 = 1.0;

/// Angle between neighbouring spots, degrees: the rings lie at elevations `½, 1½, 2½ … ×` this
/// up to the head shadow, each with as many spots as fit this far apart (GUESS: lamps 20 cm
/// apart on a ceiling 2 m above; 545 lamps covering 2.8 % of the sky below the head shadow).
pub const SPOT_SPACING: f64 = 6.0;

/// The spot map's rows (a quarter degree each; twice as many columns).
const MAP_ROWS: u32 = 720;

/// Luminance, as a share of a spot's, from which a pixel sparkles (GUESS: five times below a
/// diamond table's single Fresnel reflection of 0.17, so every spot seen through or on the stone
/// counts).
pub const SPARKLE: f64 = 0.05;

/// The extra tilt of the second spot view the scintillation compares with, degrees.
pub const TILT_STEP: f32 = 1.0;

/// The unit directions toward the spots (y up; azimuth 0 toward −z, the top of the face-up view).
pub fn spot_directions() -> Vec<DVec3> {
    let top = 90.0 - super::report::HEAD_HALF_ANGLE;
    let mut out = vec![];
    let mut e = 0.5 * SPOT_SPACING;
    while e + SPOT_HALF_ANGLE <= top {
        let er = e.to_radians();
        let n = (360.0 * er.cos() / SPOT_SPACING).round().max(1.0) as usize;
        for j in 0..n {
            let phi = std::f64::consts::TAU * j as f64 / n as f64;
            out.push(DVec3::new(
                er.cos() * phi.sin(),
                er.sin(),
                -er.cos() * phi.cos(),
            ));
        }
        e += SPOT_SPACING;
    }
    out
}

/// Whether direction `dir` (unit) meets a spot.
pub fn meets_spot(dir: DVec3, spots: &[DVec3]) -> bool {
    let cos = SPOT_HALF_ANGLE.to_radians().cos();
    spots.iter().any(|s| s.dot(dir) >= cos)
}

/// The spots as a lat-long environment map (row 0 the zenith, column 0 at azimuth −π, the
/// convention of [`crate::light::EnvironmentLight`]), each pixel the share of it a spot covers
/// (4 × 4 samples per pixel).
pub fn spot_map() -> RgbImage {
    let (w, h) = (2 * MAP_ROWS, MAP_ROWS);
    let mut pixels = vec![[0.0f32; 3]; (w * h) as usize];
    let spots = spot_directions();
    let dir = |u: f64, v: f64| {
        let (theta, phi) = (std::f64::consts::PI * v, std::f64::consts::TAU * (u - 0.5));
        DVec3::new(
            theta.sin() * phi.sin(),
            theta.cos(),
            -theta.sin() * phi.cos(),
        )
    };
    let pad = SPOT_HALF_ANGLE + 0.5;
    for s in &spots {
        // The window of pixels around the spot: rows within its polar span, columns within its
        // azimuth span at that latitude.
        let theta = s.y.clamp(-1.0, 1.0).acos().to_degrees();
        let phi = s.x.atan2(-s.z).to_degrees();
        let per_row = 180.0 / f64::from(h);
        let r0 = ((theta - pad) / per_row).floor().max(0.0) as u32;
        let r1 = (((theta + pad) / per_row).ceil() as u32).min(h);
        let span = pad / (theta - pad).to_radians().sin().max(1e-3);
        let c_mid = (phi / 360.0 + 0.5) * f64::from(w);
        let c_span = (span / 360.0 * f64::from(w)).ceil() as i64;
        for r in r0..r1 {
            for dc in -c_span..=c_span {
                let c = (c_mid.floor() as i64 + dc).rem_euclid(i64::from(w)) as u32;
                let mut hit = 0;
                for k in 0..16 {
                    let (su, sv) = ((k % 4) as f64 + 0.5, (k / 4) as f64 + 0.5);
                    let d = dir(
                        (f64::from(c) + su / 4.0) / f64::from(w),
                        (f64::from(r) + sv / 4.0) / f64::from(h),
                    );
                    hit += usize::from(d.dot(*s) >= SPOT_HALF_ANGLE.to_radians().cos());
                }
                let px = &mut pixels[(r * w + c) as usize];
                px[0] += hit as f32 / 16.0;
            }
        }
    }
    for p in &mut pixels {
        let v = p[0].min(1.0);
        *p = [v; 3];
    }
    RgbImage {
        width: w,
        height: h,
        pixels,
    }
}

/// The fire over the pixels of `mask` from two independent renders of one spot view; `None` when
/// the mask is empty. The standard error is a jackknife over groups of pixels.
pub fn fire(halves: [&Film; 2], mask: &[bool]) -> Option<Estimate> {
    let colours: Vec<[[f64; 3]; 2]> = (0..mask.len())
        .filter(|&i| mask[i])
        .map(|i| halves.map(|f| f.pixels[i].mean().0.map(f64::from)))
        .collect();
    let lum = |c: [f64; 3]| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    // The body's tint: the stone's mean colour per unit luminance (dispersion spreads each
    // spot's light over pixels but keeps its spectrum in the sum).
    let (mut sum, mut total) = ([0.0f64; 3], 0.0);
    for c in colours.iter().flatten() {
        (0..3).for_each(|k| sum[k] += c[k]);
        total += lum(*c);
    }
    if colours.is_empty() {
        return None;
    }
    let tint = if total > 0.0 {
        sum.map(|s| s / total)
    } else {
        [1.0; 3]
    };
    let departure = |c: [f64; 3]| {
        let l = lum(c);
        [0, 1, 2].map(|k| c[k] - l * tint[k])
    };
    let values: Vec<f64> = colours
        .iter()
        .map(|[a, b]| {
            let (a, b) = (departure(*a), departure(*b));
            a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
        })
        .collect();
    Some(jackknife(&values, |v| {
        (v.iter().sum::<f64>() / v.len().max(1) as f64)
            .max(0.0)
            .sqrt()
    }))
}

/// Which pixels of a view (its linear RGB pixels) sparkle — luminance at least [`SPARKLE`]; outside
/// `mask` none.
pub fn sparkling(rgb: &[[f32; 3]], mask: &[bool]) -> Vec<bool> {
    rgb.iter()
        .zip(mask)
        .map(|(&c, &m)| m && luminance(c) >= SPARKLE)
        .collect()
}

/// The share of the pixels of `mask` that sparkle, with its binomial standard error.
pub fn share(on: &[bool], mask: &[bool]) -> Option<Estimate> {
    let n = mask.iter().filter(|&&m| m).count();
    let lit = on.iter().zip(mask).filter(|(o, m)| **o && **m).count();
    (n > 0).then(|| Estimate::binomial(lit as f64 / n as f64, n))
}

/// Fewest pixels a sparkle covers: a lone sparkling pixel is most often render noise (a grey
/// facet's pixel whose few samples all happened to see a spot), and the facets' regions a
/// report's views resolve cover many pixels.
pub const MIN_SPARKLE_PIXELS: usize = 3;

/// Number of sparkles: 4-connected groups of at least [`MIN_SPARKLE_PIXELS`] sparkling pixels in
/// a `size`-wide view.
pub fn count_sparkles(on: &[bool], size: u32) -> u32 {
    let w = size as usize;
    let mut seen = vec![false; on.len()];
    let mut stack = vec![];
    let mut count = 0;
    for start in 0..on.len() {
        if !on[start] || seen[start] {
            continue;
        }
        seen[start] = true;
        stack.push(start);
        let mut pixels = 0;
        while let Some(i) = stack.pop() {
            pixels += 1;
            let (x, y) = (i % w, i / w);
            let mut visit = |j: usize| {
                if on[j] && !seen[j] {
                    seen[j] = true;
                    stack.push(j);
                }
            };
            if x > 0 {
                visit(i - 1);
            }
            if x + 1 < w {
                visit(i + 1);
            }
            if y > 0 {
                visit(i - w);
            }
            if i + w < on.len() {
                visit(i + w);
            }
        }
        count += u32::from(pixels >= MIN_SPARKLE_PIXELS);
    }
    count
}

/// The scintillation between two sparkle maps `step` degrees of tilt apart: the share of the
/// pixels of either view's stone (`mask_a ∪ mask_b`) that sparkle in one view and not the other,
/// per degree, with its binomial standard error; `None` when neither view shows the stone.
pub fn scintillation(
    a: &[bool],
    b: &[bool],
    mask_a: &[bool],
    mask_b: &[bool],
    step: f32,
) -> Option<Estimate> {
    let (mut n, mut changed) = (0usize, 0usize);
    for i in 0..a.len() {
        if mask_a[i] || mask_b[i] {
            n += 1;
            changed += usize::from(a[i] != b[i]);
        }
    }
    (n > 0).then(|| {
        let e = Estimate::binomial(changed as f64 / n as f64, n);
        let per = f64::from(step.abs().max(1e-3));
        Estimate {
            value: e.value / per,
            se: e.se / per,
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spots_lie_below_the_head_shadow_and_the_map_holds_them() {
        let spots = spot_directions();
        assert!(spots.len() > 300, "{}", spots.len());
        let top = (90.0 - super::super::report::HEAD_HALF_ANGLE)
            .to_radians()
            .sin();
        for (i, s) in spots.iter().enumerate() {
            assert!((s.length() - 1.0).abs() < 1e-12);
            assert!(s.y > 0.0 && s.y < top);
            // Neighbours no closer than the spacing allows (no overlap).
            for t in &spots[..i] {
                assert!(s.angle_between(*t).to_degrees() > 2.0 * SPOT_HALF_ANGLE);
            }
        }
        assert!(
            spots[0].z < 0.0 && spots[0].x.abs() < 1e-12,
            "the first toward −z"
        );
        // The map's pixels are lit where the directions meet a spot: every pixel whose centre is
        // inside a spot (away from its rim) is fully lit, every one outside dark.
        let map = spot_map();
        let (w, h) = (map.width as usize, map.height as usize);
        let mut lit = 0usize;
        for r in 0..h {
            for c in 0..w {
                let (u, v) = ((c as f64 + 0.5) / w as f64, (r as f64 + 0.5) / h as f64);
                let (theta, phi) = (std::f64::consts::PI * v, std::f64::consts::TAU * (u - 0.5));
                let d = DVec3::new(
                    theta.sin() * phi.sin(),
                    theta.cos(),
                    -theta.sin() * phi.cos(),
                );
                let nearest = spots
                    .iter()
                    .map(|s| s.angle_between(d))
                    .fold(f64::MAX, f64::min);
                let value = map.pixels[r * w + c][0];
                if nearest.to_degrees() < SPOT_HALF_ANGLE - 0.4 {
                    assert_eq!(value, 1.0, "row {r} column {c}");
                    lit += 1;
                } else if nearest.to_degrees() > SPOT_HALF_ANGLE + 0.4 {
                    assert_eq!(value, 0.0, "row {r} column {c}");
                }
                assert_eq!(
                    meets_spot(d, &spots),
                    nearest <= SPOT_HALF_ANGLE.to_radians() + 1e-12
                );
            }
        }
        assert!(lit > spots.len(), "{lit}");
    }

    #[test]
    fn sparkles_are_counted_as_connected_groups() {
        #[rustfmt::skip]
        let on = [
            true,  true,  false, false,
            false, false, false, true,
            true,  false, true,  true,
            true,  false, false, false,
        ];
        // Groups of 2, 3 and 2 pixels (4-connected: pixels 7, 10 and 11 join through 11):
        // only the one of MIN_SPARKLE_PIXELS counts.
        assert_eq!(MIN_SPARKLE_PIXELS, 3);
        assert_eq!(count_sparkles(&on, 4), 1);
        assert_eq!(count_sparkles(&[false; 16], 4), 0);
        assert_eq!(count_sparkles(&[true; 16], 4), 1);
    }

    #[test]
    fn scintillation_counts_changes_over_either_stone() {
        let a = [true, false, true, false];
        let b = [true, true, false, false];
        let m = [true, true, true, false];
        let s = scintillation(&a, &b, &m, &m, 2.0).unwrap();
        assert!((s.value - (2.0 / 3.0) / 2.0).abs() < 1e-12);
        assert!(scintillation(&a, &b, &[false; 4], &[false; 4], 1.0).is_none());
    }
}
