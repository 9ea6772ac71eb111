//! Statistics shared by the statistical integration tests (`mod common;` in a test file).
//!
//! - [`ln_gamma`], [`gamma_q`]: the regularised upper incomplete gamma function `Q(a, x)`, and with
//!   it [`chi2_p_value`], the upper tail of the chi-square distribution, `P(X ≥ χ²) = Q(k/2, χ²/2)`.
//! - [`sidak_alpha`]: the per-test significance that keeps a family of independent tests at an
//!   overall significance (Šidák 1967).
//! - [`chi_square_pooled`]: Pearson's statistic over histogram cells with low-expectation cells
//!   pooled and samples in zero-expectation cells reported.
//! - [`Grid2`], [`SphereGrid`]: 2-D histograms (generic rectangle; the full sphere of directions in
//!   `(θ, φ)`) with a per-bin integrator of a density (composite 3 × 3 Gauss–Legendre, refined
//!   adaptively where the density has narrow peaks or edges).
//! - [`par_map`]: runs independent configurations on all cores, results in input order.
//!
//! Every helper here is deterministic; nothing draws random numbers.

#![allow(dead_code)]

use glam::Vec3;
use std::f64::consts::PI;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

// ------------------------------------------------------------------------------------------------
// Gamma functions
// ------------------------------------------------------------------------------------------------

/// `ln Γ(z)` for `z > 0`.
///
/// The recurrence `Γ(z+1) = z Γ(z)` (Abramowitz & Stegun 6.1.15) moves the argument to `w ≥ 10`,
/// where Stirling's asymptotic series (A&S 6.1.40)
/// `ln Γ(w) = (w − ½) ln w − w + ½ ln 2π + Σ B₂ⱼ / (2j (2j−1) w^(2j−1))` is truncated after the
/// `B₁₀` term; the first omitted term is below `|B₁₂| / (132 · 10¹¹) ≈ 6e-15`.
pub fn ln_gamma(z: f64) -> f64 {
    assert!(z > 0.0, "ln_gamma needs z > 0, got {z}");
    let mut w = z;
    let mut log_shift = 0.0;
    while w < 10.0 {
        log_shift += w.ln();
        w += 1.0;
    }
    // Bernoulli numbers B2 … B10 divided by 2j(2j−1).
    let inv = 1.0 / w;
    let inv2 = inv * inv;
    let series = inv
        * (1.0 / 12.0
            + inv2
                * (-1.0 / 360.0
                    + inv2 * (1.0 / 1260.0 + inv2 * (-1.0 / 1680.0 + inv2 * (1.0 / 1188.0)))));
    (w - 0.5) * w.ln() - w + 0.5 * (2.0 * PI).ln() + series - log_shift
}

