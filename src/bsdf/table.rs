//! 1-D tables over `cos θ ∈ [0, 1]`, built once per material and linearly interpolated.
//!
//! Entries hold one value per colour channel of the RGB variant. They are not colour-independent:
//! the stack's colour enters its integrals non-linearly (absorption inside, albedo coupled with
//! internal reflection), so a spectral variant tabulates per wavelength bin instead
//! (docs/design.md §12).

use crate::sampler::{Rng, hash_words};
use crate::spectrum::RgbSample;
use glam::{Vec2, Vec3};
use rayon::prelude::*;

/// Entries in every layer table (uniform in `cos θ`).
pub const ENTRIES: usize = 64;

/// `cos θ` at which entry `i` is measured; entry 0 stands for grazing and is measured at 1e-3 so
/// that sampling there is well defined.
#[inline]
pub fn entry_cos(i: usize) -> f32 {
    (i as f32 / (ENTRIES - 1) as f32).max(1e-3)
}

/// A colour-valued function of `cos θ`.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    values: Box<[RgbSample]>,
}

impl Table {
    /// A table whose entries are `f(entry_cos(i))`.
    pub fn build(f: impl FnMut(f32) -> RgbSample) -> Self {
        let mut f = f;
        Table {
            values: (0..ENTRIES).map(|i| f(entry_cos(i))).collect(),
        }
    }

    /// A table whose entries are `f(entry_cos(i))`, computed in parallel (rayon); the result does
    /// not depend on the thread count.
    pub fn build_par(f: impl Fn(f32) -> RgbSample + Sync) -> Self {
        let values: Vec<RgbSample> = (0..ENTRIES)
            .into_par_iter()
            .map(|i| f(entry_cos(i)))
            .collect();
        Table {
            values: values.into_boxed_slice(),
        }
    }

    /// Builds two tables at once from `f(μ) -> (a, b)`, in parallel.
    pub fn build_pair_par(f: impl Fn(f32) -> (RgbSample, RgbSample) + Sync) -> (Self, Self) {
        let pairs: Vec<(RgbSample, RgbSample)> = (0..ENTRIES)
            .into_par_iter()
            .map(|i| f(entry_cos(i)))
            .collect();
        let (a, b): (Vec<_>, Vec<_>) = pairs.into_iter().unzip();
        (
            Table {
                values: a.into_boxed_slice(),
            },
            Table {
                values: b.into_boxed_slice(),
            },
        )
    }

    /// A table of directional albedos measured by stratified Monte Carlo: entry `μ` is the mean of
    /// `weight(wo, uc, u)` over [`for_strata`] with `wo = (√(1−μ²), 0, μ)`. Deterministic for a
    /// given `key`, whatever the thread count.
    pub fn by_sampling(
        grid: usize,
        key: u64,
        weight: impl Fn(Vec3, f32, Vec2) -> RgbSample + Sync,
    ) -> Self {
        Table::build_par(|mu| {
            let wo = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
            let mut sum = RgbSample::ZERO;
            for_strata(
                grid,
                hash_words(&[key, u64::from(mu.to_bits())]),
                |uc, u| sum += weight(wo, uc, u),
            );
            sum / (grid * grid * UC_STRATA) as f32
        })
    }

    /// A table holding `values[i]` at `entry_cos(i)`; `values` must have [`ENTRIES`] entries.
    pub fn from_values(values: Vec<RgbSample>) -> Self {
        assert_eq!(values.len(), ENTRIES, "a table has {ENTRIES} entries");
        Table {
            values: values.into_boxed_slice(),
        }
    }

    /// The entries, at `entry_cos(i)`.
    pub fn values(&self) -> &[RgbSample] {
        &self.values
    }

    /// A table of zeros.
    pub fn zero() -> Self {
        Table {
            values: vec![RgbSample::ZERO; ENTRIES].into_boxed_slice(),
        }
    }

    /// Applies `f` to every entry's channels.
    pub fn map(mut self, f: impl Fn(f32) -> f32) -> Self {
        for v in self.values.iter_mut() {
            *v = v.map(&f);
        }
        self
    }

    /// Linear interpolation at `cos θ` (clamped to `[0, 1]`).
    #[inline]
    pub fn at(&self, cos: f32) -> RgbSample {
        let x = cos.clamp(0.0, 1.0) * (ENTRIES - 1) as f32;
        let i = (x as usize).min(ENTRIES - 2);
        let t = x - i as f32;
        self.values[i] * (1.0 - t) + self.values[i + 1] * t
    }

    /// `∫₀¹ 2 μ · table(μ) · weight(μ) dμ` by the trapezoid rule on the entries: the cosine-weighted
    /// hemispherical average of a directional quantity.
    pub fn hemispherical(&self, weight: impl Fn(f32) -> f32) -> RgbSample {
        let n = ENTRIES - 1;
        let mut sum = RgbSample::ZERO;
        for i in 0..=n {
            let mu = i as f32 / n as f32;
            let w = if i == 0 || i == n { 0.5 } else { 1.0 };
            sum += self.values[i] * (w * 2.0 * mu * weight(mu) / n as f32);
        }
        sum
    }
}

/// Strata of `uc` per cell of [`for_strata`].
pub const UC_STRATA: usize = 4;

/// Calls `f(uc, u)` for a jittered point in each cell of a `grid × grid` stratification of
/// `[0, 1)²`, once for each of [`UC_STRATA`] jittered strata of `uc` (the lobe or micro-facet
/// choice), so discrete choices made with `uc` are averaged rather than sampled. The jitter comes
/// from a stream keyed by `key`. `f` is called `grid² · UC_STRATA` times.
pub fn for_strata(grid: usize, key: u64, mut f: impl FnMut(f32, Vec2)) {
    let mut rng = Rng::new(key);
    let g = grid as f32;
    for i in 0..grid {
        for j in 0..grid {
            let u = Vec2::new(
                (i as f32 + rng.uniform()) / g,
                (j as f32 + rng.uniform()) / g,
            );
            for k in 0..UC_STRATA {
                f((k as f32 + rng.uniform()) / UC_STRATA as f32, u);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_linear_functions_exactly() {
        let t = Table::build(|c| RgbSample::splat(2.0 * c + 1.0));
        assert!((t.at(0.5)[0] - 2.0).abs() < 1e-5);
        assert!((t.at(1.0)[0] - 3.0).abs() < 1e-5);
        assert!((t.at(7.0)[0] - 3.0).abs() < 1e-5);
        // ∫ 2μ (2μ+1) dμ = 4/3 + 1.
        let h = Table::build(|c| RgbSample::splat(2.0 * c + 1.0)).hemispherical(|_| 1.0)[0];
        assert!((h - 7.0 / 3.0).abs() < 2e-3, "{h}");
    }
}
