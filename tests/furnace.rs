//! White-furnace tests of the layer stack (docs/design.md §5.2, §10).
//!
//! The directional albedo `ρ(wo) = ∫ f(wo, wi) cos θi dωi` is estimated as the mean sample weight
//! (`measure::albedo_by_sampling`), with its standard error `σ`. A stack that only scatters and
//! never absorbs must have `ρ = 1`; no passive material may exceed 1. The Course model (course eqs.
//! 3.1–3.3) lacks the `1/η²` compression of solid angle under a coat, so it gains energy over a
//! glossy base: those departures are measured and pinned, not hidden.
//!
//! Statistics: every estimate is deterministic (fixed seeds). "Within 3σ" uses the estimate's own
//! standard error (two-sided 3σ ≈ 0.27% per comparison for a normal mean); the lossless tests use
//! 200 000 samples per point so 3σ stays well below their 2% tolerance (asserted).
//!
//! Run with the tables printed: `cargo test --release --test furnace -- --nocapture`.

use lapidary::bsdf::measure::{Estimate, albedo_by_sampling, direction_deg};
use lapidary::bsdf::{Base, Coat, ConductorIor, LayeredBsdf, Model, ReferenceParams, StackDesc};
use lapidary::color::Rgb;
use lapidary::recipe::MaterialLibrary;
use lapidary::sampler::hash_words;
use rayon::prelude::*;

/// Viewing angles of the catalogue table, degrees.
const TABLE_ANGLES: [f32; 7] = [0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 85.0];
/// Samples per point of the catalogue table (σ ≤ 0.013, Course at grazing; mostly ≤ 0.003).
const TABLE_SAMPLES: u64 = 40_000;
/// Samples per point of the lossless key stacks and the pinned departures.
const KEY_SAMPLES: u64 = 200_000;
/// Samples per point of the Reference on the key stacks (σ ≤ 0.001 today; asserted 3σ < 1%).
const REF_KEY_SAMPLES: u64 = 200_000;

fn reference() -> Model {
    Model::Reference(ReferenceParams::default())
}