/// The regularised upper incomplete gamma function `Q(a, x) = Γ(a, x) / Γ(a)` for `a > 0`,
/// `x ≥ 0`, to about 1e-13 relative accuracy.
///
/// Both branches share the prefactor `e^{−x} x^a / Γ(a)` (computed in logarithms so that it does
/// not overflow for large `a`).
/// - For `x < a + 1` the lower function is summed: expanding `e^{t}` in
///   `γ(a, x) = ∫₀ˣ t^{a−1} e^{−t} dt` after the substitution that pulls out `e^{−x} x^a` gives
///   `γ(a, x) = e^{−x} x^a Σₙ xⁿ / (a (a+1) ⋯ (a+n))` (A&S 6.5.4 with 6.5.29). The terms decrease
///   once `n > x − a`, so the series converges fast there; `Q = 1 − P`.
/// - Otherwise the continued fraction of A&S 6.5.31,
///   `Γ(a, x) = e^{−x} x^a · 1/(x + (1−a)/(1 + 1/(x + (2−a)/(1 + 2/(x + …)))))`,
///   is contracted to its even part, whose n-th step has partial numerator `−n (n − a)` and
///   denominator `x + 2n + 1 − a`, and evaluated forwards by the modified Lentz method
///   (Lentz 1976; Thompson & Barnett 1986), which needs no a-priori depth.
pub fn gamma_q(a: f64, x: f64) -> f64 {
    assert!(
        a > 0.0 && x >= 0.0,
        "gamma_q needs a > 0, x ≥ 0: a={a}, x={x}"
    );
    if x == 0.0 {
        return 1.0;
    }
    let log_prefactor = -x + a * x.ln() - ln_gamma(a);
    if x < a + 1.0 {
        // Series for P(a, x).
        let mut term = 1.0 / a;
        let mut sum = term;
        let mut n = 1.0;
        while term.abs() > sum.abs() * 1e-16 {
            term *= x / (a + n);
            sum += term;
            n += 1.0;
            assert!(n < 1e6, "gamma series did not converge: a={a}, x={x}");
        }
        (1.0 - sum * log_prefactor.exp()).clamp(0.0, 1.0)
    } else {
        // Continued fraction for Q(a, x), modified Lentz.
        const TINY: f64 = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / TINY;
        let mut d = 1.0 / b;
        let mut frac = d;
        let mut n = 1.0;
        loop {
            let an = -n * (n - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < TINY {
                d = TINY;
            }
            c = b + an / c;
            if c.abs() < TINY {
                c = TINY;
            }
            d = 1.0 / d;
            let delta = d * c;
            frac *= delta;
            if (delta - 1.0).abs() < 1e-16 {
                break;
            }
            n += 1.0;
            assert!(
                n < 1e6,
                "gamma continued fraction did not converge: a={a}, x={x}"
            );
        }
        (frac * log_prefactor.exp()).clamp(0.0, 1.0)
    }
}

/// Upper-tail probability of the chi-square distribution with `dof` degrees of freedom:
/// `P(X ≥ chi2) = Q(dof/2, chi2/2)`. With `dof == 0` the statistic is identically 0 and the
/// p-value is 1.
pub fn chi2_p_value(chi2: f64, dof: usize) -> f64 {
    if dof == 0 {
        return 1.0;
    }
    gamma_q(0.5 * dof as f64, 0.5 * chi2.max(0.0))
}

/// Šidák's per-test significance `1 − (1 − alpha)^(1/k)` for a family of `k` independent tests
/// at overall significance `alpha` (Šidák, "Rectangular confidence regions for the means of
/// multivariate normal distributions", JASA 62, 1967). Computed with `ln_1p`/`exp_m1` so that it
/// stays accurate for large `k`.
pub fn sidak_alpha(alpha: f64, k: usize) -> f64 {
    assert!(k >= 1 && (0.0..1.0).contains(&alpha));
    -((-alpha).ln_1p() / k as f64).exp_m1()
}

// ------------------------------------------------------------------------------------------------
// Pearson's chi-square with pooling
// ------------------------------------------------------------------------------------------------

/// The outcome of [`chi_square_pooled`].
#[derive(Clone, Debug, PartialEq)]
pub struct ChiSquare {
    /// Pearson's statistic `Σ (O − E)² / E` over the bins after pooling.
    pub chi2: f64,
    /// Degrees of freedom: bins after pooling − 1.
    pub dof: usize,
    /// `P(X ≥ chi2)` under the hypothesis (1 when `dof == 0`).
    pub p_value: f64,
    /// Cells that kept their own bin.
    pub own_bins: usize,
    /// Cells merged into the pooled bin.
    pub pooled_cells: usize,
    /// Cells with expectation exactly 0 that received samples: `(cell, count)`.
    pub zero_expectation_hits: Vec<(usize, u64)>,
}

impl ChiSquare {
    /// True when the fit is accepted at per-test significance `alpha` and no sample landed in a
    /// cell of zero expectation.
    pub fn passes(&self, alpha: f64) -> bool {
        self.zero_expectation_hits.is_empty() && self.p_value >= alpha
    }
}

/// Pearson's chi-square test of observed counts against expected counts.
///
/// The caller must include every possible outcome, so that `Σ observed` equals the number of
/// draws and `Σ expected` that number up to quadrature error (e.g. a cell for failed samples).
/// Cells with expectation exactly 0 are left out of the statistic; samples in them are reported in
/// [`ChiSquare::zero_expectation_hits`] and make the test fail. Cells with expectation below
/// `min_expected` (Cochran's rule: 5) are merged into one pooled bin; if that bin still expects
/// less than `min_expected` it is merged into the smallest own bin. Which cells are pooled depends
/// on the expectations only, never on the data, so the statistic keeps its chi-square law.
pub fn chi_square_pooled(observed: &[u64], expected: &[f64], min_expected: f64) -> ChiSquare {
    assert_eq!(observed.len(), expected.len());
    let mut zero_hits = Vec::new();
    let mut bins: Vec<(f64, f64)> = Vec::new();
    let (mut pool_o, mut pool_e, mut pooled_cells) = (0.0, 0.0, 0usize);
    for (i, (&o, &e)) in observed.iter().zip(expected).enumerate() {
        assert!(e.is_finite() && e >= 0.0, "cell {i}: expected count {e}");
        if e == 0.0 {
            if o > 0 {
                zero_hits.push((i, o));
            }
        } else if e < min_expected {
            pool_o += o as f64;
            pool_e += e;
            pooled_cells += 1;
        } else {
            bins.push((o as f64, e));
        }
    }
    let own_bins = bins.len();
    if pool_e > 0.0 {
        if pool_e >= min_expected || bins.is_empty() {
            bins.push((pool_o, pool_e));
        } else {
            let smallest = (0..bins.len())
                .min_by(|&a, &b| bins[a].1.total_cmp(&bins[b].1))
                .expect("non-empty");
            bins[smallest].0 += pool_o;
            bins[smallest].1 += pool_e;
        }
    }
    let chi2: f64 = bins.iter().map(|&(o, e)| (o - e) * (o - e) / e).sum();
    let dof = bins.len().saturating_sub(1);
    ChiSquare {
        chi2,
        dof,
        p_value: chi2_p_value(chi2, dof),
        own_bins,
        pooled_cells,
        zero_expectation_hits: zero_hits,
    }
}

// ------------------------------------------------------------------------------------------------
// Histograms and per-bin integration
// ------------------------------------------------------------------------------------------------

/// Nodes and weights of 3-point Gauss–Legendre quadrature on `[−1, 1]` (exact for polynomials of
/// degree ≤ 5; A&S 25.4.29).
const GL3: [(f64, f64); 3] = [
    (-0.774_596_669_241_483_4, 5.0 / 9.0),
    (0.0, 8.0 / 9.0),
    (0.774_596_669_241_483_4, 5.0 / 9.0),
];

/// A regular `nu × nv` grid of bins over the rectangle `[u0, u1) × [v0, v1)`; bin `(i, j)` has
/// index `i · nv + j`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid2 {
    /// Bins along `u`.
    pub nu: usize,
    /// Bins along `v`.
    pub nv: usize,
    /// Range of `u`.
    pub u: (f64, f64),
    /// Range of `v`.
    pub v: (f64, f64),
}

