//! Piecewise-constant distributions on `[0, 1)` and `[0, 1)²` for importance sampling by inversion
//! of the cumulative distribution (Pharr, Jakob & Humphreys, *Physically Based Rendering*, 3rd ed.,
//! §13.3.1 and §13.6.7).
//!
//! Weights that are negative or not finite count as zero. A bin of zero weight is never chosen. A
//! distribution whose weights are all zero is *black*: it samples nothing (`None`) and its density
//! is 0 everywhere, so no NaN can come out of it.

use glam::Vec2;

/// The largest `f32` below 1: where a random number in `[0, 1]` is clamped before inversion.
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// A sample of a [`Distribution1D`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample1D {
    /// The sampled point in `[0, 1)`.
    pub x: f32,
    /// Its density with respect to `x` on `[0, 1)` (> 0).
    pub pdf: f32,
    /// The bin it lies in.
    pub index: usize,
}

/// A piecewise-constant density on `[0, 1)` with `n` equal bins, proportional to the weights.
///
/// Only the cumulative table is kept (one `f32` per bin, plus one): a bin's probability is the
/// difference of two neighbouring entries, and both [`sample`](Self::sample) and
/// [`pdf`](Self::pdf) use that difference, so the density reported is exactly the one sampled (a
/// bin far below the `f32` resolution of its row's total gets width 0: it is never chosen and its
/// density is 0).
#[derive(Clone, Debug, PartialEq)]
pub struct Distribution1D {
    /// `cdf[i]` = probability of bins `0 … i−1`; `cdf[n] = 1`. Length `n + 1` (all 0 when black).
    cdf: Vec<f32>,
    /// `∫₀¹ f(x) dx` = mean weight; 0 when black.
    integral: f32,
}

/// A weight as the distributions count it: negative or non-finite weights are 0.
fn sanitised(w: f32) -> f32 {
    if w.is_finite() && w > 0.0 { w } else { 0.0 }
}

impl Distribution1D {
    /// A distribution over `weights.len()` bins; negative or non-finite weights count as 0. An empty
    /// or all-zero input gives a black distribution.
    pub fn new(weights: &[f32]) -> Distribution1D {
        let n = weights.len();
        // Accumulate in f64 so long rows of an environment map keep their small bins; the total
        // first, then the normalised running sums straight into the table (no other copy).
        let total: f64 = weights.iter().map(|&w| f64::from(sanitised(w))).sum();
        let mut cdf = Vec::with_capacity(n + 1);
        if total > 0.0 && total.is_finite() {
            let mut running = 0.0f64;
            cdf.push(0.0);
            for &w in weights {
                running += f64::from(sanitised(w));
                cdf.push((running / total) as f32);
            }
            cdf[n] = 1.0;
        } else {
            cdf.resize(n + 1, 0.0);
        }
        let integral = if n > 0 && total.is_finite() {
            (total / n as f64) as f32
        } else {
            0.0
        };
        Distribution1D {
            cdf,
            integral: if integral.is_finite() { integral } else { 0.0 },
        }
    }

    /// Number of bins.
    pub fn len(&self) -> usize {
        self.cdf.len() - 1
    }

    /// True when there are no bins.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// True when every weight is zero: nothing can be sampled.
    pub fn is_black(&self) -> bool {
        !(self.integral > 0.0)
    }

    /// `∫₀¹ f(x) dx`: the mean of the (sanitised) weights.
    pub fn integral(&self) -> f32 {
        self.integral
    }

    /// Bytes of heap the table takes.
    pub fn heap_bytes(&self) -> usize {
        self.cdf.capacity() * std::mem::size_of::<f32>()
    }

    /// The width of bin `i` in the cumulative table: its probability (0 outside the range or when
    /// black).
    fn width(&self, i: usize) -> f32 {
        if self.is_black() || i >= self.len() {
            return 0.0;
        }
        (self.cdf[i + 1] - self.cdf[i]).max(0.0)
    }

    /// The weight of bin `i` as the table represents it (its probability × n × mean weight; 0
    /// outside the range).
    pub fn weight(&self, i: usize) -> f32 {
        self.width(i) * self.len() as f32 * self.integral
    }

    /// Probability of choosing bin `i` (discrete, sums to 1 unless black).
    pub fn bin_probability(&self, i: usize) -> f32 {
        self.width(i)
    }

