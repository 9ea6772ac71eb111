//! A perfectly smooth top coat (issue 16): `Coat { roughness: 0.0, .. }`, `roughness: 0.0` or
//! `alpha: 0.0` in a recipe. Its reflection is a Dirac delta that only `sample` reaches (lobe
//! `SpecularReflection`, `pdf` = the probability of choosing it, `f = F(μo)/cos θi`); `eval` and
//! `pdf` are the body's alone. Five claims, each a test:
//!
//! 1. **Closed form** (`albedo_matches_the_closed_form`): over Lambert (ρ 0.2, 0.8, 1), η 1.5 and
//!    2, optical depths 0, 0.5, 2 (the three channels of one stack), θo 0/30/60/80°, the mean
//!    sampled weight (deltas included; 40 000 samples per cell) of Corrected and Reference equals
//!    `F + (1−F) τ(μ'o) ρ E_out/(1 − ρ E_back)` (f64 quadrature, tests/smooth_coat/closed_form.rs)
//!    within 4σ + 1 % of the closed form: 72 comparisons per model, two-sided 4σ per comparison
//!    (6.3e-5), Šidák family-wise 0.9 % over the 144 (the 1 % only lowers it). The adding
//!    solution at the same θo must agree within 1 % (deterministic). Course and uncalibrated
//!    Corrected are printed, not asserted. Negative control: the ρ = 0.8 stacks compared with the
//!    closed form of ρ = 0.75 must be rejected by every comparison at od 0 (a 3…7 % difference;
//!    at od 2 the body is too dim for any test to tell), for each model.
//! 2. **Delta bookkeeping** (`delta_is_sampled_and_never_evaluated`): 4 stacks (Lambert with
//!    absorption, η 2 over white, over rough gold, a smooth coat over a rough coat) × Course and
//!    Corrected × θo 0/20/45/70/85°: every `uc` below the top weight gives the mirror direction,
//!    SPECULAR|REFLECTION, `weight = F(μo)/pdf`, `f = F/cos` (rel 1e-5), and `uc` just above it does
//!    not; `eval`/`pdf` at the mirror are finite and within 2e-3 of the mean of four neighbours
//!    0.1° away (a leaked delta, or the 0.01° placeholder lobe, would be 10⁴…10⁷ times the body),
//!    and Course's equals its exact body `(1−F(μi))(1−F(μo)) ρ/π e^(−od(1/μ'o+1/μ'i))` (rel 2e-4);
//!    of 4 000 random samples each, every non-specular one has `pdf(wo, wi) = s.pdf` and
//!    `eval = s.f` (rel 1e-5), the specular count is within 5σ + 1 of `N·w_top`, and `∫ pdf` (3.75°
//!    bins, 2 × 2 × 3 × 3 Gauss–Legendre) equals `1 − w_top` within 1 % for single coats over
//!    Lambert and the fraction of successful non-specular samples within 5σ + 0.5 % for all. The
//!    Reference walk: `uc < F(μo)` gives the mirror with weight 1 (flux `F`), `pdf` at the mirror
//!    is `0.9 · (uncalibrated Corrected pdf) + 0.1 cos/π` exactly. Control: a 0.01° top fails.
//! 3. **Chi-square** (`non_delta_part_matches_its_pdf`): tests/smooth_coat/chi.rs; smooth coat over
//!    Lambert and over rough gold × Course, Corrected × θo 10/45/75°: 12 tests, 100 000 samples
//!    each, Šidák α = 0.01 (per test 8.4e-4); a claimed pdf of η 1.7 for an η 1.5 coat is rejected.
//! 4. **Recipes** (`recipes_speak_smooth_coats_and_calibration`): `roughness: 0.0` and
//!    `alpha: 0.0` compile to a smooth, SPECULAR top; a smooth second coat is refused at its
//!    `file:line:col` with the allowed range; `calibration: false` (material) and
//!    `calibration=off` (accuracy knob) give `LayeredBsdf::knobs()` "calibration off".
//! 5. **Render** (`white_furnace_with_a_smooth_clear_coat`, tests/smooth_coat/furnace.rs): a white
//!    Lambert sphere under a clear smooth coat (η 1.5) in a white furnace renders 1 — mean over
//!    the sphere's pixels within 3σ + 0.5 %, no pixel above 1 by more than 5σ — with MIS,
//!    light-only and BSDF-only direct light (48×48, 64 spp, independent sampler) and the
//!    Reference model (MIS, 32 spp).
//!
//! About 6 s in the release test profile on 2 cores: `cargo test --release --test smooth_coat --
//! --nocapture` prints every table. Heavy (10× the samples, θo also 45/70/85° — 252 comparisons,
//! Šidák 1.6 % —, 1 000 000 samples per chi-square, 96×96 at 256 spp; ~30 s):
//! `cargo test --release --test smooth_coat -- --ignored --nocapture heavy`.