impl Grid2 {
    /// Number of bins.
    pub fn len(&self) -> usize {
        self.nu * self.nv
    }

    /// Always false (a grid has at least one bin).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The bin holding `(u, v)`, `None` outside the rectangle or for non-finite input. A point on
    /// the upper edge `u1` (or `v1`) is put into the last bin.
    pub fn bin(&self, u: f64, v: f64) -> Option<usize> {
        let fu = (u - self.u.0) / (self.u.1 - self.u.0);
        let fv = (v - self.v.0) / (self.v.1 - self.v.0);
        if !(0.0..=1.0).contains(&fu) || !(0.0..=1.0).contains(&fv) {
            return None;
        }
        let i = ((fu * self.nu as f64) as usize).min(self.nu - 1);
        let j = ((fv * self.nv as f64) as usize).min(self.nv - 1);
        Some(i * self.nv + j)
    }

    /// `∫∫_bin density(u, v) du dv` for every bin: each bin is split into `sub × sub` cells with
    /// 3 × 3 Gauss–Legendre points each (a composite rule, A&S 25.4.29 per cell).
    pub fn integrate(&self, sub: usize, density: impl Fn(f64, f64) -> f64) -> Vec<f64> {
        self.integrate_adaptive(sub, 0.0, 0, density)
    }

    /// Like [`Self::integrate`], but every cell is refined adaptively: a cell's 3 × 3-point
    /// estimate is compared with the sum of the estimates of its four quarters; if they differ by
    /// more than `tol` (and `max_depth` allows), each quarter is refined in turn with `tol / 2`,
    /// otherwise the quarters' sum is kept. So every bin gets at least `2sub × 2sub` cells, and
    /// narrow peaks and discontinuities (a glossy lobe squeezed at grazing angles, a horizon)
    /// get as many more as they need. With `max_depth == 0` this is the plain composite rule.
    pub fn integrate_adaptive(
        &self,
        sub: usize,
        tol: f64,
        max_depth: u32,
        density: impl Fn(f64, f64) -> f64,
    ) -> Vec<f64> {
        let (du, dv) = (
            (self.u.1 - self.u.0) / (self.nu * sub) as f64,
            (self.v.1 - self.v.0) / (self.nv * sub) as f64,
        );
        let f = &density;
        let mut out = vec![0.0; self.len()];
        for i in 0..self.nu {
            for j in 0..self.nv {
                let mut sum = 0.0;
                for a in 0..sub {
                    let u0 = self.u.0 + (i * sub + a) as f64 * du;
                    for b in 0..sub {
                        let v0 = self.v.0 + (j * sub + b) as f64 * dv;
                        let coarse = gl_cell(u0, v0, du, dv, f);
                        sum += if max_depth == 0 {
                            coarse
                        } else {
                            refine(u0, v0, du, dv, coarse, tol, max_depth, f)
                        };
                    }
                }
                out[i * self.nv + j] = sum;
            }
        }
        out
    }
}