    /// Inverts the cumulative distribution at `u ∈ [0, 1)` (values outside are clamped): a point
    /// with density proportional to the weights. `None` when black.
    pub fn sample(&self, u: f32) -> Option<Sample1D> {
        if self.is_black() {
            return None;
        }
        let u = u.clamp(0.0, ONE_MINUS_EPSILON);
        // The bin with cdf[i] ≤ u < cdf[i+1]: since cdf[n] = 1 > u it exists and has positive
        // width, so a zero-weight bin (zero width) is never returned.
        let index = (self.cdf.partition_point(|&c| c <= u) - 1).min(self.len() - 1);
        let (lo, hi) = (self.cdf[index], self.cdf[index + 1]);
        let du = if hi > lo {
            ((u - lo) / (hi - lo)).clamp(0.0, 1.0)
        } else {
            0.5
        };
        let n = self.len() as f32;
        let x = ((index as f32 + du) / n).min(ONE_MINUS_EPSILON);
        let pdf = (hi - lo) * n;
        (pdf > 0.0 && pdf.is_finite()).then_some(Sample1D { x, pdf, index })
    }

    /// The bin that `x ∈ [0, 1)` falls in (clamped to the range).
    pub fn bin_of(&self, x: f32) -> usize {
        let n = self.len();
        if n == 0 || !(x > 0.0) {
            return 0;
        }
        ((x * n as f32) as usize).min(n - 1)
    }

    /// Density of [`sample`](Self::sample) at `x` with respect to `x` (0 when black or outside
    /// `[0, 1)`).
    pub fn pdf(&self, x: f32) -> f32 {
        if self.is_black() || !(0.0..1.0).contains(&x) {
            return 0.0;
        }
        self.width(self.bin_of(x)) * self.len() as f32
    }
}

/// A sample of a [`Distribution2D`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample2D {
    /// The sampled point in `[0, 1)²` (`x` along a row, `y` down the rows).
    pub uv: Vec2,
    /// Its density with respect to area on `[0, 1)²` (> 0).
    pub pdf: f32,
    /// The cell it lies in: (column, row).
    pub cell: (usize, usize),
}

/// A piecewise-constant density on `[0, 1)²` over a `width × height` grid of cells, sampled as the
/// marginal over rows then the conditional along the chosen row.
#[derive(Clone, Debug, PartialEq)]
pub struct Distribution2D {
    /// One distribution per row, along the columns.
    rows: Vec<Distribution1D>,
    /// Over the rows, weighted by each row's integral.
    marginal: Distribution1D,
}

impl Distribution2D {
    /// A distribution over a grid of weights stored row-major, top row first
    /// (`weights[row * width + col]`). Missing entries (a short slice) count as zero.
    ///
    /// # Arguments
    /// * `width`, `height` – the grid's columns and rows (a zero size gives a black distribution).
    /// * `weights` – `width · height` non-negative weights; others count as zero.
    pub fn new(width: usize, height: usize, weights: &[f32]) -> Distribution2D {
        Self::from_rows(width, height, |r, row| {
            let start = (r * width).min(weights.len());
            let end = ((r + 1) * width).min(weights.len());
            row.extend_from_slice(&weights[start..end]);
        })
    }

    /// A distribution over a `width × height` grid whose row `r` of weights `row_weights(r, buf)`
    /// appends to an empty `buf` (a short row is padded with zeros, a long one cut). Rows are
    /// built in parallel, each from a buffer of one row, so no grid-sized copy of the weights is
    /// ever made: the tables take [`heap_bytes`](Self::heap_bytes), about 4 bytes per cell.
    pub fn from_rows(
        width: usize,
        height: usize,
        row_weights: impl Fn(usize, &mut Vec<f32>) + Sync,
    ) -> Distribution2D {
        use rayon::prelude::*;
        let rows: Vec<Distribution1D> = (0..height)
            .into_par_iter()
            .map_init(
                || Vec::with_capacity(width),
                |buf, r| {
                    buf.clear();
                    row_weights(r, buf);
                    buf.resize(width, 0.0);
                    Distribution1D::new(buf)
                },
            )
            .collect();
        let marginal = Distribution1D::new(&rows.iter().map(|d| d.integral()).collect::<Vec<_>>());
        Distribution2D { rows, marginal }
    }

    /// Bytes of heap the tables take (rows, their headers and the marginal).
    pub fn heap_bytes(&self) -> usize {
        self.rows
            .iter()
            .map(Distribution1D::heap_bytes)
            .sum::<usize>()
            + self.rows.capacity() * std::mem::size_of::<Distribution1D>()
            + self.marginal.heap_bytes()
    }