#[path = "smooth_coat/chi.rs"]
mod chi;
#[path = "smooth_coat/closed_form.rs"]
mod closed_form;
mod common;
#[path = "smooth_coat/delta.rs"]
mod delta;
#[path = "smooth_coat/furnace.rs"]
mod furnace;

use common::{par_map, sidak_alpha};
use delta::{bookkeeping, cases, close, reference_checks};
use furnace::furnace;
use glam::Vec2;
use lapidary::bsdf::layered::adding;
use lapidary::bsdf::measure::{Estimate, albedo_by_sampling, direction_deg};
use lapidary::bsdf::{
    Base, Bxdf, Coat, ConductorIor, LayeredBsdf, LobeFlags, Metal, Model, ReferenceParams,
    StackDesc, fresnel,
};
use lapidary::color::Rgb;
use lapidary::render::Strategy;
use lapidary::sampler::hash_words;

const ETAS: [f32; 2] = [1.5, 2.0];
/// Optical depths of the three channels (absorption per unit thickness; thickness 1).
const ODS: [f32; 3] = [0.0, 0.5, 2.0];
const RHOS: [f32; 3] = [0.2, 0.8, 1.0];

fn reference() -> Model {
    Model::Reference(ReferenceParams::default())
}

fn coat(ior: f32, roughness: f32, od: [f32; 3]) -> Coat {
    let absorption = Rgb::new(od[0], od[1], od[2]);
    let thickness = 1.0;
    Coat {
        ior,
        roughness,
        absorption,
        thickness,
    }
}

fn lambert(rho: f32) -> Base {
    Base::Lambert {
        albedo: Rgb::splat(rho),
    }
}

fn gold(m: f32) -> Base {
    let (n, k) = Metal::Gold.nk();
    let ior = ConductorIor::Complex { n, k };
    Base::Conductor { ior, roughness: m }
}

fn build(coats: &[Coat], base: Base, model: Model, calibration: bool) -> LayeredBsdf {
    let mut d = StackDesc::new(coats.to_vec(), base).with_model(model);
    d.calibration = calibration;
    LayeredBsdf::new(&d).expect("a valid stack")
}

// ------------------------------------------------------------------------------------------------
// 1. Closed form

/// `(η, ρ, θo, estimate)` for every smooth coat over Lambert of item 1 under `model`.
fn albedos(
    model: Model,
    calibration: bool,
    thetas: &[f32],
    n: u64,
) -> Vec<(f32, f32, f32, Estimate)> {
    let stacks: Vec<(f32, f32)> = ETAS.iter().flat_map(|&e| RHOS.map(|r| (e, r))).collect();
    let built = par_map(&stacks, |&(eta, rho)| {
        build(&[coat(eta, 0.0, ODS)], lambert(rho), model, calibration)
    });
    let jobs: Vec<(usize, f32)> = (0..stacks.len())
        .flat_map(|s| thetas.iter().map(move |&t| (s, t)))
        .collect();
    let tag: Vec<u64> = format!("{model:?} {calibration}")
        .bytes()
        .map(u64::from)
        .collect();
    let tag = hash_words(&tag);
    par_map(&jobs, |&(s, th)| {
        let (eta, rho) = stacks[s];
        let words = [
            tag,
            eta.to_bits().into(),
            rho.to_bits().into(),
            th.to_bits().into(),
            n,
        ];
        let est = albedo_by_sampling(&built[s], direction_deg(th, 0.0), n, hash_words(&words));
        (eta, rho, th, est)
    })
}

