//! Measured spectra a recipe gives as `(wavelength nm, value)` points (issue 19): resampled once
//! to a fixed 10 nm grid over 360–830 nm, read by linear interpolation at a path's wavelengths,
//! and projected to a linear Rec.709 triple for RGB renders.
//!
//! **Resampling.** The points define a piecewise-linear function (constant beyond the first and
//! last point). Each grid value is that function's mean over the 10 nm cell around the grid
//! wavelength (ten midpoint samples 1 nm apart), so a feature narrower than the grid keeps its area rather
//! than being missed between two grid points. 48 values (`Copy`, no allocation on the hot path).
//!
//! **RGB.** A coefficient spectrum (absorption, scattering) projects as a reflectance does: the
//! D65-weighted, white-balanced linear sRGB of the spectrum ([`super::rgb2spec::reflectance_to_rgb`]),
//! so a flat spectrum `c` is exactly the grey `c`. Negative channels (a narrow spectrum outside
//! the sRGB gamut) are clamped to 0 for the RGB render, which cannot represent them.

use super::rgb2spec::reflectance_to_rgb;
use super::wavelengths::LAMBDA_MIN;
use crate::color::Rgb;

/// Grid spacing, nm.
pub const STEP: f32 = 10.0;
/// Grid values: 360, 370, …, 830 nm.
pub const SAMPLES: usize = 48;
/// Most points a recipe spectrum may have.
pub const MAX_POINTS: usize = 4096;

/// A spectrum on the 10 nm grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measured {
    values: [f32; SAMPLES],
}

impl Measured {
    /// The spectrum through `points` (`(nm, value)`, wavelengths strictly increasing in
    /// 200 ..= 2000 nm, values finite in `0 ..= max`, 2 ..= [`MAX_POINTS`] points), or what is
    /// wrong with them.
    pub fn from_points(points: &[(f32, f32)], max: f32) -> Result<Measured, String> {
        if points.len() < 2 || points.len() > MAX_POINTS {
            return Err(format!(
                "a spectrum has {} points: allowed 2 ..= {MAX_POINTS}",
                points.len()
            ));
        }
        for (i, &(l, v)) in points.iter().enumerate() {
            if !(200.0..=2000.0).contains(&l) {
                return Err(format!(
                    "spectrum point {i}: wavelength {l} nm is out of range: allowed 200 ..= 2000"
                ));
            }
            if !(v.is_finite() && (0.0..=max).contains(&v)) {
                return Err(format!(
                    "spectrum point {i} ({l} nm): value {v} is out of range: allowed 0 ..= {max}"
                ));
            }
            if i > 0 && !(l > points[i - 1].0) {
                return Err(format!(
                    "spectrum point {i}: wavelength {l} nm does not increase (after {} nm)",
                    points[i - 1].0
                ));
            }
        }
        let f = |l: f32| {
            let k = points.partition_point(|p| p.0 <= l);
            if k == 0 {
                points[0].1
            } else if k == points.len() {
                points[k - 1].1
            } else {
                let (a, b) = (points[k - 1], points[k]);
                a.1 + (l - a.0) / (b.0 - a.0) * (b.1 - a.1)
            }
        };
        let values = std::array::from_fn(|i| {
            let c = LAMBDA_MIN + i as f32 * STEP;
            let s: [f32; 10] = std::array::from_fn(|d| f(c - 4.5 + d as f32));
            if s.iter().all(|&v| v == s[0]) {
                s[0] // exact where the spectrum is flat (no rounding of the mean)
            } else {
                s.iter().sum::<f32>() / 10.0
            }
        });
        Ok(Measured { values })
    }

    /// `f` applied to every grid value.
    pub fn map(&self, f: impl Fn(f32) -> f32) -> Measured {
        Measured {
            values: self.values.map(f),
        }
    }

    /// The same spectrum times `s` (a unit change).
    pub fn scaled(&self, s: f32) -> Measured {
        Measured {
            values: self.values.map(|v| v * s),
        }
    }

    /// The value at `lambda_nm` (clamped to 360–830 nm), linear between grid values.
    #[inline]
    pub fn at(&self, lambda_nm: f32) -> f32 {
        let x = ((lambda_nm - LAMBDA_MIN) / STEP).clamp(0.0, (SAMPLES - 1) as f32);
        let i = (x as usize).min(SAMPLES - 2);
        let t = x - i as f32;
        self.values[i] + t * (self.values[i + 1] - self.values[i])
    }

    /// The largest grid value.
    pub fn max(&self) -> f32 {
        self.values.iter().copied().fold(0.0, f32::max)
    }

