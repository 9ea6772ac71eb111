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
//! and **leakage**, the fraction that is dark (luminance below [`DARK`]); **extinction**, the
//! fraction darker than [`EXTINCT`] under ISO; **contrast**, the RMS contrast under ISO — shares
//! with binomial standard errors, the contrast with a jackknife's. The spot lighting's fire and
//! scintillation are in [`super::sparkle`].

use crate::image::RgbImage;
use crate::render::film::Film;

/// Half-angle of the observer's head shadow around the zenith, degrees: a 20 cm head 27 cm above
/// the stone (GUESS: a reading distance; BOG and GemRay use a head shadow of this order).
pub const HEAD_HALF_ANGLE: f64 = 20.0;

/// Luminance below which an ASET pixel counts as dark (leakage).
pub const DARK: f64 = 0.05;

/// Luminance, as a share of the ISO lighting, below which a pixel counts as extinct (GUESS: a
/// quarter, where a facet reads as dark beside its neighbours).
pub const EXTINCT: f64 = 0.25;

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

/// Rec. 709 luminance of a linear RGB colour.
pub fn luminance(c: [f32; 3]) -> f64 {
    0.2126 * f64::from(c[0]) + 0.7152 * f64::from(c[1]) + 0.0722 * f64::from(c[2])
}

impl Estimate {
    /// The mean of two independent estimates of one quantity; `None` if either is.
    pub fn mean_of(e: [Option<Estimate>; 2]) -> Option<Estimate> {
        let [a, b] = e;
        let (a, b) = (a?, b?);
        Some(Estimate {
            value: 0.5 * (a.value + b.value),
            se: 0.5 * a.se.hypot(b.se),
        })
    }

    /// A share `p` of `n` pixels with its binomial standard error.
    pub fn binomial(p: f64, n: usize) -> Estimate {
        Estimate {
            value: p,
            se: (p * (1.0 - p) / n.max(1) as f64).sqrt(),
        }
    }
}

/// Groups the jackknife splits the pixels into.
const GROUPS: usize = 20;

/// `statistic` of `values` with its standard error by the delete-a-group jackknife (Efron &
/// Tibshirani, *An Introduction to the Bootstrap*, 1993, §11.5) over [`GROUPS`] interleaved groups
/// of the values (pixels `i ≡ g mod GROUPS`): for statistics of many pixels that are not plain
/// means.
pub fn jackknife<T: Copy>(values: &[T], statistic: impl Fn(&[T]) -> f64) -> Estimate {
    let value = statistic(values);
    let g = GROUPS.min(values.len());
    if g < 2 {
        return Estimate { value, se: 0.0 };
    }
    let leave_out: Vec<f64> = (0..g)
        .map(|k| {
            let rest: Vec<T> = values
                .iter()
                .enumerate()
                .filter(|(i, _)| i % g != k)
                .map(|(_, &v)| v)
                .collect();
            statistic(&rest)
        })
        .collect();
    let mean = leave_out.iter().sum::<f64>() / g as f64;
    let var = leave_out.iter().map(|t| (t - mean).powi(2)).sum::<f64>() * (g - 1) as f64 / g as f64;
    Estimate {
        value,
        se: var.sqrt(),
    }
}

/// The **extinction** of an ISO view (its linear RGB pixels): the share of the stone's pixels
/// darker than [`EXTINCT`] of the lighting (the head's shadow and leaked light seen in the
/// stone), binomial standard error.
pub fn extinction(rgb: &[[f32; 3]], mask: &[bool]) -> Option<Estimate> {
    let lum: Vec<f64> = rgb
        .iter()
        .zip(mask)
        .filter(|(_, m)| **m)
        .map(|(&c, _)| luminance(c))
        .collect();
    (!lum.is_empty()).then(|| {
        let dark = lum.iter().filter(|&&l| l < EXTINCT).count();
        Estimate::binomial(dark as f64 / lum.len() as f64, lum.len())
    })
}

/// The **contrast** of an ISO view from two independent renders of it: the RMS contrast of the
/// stone's pixels — the standard deviation of their luminance over its mean (Peli, "Contrast in
/// complex images", JOSA A 7(10), 1990) — with a jackknife standard error over groups of pixels.
/// The variance is the mean product of the two renders' deviations from their means, which
/// render noise does not inflate (the renders are independent), so the contrast does not depend
/// on the samples per pixel.
pub fn contrast(halves: [&Film; 2], mask: &[bool]) -> Option<Estimate> {
    let pixels: Vec<[f64; 2]> = (0..mask.len())
        .filter(|&i| mask[i])
        .map(|i| halves.map(|f| luminance(f.pixels[i].mean().0)))
        .collect();
    (!pixels.is_empty()).then(|| {
        jackknife(&pixels, |px| {
            let n = px.len().max(1) as f64;
            let m = [0, 1].map(|k| px.iter().map(|p| p[k]).sum::<f64>() / n);
            let var = px
                .iter()
                .map(|p| (p[0] - m[0]) * (p[1] - m[1]))
                .sum::<f64>()
                / n;
            let mean = 0.5 * (m[0] + m[1]);
            if mean > 0.0 {
                var.max(0.0).sqrt() / mean
            } else {
                0.0
            }
        })
    })
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
