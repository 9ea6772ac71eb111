//! The cut report's lightings and measures (`lapidary cut`, docs/cuts.md): the stone is seen face-up
//! through an orthographic camera, as ASET images are made, under lightings that depend only on
//! the elevation of the direction light comes from.
//!
//! - **ISO**: uniform white over the upper hemisphere, black below the horizon, with the
//!   observer's head shadowing a cone of [`HEAD_HALF_ANGLE`] around the zenith — the diffuse
//!   lighting with a head shadow of BOG ("brightness of gems", Strickland) and Gem Cut Studio.
//! - **COS**: as ISO with radiance ∝ sin(elevation) (brightest overhead): the cosine lighting.
//! - **ASET**: the elevation bands of the American Gem Society's Angular Spectrum Evaluation Tool
//!   as Sasian et al. describe them ("Evaluation of brilliance, fire, and scintillation in round
//!   brilliant gemstones", Optical Engineering 46(9), 2007): light from 75–90° (where the observer
//!   is) blue, from 45–75° red, from 0–45° green; below the horizon black, so a dark pixel is light
//!   that leaks out through the pavilion.
//!
//! Measures over the stone's pixels (the pixels whose camera ray meets the stone): **light
//! return** — the mean luminance under ISO over the mean the lighting gives outside the head
//! shadow (1), BOG's brightness in kind; its standard error from the renders' per-pixel variance;
//! **ASET shares** — the fraction of stone pixels whose ASET colour is mostly blue, red or green,
//! and **leakage**, the fraction that is dark (luminance below [`DARK`]), each with the binomial
//! standard error over the stone's pixels.

use crate::image::RgbImage;
use crate::render::film::Film;

/// Half-angle of the observer's head shadow around the zenith, degrees: a 20 cm head 27 cm above
/// the stone (GUESS: a reading distance; BOG and GemRay use a head shadow of this order).
pub const HEAD_HALF_ANGLE: f64 = 20.0;

/// Luminance below which an ASET pixel counts as dark (leakage).
pub const DARK: f64 = 0.05;

/// The report's lightings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lighting {
    /// Uniform with a head shadow.
    Iso,
    /// Cosine-weighted with a head shadow.
    Cos,
    /// ASET elevation colours.
    Aset,
}

impl Lighting {
    /// All of them, in report order.
    pub const ALL: [Lighting; 3] = [Lighting::Iso, Lighting::Cos, Lighting::Aset];

    /// The name as the report prints it.
    pub fn name(self) -> &'static str {
        match self {
            Lighting::Iso => "ISO",
            Lighting::Cos => "COS",
            Lighting::Aset => "ASET",
        }
    }

    /// Linear RGB radiance from elevation `e` degrees above the horizon.
    pub fn radiance(self, e: f64) -> [f32; 3] {
        if e <= 0.0 {
            return [0.0; 3];
        }
        let head = 90.0 - e < HEAD_HALF_ANGLE;
        match self {
            Lighting::Iso if head => [0.0; 3],
            Lighting::Iso => [1.0; 3],
            Lighting::Cos if head => [0.0; 3],
            Lighting::Cos => [e.to_radians().sin() as f32; 3],
            Lighting::Aset if e >= 75.0 => [0.0, 0.0, 1.0],
            Lighting::Aset if e >= 45.0 => [1.0, 0.0, 0.0],
            Lighting::Aset => [0.0, 1.0, 0.0],
        }
    }

    /// The lighting as a lat-long environment map (row 0 at the zenith, the convention of
    /// [`crate::light::EnvironmentLight`]): 720 rows of a quarter degree, 4 columns (it does not
    /// depend on the azimuth).
    pub fn environment(self) -> RgbImage {
        let (w, h) = (4u32, 720u32);
        let pixels = (0..h)
            .flat_map(|r| {
                let theta = 180.0 * (f64::from(r) + 0.5) / f64::from(h);
                let c = self.radiance(90.0 - theta);
                (0..w).map(move |_| c)
            })
            .collect();
        RgbImage {
            width: w,
            height: h,
            pixels,
        }
    }
}

/// A measure and its standard error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// The value.
    pub value: f64,
    /// Its standard error.
    pub se: f64,
}

fn luminance(c: [f32; 3]) -> f64 {
    0.2126 * f64::from(c[0]) + 0.7152 * f64::from(c[1]) + 0.0722 * f64::from(c[2])
}

/// Mean luminance of `film` over the pixels of `mask`, with its standard error from each pixel's
/// variance of the mean (pixels independent); `None` when the mask is empty.
pub fn mean_luminance(film: &Film, mask: &[bool]) -> Option<Estimate> {
    let (mut sum, mut var, mut n) = (0.0f64, 0.0f64, 0usize);
    for (p, &m) in film.pixels.iter().zip(mask) {
        if m {
            sum += luminance(p.mean().0);
            let v = p.variance_of_mean();
            var += 0.2126f64.powi(2) * f64::from(v[0])
                + 0.7152f64.powi(2) * f64::from(v[1])
                + 0.0722f64.powi(2) * f64::from(v[2]);
            n += 1;
        }
    }
    (n > 0).then(|| Estimate {
        value: sum / n as f64,
        se: var.sqrt() / n as f64,
    })
}

/// The ASET shares over the stone's pixels: mostly red, green, blue, and dark (leakage), each
/// with its binomial standard error over the pixels.
pub fn aset_shares(film: &Film, mask: &[bool]) -> Option<[Estimate; 4]> {
    let mut counts = [0usize; 4];
    for (p, &m) in film.pixels.iter().zip(mask) {
        if !m {
            continue;
        }
        let c = p.mean().0;
        let k = if luminance(c) < DARK {
            3
        } else if c[0] >= c[1] && c[0] >= c[2] {
            0
        } else if c[1] >= c[2] {
            1
        } else {
            2
        };
        counts[k] += 1;
    }
    let n: usize = counts.iter().sum();
    (n > 0).then(|| {
        counts.map(|c| {
            let p = c as f64 / n as f64;
            Estimate {
                value: p,
                se: (p * (1.0 - p) / n as f64).sqrt(),
            }
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lightings_depend_on_elevation_only() {
        assert_eq!(Lighting::Iso.radiance(30.0), [1.0; 3]);
        assert_eq!(Lighting::Iso.radiance(80.0), [0.0; 3], "head shadow");
        assert_eq!(Lighting::Iso.radiance(-5.0), [0.0; 3]);
        assert!((Lighting::Cos.radiance(30.0)[0] - 0.5).abs() < 1e-6);
        assert_eq!(Lighting::Aset.radiance(80.0), [0.0, 0.0, 1.0]);
        assert_eq!(Lighting::Aset.radiance(60.0), [1.0, 0.0, 0.0]);
        assert_eq!(Lighting::Aset.radiance(10.0), [0.0, 1.0, 0.0]);
        let env = Lighting::Aset.environment();
        assert_eq!(env.pixels.len(), 4 * 720);
        // Row 0 is the zenith (blue), the last row the nadir (black).
        assert_eq!(env.pixels[0], [0.0, 0.0, 1.0]);
        assert_eq!(env.pixels[env.pixels.len() - 1], [0.0; 3]);
    }
}
