//! Chi-square goodness of fit of `RoughDielectric::sample_mode` against `pdf` over the **full**
//! sphere (reflection and transmission hemispheres), with the per-sample checks of
//! [`super::checks`] in both transport modes. The method is tests/chi_square.rs's (the same grid,
//! quadrature, pooling and failed-sample cell), on the machinery of tests/common.

use super::checks::{SampleStats, check_rough};
use super::common::{ChiSquare, SphereGrid, chi_square_pooled};
use glam::Vec3;
use lapidary::bsdf::measure::direction_deg;
use lapidary::bsdf::{Bxdf, Distribution, Masking, MicrofacetDistribution, RoughDielectric};
use lapidary::sampler::{Rng, hash_words};

/// Histogram resolution over the sphere (3.75° bins), as in tests/chi_square.rs.
pub const N_THETA: usize = 48;
pub const N_PHI: usize = 96;
/// Quadrature of the expected counts: 4 × 4 cells per bin, each refined adaptively to 1e-8 of
/// probability (halved per level, at most 6 levels).
const SUB: usize = 4;
const QUAD_TOL: f64 = 1e-8;
const QUAD_DEPTH: u32 = 6;
/// Cochran's rule: pool cells expecting fewer samples than this.
const MIN_EXPECTED: f64 = 5.0;
/// Largest accepted `∫ pdf dω` (quadrature error allowance).
pub const MAX_INTEGRAL: f64 = 1.0 + 1e-3;

/// Micro-facet distributions `(kind, RMS slope m in degrees)`.
pub const SURFACES: [(Distribution, f32); 4] = [
    (Distribution::Blinn, 5.0),
    (Distribution::Blinn, 20.0),
    (Distribution::Blinn, 45.0),
    (Distribution::Beckmann, 20.0),
];
/// Surfaces with Smith masking (issue 16): GGX with its visible-normal sampler, Beckmann with
/// `D cos` sampling; height-correlated and separable forms.
pub const SMITH_SURFACES: [(Distribution, f32, Masking); 3] = [
    (Distribution::Ggx, 20.0, Masking::Smith),
    (Distribution::Ggx, 45.0, Masking::SmithSeparable),
    (Distribution::Beckmann, 20.0, Masking::Smith),
];
/// Relative IORs (below / above): glass, diamond, and glass with the dense side above.
pub const ETAS: [f32; 3] = [1.5, 2.4, 1.0 / 1.5];
/// Viewing directions `(θo, φo)` in degrees above the surface; each is also used mirrored below
/// (reported as `180° − θo`).
pub const VIEWS: [(f32, f32); 3] = [(10.0, 0.0), (40.0, 40.0), (75.0, 250.0)];

/// One configuration.
#[derive(Clone)]
pub struct Config {
    /// Report label.
    pub label: String,
    /// The interface.
    pub bsdf: RoughDielectric,
    /// Viewing direction.
    pub wo: Vec3,
    /// `(θo, φo)` in degrees (θo > 90° below the surface).
    pub wo_deg: (f32, f32),
}

/// Every surface × IOR × view, above and below.
pub fn configs() -> Vec<Config> {
    let mut v = Vec::new();
    let surfaces = SURFACES
        .iter()
        .map(|&(k, m)| (k, m, Masking::VCavity))
        .chain(SMITH_SURFACES);
    for (kind, m, masking) in surfaces {
        for &eta in &ETAS {
            for &(t, p) in &VIEWS {
                for below in [false, true] {
                    let w = direction_deg(t, p);
                    let (wo, deg) = if below {
                        (Vec3::new(w.x, w.y, -w.z), (180.0 - t, p))
                    } else {
                        (w, (t, p))
                    };
                    v.push(Config {
                        label: format!("{kind:?} {masking:?} m={m} eta={eta:.4}"),
                        bsdf: RoughDielectric::new(
                            MicrofacetDistribution::new(kind, m).with_masking(masking),
                            eta,
                        ),
                        wo,
                        wo_deg: deg,
                    });
                }
            }
        }
    }
    v
}

/// Number of configurations of [`configs`].
pub const COUNT: usize = (SURFACES.len() + SMITH_SURFACES.len()) * ETAS.len() * VIEWS.len() * 2;

/// The result of one configuration.
pub struct Row {
    pub label: String,
    pub wo_deg: (f32, f32),
    pub samples: u64,
    pub failed: u64,
    pub invalid: u64,
    pub integral: f64,
    pub chi: ChiSquare,
    pub stats: SampleStats,
}