fn models() -> [(&'static str, Model); 3] {
    [
        ("Course", Model::Course),
        ("Corrected", Model::Corrected),
        ("Reference", reference()),
    ]
}

fn clear_coat(ior: f32, roughness: f32) -> Coat {
    Coat {
        ior,
        roughness,
        absorption: Rgb::ZERO,
        thickness: 0.0,
    }
}

/// Key stack (a): a white Lambert base (albedo 1) under a clear coat (η 1.5, m 5°).
fn white_lambert_under_coat() -> StackDesc {
    StackDesc::new(
        vec![clear_coat(1.5, 5.0)],
        Base::Lambert { albedo: Rgb::ONE },
    )
}

/// Key stack (b): a perfect conductor (m 10°) under a clear coat (η 1.7, m 7°).
fn mirror_under_coat() -> StackDesc {
    StackDesc::new(
        vec![clear_coat(1.7, 7.0)],
        Base::Conductor {
            ior: ConductorIor::Perfect,
            roughness: 10.0,
        },
    )
}

fn build(desc: &StackDesc, model: Model) -> LayeredBsdf {
    LayeredBsdf::new(&desc.clone().with_model(model)).expect("valid stack")
}

/// Albedo at `theta_deg` (azimuth 0) with a seed derived from a label and the angle.
fn albedo(b: &LayeredBsdf, theta_deg: f32, n: u64, label: u64) -> Estimate {
    let seed = hash_words(&[label, u64::from(theta_deg.to_bits())]);
    albedo_by_sampling(b, direction_deg(theta_deg, 0.0), n, seed)
}

/// Largest `(mean − 1)/σ` over the channels (σ floored so an exact 1 with σ = 0 gives 0).
fn excess_sigma(e: &Estimate) -> f32 {
    (0..3)
        .map(|c| (e.mean[c] - 1.0) / e.std_error[c].max(1e-7))
        .fold(f32::NEG_INFINITY, f32::max)
}

fn max_channel_cell(e: &Estimate) -> String {
    let c = (0..3)
        .max_by(|&a, &b| e.mean[a].total_cmp(&e.mean[b]))
        .unwrap_or(0);
    format!("{:.4}±{:.4}", e.mean[c], e.std_error[c])
}

#[test]
fn catalogue_albedo_table() {
    let lib = MaterialLibrary::course();
    let names: Vec<String> = lib.names().map(str::to_string).collect();
    let jobs: Vec<(usize, usize)> = (0..names.len())
        .flat_map(|m| (0..3).map(move |k| (m, k)))
        .collect();
    // One row per (material, model): the estimates at every table angle.
    let rows: Vec<Vec<Estimate>> = jobs
        .par_iter()
        .map(|&(m, k)| {
            let b = lib.build(&names[m], Some(models()[k].1)).expect("builds");
            TABLE_ANGLES
                .iter()
                .map(|&th| albedo(&b, th, TABLE_SAMPLES, hash_words(&[m as u64, k as u64])))
                .collect()
        })
        .collect();

    println!(
        "\nDirectional albedo by sampling, max channel ± standard error ({TABLE_SAMPLES} samples per point; Reference: default samples 4, max_depth 256)"
    );
    let mut header = format!("{:<24} {:<10}", "material", "model");
    for th in TABLE_ANGLES {
        header += &format!(" {:>15}", format!("θo={th}°"));
    }
    println!("{header}");
    let mut failures = Vec::new();
    for (&(m, k), row) in jobs.iter().zip(&rows) {
        let (model_name, _) = models()[k];
        let mut line = format!("{:<24} {:<10}", names[m], model_name);
        for (th, e) in TABLE_ANGLES.iter().zip(row) {
            line += &format!(" {:>15}", max_channel_cell(e));
            assert!(
                e.mean.is_valid(),
                "{} {model_name} θo={th}: {e:?}",
                names[m]
            );
            // Energy conservation for the two energy-consistent models: never above 1 by more
            // than 3σ in any channel.
            if k > 0 && excess_sigma(e) > 3.0 {
                failures.push(format!("{} {model_name} θo={th}°: {e:?}", names[m]));
            }
        }
        println!("{line}");
    }
    assert!(
        failures.is_empty(),
        "albedo > 1 beyond 3σ:\n{}",
        failures.join("\n")
    );
}

/// Albedo curves of a key stack at θo = 0, 5, …, 85° under `model`, in parallel.
fn curve(desc: &StackDesc, model: Model, n: u64, label: u64) -> Vec<(f32, Estimate)> {
    let b = build(desc, model);
    (0..18)
        .into_par_iter()
        .map(|i| {
            let th = 5.0 * i as f32;
            (th, albedo(&b, th, n, label))
        })
        .collect()
}

fn cell(e: &Estimate) -> String {
    format!("{:.4}±{:.4}", e.mean[0], e.std_error[0])
}

/// Asserts that Corrected and Reference keep a lossless stack within 2% of 1 at every angle
/// (every channel), with 3σ < 1% so that a 2% departure cannot hide in the noise.
fn assert_lossless(name: &str, desc: &StackDesc) {
    let corrected = curve(desc, Model::Corrected, KEY_SAMPLES, 11);
    let refer = curve(desc, reference(), REF_KEY_SAMPLES, 12);
    let mut out = format!(
        "\nWhite furnace, {name} (Corrected {KEY_SAMPLES}, Reference {REF_KEY_SAMPLES} samples per point), channel 0:\n{:>6} {:>15} {:>15}\n",
        "θo", "Corrected", "Reference"
    );
    let mut failures = Vec::new();
    for ((th, c), (_, r)) in corrected.iter().zip(&refer) {
        out += &format!("{th:>5}° {:>15} {:>15}\n", cell(c), cell(r));
        for (model, e) in [("Corrected", c), ("Reference", r)] {
            for ch in 0..3 {
                if 3.0 * e.std_error[ch] >= 0.01 {
                    failures.push(format!("{model} θo={th}° ch{ch}: σ too large {e:?}"));
                }
                if !holds((e.mean[ch] - 1.0).abs() <= 0.02) {
                    failures.push(format!("{model} θo={th}° ch{ch}: {e:?}"));
                }
            }
        }
    }
    print!("{out}");
    assert!(
        failures.is_empty(),
        "{name} not lossless within 2%:\n{}",
        failures.join("\n")
    );
}

#[test]
fn white_lambert_under_clear_coat_is_lossless() {
    assert_lossless(
        "(a) white Lambert under coat η1.5 m5°",
        &white_lambert_under_coat(),
    );
}

#[test]
fn perfect_mirror_under_clear_coat_is_lossless() {
    assert_lossless(
        "(b) perfect conductor m10° under coat η1.7 m7°",
        &mirror_under_coat(),
    );
}

/// Measures `b` at the pinned angles (channel 0; the key stacks are grey) with `n` samples and
/// checks each value within `rel_tol` of its pin, with 3σ below half the tolerance. Appends the
/// printed lines to `out` and problems to `failures`; returns the estimates.
fn check_pins(
    label: &str,
    b: &LayeredBsdf,
    pins: &[(f32, f32)],
    (n, rel_tol, seed): (u64, f32, u64),
    out: &mut String,
    failures: &mut Vec<String>,
) -> Vec<Estimate> {
    let got: Vec<Estimate> = pins
        .par_iter()
        .map(|&(th, _)| albedo(b, th, n, seed))
        .collect();
    for (&(th, want), e) in pins.iter().zip(&got) {
        *out += &format!("{label:<34} θo={th:>2}°: {} (pinned {want})\n", cell(e));
        if 3.0 * e.std_error[0] >= 0.5 * rel_tol * want {
            failures.push(format!("{label} θo={th}: σ too large for the pin, {e:?}"));
        }
        if !holds((e.mean[0] / want - 1.0).abs() < rel_tol) {
            failures.push(format!(
                "{label} θo={th}: measured {}, pinned {want} ± {}%",
                cell(e),
                rel_tol * 100.0
            ));
        }
    }
    got
}

/// Course-model albedos of (b) and (a), with its `t` term (eq. 3.3, the default) and without,
/// measured with these seeds and 200 000 samples (σ ≤ 0.0035); pinned at ±2%.
const PIN_B_T: [(f32, f32); 3] = [(0.0, 2.4463), (45.0, 1.8248), (85.0, 1.3377)];
const PIN_B_NO_T: [(f32, f32); 3] = [(0.0, 2.6154), (45.0, 1.9757), (85.0, 1.6195)];
const PIN_A_T: [(f32, f32); 3] = [(0.0, 0.9160), (45.0, 0.9194), (85.0, 1.2818)];
const PIN_A_NO_T: [(f32, f32); 3] = [(0.0, 0.9484), (45.0, 0.9568), (85.0, 1.3775)];

/// The Course model's departures from energy conservation (the missing `1/η²`: a glossy base
/// under a coat gains energy) are pinned, so that neither they nor the Course model drift.
#[test]
fn course_model_departures_are_pinned() {
    let with_t = |d: StackDesc, t: bool| {
        let mut d = d.with_model(Model::Course);
        d.t_term = Some(t);
        LayeredBsdf::new(&d).expect("valid stack")
    };
    let b_t = with_t(mirror_under_coat(), true);
    assert!(b_t.t_term(), "the t term is on when asked");
    let cfg = |seed| (KEY_SAMPLES, 0.02, seed);
    let (mut out, mut failures) = (
        "\nCourse model departures (channel 0):\n".to_string(),
        vec![],
    );
    let (o, f) = (&mut out, &mut failures);
    let b = check_pins(
        "(b) Course, t term on (default)",
        &b_t,
        &PIN_B_T,
        cfg(21),
        o,
        f,
    );
    let b_no_t = with_t(mirror_under_coat(), false);
    check_pins(
        "(b) Course, t term off",
        &b_no_t,
        &PIN_B_NO_T,
        cfg(22),
        o,
        f,
    );
    let a_t = with_t(white_lambert_under_coat(), true);
    check_pins(
        "(a) Course, t term on (default)",
        &a_t,
        &PIN_A_T,
        cfg(23),
        o,
        f,
    );
    let a_no_t = with_t(white_lambert_under_coat(), false);
    check_pins(
        "(a) Course, t term off",
        &a_no_t,
        &PIN_A_NO_T,
        cfg(24),
        o,
        f,
    );
    print!("{out}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // The gain of a glossy base under a coat (≈ η² T(wo) T at normal incidence).
    assert!(
        b[0].mean[0] - 3.0 * b[0].std_error[0] > 1.5,
        "Course (b) gains: {:?}",
        b[0]
    );
}

/// Without multiple-scattering compensation (Turquin 2019 at the conductor, the interfaces'
/// multiple-scattering lobe in the walk) stack (b) loses the energy that single-scattering
/// masking discards at every event, more at grazing angles. The Reference walk measures that
/// loss; the Corrected model, calibrated to the adding solution of the same uncompensated stack,
/// follows it within 2 % (4σ added for the walk's noise). Both stay below 1 by more than 3σ + 0.4%.
#[test]
fn uncompensated_conductor_loses_energy() {
    let mut d = mirror_under_coat();
    d.compensation = false;
    let b = build(&d, Model::Corrected);
    let walk = build(&d, reference());
    let angles = [0.0f32, 45.0, 85.0];
    let res: Vec<(Estimate, Estimate)> = angles
        .par_iter()
        .enumerate()
        .map(|(i, &th)| {
            (
                albedo(&b, th, 200_000, 31 + i as u64),
                albedo(&walk, th, 300_000, 35 + i as u64),
            )
        })
        .collect();
    let mut out =
        "\n(b) compensation off: Corrected (200000 samples), Reference (300000):\n".to_string();
    for (th, (c, r)) in angles.iter().zip(&res) {
        out += &format!("{th:>5}° {:>15} {:>15}\n", cell(c), cell(r));
    }
    print!("{out}");
    for (th, (c, r)) in angles.iter().zip(&res) {
        for e in [c, r] {
            assert!(
                e.mean[0] + 3.0 * e.std_error[0] < 0.996,
                "θo={th}: expected an energy loss, got {e:?}"
            );
        }
        let tol = 0.02 * r.mean[0] + 4.0 * (c.std_error[0].powi(2) + r.std_error[0].powi(2)).sqrt();
        assert!(
            (c.mean[0] - r.mean[0]).abs() <= tol,
            "θo={th}: Corrected {c:?} vs Reference {r:?}"
        );
    }
}

/// A near-mirror base (perfect conductor, m 0.5°) under a clear coat traps light by total internal
/// reflection for many bounces. With the default walk depth (256) the Reference keeps it lossless
/// within 2%; a shallow walk (max_depth 32, the earlier default) loses the truncated tail (about
/// 6% at θo 80°) but never exceeds 1 by more than 3σ. Both are printed.
#[test]
fn reference_walk_depth_on_a_trapping_stack() {
    let d = StackDesc::new(
        vec![clear_coat(1.7, 7.0)],
        Base::Conductor {
            ior: ConductorIor::Perfect,
            roughness: 0.5,
        },
    );
    assert_eq!(ReferenceParams::default().max_depth, 256);
    let deep = build(&d, reference());
    let default = build(
        &d,
        Model::Reference(ReferenceParams {
            max_depth: 32,
            ..ReferenceParams::default()
        }),
    );
    let angles = [0.0f32, 60.0, 80.0];
    let res: Vec<(Estimate, Estimate)> = angles
        .par_iter()
        .map(|&th| {
            (
                albedo(&deep, th, 300_000, 41),
                albedo(&default, th, 300_000, 42),
            )
        })
        .collect();
    let mut out =
        "\nNear-mirror (m 0.5°) under coat η1.7 m7°, Reference albedo (300000 samples):\n"
            .to_string();
    out += &format!(
        "{:>6} {:>15} {:>15}\n",
        "θo", "default (256)", "max_depth 32"
    );
    for (th, (a, b)) in angles.iter().zip(&res) {
        out += &format!("{th:>5}° {:>15} {:>15}\n", cell(a), cell(b));
    }
    print!("{out}");
    for (th, (deep, default)) in angles.iter().zip(&res) {
        assert!(3.0 * deep.std_error[0] < 0.01, "θo={th}: {deep:?}");
        assert!((deep.mean[0] - 1.0).abs() <= 0.02, "θo={th}: {deep:?}");
        assert!(excess_sigma(default) <= 3.0, "θo={th}: {default:?}");
    }
}

/// `cond`, spelled as a call so that a comparison involving NaN reads as a failure in
/// `if !holds(a <= b)` without tripping clippy's `neg_cmp_op_on_partial_ord`.
fn holds(cond: bool) -> bool {
    cond
}