    /// Number of columns.
    pub fn width(&self) -> usize {
        self.rows.first().map_or(0, Distribution1D::len)
    }

    /// Number of rows.
    pub fn height(&self) -> usize {
        self.rows.len()
    }

    /// True when every weight is zero.
    pub fn is_black(&self) -> bool {
        self.marginal.is_black()
    }

    /// `∫∫ f du dv`: the mean weight.
    pub fn integral(&self) -> f32 {
        self.marginal.integral()
    }

    /// Probability of choosing cell (`col`, `row`) (sums to 1 unless black).
    pub fn cell_probability(&self, col: usize, row: usize) -> f32 {
        match self.rows.get(row) {
            Some(r) => self.marginal.bin_probability(row) * r.bin_probability(col),
            None => 0.0,
        }
    }

    /// A point with density proportional to the weights, from `u ∈ [0, 1)²`; `None` when black.
    pub fn sample(&self, u: Vec2) -> Option<Sample2D> {
        let m = self.marginal.sample(u.y)?;
        let c = self.rows[m.index].sample(u.x)?;
        let pdf = m.pdf * c.pdf;
        (pdf > 0.0 && pdf.is_finite()).then_some(Sample2D {
            uv: Vec2::new(c.x, m.x),
            pdf,
            cell: (c.index, m.index),
        })
    }

    /// Density of [`sample`](Self::sample) at `uv` with respect to area (0 when black or outside
    /// `[0, 1)²`).
    pub fn pdf(&self, uv: Vec2) -> f32 {
        if self.is_black() || !(0.0..1.0).contains(&uv.x) || !(0.0..1.0).contains(&uv.y) {
            return 0.0;
        }
        self.marginal.pdf(uv.y) * self.rows[self.marginal.bin_of(uv.y)].pdf(uv.x)
    }
}

/// Statistical helpers shared by the tests of the light module.
#[cfg(test)]
pub(crate) mod testing {
    use crate::sampler::Rng;
    use glam::{Vec2, Vec3};
    use std::f32::consts::{PI, TAU};

    /// Mean and standard error of `f` over `n` hashed uniform points of `[0, 1)²`.
    pub fn estimate(n: usize, seed: u64, mut f: impl FnMut(Vec2) -> f64) -> (f64, f64) {
        let mut rng = Rng::new(seed);
        let xs: Vec<f64> = (0..n).map(|_| f(rng.uniform2())).collect();
        let (n, m) = (n as f64, xs.iter().sum::<f64>() / n as f64);
        let var = xs.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1.0);
        (m, (var / n).sqrt())
    }

    /// The unit direction at polar angle `theta` from +y and azimuth `phi` in the environment
    /// map's convention: `(sin θ sin φ, cos θ, −sin θ cos φ)`.
    pub fn latlong(theta: f32, phi: f32) -> Vec3 {
        let ((st, ct), (sp, cp)) = (theta.sin_cos(), phi.sin_cos());
        Vec3::new(st * sp, ct, -st * cp)
    }

    /// `∫ pdf dω` over the sphere by Monte Carlo with 200 000 uniform directions: (mean,
    /// standard error).
    pub fn sphere_integral(pdf: impl Fn(Vec3) -> f32) -> (f64, f64) {
        estimate(200_000, 11, |u| {
            let w = latlong((1.0 - 2.0 * u.x).clamp(-1.0, 1.0).acos(), TAU * u.y);
            4.0 * std::f64::consts::PI * f64::from(pdf(w))
        })
    }

    /// Critical value of χ² at significance 0.01 for `dof` degrees of freedom (Wilson–Hilferty
    /// cube approximation, within about 1 % for `dof ≥ 10`).
    pub fn chi2_critical_001(dof: usize) -> f64 {
        let k = dof as f64;
        let z = 2.326_347_874; // upper 1 % point of the standard normal
        let a = 2.0 / (9.0 * k);
        k * (1.0 - a + z * a.sqrt()).powi(3)
    }

    /// Pearson's χ² of observed against expected counts, pooling cells whose expectation is below
    /// 5 into one; asserts it is below the critical value at significance 0.01 and that no sample
    /// fell where none was expected. Returns (statistic, degrees of freedom).
    pub fn assert_chi2(observed: &[f64], expected: &[f64]) -> (f64, usize) {
        let (mut stat, mut cells) = (0.0, 0usize);
        let (mut pool_o, mut pool_e) = (0.0, 0.0);
        for (&o, &e) in observed.iter().zip(expected) {
            if e < 5.0 {
                pool_o += o;
                pool_e += e;
            } else {
                stat += (o - e) * (o - e) / e;
                cells += 1;
            }
        }
        if pool_e > 0.0 {
            stat += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
            cells += 1;
        } else {
            assert!(pool_o == 0.0, "{pool_o} samples where none are expected");
        }
        let dof = cells.saturating_sub(1);
        assert!(stat < chi2_critical_001(dof), "χ² = {stat} with {dof} dof");
        (stat, dof)
    }

    /// χ² test of `n` sampled directions against `∫ pdf dω` over a 16 × 8 lat-long grid (θ from
    /// +y, φ = atan2(x, −z)), the integrals by the midpoint rule on a 64 × 32 grid.
    pub fn assert_latlong_chi2(
        n: usize,
        mut sample: impl FnMut(Vec2) -> Vec3,
        pdf: impl Fn(Vec3) -> f32,
    ) -> (f64, usize) {
        let (bw, bh, fw, fh) = (16, 8, 64, 32);
        let bin = |d: Vec3| {
            let u = (d.x.atan2(-d.z) / TAU + 0.5) * bw as f32;
            let v = d.y.clamp(-1.0, 1.0).acos() / PI * bh as f32;
            (v as usize).min(bh - 1) * bw + (u as usize).min(bw - 1)
        };
        let mut observed = vec![0.0f64; bw * bh];
        let mut rng = Rng::new(8);
        for _ in 0..n {
            observed[bin(sample(rng.uniform2()))] += 1.0;
        }
        let mut expected = vec![0.0f64; bw * bh];
        for k in 0..fw * fh {
            let theta = PI * ((k / fw) as f32 + 0.5) / fh as f32;
            let d = latlong(theta, TAU * (((k % fw) as f32 + 0.5) / fw as f32 - 0.5));
            let dw = theta.sin() * (PI / fh as f32) * (TAU / fw as f32);
            expected[bin(d)] += f64::from(pdf(d) * dw) * n as f64;
        }
        assert_chi2(&observed, &expected)
    }
}