/// Compares rows (only those of base albedo `only.0` and channels of optical depth `only.1`, when
/// given) with the closed form of base albedo `rho_claim(ρ)`; returns (comparisons, failures,
/// worst |Δ|, worst |Δ|/(4σ + 1 %)).
fn compare(
    rows: &[(f32, f32, f32, Estimate)],
    only: (Option<f32>, Option<f32>),
    rho_claim: impl Fn(f32) -> f64,
) -> (usize, Vec<String>, f64, f64) {
    let (mut k, mut fails, mut worst, mut worst_ratio) = (0, Vec::new(), 0.0f64, 0.0f64);
    for &(eta, rho, th, est) in rows.iter().filter(|r| only.0.is_none_or(|p| r.1 == p)) {
        let mu = f64::from(direction_deg(th, 0.0).z);
        for (c, &od) in ODS.iter().enumerate() {
            if only.1.is_some_and(|o| o != od) {
                continue;
            }
            let closed = closed_form::closed_form(eta.into(), od.into(), rho_claim(rho), mu);
            let (m, se) = (f64::from(est.mean[c]), f64::from(est.std_error[c]));
            let (dev, allowed) = ((m - closed).abs(), 4.0 * se + 0.01 * closed);
            k += 1;
            worst = worst.max(dev);
            worst_ratio = worst_ratio.max(dev / allowed);
            if dev > allowed {
                fails.push(format!(
                    "η {eta} ρ {rho} od {od} θo {th}°: {m:.5} ± {se:.5} vs closed form {closed:.5}"
                ));
            }
        }
    }
    (k, fails, worst, worst_ratio)
}

