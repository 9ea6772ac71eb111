//! The film: per-pixel sums of samples, from which the mean, the variance of the mean and the
//! AOVs are read.
//!
//! **Exact sums.** Every sum is a fixed-point integer (see [`super::fixed`]), so adding samples is
//! associative and commutative: a pixel's sums do not depend on the order its samples were
//! added, on the thread count, or on how its sample range was split into parts rendered on
//! different machines and merged ([`PixelSums::merge`], `lapidary merge`). A render of samples
//! `0..N` and the merge of renders of `0..k` and `k..N` are bit-identical.

use super::fixed;
use super::path::PathSample;
use crate::spectrum::RgbSample;

/// The accumulated samples of one pixel. Sums are fixed-point integers ([`super::fixed`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PixelSums {
    /// Σ radiance per channel, in units of [`fixed::RADIANCE_UNIT`] (wrapping: exact while the
    /// true sum fits, which it does for any count of samples a render accepts).
    pub sum: [i128; 3],
    /// Σ radiance² per channel, in units of [`fixed::SQUARE_UNIT`], saturating at `u128::MAX`.
    pub sum_sq: [u128; 3],
    /// Samples kept.
    pub n: u32,
    /// Samples dropped because their radiance was not finite, negative, or beyond
    /// [`fixed::RADIANCE_LIMIT`].
    pub dropped: u32,
    /// Σ first-hit albedo, in units of [`fixed::AOV_UNIT`].
    pub albedo: [i64; 3],
    /// Σ first-hit normal, in units of [`fixed::AOV_UNIT`].
    pub normal: [i64; 3],
    /// Σ first-hit distance over samples that hit something, in units of [`fixed::DEPTH_UNIT`].
    pub depth: i128,
    /// Samples that hit something.
    pub depth_n: u32,
    /// Material index of the pixel's lowest-numbered sample (−1 floor, −2 nothing), `i32::MIN`
    /// before any.
    pub material: i32,
    /// Rays traced for the pixel.
    pub rays: u64,
}

impl PixelSums {
    /// An empty pixel.
    pub const EMPTY: PixelSums = PixelSums {
        sum: [0; 3],
        sum_sq: [0; 3],
        n: 0,
        dropped: 0,
        albedo: [0; 3],
        normal: [0; 3],
        depth: 0,
        depth_n: 0,
        material: i32::MIN,
        rays: 0,
    };

    /// Adds one sample; a sample whose radiance is not finite and non-negative (or beyond
    /// [`fixed::RADIANCE_LIMIT`]) is dropped and counted (its AOVs are kept: they are finite by
    /// construction). Samples must be added in increasing sample order within one film (the
    /// material AOV keeps the first). Returns whether the sample was kept.
    pub fn add(&mut self, s: &PathSample) -> bool {
        self.rays += u64::from(s.rays);
        if self.material == i32::MIN {
            self.material = s.material;
        }
        for c in 0..3 {
            self.albedo[c] = self.albedo[c].wrapping_add(fixed::aov(s.albedo[c]));
        }
        for (acc, v) in self.normal.iter_mut().zip(s.normal.to_array()) {
            *acc = acc.wrapping_add(fixed::aov(v));
        }
        if let Some(t) = s.depth.filter(|t| t.is_finite()) {
            self.depth = self.depth.wrapping_add(fixed::depth(t));
            self.depth_n += 1;
        }
        let ok = if s.signed {
            s.radiance.0.iter().all(|v| v.is_finite())
        } else {
            s.radiance.is_valid()
        };
        if !ok || s.radiance.0.iter().any(|v| v.abs() > fixed::RADIANCE_LIMIT) {
            self.dropped += 1;
            return false;
        }
        self.n += 1;
        for c in 0..3 {
            let v = s.radiance[c];
            self.sum[c] = self.sum[c].wrapping_add(fixed::radiance(v));
            self.sum_sq[c] = self.sum_sq[c].saturating_add(fixed::square(v));
        }
        true
    }