#[cfg(test)]
mod tests {
    use super::testing::*;
    use super::*;
    use crate::sampler::Rng;

    #[test]
    fn one_dimensional_sampling_inverts_the_cdf() {
        let d = Distribution1D::new(&[1.0, 0.0, 3.0, f32::NAN, -2.0, 4.0, 0.0, 2.0]);
        assert_eq!(d.len(), 8);
        assert!((d.integral() - 10.0 / 8.0).abs() < 1e-6);
        let mut rng = Rng::new(1);
        // 32 sub-bins, 4 per bin, so that the spread inside a bin is tested too.
        let mut counts = [0.0f64; 32];
        for _ in 0..20_000 {
            let s = d.sample(rng.uniform()).expect("not black");
            assert!((0.0..1.0).contains(&s.x));
            assert_eq!(s.index, d.bin_of(s.x));
            // sample then pdf: the same density.
            assert!((d.pdf(s.x) - s.pdf).abs() <= 1e-6 * s.pdf, "{s:?}");
            counts[(s.x * 32.0) as usize] += 1.0;
        }
        // Zero, NaN and negative bins are never chosen.
        for i in [1, 3, 4, 6] {
            assert_eq!(counts[4 * i..4 * i + 4].iter().sum::<f64>(), 0.0, "bin {i}");
            assert_eq!(d.pdf((i as f32 + 0.5) / 8.0), 0.0);
        }
        // Exact inversion at bin edges: u = cdf[2] = 0.1 starts bin 2.
        let s = d.sample(0.1).unwrap();
        assert_eq!(s.index, 2);
        assert!((s.x - 2.0 / 8.0).abs() < 1e-6);
        // u = 1 is clamped into the last positive bin.
        assert_eq!(d.sample(1.0).unwrap().index, 7);
        // χ² of 20 000 samples in the 32 sub-bins against pdf/32: 16 positive → 15 dof.
        let expected: Vec<f64> = (0..32)
            .map(|k| f64::from(d.pdf((k as f32 + 0.5) / 32.0)) / 32.0 * 20_000.0)
            .collect();
        assert_eq!(assert_chi2(&counts, &expected).1, 15);
    }

