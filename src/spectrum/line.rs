//! A narrow emission line (issue 20): a laser's or a monochromatic lamp's spectrum, a Gaussian of
//! given centre and full width at half maximum, evaluated exactly at a path's wavelengths (the
//! 10 nm grid of [`super::measured`] would widen a 1 nm line tenfold and move its centre to a
//! grid point).
//!
//! `L(λ) = s · exp(−(λ − λ₀)² / (2σ²))`, `σ = FWHM / (2 √(2 ln 2))`; `s` is chosen so that the
//! line has a given luminance. Its RGB colour (for RGB renders) is the line's CIE XYZ through the
//! sRGB matrix with negative channels clamped to 0, as for measured emission: a 532 nm laser lies
//! outside the sRGB gamut, and what the clamp loses is part of what `lapidary tradeoff`'s
//! `spectral` knob measures.

use super::cie::{self, CIE_Y_INTEGRAL};
use crate::color::Rgb;
use glam::Vec3;

/// Narrowest and widest line a recipe may give, nm (FWHM).
pub const FWHM_RANGE: (f32, f32) = (0.1, 100.0);

/// A Gaussian emission line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Line {
    /// Centre, nm.
    pub center: f32,
    /// Standard deviation, nm.
    sigma: f32,
    /// Peak value (radiance per nm at the centre).
    scale: f32,
    /// [`Line::support`], computed once.
    support: (f32, f32),
}

impl Line {
    /// A line of peak 1 at `center` nm with full width at half maximum `fwhm` nm.
    pub fn new(center: f32, fwhm: f32) -> Line {
        Line {
            center,
            sigma: fwhm / (2.0 * (2.0 * std::f32::consts::LN_2).sqrt()),
            scale: 1.0,
            support: (
                (center - 2.0 * fwhm).max(super::cie::LAMBDA_MIN),
                (center + 2.0 * fwhm).min(super::cie::LAMBDA_MAX),
            ),
        }
    }

    /// The interval `[lo, hi]` that importance sampling draws from for this line: ±2 FWHM
    /// around the centre (99.99 % of the Gaussian's area), clipped to 360 ..= 830 nm.
    #[inline]
    pub fn support(&self) -> (f32, f32) {
        self.support
    }

    /// `L(λ)`.
    #[inline]
    pub fn eval(&self, lambda: f32) -> f32 {
        let x = (lambda - self.center) / self.sigma;
        if x.abs() > 12.0 {
            0.0
        } else {
            self.scale * (-0.5 * x * x).exp()
        }
    }

    /// The midpoint rule's grid over ±6σ: its start, step and node count (2000); node `k` is at
    /// `start + (k + ½) step`.
    fn grid(&self) -> (f32, f32, usize) {
        let n = 2000;
        let (lo, hi) = (
            self.center - 6.0 * self.sigma,
            self.center + 6.0 * self.sigma,
        );
        (lo, (hi - lo) / n as f32, n)
    }

    /// The line as quadrature nodes `(λ, L(λ) dλ)` on [`Line::xyz`]'s grid (nm, radiance per
    /// node). Integrals against smooth functions of λ (colour-matching functions, reflectances)
    /// read it instead of a 1 nm grid, which a 1 nm wide line falls between.
    pub fn nodes(&self) -> impl Iterator<Item = (f32, f32)> {
        let line = *self;
        let (lo, h, n) = self.grid();
        (0..n).map(move |k| {
            let l = lo + (k as f32 + 0.5) * h;
            (l, line.eval(l) * h)
        })
    }

    /// CIE XYZ of the line, normalised like [`cie::spectrum_to_xyz`] (`∫ L x̄ / ∫ ȳ` …), by the
    /// midpoint rule over ±6σ in 2000 steps.
    pub fn xyz(&self) -> Vec3 {
        let (_, h, _) = self.grid();
        let mut sum = Vec3::ZERO;
        for (l, _) in self.nodes() {
            sum += cie::xyz_bar(l) * self.eval(l);
        }
        sum * (h / CIE_Y_INTEGRAL)
    }

    /// The same line scaled to luminance `y` (unchanged if it has none in the visible range).
    pub fn with_luminance(mut self, y: f32) -> Line {
        let have = self.xyz().y;
        if have > 0.0 && y.is_finite() && y >= 0.0 {
            self.scale *= y / have;
        }
        self
    }

    /// The line's linear Rec.709 colour as emitted radiance (module docs).
    pub fn to_rgb_emission(&self) -> Rgb {
        let c = cie::xyz_to_linear_srgb(self.xyz());
        Rgb::new(c.x.max(0.0), c.y.max(0.0), c.z.max(0.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_has_its_luminance_width_and_colour() {
        let l = Line::new(532.0, 1.0).with_luminance(2.0);
        assert!((l.xyz().y - 2.0).abs() < 1e-4, "{}", l.xyz().y);
        // Half maximum half a FWHM from the centre.
        assert!((l.eval(532.5) / l.eval(532.0) - 0.5).abs() < 1e-5);
        assert_eq!(l.eval(560.0), 0.0);
        // A 532 nm laser is saturated green: R and B clamp to 0 (outside the gamut).
        let c = l.to_rgb_emission();
        assert!(c[1] > 0.0 && c[0] == 0.0 && c[2] == 0.0, "{c:?}");
        // Its area: peak × σ √(2π).
        let area: f32 = (0..4000)
            .map(|k| l.eval(522.0 + k as f32 * 0.005) * 0.005)
            .sum();
        let sigma = 1.0 / (2.0 * (2.0 * std::f32::consts::LN_2).sqrt());
        let want = l.eval(532.0) * sigma * (2.0 * std::f32::consts::PI).sqrt();
        assert!((area / want - 1.0).abs() < 1e-3, "{area} vs {want}");
    }
}
