//! The analytic layer models (Course, Corrected) against the stochastic Reference walk, per
//! catalogue material (docs/design.md §5.2, §9).
//!
//! Error over a grid of direction pairs (θo, θi ∈ {10, 30, 50, 70, 85}°, Δφ ∈ {0, 90, 180}°, 75
//! ordered pairs), on luminance:
//!
//! `err = Σ |f_model − f_ref| cos θo cos θi / Σ f_ref cos θo cos θi`.
//!
//! The five exact mirror pairs (θo = θi, Δφ = 180°) carry the top coat's specular peak, which for
//! smooth coats (m ≤ 1°) is orders of magnitude above everything else and makes the error a
//! comparison of the top lobes alone; the error is therefore also reported without them
//! ("off-mirror").
//!
//! The Reference is evaluated with 1024 walks per `eval` (its noise is seeded by `(wo, wi)`, so two
//! seeds of the same pair cannot be compared; instead the same measure between 256 and 1024 walks
//! estimates the noise: `E|f256 − f1024| ≈ 1.12 σ256` and `σ1024 = σ256/2`, so the yardstick's own
//! noise is ≈ err(256 vs 1024)/2.24, printed per material).
//!
//! Directional albedos (luminance, by sampling, 50 000 samples each, σ ≲ 1%) of all three models
//! are compared at θo = 0, 45, 85° in the same table.
//!
//! Run with the table printed: `cargo test --release --test model_error -- --nocapture`.

use glam::Vec3;
use lapidary::bsdf::measure::{albedo_by_sampling, direction_deg};
use lapidary::bsdf::{Bxdf, LayeredBsdf, Model, ReferenceParams};
use lapidary::recipe::MaterialLibrary;
use lapidary::sampler::hash_words;
use rayon::prelude::*;

const THETAS: [f32; 5] = [10.0, 30.0, 50.0, 70.0, 85.0];
const DPHIS: [f32; 3] = [0.0, 90.0, 180.0];
const ALBEDO_ANGLES: [f32; 3] = [0.0, 45.0, 85.0];
const ALBEDO_SAMPLES: u64 = 50_000;

/// Ordered pairs `(wo, wi, is_mirror)`.
fn pairs() -> Vec<(Vec3, Vec3, bool)> {
    let mut v = Vec::new();
    for &to in &THETAS {
        for &ti in &THETAS {
            for &dphi in &DPHIS {
                let mirror = to == ti && dphi == 180.0;
                v.push((direction_deg(to, 0.0), direction_deg(ti, dphi), mirror));
            }
        }
    }
    v
}

fn walk(samples: u32) -> Model {
    Model::Reference(ReferenceParams {
        samples,
        ..ReferenceParams::default()
    })
}

/// Luminance of `f` over the grid.
fn eval_grid(b: &LayeredBsdf) -> Vec<f32> {
    pairs()
        .iter()
        .map(|&(wo, wi, _)| {
            let f = b.eval(wo, wi);
            assert!(f.is_valid(), "{wo} {wi}: {f:?}");
            f.luminance()
        })
        .collect()
}

/// `(all pairs, off-mirror)` cosine-weighted relative L1 error of `model` against `reference`.
fn error(model: &[f32], reference: &[f32]) -> (f32, f32) {
    let mut acc = [[0.0f64; 2]; 2]; // [all, off][num, den]
    for ((&(wo, wi, mirror), &m), &r) in pairs().iter().zip(model).zip(reference) {
        let w = f64::from(wo.z * wi.z);
        let (num, den) = (f64::from((m - r).abs()) * w, f64::from(r) * w);
        for (k, a) in acc.iter_mut().enumerate() {
            if k == 0 || !mirror {
                a[0] += num;
                a[1] += den;
            }
        }
    }
    (
        (acc[0][0] / acc[0][1]) as f32,
        (acc[1][0] / acc[1][1]) as f32,
    )
}

struct Row {
    name: String,
    course: (f32, f32),
    corrected: (f32, f32),
    /// err(256 walks vs 1024 walks), all pairs and off-mirror.
    noise: (f32, f32),
    /// Luminance albedo `[Course, Corrected, Reference]` at each of [`ALBEDO_ANGLES`].
    albedo: [[f32; 3]; 3],
}

fn measure(lib: &MaterialLibrary, name: &str, index: u64) -> Row {
    let build = |m| lib.build(name, Some(m)).expect("catalogue material builds");
    let models = [
        build(Model::Course),
        build(Model::Corrected),
        build(walk(4)),
    ];
    let course = eval_grid(&models[0]);
    let corrected = eval_grid(&models[1]);
    let reference = eval_grid(&build(walk(1024)));
    let rough = eval_grid(&build(walk(256)));
    let mut albedo = [[0.0; 3]; 3];
    for (a, &th) in ALBEDO_ANGLES.iter().enumerate() {
        for (k, b) in models.iter().enumerate() {
            let seed = hash_words(&[index, a as u64, k as u64]);
            let e = albedo_by_sampling(b, direction_deg(th, 0.0), ALBEDO_SAMPLES, seed);
            albedo[a][k] = e.mean.luminance();
        }
    }
    Row {
        name: name.to_string(),
        course: error(&course, &reference),
        corrected: error(&corrected, &reference),
        noise: error(&rough, &reference),
        albedo,
    }
}