    /// Adds another part's sums of the same pixel: exact, so the result does not depend on the
    /// order parts are merged in. `self` must hold the lower-numbered samples (it keeps its
    /// material unless it has none).
    pub fn merge(&mut self, other: &PixelSums) {
        for c in 0..3 {
            self.sum[c] = self.sum[c].wrapping_add(other.sum[c]);
            self.sum_sq[c] = self.sum_sq[c].saturating_add(other.sum_sq[c]);
            self.albedo[c] = self.albedo[c].wrapping_add(other.albedo[c]);
            self.normal[c] = self.normal[c].wrapping_add(other.normal[c]);
        }
        self.n += other.n;
        self.dropped += other.dropped;
        self.depth = self.depth.wrapping_add(other.depth);
        self.depth_n += other.depth_n;
        if self.material == i32::MIN {
            self.material = other.material;
        }
        self.rays += other.rays;
    }

    /// Σ radiance per channel as real numbers.
    pub fn radiance_sum(&self) -> [f64; 3] {
        self.sum.map(fixed::radiance_value)
    }

    /// Σ radiance² per channel as real numbers.
    pub fn radiance_sq_sum(&self) -> [f64; 3] {
        self.sum_sq.map(fixed::radiance_value_sq)
    }

    /// Mean radiance (0 without samples).
    pub fn mean(&self) -> RgbSample {
        let n = f64::from(self.n.max(1));
        RgbSample(self.radiance_sum().map(|s| (s / n) as f32))
    }

    /// Variance of the mean per channel: the unbiased sample variance over `n` (0 below 2
    /// samples; `f32::MAX` if the sum of squares saturated).
    pub fn variance_of_mean(&self) -> [f32; 3] {
        if self.n < 2 {
            return [0.0; 3];
        }
        let n = f64::from(self.n);
        let sum = self.radiance_sum();
        std::array::from_fn(|c| {
            if self.sum_sq[c] == u128::MAX {
                return f32::MAX;
            }
            let sq = fixed::radiance_value_sq(self.sum_sq[c]);
            let var = (sq - sum[c] * sum[c] / n) / (n - 1.0);
            (var.max(0.0) / n) as f32
        })
    }

    /// Samples taken (kept and dropped), the denominator of the AOV means.
    fn taken(&self) -> f64 {
        f64::from((self.n + self.dropped).max(1))
    }

    /// Mean first-hit albedo.
    pub fn mean_albedo(&self) -> [f32; 3] {
        self.albedo
            .map(|a| (fixed::aov_value(a) / self.taken()) as f32)
    }

    /// Mean first-hit normal, renormalised (0 where nothing was hit).
    pub fn mean_normal(&self) -> [f32; 3] {
        let v = self.normal.map(fixed::aov_value);
        let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if len > 0.0 {
            v.map(|c| (c / len) as f32)
        } else {
            [0.0; 3]
        }
    }

    /// Mean first-hit distance over the samples that hit something (0 if none did).
    pub fn mean_depth(&self) -> f32 {
        if self.depth_n == 0 {
            0.0
        } else {
            (fixed::depth_value(self.depth) / f64::from(self.depth_n)) as f32
        }
    }
}

/// The Stokes AOVs' sums of one pixel (`--stokes`, [`crate::polarisation::stokes`]): Σ `S0`…`S3`
/// per colour channel over the samples the pixel kept, in units of [`fixed::RADIANCE_UNIT`]
/// (exact and order-independent like the radiance sums).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StokesSums(pub [[i128; 3]; 4]);

impl StokesSums {
    /// Adds a kept sample's Stokes vector (a component that is not finite counts as 0, one
    /// beyond [`fixed::RADIANCE_LIMIT`] as the limit).
    pub fn add(&mut self, stokes: &[crate::color::Rgb; 4]) {
        for (sum, v) in self.0.iter_mut().zip(stokes) {
            for c in 0..3 {
                let x = if v[c].is_finite() {
                    v[c].clamp(-fixed::RADIANCE_LIMIT, fixed::RADIANCE_LIMIT)
                } else {
                    0.0
                };
                sum[c] = sum[c].wrapping_add(fixed::radiance(x));
            }
        }
    }

    /// Adds another range's sums of the same pixel (exact: the order does not matter).
    pub fn merge(&mut self, other: &StokesSums) {
        for (a, b) in self.0.iter_mut().zip(&other.0) {
            for (x, y) in a.iter_mut().zip(b) {
                *x = x.wrapping_add(*y);
            }
        }
    }

    /// The mean Stokes vector over `n` kept samples (0 without samples).
    pub fn mean(&self, n: u32) -> [[f32; 3]; 4] {
        let n = f64::from(n.max(1));
        self.0
            .map(|s| s.map(|v| (fixed::radiance_value(v) / n) as f32))
    }
}

