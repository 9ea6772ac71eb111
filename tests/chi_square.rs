//! Chi-square goodness of fit of `sample()` against `pdf()` (docs/design.md §10), and the consistency of the
//! weight `sample()` returns with `eval()` and `pdf()`.
//!
//! Method (the test of Jakob's Mitsuba `ChiSquareTest`, written from its description): draw `N`
//! directions `wi` from `sample(wo, ·)`, histogram them over the full sphere (48 θ × 96 φ bins of
//! 3.75°, so that a stray sample below the horizon lands in a bin of its own), and compare with
//! the expected counts `N · ∫_bin pdf(wo, ω) dω`. `N` counts failed samples (`None`) too, since a
//! pdf may integrate to less than 1; they form one more cell whose expectation is
//! `N (1 − ∫ pdf)`. Cells expecting fewer than 5 samples are pooled; a sample in a bin whose
//! integrated pdf is exactly 0 fails the test outright, as does a total integral above `1 + 1e-3`.
//!
//! The per-bin integral must be accurate to far better than a sample's worth of probability
//! (1/N), or the failed-sample cell alone rejects a correct sampler: a glossy lobe seen at 85° is
//! squeezed across the plane of incidence by `cos θd` (a coat with m = 1° gives a lobe ≈ 0.1°
//! wide), which a fixed 8 × 8 × (3 × 3 Gauss–Legendre) rule per bin integrates 1e-3 wrong. So each
//! bin starts from 4 × 4 cells of 3 × 3 Gauss–Legendre points and every cell is refined
//! adaptively (quarters compared with the whole; tolerance 1e-8 of probability per cell, halved
//! per level, at most 6 levels): every bin gets at least 8 × 8 cells, peaks as many as they need.
//!
//! Significance: 0.01 for the whole suite, split over its `K` tests by Šidák's correction,
//! `α_i = 1 − (1 − 0.01)^(1/K)` (K = 211 today: 108 component, 88 stack and 15 distribution
//! configurations, so `α_i ≈ 6.5e-5`). A correct implementation then fails a run with probability
//! 0.01. Default runs draw 200 000 samples per configuration; the full runs behind `#[ignore]`
//! draw 2 000 000: `cargo test --release --test chi_square -- --ignored --nocapture`.
//! Tables are printed with `--nocapture`.
//!
//! The Reference model is not tested: its pdf is an approximation by design (the Corrected mixture
//! with a cosine lobe), not the density of its random walk.

mod common;
#[path = "chi_square/slope.rs"]
mod slope;
#[path = "chi_square/subjects.rs"]
mod subjects;
#[path = "chi_square/weights.rs"]
mod weights;
#[path = "chi_square/wrong.rs"]
mod wrong;

use common::{ChiSquare, SphereGrid, chi_square_pooled, chi2_p_value, par_map, sidak_alpha};
use glam::Vec3;
use lapidary::bsdf::{Bxdf, Lambert, MicrofacetDistribution, TorranceSparrow};
use lapidary::bsdf::{Distribution, Fresnel, measure::direction_deg};
use lapidary::sampler::{Rng, hash_words};
use lapidary::spectrum::RgbSample;
use std::sync::Arc;
use subjects::{SharedBxdf, Subject};
use weights::{ABS_FLOOR, N_WEIGHT, REL_TOL, weight_check};
use wrong::{UniformClaim, Wrong};

/// Samples per configuration in the default (CI) runs.
const N_CI: u64 = 200_000;
/// Samples per configuration in the full (`--ignored`) runs.
const N_FULL: u64 = 2_000_000;
/// Overall significance of the suite.
const ALPHA: f64 = 0.01;
/// Histogram resolution over the sphere (3.75° bins).
const N_THETA: usize = 48;
const N_PHI: usize = 96;
/// Quadrature cells per bin along each axis, before adaptive refinement.
const SUB: usize = 4;
/// Absolute tolerance (probability mass) of a quadrature cell's refinement, and most halvings.
const QUAD_TOL: f64 = 1e-8;
const QUAD_DEPTH: u32 = 6;
/// Cochran's rule: pool cells expecting fewer samples than this.
const MIN_EXPECTED: f64 = 5.0;
/// Largest accepted `∫ pdf dω` (quadrature error allowance).
const MAX_INTEGRAL: f64 = 1.0 + 1e-3;