fn closed_form_suite(thetas: &[f32], n: u64) {
    println!(
        "\nsmooth coat over Lambert: mean sampled weight vs closed form ({n} samples per cell)"
    );
    let models = [
        ("Corrected", Model::Corrected, true, true),
        ("Reference", reference(), true, true),
        ("Corrected, calibration off", Model::Corrected, false, false),
        ("Course", Model::Course, true, false),
    ];
    let mut failures = Vec::new();
    for (name, model, calibration, asserted) in models {
        let rows = albedos(model, calibration, thetas, n);
        let (k, fails, worst, ratio) = compare(&rows, (None, None), f64::from);
        let (kc, rejected, ..) = compare(&rows, (Some(0.8), None), |_| 0.75);
        let (k0, rejected0, ..) = compare(&rows, (Some(0.8), Some(0.0)), |_| 0.75);
        println!(
            "{name:<28} {k} comparisons, {} outside 4σ + 1 %, worst |Δ| {worst:.5} ({ratio:.2} of \
             the allowance); control ρ 0.75: {} of {kc} reject ({} of {k0} at od 0)",
            fails.len(),
            rejected.len(),
            rejected0.len()
        );
        if asserted {
            failures.extend(fails.into_iter().map(|f| format!("{name}: {f}")));
            if rejected0.len() < k0 {
                failures.push(format!("{name}: the ρ 0.75 control passes at od 0"));
            }
        }
    }
    // The adding solution (what Corrected is calibrated to), deterministic.
    let mut worst = 0.0f64;
    for (eta, rho) in ETAS.iter().flat_map(|&e| RHOS.map(|r| (e, r))) {
        let stack = build(&[coat(eta, 0.0, ODS)], lambert(rho), Model::Corrected, true);
        let solution = adding::Solution::new(&stack);
        for &th in thetas {
            let mu = direction_deg(th, 0.0).z;
            let a = solution.albedo(mu, 24);
            for (c, &od) in ODS.iter().enumerate() {
                let closed = closed_form::closed_form(eta.into(), od.into(), rho.into(), mu.into());
                let dev = (f64::from(a[c]) - closed).abs();
                worst = worst.max(dev / closed);
                if dev > 0.01 * closed {
                    failures.push(format!(
                        "adding: η {eta} ρ {rho} od {od} θo {th}°: {} vs {closed:.5}",
                        a[c]
                    ));
                }
            }
        }
    }
    println!("adding solution: worst relative deviation {worst:.2e}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn albedo_matches_the_closed_form() {
    closed_form_suite(&[0.0, 30.0, 60.0, 80.0], 40_000);
}

/// `cargo test --release --test smooth_coat -- --ignored --nocapture heavy` (400 000 samples per
/// cell, θo 0/30/45/60/70/80/85°).
#[test]
#[ignore]
fn albedo_matches_the_closed_form_heavy() {
    closed_form_suite(&[0.0, 30.0, 45.0, 60.0, 70.0, 80.0, 85.0], 400_000);
}

// ------------------------------------------------------------------------------------------------
// 2. Delta bookkeeping

#[test]
fn delta_is_sampled_and_never_evaluated() {
    let thetas = [0.0f32, 20.0, 45.0, 70.0, 85.0];
    let jobs: Vec<(usize, Model)> = (0..cases().len())
        .flat_map(|c| [(c, Model::Course), (c, Model::Corrected)])
        .collect();
    let cases = cases();
    let out = par_map(&jobs, |&(c, model)| {
        let b = build(&cases[c].1, cases[c].2, model, true);
        let walk = matches!(model, Model::Corrected).then(|| {
            (
                build(&cases[c].1, cases[c].2, reference(), true),
                build(&cases[c].1, cases[c].2, model, false),
            )
        });
        let mut bad = Vec::new();
        for th in thetas {
            let wo = direction_deg(th, 30.0);
            let seed = hash_words(&[c as u64, th.to_bits().into(), u64::from(walk.is_some())]);
            let ctx = format!("{} {model:?} θo {th}°", cases[c].0);
            bad.extend(
                bookkeeping(&b, &cases[c], wo, 4_000, seed)
                    .into_iter()
                    .map(|m| format!("{ctx}: {m}")),
            );
            if let Some((r, uncal)) = &walk {
                bad.extend(
                    reference_checks(r, uncal, cases[c].1[0].ior, wo)
                        .map(|m| format!("{ctx} Reference: {m}")),
                );
            }
        }
        bad
    });
    let bad: Vec<String> = out.into_iter().flatten().collect();
    println!(
        "delta bookkeeping: {} configurations, {} failures",
        jobs.len() * thetas.len(),
        bad.len()
    );
    assert!(bad.is_empty(), "{}", bad.join("\n"));
    // Control: a 0.01° top coat (a rough lobe, no delta) fails the checks.
    let mut rough = cases[0].clone();
    rough.1[0].roughness = 0.01;
    let b = build(&rough.1, rough.2, Model::Corrected, true);
    let wo = direction_deg(45.0, 30.0);
    assert!(!bookkeeping(&b, &rough, wo, 100, 1).is_empty());
}

/// The Reference walk reports a smooth coat's specular sample as the `BsdfSample` contract (and
/// the Corrected/Course delta) do: `pdf` is the discrete probability of the choice (`F(μo)`: the
/// walk reflects when `uc < F`) and `f = F/cos θi`, so `f·cos/pdf` is the weight 1. Before the fix
/// it reported `pdf = 1` and `f = 1/cos θi` (the rendered result was right either way).
#[test]
fn reference_specular_sample_reports_its_probability() {
    let r = build(&[coat(1.5, 0.0, [0.0; 3])], lambert(0.8), reference(), true);
    let wo = direction_deg(60.0, 0.0);
    let f = fresnel::dielectric(wo.z, 1.5);
    let s = r
        .sample(wo, 0.5 * f, Vec2::new(0.3, 0.7))
        .expect("a sample");
    assert!(s.flags.is_specular());
    assert!(
        close(s.pdf, f, 1e-5) && close(s.f[0], f / s.wi.z, 1e-5),
        "F {f}: {s:?}"
    );
}

// ------------------------------------------------------------------------------------------------
// 3. Chi-square

fn chi_suite(n: u64) {
    let bases = [
        ("Lambert 0.8, od 0/0.5/2", lambert(0.8), ODS),
        ("gold 10°", gold(10.0), [0.0, 0.2, 0.5]),
    ];
    let mut jobs = Vec::new();
    for (b, base) in bases.iter().enumerate() {
        for model in [Model::Course, Model::Corrected] {
            for th in [10.0f32, 45.0, 75.0] {
                jobs.push((b, base.1, base.2, model, th));
            }
        }
    }
    let alpha = sidak_alpha(0.01, jobs.len());
    let rows = par_map(&jobs, |&(b, base, od, model, th)| {
        let stack = build(&[coat(1.5, 0.0, od)], base, model, true);
        let seed = hash_words(&[
            b as u64,
            u64::from(model == Model::Course),
            th.to_bits().into(),
            n,
        ]);
        chi::run(&stack, &stack, direction_deg(th, 120.0), n, seed)
    });
    println!("\nchi-square of the non-delta part, {n} samples, per-test α {alpha:.2e}");
    let mut failures = Vec::new();
    for (&(b, _, _, model, th), r) in jobs.iter().zip(&rows) {
        let verdict = if r.passes(alpha) { "ok" } else { "FAIL" };
        let row = format!(
            "{:<24} {:<9} θo {th:>2}°: w_top {:.4} (specular {:.4}), ∫pdf {:.4}, failed {}, dof {}, \
             χ² {:.1}, p {:.3}",
            bases[b].0,
            format!("{model:?}"),
            r.top,
            r.specular as f64 / n as f64,
            r.integral,
            r.failed,
            r.chi.dof,
            r.chi.chi2,
            r.chi.p_value
        );
        println!("{row}  {verdict}");
        if !r.passes(alpha) {
            failures.push(format!(
                "{row} (invalid {}, odd deltas {})",
                r.invalid, r.odd_delta
            ));
        }
    }
    // Negative control: sampling η 1.5 against the pdf and top weight of η 1.7.
    let sampled = build(&[coat(1.5, 0.0, ODS)], lambert(0.8), Model::Corrected, true);
    let claimed = build(&[coat(1.7, 0.0, ODS)], lambert(0.8), Model::Corrected, true);
    let wrong = chi::run(&sampled, &claimed, direction_deg(45.0, 120.0), n, 17);
    println!("control (claimed η 1.7): p {:.2e}", wrong.chi.p_value);
    if wrong.passes(alpha) {
        failures.push("the η 1.7 control passes: the test has no power".into());
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn non_delta_part_matches_its_pdf() {
    chi_suite(100_000);
}

/// `cargo test --release --test smooth_coat -- --ignored --nocapture heavy` (1 000 000 samples
/// each).
#[test]
#[ignore]
fn non_delta_part_matches_its_pdf_heavy() {
    chi_suite(1_000_000);
}

// ------------------------------------------------------------------------------------------------
// 4. Recipes

#[test]
fn recipes_speak_smooth_coats_and_calibration() {
    use lapidary::recipe::{GemRecipe, MaterialLibrary};
    use lapidary::scene::Accuracy;
    let lib =
        |m: &str| MaterialLibrary::parse("t.ron", &format!("(materials: {{\n \"m\": {m},\n}})"));
    for coat in ["roughness: 0.0", "alpha: 0.0"] {
        let text = format!("(coats: [(ior: 1.5, {coat})], base: Lambert(albedo: Gray(0.8)))");
        let b = lib(&text)
            .and_then(|l| l.build("m", None))
            .unwrap_or_else(|e| panic!("{coat}: {e}"));
        assert!(
            b.smooth_top() && b.flags().contains(LobeFlags::SPECULAR),
            "{coat}"
        );
        assert!(b.knobs().contains("calibration on"), "{}", b.knobs());
    }
    // Line 2 is ` "m": (coats: [(ior: 1.5, roughness: 5.0), (ior: 1.6, COAT)], …`: the second coat
    // opens at column 44, its roughness field at 55 (`alpha` is located at the coat: the message
    // names `roughness`).
    for (coat, cols) in [("roughness: 0.0", [55, 55]), ("alpha: 0.0", [44, 55])] {
        let text = format!(
            "(coats: [(ior: 1.5, roughness: 5.0), (ior: 1.6, {coat})], base: Lambert(albedo: Gray(0.8)))"
        );
        let e = lib(&text).and_then(|l| l.build("m", None)).expect_err(coat);
        println!("smooth second coat ({coat}): {e}");
        let msg = e.to_string();
        assert!(
            e.file == "t.ron" && e.line == 2 && cols.contains(&e.col),
            "{msg}"
        );
        assert!(msg.starts_with(&format!("t.ron:2:{}: ", e.col)), "{msg}");
        assert!(
            msg.contains("coats[1].roughness = 0 ") && msg.contains("0.01 ..< 90"),
            "{msg}"
        );
        assert!(msg.contains("must be coats[0]"), "{msg}");
    }
    let text = "(coats: [(ior: 1.5, roughness: 0.0)], base: Lambert(albedo: Gray(0.8)), calibration: false)";
    let off = lib(text)
        .and_then(|l| l.build("m", None))
        .expect("calibration: false compiles");
    assert!(off.knobs().contains("calibration off"), "{}", off.knobs());
    let on = build(
        &[coat(1.5, 0.0, [0.0; 3])],
        lambert(0.8),
        Model::Corrected,
        true,
    );
    let (wo, wi) = (direction_deg(70.0, 0.0), direction_deg(50.0, 180.0));
    assert_ne!(
        on.eval(wo, wi).0,
        off.eval(wo, wi).0,
        "the calibration changes nothing"
    );
    // The accuracy knob, on a compiled scene.
    let recipe = "(materials: { \"m\": (coats: [(ior: 1.5, roughness: 0.0)], base: Lambert(albedo: Gray(0.8))) },\
                  surface: Material(\"m\"))";
    let mut scene = GemRecipe::parse("g.ron", recipe)
        .and_then(|r| r.compile())
        .expect("compiles");
    let mut acc = Accuracy::default();
    acc.set("calibration", "off").expect("a known knob");
    scene.set_accuracy(&acc, "test").expect("applies");
    let stack = &scene.surface.stacks[0];
    assert!(!stack.calibration && stack.coats[0].roughness == 0.0);
    let knobs = LayeredBsdf::new(stack).expect("builds").knobs();
    assert!(knobs.contains("calibration off"), "{knobs}");
}

// ------------------------------------------------------------------------------------------------
// 5. Render

#[test]
fn white_furnace_with_a_smooth_clear_coat() {
    for strategy in [Strategy::Mis, Strategy::LightOnly, Strategy::BsdfOnly] {
        furnace(48, 64, strategy, "Corrected");
    }
    furnace(48, 32, Strategy::Mis, "Reference(samples: 4)");
}

/// `cargo test --release --test smooth_coat -- --ignored --nocapture heavy` (96×96, 256 spp).
#[test]
#[ignore]
fn white_furnace_with_a_smooth_clear_coat_heavy() {
    for strategy in [Strategy::Mis, Strategy::LightOnly, Strategy::BsdfOnly] {
        furnace(96, 256, strategy, "Corrected");
    }
    furnace(96, 128, Strategy::Mis, "Reference(samples: 4)");
}
