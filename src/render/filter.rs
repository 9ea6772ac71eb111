//! Pixel filters by importance sampling (Ernst et al., "Filter Importance Sampling", RT 2006;
//! the approach of pbrt-v4 §8.8): each sample's film position is drawn with the density of the
//! (non-negative, separable) filter around the pixel centre, and every sample has weight 1. A pixel
//! is then the plain mean of its own samples, so its variance is the sample variance over `n` and
//! samples of different pixels never mix — which keeps renders deterministic per pixel.

use crate::scene::stage::Filter;
use glam::Vec2;

/// Segments of the tabulated inverse CDF of the truncated Gaussian.
const TABLE: usize = 256;

/// Buckets of the guide table: equal slices of `u` (a power of two, so a bucket's lower end
/// `j / GUIDE` is exact in `f32`).
const GUIDE: usize = 1024;

/// Draws film offsets from a pixel filter.
#[derive(Clone, Debug)]
pub struct FilterSampler {
    /// Half-width of the support in pixels.
    radius: f32,
    /// CDF of one axis at `TABLE + 1` equally spaced points over `[−radius, radius]` (empty for the
    /// box filter).
    cdf: Vec<f32>,
    /// `guide[j]`: how many CDF values are ≤ `j / GUIDE`, for `j = 0 ..= GUIDE` (a guide table,
    /// Chen & Asau 1974: the search for `u` starts in its bucket rather than over the whole CDF,
    /// and finds the same segment; with 1024 buckets most hold at most one CDF value, counted
    /// without a branch).
    guide: Vec<u32>,
}

impl FilterSampler {
    /// A sampler for `filter`.
    pub fn new(filter: Filter) -> Self {
        match filter {
            Filter::Box => FilterSampler {
                radius: 0.5,
                cdf: Vec::new(),
                guide: Vec::new(),
            },
            Filter::Gaussian { radius } => {
                // σ = radius / 3; the Gaussian truncated to [−r, r] and shifted to 0 at ±r (as
                // pbrt does, so the filter is continuous at the edge of its support).
                let sigma = radius / 3.0;
                let g = |x: f32| (-x * x / (2.0 * sigma * sigma)).exp();
                let edge = g(radius);
                let dx = 2.0 * radius / TABLE as f32;
                let mut cdf = Vec::with_capacity(TABLE + 1);
                cdf.push(0.0);
                let mut acc = 0.0f64;
                for k in 0..TABLE {
                    // Simpson's rule on each segment.
                    let a = -radius + k as f32 * dx;
                    let f = |x: f32| f64::from((g(x) - edge).max(0.0));
                    acc += f64::from(dx) / 6.0 * (f(a) + 4.0 * f(a + 0.5 * dx) + f(a + dx));
                    cdf.push(acc as f32);
                }
                let total = *cdf.last().unwrap_or(&1.0);
                for c in &mut cdf {
                    *c /= total;
                }
                let guide = (0..=GUIDE)
                    .map(|j| {
                        let u = j as f32 / GUIDE as f32;
                        cdf.partition_point(|&c| c <= u) as u32
                    })
                    .collect();
                FilterSampler { radius, cdf, guide }
            }
        }
    }

    /// The support radius in pixels.
    pub fn radius(&self) -> f32 {
        self.radius
    }

    /// An offset from the pixel centre, in pixels, for `u ∈ [0,1)²`.
    pub fn sample(&self, u: Vec2) -> Vec2 {
        Vec2::new(self.sample_1d(u.x), self.sample_1d(u.y))
    }

    fn sample_1d(&self, u: f32) -> f32 {
        if self.cdf.is_empty() {
            return u - 0.5;
        }
        // The segment with cdf[k] ≤ u < cdf[k+1], then linear inside it. The count of CDF values
        // ≤ u lies between those of its bucket's ends (the CDF is non-decreasing).
        let k = self.count_at_most(u).clamp(1, TABLE) - 1;
        let (c0, c1) = (self.cdf[k], self.cdf[k + 1]);
        let t = if c1 > c0 { (u - c0) / (c1 - c0) } else { 0.5 };
        let dx = 2.0 * self.radius / TABLE as f32;
        -self.radius + (k as f32 + t.clamp(0.0, 1.0)) * dx
    }

    /// How many CDF values are ≤ `u` (`partition_point`), searched within `u`'s guide bucket.
    #[inline]
    fn count_at_most(&self, u: f32) -> usize {
        let scaled = u * GUIDE as f32;
        if !(scaled >= 0.0 && scaled < GUIDE as f32) {
            return self.cdf.partition_point(|&c| c <= u);
        }
        let j = scaled as usize;
        let (lo, hi) = (self.guide[j] as usize, self.guide[j + 1] as usize);
        if hi <= lo + 1 {
            // Most buckets hold at most one CDF value: count it without a branch (the bucket's
            // values are ≤ its upper end, the next value is beyond it).
            lo + usize::from(hi > lo && self.cdf[lo] <= u)
        } else {
            lo + self.cdf[lo..hi].partition_point(|&c| c <= u)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_offsets_cover_the_pixel() {
        let f = FilterSampler::new(Filter::Box);
        assert_eq!(f.sample(Vec2::ZERO), Vec2::splat(-0.5));
        assert!(f.sample(Vec2::splat(0.999_999)).max_element() < 0.5);
    }

    #[test]
    fn gaussian_offsets_have_the_filter_moments() {
        let f = FilterSampler::new(Filter::Gaussian { radius: 1.5 });
        // Midpoint quadrature of the inverse CDF: mean 0 by symmetry; the variance of the shifted,
        // truncated Gaussian with σ = 0.5 on [−1.5, 1.5] is 0.22945 (numerical integration).
        let n = 100_000;
        let (mut m1, mut m2) = (0.0f64, 0.0f64);
        let mut max = 0.0f32;
        for i in 0..n {
            let x = f.sample_1d((i as f32 + 0.5) / n as f32);
            max = max.max(x.abs());
            m1 += f64::from(x);
            m2 += f64::from(x) * f64::from(x);
        }
        let (mean, var) = (m1 / f64::from(n), m2 / f64::from(n));
        assert!(mean.abs() < 1e-4, "mean {mean}");
        assert!((var - 0.22945).abs() < 2e-3, "variance {var}");
        assert!(max <= 1.5);
        // The guide table finds the segment the plain search finds, for every u of a fine grid
        // and at the buckets' ends.
        let whole = |u: f32| f.cdf.partition_point(|&c| c <= u);
        for i in 0..=1_000_000u32 {
            let u = i as f32 / 1_000_000.0;
            assert_eq!(f.count_at_most(u), whole(u), "u = {u}");
        }
        for j in 0..=GUIDE {
            let u = j as f32 / GUIDE as f32;
            for v in [
                u,
                f32::from_bits(u.to_bits().saturating_sub(1)),
                f32::from_bits(u.to_bits() + 1),
            ] {
                assert_eq!(f.count_at_most(v), whole(v), "u = {v}");
            }
        }
        for &c in &f.cdf {
            assert_eq!(f.count_at_most(c), whole(c), "u = {c}");
        }
        // Monotone in u.
        let xs: Vec<f32> = (0..100).map(|i| f.sample_1d(i as f32 / 100.0)).collect();
        assert!(xs.windows(2).all(|w| w[0] <= w[1]));
    }
}