/// Number of chi-square tests in the suite, for the Šidák correction.
fn suite_size() -> usize {
    subjects::component_count() + subjects::stack_count() + slope::count()
}

/// Per-test significance.
fn alpha_i() -> f64 {
    sidak_alpha(ALPHA, suite_size())
}

/// A stable seed from a configuration's name and view.
fn seed_of(name: &str, wo_deg: (f32, f32), salt: u64) -> u64 {
    let mut words: Vec<u64> = name.bytes().map(u64::from).collect();
    words.extend([
        u64::from(wo_deg.0.to_bits()),
        u64::from(wo_deg.1.to_bits()),
        salt,
    ]);
    hash_words(&words)
}

/// The result of one sphere-histogram test.
struct Row {
    label: String,
    wo_deg: (f32, f32),
    samples: u64,
    failed: u64,
    /// Samples that were not a finite, non-zero direction.
    invalid: u64,
    integral: f64,
    chi: ChiSquare,
}

impl Row {
    fn passes(&self, alpha: f64) -> bool {
        self.invalid == 0 && self.integral <= MAX_INTEGRAL && self.chi.passes(alpha)
    }

    fn why(&self, alpha: f64) -> String {
        let mut v = Vec::new();
        if self.invalid > 0 {
            v.push(format!("{} invalid directions", self.invalid));
        }
        if self.integral > MAX_INTEGRAL {
            v.push(format!("∫pdf = {:.6} > {MAX_INTEGRAL}", self.integral));
        }
        if !self.chi.zero_expectation_hits.is_empty() {
            let hits = &self.chi.zero_expectation_hits;
            let total: u64 = hits.iter().map(|h| h.1).sum();
            let shown: Vec<String> = hits
                .iter()
                .take(4)
                .map(|&(cell, n)| bin_name(cell, n))
                .collect();
            v.push(format!(
                "{total} samples in {} zero-pdf bins, e.g. {}",
                hits.len(),
                shown.join(", ")
            ));
        }
        if self.chi.p_value < alpha {
            v.push(format!("p = {:.3e} < {alpha:.3e}", self.chi.p_value));
        }
        v.join("; ")
    }
}

/// Human-readable sphere bin (θ, φ ranges in degrees) with its count.
fn bin_name(cell: usize, n: u64) -> String {
    if cell >= N_THETA * N_PHI {
        return format!("failed-sample cell ×{n}");
    }
    let (i, j) = (cell / N_PHI, cell % N_PHI);
    let (dt, dp) = (180.0 / N_THETA as f64, 360.0 / N_PHI as f64);
    format!(
        "θ∈[{:.2},{:.2}]° φ∈[{:.2},{:.2}]° ×{n}",
        i as f64 * dt,
        (i + 1) as f64 * dt,
        j as f64 * dp,
        (j + 1) as f64 * dp
    )
}

/// Runs the sphere-histogram chi-square test of `bsdf` at `wo` with `n` samples.
fn sphere_test(label: &str, bsdf: &dyn Bxdf, wo: Vec3, wo_deg: (f32, f32), n: u64) -> Row {
    let grid = SphereGrid::new(N_THETA, N_PHI);
    let cells = grid.len();
    let mut observed = vec![0u64; cells + 1];
    let (mut failed, mut invalid) = (0u64, 0u64);
    let mut rng = Rng::new(seed_of(label, wo_deg, n));
    for _ in 0..n {
        match bsdf.sample(wo, rng.uniform(), rng.uniform2()) {
            None => failed += 1,
            Some(s) => match grid.bin(s.wi) {
                Some(b) => observed[b] += 1,
                None => invalid += 1,
            },
        }
    }
    observed[cells] = failed;
    let mass = grid.integrate(SUB, QUAD_TOL, QUAD_DEPTH, |w| f64::from(bsdf.pdf(wo, w)));
    let integral: f64 = mass.iter().sum();
    let mut expected: Vec<f64> = mass.iter().map(|m| m * n as f64).collect();
    expected.push((1.0 - integral).max(0.0) * n as f64);
    Row {
        label: label.to_string(),
        wo_deg,
        samples: n,
        failed,
        invalid,
        integral,
        chi: chi_square_pooled(&observed, &expected, MIN_EXPECTED),
    }
}

