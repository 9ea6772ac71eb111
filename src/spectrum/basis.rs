//! A linear RGB → spectrum map for values a model has already computed in RGB (a coated layer
//! stack's `f`, whose tables are per RGB channel: [`crate::bsdf::spectral`]).
//!
//! Recipe colours go through Jakob & Hanika's table ([`super::rgb2spec`]): one lookup per colour,
//! memoised, because a recipe has few. A stack's value changes with every direction, and the
//! table's scattered reads then cost a quarter of a spectral path. This map is Smits'
//! construction (B. Smits, "An RGB-to-Spectrum Conversion for Reflectances", Journal of Graphics
//! Tools 4(4), 1999): with the channels sorted `lo ≤ mid ≤ hi`,
//!
//! `s(λ) = lo · 1 + (mid − lo) · secondary(λ) + (hi − mid) · primary(λ)`,
//!
//! where `secondary` is the two-channel colour of the two largest channels (cyan, magenta or
//! yellow) and `primary` the largest channel's colour. Here the six basis spectra are not Smits'
//! tabulated ones but this project's Jakob–Hanika fits of the pure colours (each within the
//! table's ΔE76 of its colour), read from a 1 nm table. The map is linear in the value's scale,
//! exactly flat for a grey, non-negative for a non-negative colour, at most `max(rgb)` for a
//! reflectance (each basis spectrum is ≤ 1 and the weights sum to `hi`), and its colour is the
//! input's to the basis spectra's fit error (tested below).

use super::cie::{CMF_SAMPLES, LAMBDA_MIN};
use super::rgb2spec;
use std::sync::OnceLock;

/// The six basis spectra at 1 nm over 360–830 nm: cyan, magenta, yellow, red, green, blue.
struct Basis([[f32; CMF_SAMPLES]; 6]);

fn basis() -> &'static Basis {
    static BASIS: OnceLock<Basis> = OnceLock::new();
    BASIS.get_or_init(|| {
        let colours = [
            [0.0, 1.0, 1.0],
            [1.0, 0.0, 1.0],
            [1.0, 1.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        Basis(colours.map(|c| {
            let s = rgb2spec::reflectance(c);
            std::array::from_fn(|i| s.eval(LAMBDA_MIN + i as f32))
        }))
    })
}

/// Index of the cyan, magenta, yellow, red, green, blue basis spectra.
const CYAN: usize = 0;
const MAGENTA: usize = 1;
const YELLOW: usize = 2;
const RED: usize = 3;
const GREEN: usize = 4;
const BLUE: usize = 5;

/// Builds the basis now (six table lookups; the table itself is built on first use).
pub fn warm_up() {
    basis();
}

/// The spectrum of the linear sRGB value `rgb` (negative or NaN channels count as 0) at the
/// wavelengths `lambda` (nm, clamped to 360–830).
#[inline]
pub fn upsample<const N: usize>(rgb: [f32; 3], lambda: &[f32; N]) -> [f32; N] {
    let [r, g, b] = rgb.map(|v| if v > 0.0 { v } else { 0.0 });
    // (lo, secondary weight and index, primary weight and index), Smits 1999.
    let (lo, w2, i2, w1, i1) = if r <= g && r <= b {
        if g <= b {
            (r, g - r, CYAN, b - g, BLUE)
        } else {
            (r, b - r, CYAN, g - b, GREEN)
        }
    } else if g <= r && g <= b {
        if r <= b {
            (g, r - g, MAGENTA, b - r, BLUE)
        } else {
            (g, b - g, MAGENTA, r - b, RED)
        }
    } else if r <= g {
        (b, r - b, YELLOW, g - r, GREEN)
    } else {
        (b, g - b, YELLOW, r - g, RED)
    };
    if w2 == 0.0 && w1 == 0.0 {
        return [lo; N];
    }
    let t = &basis().0;
    lambda.map(|l| {
        let x = l - LAMBDA_MIN;
        let i = super::wavelengths::index(x, CMF_SAMPLES - 2);
        let f = (x - i as f32).clamp(0.0, 1.0);
        let at = |k: usize| t[k][i] + f * (t[k][i + 1] - t[k][i]);
        lo + w2 * at(i2) + w1 * at(i1)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::rgb2spec::reflectance_to_rgb;

    fn at(rgb: [f32; 3], l: f32) -> f32 {
        upsample(rgb, &[l])[0]
    }

    #[test]
    fn greys_are_flat_and_scale_is_linear() {
        for v in [0.0f32, 0.3, 1.0, 7.5] {
            for l in [360.0f32, 500.0, 830.0] {
                assert_eq!(at([v; 3], l), v);
            }
        }
        let c = [0.2f32, 0.7, 0.4];
        for l in [400.0f32, 555.5, 700.0] {
            assert!((at(c.map(|v| 3.0 * v), l) - 3.0 * at(c, l)).abs() < 1e-5);
        }
    }

    /// Colours round-trip (under D65, white-balanced) within the basis spectra's own fit error;
    /// reflectances stay in [0, max(rgb)].
    #[test]
    fn colours_round_trip() {
        let mut worst = 0.0f32;
        let steps = 9;
        for i in 0..steps {
            for j in 0..steps {
                for k in 0..steps {
                    let c = [i, j, k].map(|v| v as f32 / (steps - 1) as f32);
                    let back = reflectance_to_rgb(|l| at(c, l));
                    for ch in 0..3 {
                        worst = worst.max((back[ch] - c[ch]).abs());
                    }
                    let hi = c[0].max(c[1]).max(c[2]);
                    for l in (360..=830).step_by(10) {
                        let v = at(c, l as f32);
                        assert!((0.0..=hi + 1e-6).contains(&v), "{c:?} at {l}: {v}");
                    }
                }
            }
        }
        assert!(worst < 4e-3, "worst channel error {worst}");
    }
}