impl Row {
    /// True when the fit is accepted and every sample kept its invariants.
    pub fn passes(&self, alpha: f64) -> bool {
        self.invalid == 0
            && self.integral <= MAX_INTEGRAL
            && self.chi.passes(alpha)
            && self.stats.bad == 0
    }

    /// Why a row fails.
    pub fn why(&self, alpha: f64) -> String {
        let mut v = Vec::new();
        if self.invalid > 0 {
            v.push(format!("{} invalid directions", self.invalid));
        }
        if self.integral > MAX_INTEGRAL {
            v.push(format!("∫pdf = {:.6} > {MAX_INTEGRAL}", self.integral));
        }
        if !self.chi.zero_expectation_hits.is_empty() {
            let n: u64 = self.chi.zero_expectation_hits.iter().map(|h| h.1).sum();
            v.push(format!("{n} samples in zero-pdf bins"));
        }
        if self.chi.p_value < alpha {
            v.push(format!("p = {:.3e} < {alpha:.3e}", self.chi.p_value));
        }
        if self.stats.bad > 0 {
            v.push(format!(
                "{} samples break an invariant; first: {}",
                self.stats.bad,
                self.stats.first_bad.as_deref().unwrap_or("")
            ));
        }
        v.join("; ")
    }
}

/// Draws `n` samples of `sampler` at `c.wo` (each checked in both modes) and tests their
/// directions against `claimed`'s pdf (the interface itself, or a wrong one for the self-test).
pub fn run(c: &Config, claimed: &dyn Bxdf, n: u64) -> Row {
    let grid = SphereGrid::new(N_THETA, N_PHI);
    let cells = grid.len();
    let mut observed = vec![0u64; cells + 1];
    let (mut failed, mut invalid) = (0u64, 0u64);
    let mut stats = SampleStats::default();
    let mut words: Vec<u64> = c.label.bytes().map(u64::from).collect();
    words.extend([
        u64::from(c.wo_deg.0.to_bits()),
        u64::from(c.wo_deg.1.to_bits()),
        n,
    ]);
    let mut rng = Rng::new(hash_words(&words));
    for _ in 0..n {
        let (uc, u) = (rng.uniform(), rng.uniform2());
        match check_rough(&c.bsdf, c.wo, uc, u, &mut stats) {
            None => failed += 1,
            Some((s, _)) => match grid.bin(s.wi) {
                Some(b) => observed[b] += 1,
                None => invalid += 1,
            },
        }
    }
    observed[cells] = failed;
    let mass = grid.integrate(SUB, QUAD_TOL, QUAD_DEPTH, |w| {
        f64::from(claimed.pdf(c.wo, w))
    });
    let integral: f64 = mass.iter().sum();
    let mut expected: Vec<f64> = mass.iter().map(|m| m * n as f64).collect();
    expected.push((1.0 - integral).max(0.0) * n as f64);
    Row {
        label: c.label.clone(),
        wo_deg: c.wo_deg,
        samples: n,
        failed,
        invalid,
        integral,
        chi: chi_square_pooled(&observed, &expected, MIN_EXPECTED),
        stats,
    }
}

/// Prints the table and returns the failures.
pub fn report(title: &str, rows: &[Row], alpha: f64) -> Vec<String> {
    println!("\n{title} (per-test α = {alpha:.3e})");
    println!(
        "{:<28} {:>6} {:>5} {:>8} {:>7} {:>7} {:>7} {:>9} {:>5} {:>9} {:>9} {:>8}  result",
        "configuration",
        "θo",
        "φo",
        "samples",
        "failed",
        "refl",
        "trans",
        "∫pdf",
        "dof",
        "chi²",
        "p-value",
        "max Δw"
    );
    let mut failures = Vec::new();
    for r in rows {
        let ok = r.passes(alpha);
        println!(
            "{:<28} {:>6.1} {:>5.0} {:>8} {:>7} {:>7} {:>7} {:>9.6} {:>5} {:>9.1} {:>9.3e} {:>8.1e}  {}",
            r.label,
            r.wo_deg.0,
            r.wo_deg.1,
            r.samples,
            r.failed,
            r.stats.reflected,
            r.stats.transmitted,
            r.integral,
            r.chi.dof,
            r.chi.chi2,
            r.chi.p_value,
            r.stats.worst_weight,
            if ok { "ok" } else { "FAIL" }
        );
        if !ok {
            failures.push(format!(
                "{} at θo={}°, φo={}°: {}",
                r.label,
                r.wo_deg.0,
                r.wo_deg.1,
                r.why(alpha)
            ));
        }
    }
    failures
}