/// Prints the table of a test and panics listing every failed configuration.
fn report(title: &str, rows: &[Row], alpha: f64) {
    println!(
        "\n{title} (per-test α = {alpha:.3e}, suite K = {})",
        suite_size()
    );
    println!(
        "{:<48} {:>6} {:>5} {:>8} {:>8} {:>9} {:>5} {:>6} {:>5} {:>9} {:>9}  result",
        "configuration",
        "θo",
        "φo",
        "samples",
        "failed",
        "∫pdf",
        "bins",
        "pooled",
        "dof",
        "chi²",
        "p-value"
    );
    let mut failures = Vec::new();
    for r in rows {
        let ok = r.passes(alpha);
        println!(
            "{:<48} {:>6.1} {:>5.0} {:>8} {:>8} {:>9.6} {:>5} {:>6} {:>5} {:>9.1} {:>9.3e}  {}",
            r.label,
            r.wo_deg.0,
            r.wo_deg.1,
            r.samples,
            r.failed,
            r.integral,
            r.chi.own_bins,
            r.chi.pooled_cells,
            r.chi.dof,
            r.chi.chi2,
            r.chi.p_value,
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
    assert!(
        failures.is_empty(),
        "{title}: {} of {} configurations fail:\n{}",
        failures.len(),
        rows.len(),
        failures.join("\n")
    );
}

fn run_subjects(title: &str, list: &[Subject], n: u64) {
    let rows = par_map(list, |s| {
        sphere_test(&s.name, s.bsdf.as_ref(), s.wo, s.wo_deg, n)
    });
    report(title, &rows, alpha_i());
}

fn run_slope(n: u64) {
    let cases: Vec<(Distribution, f32)> = slope::KINDS
        .iter()
        .flat_map(|&k| slope::ROUGHNESS.iter().map(move |&m| (k, m)))
        .collect();
    let results = par_map(&cases, |&(k, m)| slope::run(k, m, n, 0x51_09e));
    let rows: Vec<Row> = cases
        .iter()
        .zip(results)
        .map(|(&(k, m), r)| {
            assert!(
                (r.integral - 1.0).abs() < 1e-3,
                "{k:?} m={m}: ∫ pdf_h dω = {} (D is normalised: ∫ D cos θh dω = 1)",
                r.integral
            );
            Row {
                label: format!("sample_h {k:?} m={m} (slope space)"),
                wo_deg: (0.0, 0.0),
                samples: r.samples,
                failed: r.failed,
                invalid: r.invalid,
                integral: r.integral,
                chi: r.chi,
            }
        })
        .collect();
    report("micro-facet distributions, slope space", &rows, alpha_i());
}

#[test]
fn chi_square_components() {
    run_subjects("components", &subjects::components(), N_CI);
}

#[test]
fn chi_square_stacks() {
    run_subjects("catalogue stacks", &subjects::stacks(true), N_CI);
}

#[test]
fn chi_square_distributions_in_slope_space() {
    run_slope(N_CI);
}

/// Full version: `cargo test --release --test chi_square -- --ignored --nocapture`.
#[test]
#[ignore = "slow: cargo test --release --test chi_square -- --ignored"]
fn chi_square_components_full() {
    run_subjects("components (full)", &subjects::components(), N_FULL);
}

/// Full version: `cargo test --release --test chi_square -- --ignored --nocapture`.
#[test]
#[ignore = "slow: cargo test --release --test chi_square -- --ignored"]
fn chi_square_stacks_full() {
    run_subjects("catalogue stacks (full)", &subjects::stacks(true), N_FULL);
}

/// Full version: `cargo test --release --test chi_square -- --ignored --nocapture`.
#[test]
#[ignore = "slow: cargo test --release --test chi_square -- --ignored"]
fn chi_square_distributions_in_slope_space_full() {
    run_slope(N_FULL);
}

#[test]
fn suite_size_matches_the_configurations() {
    assert_eq!(subjects::components().len(), subjects::component_count());
    assert_eq!(
        subjects::stack_count(),
        subjects::CATALOGUE_SIZE * 2 * subjects::WO_DEG.len()
    );
    assert_eq!(suite_size(), 211);
}

// ------------------------------------------------------------------------------------------------
// The weight sample() returns equals f·cos/pdf from eval() and pdf() for the same direction.
// ------------------------------------------------------------------------------------------------

#[test]
fn sample_weight_matches_eval_and_pdf() {
    let mut list = subjects::components();
    list.extend(subjects::dielectric_variants());
    list.extend(subjects::stacks(false));
    let stats = par_map(&list, |s| {
        weight_check(
            s.bsdf.as_ref(),
            s.wo,
            N_WEIGHT,
            seed_of(&s.name, s.wo_deg, 7),
        )
    });
    println!(
        "\nweight = f·cos/pdf, s.pdf = pdf(), s.f = eval() (tolerance rel {REL_TOL:e} + abs {ABS_FLOOR:e})"
    );
    println!(
        "{:<48} {:>6} {:>5} {:>8} {:>5} {:>10} {:>10} {:>10}",
        "configuration", "θo", "φo", "returned", "bad", "max Δw", "max Δpdf", "max Δf"
    );
    let mut failures = Vec::new();
    for (s, st) in list.iter().zip(&stats) {
        println!(
            "{:<48} {:>6.1} {:>5.0} {:>8} {:>5} {:>10.2e} {:>10.2e} {:>10.2e}",
            s.name,
            s.wo_deg.0,
            s.wo_deg.1,
            st.returned,
            st.bad,
            st.worst_weight,
            st.worst_pdf,
            st.worst_f
        );
        if st.bad > 0 {
            failures.push(format!(
                "{} at θo={}°, φo={}°: {} of {} samples inconsistent; first: {}",
                s.name,
                s.wo_deg.0,
                s.wo_deg.1,
                st.bad,
                st.returned,
                st.first_bad.as_deref().unwrap_or("")
            ));
        }
    }
    // Not vacuous: every BSDF returns samples for most of its views (one view alone may return
    // none, e.g. transmission only from below beyond the critical angle).
    let mut names: Vec<&str> = list.iter().map(|s| s.name.as_str()).collect();
    names.dedup();
    for name in names {
        let (views, returned) = list
            .iter()
            .zip(&stats)
            .filter(|(s, _)| s.name == name)
            .fold((0u64, 0u64), |(v, r), (_, st)| (v + 1, r + st.returned));
        if returned < views * N_WEIGHT / 10 {
            failures.push(format!(
                "{name}: only {returned} of {} samples returned, the check is vacuous",
                views * N_WEIGHT
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

// ------------------------------------------------------------------------------------------------
// The machinery itself: known p-values, and deliberately wrong samplers that must be rejected.
// ------------------------------------------------------------------------------------------------

#[test]
fn p_values_match_known_values() {
    // Reference values of Q(k/2, x/2) from an arbitrary-precision evaluation (mpmath.gammainc,
    // 30 digits); the first, fourth and fifth are textbook critical values (0.05, 0.05, 0.01).
    let cases: [(usize, f64, f64); 12] = [
        (1, 3.841_458_820_694_124, 0.05),
        (1, 0.5, 0.479_500_122_186_953_5),
        (2, 5.0, 0.082_084_998_623_898_8),
        (10, 18.307_038_053_275_146, 0.05),
        (100, 135.806_723_171_026_76, 0.01),
        (1000, 1106.9689, 0.010_000_052_558_951_86),
        (4000, 4000.0, 0.497_026_451_555_797_5),
        (4000, 4300.0, 5.169_327_538_602_621e-4),
        (3, 0.01, 0.999_734_834_941_344_4),
        (50, 200.0, 7.857_610_724_654_743e-20),
        (1, 1e-6, 0.999_202_115_572_177_9),
        (7, 30.0, 9.495_972_508_134_184e-5),
    ];
    for (k, x, q) in cases {
        let p = chi2_p_value(x, k);
        assert!(
            ((p - q) / q).abs() < 1e-9,
            "Q({k}/2, {x}/2) = {p:e}, expected {q:e}"
        );
    }
    // dof 2: Q(1, x/2) = exp(−x/2) exactly.
    for x in [0.1, 1.0, 7.0, 40.0] {
        assert!((chi2_p_value(x, 2) / (-0.5 * x).exp() - 1.0).abs() < 1e-12);
    }
    assert_eq!(chi2_p_value(0.0, 5), 1.0);
    assert_eq!(chi2_p_value(12.0, 0), 1.0);
    // ln Γ at integers and half-integers: Γ(n) = (n−1)!, Γ(½) = √π.
    assert!((common::ln_gamma(5.0) - 24f64.ln()).abs() < 1e-13);
    assert!((common::ln_gamma(0.5) - std::f64::consts::PI.sqrt().ln()).abs() < 1e-13);
    assert!((common::ln_gamma(1.0)).abs() < 1e-13);
    let ln_fact_170: f64 = (1..=170).map(|i| (i as f64).ln()).sum();
    assert!((common::ln_gamma(171.0) / ln_fact_170 - 1.0).abs() < 1e-13);
    // Šidák: 1 test keeps α; K tests multiply out to α overall.
    assert!((sidak_alpha(0.01, 1) - 0.01).abs() < 1e-15);
    let a = sidak_alpha(0.01, 154);
    // Šidák is slightly less strict than Bonferroni (α/K).
    assert!(((1.0 - a).powi(154) - 0.99).abs() < 1e-12 && a > 0.01 / 154.0 && a < 0.01);
}

#[test]
fn pooling_rules() {
    // Cells expecting < 5 are pooled; a pooled bin below 5 joins the smallest own bin.
    let c = chi_square_pooled(&[10, 12, 1, 2], &[10.0, 12.0, 2.0, 2.0], 5.0);
    assert_eq!((c.own_bins, c.pooled_cells, c.dof), (2, 2, 1));
    assert!((c.chi2 - 1.0 / 14.0).abs() < 1e-12, "{}", c.chi2);
    let c = chi_square_pooled(&[10, 10, 1, 2], &[10.0, 10.0, 2.0, 1.0], 5.0);
    assert_eq!(c.dof, 1);
    // A sample where nothing is expected fails regardless of the p-value.
    let c = chi_square_pooled(&[10, 10, 1], &[10.5, 10.5, 0.0], 5.0);
    assert_eq!(c.zero_expectation_hits, vec![(2, 1)]);
    assert!(c.p_value > 0.5 && !c.passes(1e-6));
}

#[test]
fn machinery_rejects_wrong_samplers() {
    let alpha = alpha_i();
    let wo = direction_deg(30.0, 40.0);
    let lambert: SharedBxdf = Arc::new(Lambert {
        albedo: RgbSample::ONE,
    });
    let glossy = |m: f32| -> SharedBxdf {
        Arc::new(TorranceSparrow::new(
            MicrofacetDistribution::new(Distribution::Blinn, m),
            Fresnel::Perfect,
        ))
    };
    let wrong = |sampler: &SharedBxdf, claimed: &SharedBxdf, below_every, fail_share| Wrong {
        sampler: sampler.clone(),
        claimed: claimed.clone(),
        below_every,
        fail_share,
    };
    // The correct pairs pass (the control), each wrong one is rejected.
    let control = sphere_test("control lambert", lambert.as_ref(), wo, (30.0, 40.0), N_CI);
    let control_glossy = sphere_test("control ts", glossy(10.0).as_ref(), wo, (30.0, 40.0), N_CI);
    let cases: Vec<(&str, Box<dyn Bxdf>)> = vec![
        ("cosine sampled, uniform pdf", Box::new(UniformClaim)),
        (
            "ts m=10° sampled, pdf of m=11°",
            Box::new(wrong(&glossy(10.0), &glossy(11.0), 0, 0.0)),
        ),
        (
            "lambert, 1 in ~1000 samples below the horizon",
            Box::new(wrong(&lambert, &lambert, 1000, 0.0)),
        ),
        (
            "lambert, 1% of samples fail but pdf integrates to 1",
            Box::new(wrong(&lambert, &lambert, 0, 0.01)),
        ),
    ];
    println!("\nself-test (per-test α = {alpha:.3e})");
    for r in [&control, &control_glossy] {
        println!(
            "{:<52} dof {:>5} chi² {:>9.1} p {:.3e}",
            r.label, r.chi.dof, r.chi.chi2, r.chi.p_value
        );
        assert!(r.passes(alpha), "{}: {}", r.label, r.why(alpha));
    }
    for (label, b) in &cases {
        let r = sphere_test(label, b.as_ref(), wo, (30.0, 40.0), N_CI);
        println!(
            "{label:<52} dof {:>5} chi² {:>9.1} p {:.3e} zero-pdf hits {}",
            r.chi.dof,
            r.chi.chi2,
            r.chi.p_value,
            r.chi.zero_expectation_hits.len()
        );
        assert!(
            !r.passes(alpha),
            "{label} was accepted: p = {:e}",
            r.chi.p_value
        );
    }
}