/// 3 × 3-point Gauss–Legendre estimate of `∫∫ f` over the cell `[u0, u0+du] × [v0, v0+dv]`.
fn gl_cell(u0: f64, v0: f64, du: f64, dv: f64, f: &impl Fn(f64, f64) -> f64) -> f64 {
    let (uc, vc) = (u0 + 0.5 * du, v0 + 0.5 * dv);
    let mut sum = 0.0;
    for &(xu, wu) in &GL3 {
        for &(xv, wv) in &GL3 {
            sum += wu * wv * f(uc + 0.5 * du * xu, vc + 0.5 * dv * xv);
        }
    }
    sum * 0.25 * du * dv
}

/// One step of the adaptive rule of [`Grid2::integrate_adaptive`]; `coarse` is the cell's own
/// estimate.
#[allow(clippy::too_many_arguments)]
fn refine(
    u0: f64,
    v0: f64,
    du: f64,
    dv: f64,
    coarse: f64,
    tol: f64,
    depth: u32,
    f: &impl Fn(f64, f64) -> f64,
) -> f64 {
    let (hu, hv) = (0.5 * du, 0.5 * dv);
    let corners = [(u0, v0), (u0 + hu, v0), (u0, v0 + hv), (u0 + hu, v0 + hv)];
    let quarters = corners.map(|(a, b)| gl_cell(a, b, hu, hv, f));
    let fine: f64 = quarters.iter().sum();
    if depth <= 1 || (fine - coarse).abs() <= tol {
        return fine;
    }
    corners
        .iter()
        .zip(quarters)
        .map(|(&(a, b), q)| refine(a, b, hu, hv, q, 0.5 * tol, depth - 1, f))
        .sum()
}

/// A histogram over the **full** sphere of directions: `θ ∈ [0, π]` from `+z` in `n_theta`
/// uniform bins, `φ ∈ [0, 2π)` from `+x` in `n_phi` uniform bins. Directions below the horizon
/// have bins of their own, so a stray sample there lands in a bin whose integrated pdf is 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereGrid {
    /// The underlying `(θ, φ)` grid.
    pub grid: Grid2,
}

impl SphereGrid {
    /// `n_theta × n_phi` bins.
    pub fn new(n_theta: usize, n_phi: usize) -> Self {
        SphereGrid {
            grid: Grid2 {
                nu: n_theta,
                nv: n_phi,
                u: (0.0, PI),
                v: (0.0, 2.0 * PI),
            },
        }
    }

    /// Number of bins.
    pub fn len(&self) -> usize {
        self.grid.len()
    }

    /// Always false.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// `(θ, φ)` of a (not necessarily normalised) direction, in `f64` with `θ` from `atan2` so
    /// that it is accurate near the poles.
    pub fn angles(w: Vec3) -> (f64, f64) {
        let (x, y, z) = (f64::from(w.x), f64::from(w.y), f64::from(w.z));
        let theta = (x * x + y * y).sqrt().atan2(z);
        let mut phi = y.atan2(x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        (theta, phi)
    }

    /// The bin of direction `w`; `None` for a non-finite or zero vector.
    pub fn bin(&self, w: Vec3) -> Option<usize> {
        if !w.is_finite() || w.length_squared() == 0.0 {
            return None;
        }
        let (t, p) = Self::angles(w);
        self.grid.bin(t, p)
    }

    /// `∫_bin pdf(ω) dω` for every bin (`dω = sin θ dθ dφ`) by [`Grid2::integrate_adaptive`]
    /// (`sub × sub` cells per bin, each refined to absolute tolerance `tol`, at most `max_depth`
    /// halvings). `pdf` receives unit `f32` directions.
    pub fn integrate(
        &self,
        sub: usize,
        tol: f64,
        max_depth: u32,
        pdf: impl Fn(Vec3) -> f64,
    ) -> Vec<f64> {
        self.grid
            .integrate_adaptive(sub, tol, max_depth, |theta, phi| {
                let (st, ct) = theta.sin_cos();
                let (sp, cp) = phi.sin_cos();
                let w = Vec3::new((st * cp) as f32, (st * sp) as f32, ct as f32);
                pdf(w) * st
            })
    }
}

// ------------------------------------------------------------------------------------------------
// Running configurations in parallel
// ------------------------------------------------------------------------------------------------

/// `items.iter().map(f)` on all available cores (scoped threads pulling indices from a shared
/// counter); the results come back in input order, so output is independent of scheduling.
pub fn par_map<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(items.len().max(1));
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<R>>> = Mutex::new((0..items.len()).map(|_| None).collect());
    std::thread::scope(|s| {
        for _ in 0..threads {
            s.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    if i >= items.len() {
                        break;
                    }
                    let r = f(&items[i]);
                    results.lock().expect("no poisoned lock")[i] = Some(r);
                }
            });
        }
    });
    results
        .into_inner()
        .expect("no poisoned lock")
        .into_iter()
        .map(|r| r.expect("every item was processed"))
        .collect()
}