    /// CIE 1931 Y of this spectrum as emitted radiance (`∫ L ȳ / ∫ ȳ`, so a flat 1 has Y = 1).
    pub fn luminance(&self) -> f32 {
        super::cie::spectrum_to_xyz(|l| self.at(l)).y
    }

    /// The linear Rec.709 colour of this spectrum as emitted radiance: its CIE XYZ
    /// (`∫ L (x̄, ȳ, z̄) / ∫ ȳ`) through the sRGB matrix, negative channels clamped to 0 (a
    /// D65-shaped spectrum of luminance `c` is the grey `c`, to 2.4e-4).
    pub fn to_rgb_emission(&self) -> Rgb {
        let xyz = super::cie::spectrum_to_xyz(|l| self.at(l));
        let c = super::cie::xyz_to_linear_srgb(xyz);
        Rgb::new(c.x.max(0.0), c.y.max(0.0), c.z.max(0.0))
    }

    /// This spectrum with a `'static` lifetime, for runtime records that stay `Copy` (a stack's
    /// measured albedo). Equal spectra share one allocation, so memory grows with the number of
    /// distinct spectra a process loads, not with how often they are loaded.
    pub fn intern(self) -> &'static Measured {
        use std::sync::Mutex;
        static INTERNED: Mutex<Vec<&'static Measured>> = Mutex::new(Vec::new());
        let mut list = INTERNED.lock().unwrap_or_else(|p| p.into_inner());
        if let Some(m) = list.iter().find(|m| ***m == self) {
            return m;
        }
        let m: &'static Measured = Box::leak(Box::new(self));
        list.push(m);
        m
    }

    /// The linear Rec.709 triple an RGB render uses for this coefficient spectrum (module docs).
    pub fn to_rgb(&self) -> Rgb {
        if self.values.iter().all(|&v| v == self.values[0]) {
            // Flat: exactly the grey (the projection's white balance leaves 2e-4).
            return Rgb::splat(self.values[0]);
        }
        let c = reflectance_to_rgb(|l| self.at(l));
        Rgb::new(c[0].max(0.0), c[1].max(0.0), c[2].max(0.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_spectra_are_greys_and_lines_are_interpolated() {
        let flat = Measured::from_points(&[(300.0, 0.5), (900.0, 0.5)], 1e4).unwrap();
        assert_eq!(flat.at(555.0), 0.5);
        assert_eq!(flat.to_rgb(), Rgb::splat(0.5));
        // A reddish absorption projects to a triple with red largest.
        let red = Measured::from_points(&[(360.0, 0.1), (560.0, 0.1), (700.0, 2.0)], 1e4).unwrap();
        let c = red.to_rgb();
        assert!(c[0] > c[1] && c[1] >= c[2] && c[2] > 0.0, "{c:?}");
        let ramp = Measured::from_points(&[(360.0, 0.0), (830.0, 4.7)], 1e4).unwrap();
        assert!((ramp.at(595.0) - 2.35).abs() < 1e-4);
        assert!((ramp.scaled(2.0).at(595.0) - 4.7).abs() < 2e-4);
        // Constant beyond the ends (the box mean at 360 sees the clamped left part).
        let short = Measured::from_points(&[(500.0, 1.0), (600.0, 3.0)], 1e4).unwrap();
        assert_eq!(short.at(400.0), 1.0);
        assert_eq!(short.at(800.0), 3.0);
    }

    #[test]
    fn a_narrow_line_keeps_its_area() {
        // A 2 nm wide triangle of height 10 between grid points: area 10 nm.
        let line = Measured::from_points(
            &[(400.0, 0.0), (524.0, 0.0), (525.0, 10.0), (526.0, 0.0)],
            1e4,
        )
        .unwrap();
        let area: f32 = (0..=470).map(|i| line.at(360.0 + i as f32)).sum();
        assert!((area - 10.0).abs() < 0.5, "area {area}");
    }

    #[test]
    fn bad_points_are_refused() {
        for (pts, expect) in [
            (vec![(500.0, 1.0)], "2 ..= 4096"),
            (vec![(500.0, 1.0), (500.0, 2.0)], "does not increase"),
            (vec![(100.0, 1.0), (500.0, 2.0)], "200 ..= 2000"),
            (vec![(400.0, -1.0), (500.0, 2.0)], "0 ..= 10000"),
            (vec![(400.0, f32::NAN), (500.0, 2.0)], "out of range"),
        ] {
            let e = Measured::from_points(&pts, 1e4).unwrap_err();
            assert!(e.contains(expect), "{pts:?}: {e}");
        }
    }
}
