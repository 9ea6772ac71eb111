//! Chi-square of the non-delta part of a stack with a smooth top coat, with the machinery of
//! tests/chi_square.rs (tests/common: Pearson's statistic with cells expecting < 5 pooled, the
//! adaptively refined per-bin integral of `pdf`), on the upper hemisphere only (24 θ × 96 φ bins of
//! 3.75°; a sample below the horizon is invalid and fails the test) and with two extra cells: the
//! specular samples, expected `N · w_top` (`w_top` = the delta's `pdf`, the discrete probability
//! of choosing it), and the failed samples, expected `N (1 − w_top − ∫ pdf)`.

use super::common::{ChiSquare, Grid2, SphereGrid, chi_square_pooled};
use glam::{Vec2, Vec3};
use lapidary::bsdf::Bxdf;
use lapidary::sampler::Rng;
use std::f64::consts::PI;

/// Bins of the upper hemisphere.
const N_THETA: usize = 24;
const N_PHI: usize = 96;
/// Quadrature: 4 × 4 cells per bin, refined to 1e-8 of probability, at most 6 halvings.
const SUB: usize = 4;
const QUAD_TOL: f64 = 1e-8;
const QUAD_DEPTH: u32 = 6;
/// Cochran's rule.
const MIN_EXPECTED: f64 = 5.0;

/// The upper hemisphere as a [`SphereGrid`] (θ from 0 to π/2).
pub fn hemisphere(n_theta: usize, n_phi: usize) -> SphereGrid {
    SphereGrid {
        grid: Grid2 {
            nu: n_theta,
            nv: n_phi,
            u: (0.0, 0.5 * PI),
            v: (0.0, 2.0 * PI),
        },
    }
}

/// The delta's selection probability as `claimed` reports it (0 when `uc = 0` is not specular).
pub fn top_weight(claimed: &impl Bxdf, wo: Vec3) -> f64 {
    claimed
        .sample(wo, 0.0, Vec2::splat(0.5))
        .filter(|s| s.flags.is_specular())
        .map_or(0.0, |s| f64::from(s.pdf))
}

/// One test's outcome.
pub struct Outcome {
    pub specular: u64,
    pub failed: u64,
    pub invalid: u64,
    /// Specular samples whose `pdf` differs from the claimed top weight.
    pub odd_delta: u64,
    pub top: f64,
    pub integral: f64,
    pub chi: ChiSquare,
}

impl Outcome {
    pub fn passes(&self, alpha: f64) -> bool {
        self.invalid == 0
            && self.odd_delta == 0
            && self.top + self.integral <= 1.0 + 1e-3
            && self.chi.passes(alpha)
    }
}

/// Draws `n` samples of `sampled` at `wo` and tests them against `claimed`'s pdf and top weight.
pub fn run(sampled: &impl Bxdf, claimed: &impl Bxdf, wo: Vec3, n: u64, seed: u64) -> Outcome {
    let grid = hemisphere(N_THETA, N_PHI);
    let cells = grid.len();
    let top = top_weight(claimed, wo);
    let mut observed = vec![0u64; cells + 2];
    let (mut invalid, mut odd_delta) = (0, 0);
    let mut rng = Rng::new(seed);
    for _ in 0..n {
        match sampled.sample(wo, rng.uniform(), rng.uniform2()) {
            None => observed[cells + 1] += 1,
            Some(s) if s.flags.is_specular() => {
                observed[cells] += 1;
                if f64::from(s.pdf) != top {
                    odd_delta += 1;
                }
            }
            Some(s) => match grid.bin(s.wi) {
                Some(b) => observed[b] += 1,
                None => invalid += 1,
            },
        }
    }
    let mass = grid.integrate(SUB, QUAD_TOL, QUAD_DEPTH, |w| f64::from(claimed.pdf(wo, w)));
    let integral: f64 = mass.iter().sum();
    let mut expected: Vec<f64> = mass.iter().map(|m| m * n as f64).collect();
    expected.push(top * n as f64);
    expected.push((1.0 - top - integral).max(0.0) * n as f64);
    Outcome {
        specular: observed[cells],
        failed: observed[cells + 1],
        invalid,
        odd_delta,
        top,
        integral,
        chi: chi_square_pooled(&observed, &expected, MIN_EXPECTED),
    }
}