    #[test]
    fn all_zero_and_empty_inputs_are_black_without_nan() {
        for w in [&[][..], &[0.0, 0.0, 0.0][..], &[f32::INFINITY, -1.0][..]] {
            let d = Distribution1D::new(w);
            assert!(d.is_black());
            assert!(d.sample(0.3).is_none());
            assert_eq!(d.pdf(0.3), 0.0);
            assert_eq!(d.bin_probability(0), 0.0);
        }
        let d2 = Distribution2D::new(4, 3, &[0.0; 12]);
        assert!(d2.is_black() && d2.sample(Vec2::splat(0.5)).is_none());
        assert_eq!(d2.pdf(Vec2::splat(0.5)), 0.0);
        let empty = Distribution2D::new(0, 0, &[]);
        assert!(empty.is_black() && empty.sample(Vec2::ZERO).is_none());
    }

    #[test]
    fn two_dimensional_sampling_matches_the_weights() {
        // 4 × 3 grid with a zero row and zero cells.
        #[rustfmt::skip]
        let w = [
            1.0, 0.0, 2.0, 1.0,
            0.0, 0.0, 0.0, 0.0,
            3.0, 1.0, 0.0, 4.0,
        ];
        let d = Distribution2D::new(4, 3, &w);
        assert_eq!((d.width(), d.height()), (4, 3));
        let total: f32 = w.iter().sum();
        let n = 60_000;
        let mut counts = [0.0f64; 12];
        let mut rng = Rng::new(2);
        for _ in 0..n {
            let s = d.sample(rng.uniform2()).expect("not black");
            let (c, r) = s.cell;
            assert!(w[r * 4 + c] > 0.0, "zero cell {c},{r} chosen");
            assert!((d.pdf(s.uv) - s.pdf).abs() <= 1e-5 * s.pdf);
            // Density = weight / mean weight.
            assert!((s.pdf - w[r * 4 + c] / (total / 12.0)).abs() < 1e-5 * s.pdf);
            counts[r * 4 + c] += 1.0;
        }
        let expected: Vec<f64> = (0..12)
            .map(|i| f64::from(d.cell_probability(i % 4, i / 4)) * f64::from(n))
            .collect();
        for (i, e) in expected.iter().enumerate() {
            assert!((e / f64::from(n) - f64::from(w[i] / total)).abs() < 1e-6);
        }
        let positive: Vec<usize> = (0..12).filter(|&i| w[i] > 0.0).collect();
        let o: Vec<f64> = positive.iter().map(|&i| counts[i]).collect();
        let e: Vec<f64> = positive.iter().map(|&i| expected[i]).collect();
        // 6 positive cells → 5 dof.
        assert_eq!(assert_chi2(&o, &e).1, 5);
    }

    #[test]
    fn tables_hold_one_f32_per_bin_and_report_the_density_they_sample() {
        // A bin far below the f32 resolution of the row total gets width 0: never sampled, and
        // its density is 0 too (what is reported is what is sampled).
        let mut w = vec![1.0f32; 1000];
        w[500] = 1e-12;
        let d = Distribution1D::new(&w);
        assert_eq!(d.pdf(500.5 / 1000.0), 0.0);
        assert_eq!(d.bin_probability(500), 0.0);
        let mut rng = Rng::new(3);
        for _ in 0..5000 {
            let s = d.sample(rng.uniform()).unwrap();
            assert_ne!(s.index, 500);
            assert_eq!(d.pdf(s.x), s.pdf);
        }
        let d2 = Distribution2D::from_rows(100, 50, |r, buf| {
            buf.extend((0..100).map(|c| (r * 100 + c) as f32));
        });
        assert_eq!(
            d2,
            Distribution2D::new(100, 50, &(0..5000).map(|i| i as f32).collect::<Vec<_>>())
        );
        let bytes = d2.heap_bytes();
        let min = 50 * 101 * 4 + 51 * 4;
        assert!(bytes >= min && bytes <= min + 50 * 64, "{bytes}");
        for _ in 0..2000 {
            let s = d2.sample(rng.uniform2()).unwrap();
            assert!((d2.pdf(s.uv) - s.pdf).abs() <= 1e-6 * s.pdf);
        }
    }

    #[test]
    fn chi2_critical_value_is_close_to_the_table() {
        // Tabulated χ²₀.₉₉: 23.21 (10 dof), 63.69 (40), 135.81 (100).
        for (k, t) in [(10, 23.21), (40, 63.69), (100, 135.81)] {
            assert!((chi2_critical_001(k) - t).abs() / t < 0.01, "{k}");
        }
    }
}