/// A `width × height` grid of pixel sums, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The pixels.
    pub pixels: Vec<PixelSums>,
    /// The Stokes AOVs' sums per pixel when the render measures them (`--stokes`); empty
    /// otherwise.
    pub stokes: Vec<StokesSums>,
}

impl Film {
    /// An empty film.
    pub fn new(width: u32, height: u32) -> Self {
        Film {
            width,
            height,
            pixels: vec![PixelSums::EMPTY; width as usize * height as usize],
            stokes: Vec::new(),
        }
    }

    /// Mean radiance per pixel.
    pub fn rgb(&self) -> Vec<[f32; 3]> {
        self.pixels.iter().map(|p| p.mean().0).collect()
    }

    /// Samples dropped over the whole film.
    pub fn dropped(&self) -> u64 {
        self.pixels.iter().map(|p| u64::from(p.dropped)).sum()
    }

    /// Samples kept over the whole film.
    pub fn samples(&self) -> u64 {
        self.pixels.iter().map(|p| u64::from(p.n)).sum()
    }

    /// Rays traced over the whole film.
    pub fn rays(&self) -> u64 {
        self.pixels.iter().map(|p| p.rays).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(v: f32) -> PathSample {
        PathSample {
            radiance: crate::color::Rgb::splat(v),
            albedo: crate::color::Rgb::splat(0.5),
            normal: glam::Vec3::Y,
            depth: Some(2.0),
            material: 3,
            rays: 2,
            signed: false,
        }
    }

    /// The Stokes sums are exact and order-independent like the radiance's, clamp what a
    /// sample cannot hold and ignore what is not finite.
    #[test]
    fn stokes_sums_are_exact_and_bounded() {
        let mut a = StokesSums::default();
        let mut b = StokesSums::default();
        let vals = [0.25, -1.5, 3.0];
        for v in vals {
            a.add(&[crate::color::Rgb::splat(v); 4]);
        }
        for v in vals.iter().rev() {
            b.add(&[crate::color::Rgb::splat(*v); 4]);
        }
        assert_eq!(a, b);
        assert_eq!(a.mean(3)[2][1], (0.25 - 1.5 + 3.0) / 3.0);
        let mut c = StokesSums::default();
        let mut s = [crate::color::Rgb::ZERO; 4];
        s[1] = crate::color::Rgb([f32::NAN, f32::INFINITY, 1e30]);
        c.add(&s);
        let m = c.mean(1)[1];
        assert_eq!(m[0], 0.0);
        assert_eq!(m[1], 0.0);
        assert_eq!(m[2], fixed::RADIANCE_LIMIT);
    }

    #[test]
    fn mean_and_variance_of_the_mean() {
        let mut p = PixelSums::EMPTY;
        for v in [1.0, 2.0, 3.0, 4.0] {
            p.add(&sample(v));
        }
        assert_eq!(p.mean()[0], 2.5);
        // Sample variance 5/3, over n = 4.
        assert!((p.variance_of_mean()[1] - 5.0 / 12.0).abs() < 1e-6);
        assert_eq!(p.material, 3);
        assert_eq!(p.mean_depth(), 2.0);
        assert_eq!(p.mean_normal(), [0.0, 1.0, 0.0]);
        assert_eq!(p.rays, 8);
    }

    #[test]
    fn non_finite_and_negative_samples_are_dropped_and_counted() {
        let mut p = PixelSums::EMPTY;
        for v in [1.0, f32::NAN, f32::INFINITY, -1.0, 3.0] {
            p.add(&sample(v));
        }
        assert_eq!((p.n, p.dropped), (2, 3));
        assert_eq!(p.mean()[2], 2.0);
        assert!(p.variance_of_mean().iter().all(|v| v.is_finite()));
        assert_eq!(p.mean_albedo(), [0.5; 3]);
    }

    /// A spectral sample's Rec.709 image may have a negative channel (a saturated colour): it is
    /// kept, and only a non-finite one is dropped.
    #[test]
    fn signed_samples_keep_negative_channels() {
        let mut p = PixelSums::EMPTY;
        for v in [1.0, -0.25, f32::NAN, 0.5] {
            p.add(&PathSample {
                signed: true,
                ..sample(v)
            });
        }
        assert_eq!((p.n, p.dropped), (3, 1));
        assert!((p.mean()[0] - 1.25 / 3.0).abs() < 1e-6);
    }
}
