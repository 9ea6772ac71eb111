//! Statistical and robustness tests of the texture maps (`lapidary::texture`, docs/design.md §6): Voronoi
//! entry and fill frequencies, facet-tilt distributions, the geometry of the cellular basis,
//! determinism across threads, seed decorrelation, finiteness at awkward coordinates, switch blend
//! bands and the energy of the rule for facets seen from behind.
//!
//! Maps are built directly with `Map::new(nodes, entries, stops, FieldTable, root)`; materials are
//! plain `u32` indices. Every random number comes from `lapidary::sampler` with fixed keys, so a run
//! is reproducible; the significance statements below are about the choice of those keys.
//!
//! **Significance.** The file's hypothesis tests (chi-square, exact binomial, normal tests of a
//! correlation or a Monte Carlo mean) form one family at overall significance `ALPHA = 0.01`, split
//! over its `K` tests by Šidák's correction, `α_i = 1 − (1 − 0.01)^(1/K)` (see [`family_size`]:
//! `K = 2 + 3 + 2 + 5 + 8 + 32 = 52`, so `α_i ≈ 1.93e-4`). A correct implementation fails a default
//! run with probability ≤ 0.01. The furnace's extra one-sided bound `≤ 1 + 4σ` adds at most
//! `8 · 3.2e-5` (it can only be reached by chance in the 8 configurations whose exact value is 1).
//! The negative controls (a deliberately wrong tilt pdf, correlated fields, correlated maps) must
//! be rejected at `α_i`, which shows the tests have power at the sample sizes used.
//!
//! Default sample counts keep the file under a few seconds at `opt-level = 3`; the tests that
//! gain power from more samples have `#[ignore]`d full-strength versions (10×):
//! `cargo test --release --test maps -- --ignored --nocapture`. Tables are printed with
//! `--nocapture`.

#[path = "../common/mod.rs"]
mod common;

mod basis;
mod determinism;
mod facet;
mod finite;
mod frequencies;
mod support;
mod switch;
mod tilt;

use common::{chi2_p_value, ln_gamma, sidak_alpha};
use glam::{IVec3, Vec3};
use lapidary::sampler::Rng;
use lapidary::texture::Voronoi;

// ------------------------------------------------------------------------------------------------
// The test family and its significance
// ------------------------------------------------------------------------------------------------

/// Overall significance of the file's hypothesis tests.
const ALPHA: f64 = 0.01;
/// Entry frequencies: by cell id, and end to end through `Map::lookup`.
const K_ENTRY: usize = 2;
/// Fill fractions 0.02, 0.25, 0.9.
const K_FILL: usize = 3;
/// Tilt distributions: cone, Beckmann.
const K_TILT: usize = 2;
/// Seed decorrelation: material agreement, two fBm correlations, turbulence, overlapping octaves.
const K_SEED: usize = 5;
/// Switch bands: five two-stop and two three-stop band values, one nested switch.
const K_SWITCH: usize = 8;
/// Furnace configurations compared with the analytic value.
pub(crate) const K_FURNACE: usize =
    facet::FURNACE_TILT_DEG.len() * facet::FURNACE_THETA_O_DEG.len() * 2;

/// Number of hypothesis tests in the family (module docs).
const fn family_size() -> usize {
    K_ENTRY + K_FILL + K_TILT + K_SEED + K_SWITCH + K_FURNACE
}

/// Per-test significance (Šidák).
pub(crate) fn alpha_i() -> f64 {
    sidak_alpha(ALPHA, family_size())
}

/// Two-sided p-value of a standard normal statistic: `P(|Z| ≥ |z|) = P(χ²₁ ≥ z²)`.
pub(crate) fn normal_p(z: f64) -> f64 {
    chi2_p_value(z * z, 1)
}

/// The `z` with two-sided normal tail `alpha` (the library's quantile, `image::stats`).
pub(crate) fn z_critical(alpha: f64) -> f64 {
    lapidary::image::stats::normal_quantile_two_sided(alpha)
}