#[test]
fn analytic_models_against_reference() {
    let lib = MaterialLibrary::course();
    let names: Vec<String> = lib.names().map(str::to_string).collect();
    let rows: Vec<Row> = names
        .par_iter()
        .enumerate()
        .map(|(i, n)| measure(&lib, n, i as u64))
        .collect();

    let mut out = String::from(
        "\nError against the Reference (1024 walks/eval): Σ|f − f_ref| cosθo cosθi / Σ f_ref cosθo cosθi\n\
         (luminance; 75 pairs: θo, θi ∈ {10,30,50,70,85}°, Δφ ∈ {0,90,180}°; \"off\" = without the 5 mirror\n\
         pairs). noise = same measure, 256 vs 1024 walks (yardstick noise ≈ noise/2.24).\n\
         Albedo = luminance directional albedo by sampling (50000 samples), Course / Corrected / Reference.\n",
    );
    out += &format!(
        "{:<24} {:>8} {:>8} {:>8} {:>8} {:>15} {:>20} {:>20} {:>20}\n",
        "material",
        "Course",
        "Corr.",
        "Course",
        "Corr.",
        "noise",
        "albedo θo=0°",
        "albedo θo=45°",
        "albedo θo=85°"
    );
    out += &format!(
        "{:<24} {:>8} {:>8} {:>8} {:>8} {:>15}\n",
        "", "all", "all", "off", "off", "all / off"
    );
    for r in &rows {
        let alb = |a: usize| {
            format!(
                "{:.3}/{:.3}/{:.3}",
                r.albedo[a][0], r.albedo[a][1], r.albedo[a][2]
            )
        };
        out += &format!(
            "{:<24} {:>8.4} {:>8.4} {:>8.4} {:>8.4} {:>15} {:>20} {:>20} {:>20}\n",
            r.name,
            r.course.0,
            r.corrected.0,
            r.course.1,
            r.corrected.1,
            format!("{:.4}/{:.4}", r.noise.0, r.noise.1),
            alb(0),
            alb(1),
            alb(2)
        );
    }
    print!("{out}");

    let mut failures = Vec::new();
    for r in &rows {
        // Corrected's error must not grow: bounds 20% above today's values, plus 0.005 for the
        // Reference's noise and the tables' quadrature (a change of table strata alone moved
        // green_latex's off-mirror error from 0.054 to 0.060).
        let Some(&(_, [all, off])) = CORRECTED_ERROR.iter().find(|(n, _)| *n == r.name) else {
            failures.push(format!("{}: no measured error recorded", r.name));
            continue;
        };
        if !holds(r.corrected.0 <= 1.2 * all + 0.005 && r.corrected.1 <= 1.2 * off + 0.005) {
            failures.push(format!(
                "{}: Corrected error {:?} above the bounds from {:?}",
                r.name,
                r.corrected,
                (all, off)
            ));
        }
        // Corrected's albedo within 4% of the Reference's (it is calibrated to the adding
        // solution, ≲ 2% from the walk; 11% before, light_blue_house_paint at θo = 0°); each
        // albedo has σ ≲ 1%.
        for (a, th) in ALBEDO_ANGLES.iter().enumerate() {
            let [_, corr, refr] = r.albedo[a];
            if !holds((corr - refr).abs() <= 0.04 * refr) {
                failures.push(format!(
                    "{} θo={th}°: Corrected albedo {corr:.4} vs Reference {refr:.4}",
                    r.name
                ));
            }
        }
        // Glossy metal under a coat: the Course model's missing 1/η² makes it gain energy;
        // Corrected must be closer to the Reference, pointwise and in albedo.
        if GLOSSY_METALS.contains(&r.name.as_str()) {
            if !holds(r.corrected.0 < r.course.0 && r.corrected.1 < r.course.1) {
                failures.push(format!(
                    "{}: Corrected {:?} not closer than Course {:?}",
                    r.name, r.corrected, r.course
                ));
            }
            for (a, th) in ALBEDO_ANGLES.iter().enumerate() {
                let [course, corr, refr] = r.albedo[a];
                if !holds((corr - refr).abs() < (course - refr).abs()) {
                    failures.push(format!(
                        "{} θo={th}°: albedo Course {course:.4}, Corrected {corr:.4}, Reference {refr:.4}",
                        r.name
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Glossy metal bases under a coat, where the Course model is known to be far off.
const GLOSSY_METALS: [&str; 4] = [
    "silver_paint",
    "brass",
    "blue_metallic_car_paint",
    "gold_car_paint",
];

/// Corrected's error against the Reference measured today, `[all pairs, off-mirror]`.
const CORRECTED_ERROR: [(&str, [f32; 2]); 11] = [
    ("garnet_red_spray_paint", [0.0025, 0.0052]),
    ("sugar", [0.0133, 0.0144]),
    ("green_latex", [0.0045, 0.0051]),
    ("brass", [0.0003, 0.0337]),
    ("blue_metallic_car_paint", [0.0000, 0.0081]),
    ("gold_car_paint", [0.0001, 0.0183]),
    ("blue_metallic_paint", [2.2821, 0.1159]),
    ("silver_paint", [0.0640, 0.1002]),
    ("light_blue_house_paint", [0.0057, 0.0065]),
    ("blue_glossy_ceramic", [0.0000, 0.0045]),
    ("red_glossy_ceramic", [0.0000, 0.0066]),
];

/// `cond`, spelled as a call so that a comparison involving NaN reads as a failure in
/// `if !holds(a <= b)` without tripping clippy's `neg_cmp_op_on_partial_ord`.
fn holds(cond: bool) -> bool {
    cond
}