/// Exact two-sided binomial p-value of `k` successes in `n` trials of probability `p`: twice the
/// smaller tail `min(P(X ≤ k), P(X ≥ k))`, capped at 1. Tails are summed from `k` outwards in log
/// space and stopped once the terms (past the mode) fall below 1e-17 of the sum.
pub(crate) fn binomial_p(k: u64, n: u64, p: f64) -> f64 {
    assert!(k <= n && p > 0.0 && p < 1.0, "k={k} n={n} p={p}");
    let (nf, lp, lq) = (n as f64, p.ln(), (-p).ln_1p());
    let ln_n = ln_gamma(nf + 1.0);
    let pmf = |j: u64| {
        (ln_n - ln_gamma(j as f64 + 1.0) - ln_gamma((n - j) as f64 + 1.0)
            + j as f64 * lp
            + (n - j) as f64 * lq)
            .exp()
    };
    let mode = nf * p;
    let mut lower = 0.0;
    let mut j = k;
    loop {
        let t = pmf(j);
        lower += t;
        if j == 0 || ((j as f64) < mode && t <= lower * 1e-17) {
            break;
        }
        j -= 1;
    }
    let mut upper = 0.0;
    let mut j = k;
    loop {
        let t = pmf(j);
        upper += t;
        if j == n || ((j as f64) > mode && t <= upper * 1e-17) {
            break;
        }
        j += 1;
    }
    (2.0 * lower.min(upper)).min(1.0)
}

/// Exact probability that `to_unit_f32` (a multiple of 2⁻²⁴ in `[0, 1)`) is below `x`.
pub(crate) fn p_below(x: f32) -> f64 {
    let scale = 16_777_216.0;
    (f64::from(x) * scale).ceil().clamp(0.0, scale) / scale
}

/// Exact probabilities of the entries of a cumulative list (`pick` compares `to_unit_f32` with
/// the cumulative weights).
pub(crate) fn pick_probabilities(cumulative: &[f32]) -> Vec<f64> {
    let mut prev = 0.0;
    cumulative
        .iter()
        .enumerate()
        .map(|(i, &c)| {
            let at = if i + 1 == cumulative.len() {
                1.0
            } else {
                p_below(c)
            };
            let p = at - prev;
            prev = at;
            p
        })
        .collect()
}

pub(crate) fn pearson(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len() as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (&x, &y) in a.iter().zip(b) {
        sab += (x - ma) * (y - mb);
        saa += (x - ma) * (x - ma);
        sbb += (y - mb) * (y - mb);
    }
    sab / (saa * sbb).sqrt()
}

pub(crate) fn random_point(rng: &mut Rng, lo: f32, hi: f32) -> Vec3 {
    Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * (hi - lo) + Vec3::splat(lo)
}

pub(crate) fn random_unit(rng: &mut Rng) -> Vec3 {
    let z = 2.0 * rng.uniform() - 1.0;
    let phi = std::f32::consts::TAU * rng.uniform();
    let r = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// The ids of `n` distinct lattice cells: a block 64 × 64 × ⌈n / 4096⌉ around the origin
/// (negative coordinates included), in order.
pub(crate) fn block_ids(basis: &Voronoi, n: usize) -> Vec<u64> {
    let depth = n.div_ceil(4096) as i32;
    let mut out = Vec::with_capacity(n);
    'outer: for z in 0..depth {
        for y in 0..64 {
            for x in 0..64 {
                if out.len() == n {
                    break 'outer;
                }
                out.push(basis.cell_id(IVec3::new(x - 32, y - 32, z - depth / 2)));
            }
        }
    }
    out
}

#[test]
fn family_size_matches_the_tests() {
    assert_eq!(family_size(), 52);
    assert!((alpha_i() - 1.933e-4).abs() < 1e-6, "{}", alpha_i());
}
