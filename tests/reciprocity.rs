//! Helmholtz reciprocity (docs/design.md §10).
//!
//! Every component must satisfy `f(wo, wi) = f(wi, wo)` up to `f32` rounding; transmission through
//! a dielectric in radiance mode satisfies the generalised relation `f(wo, wi)/η(wo)² =
//! f(wi, wo)/η(wi)²` (Veach 1997, §5.2, with `η(w)` the IOR on `w`'s side) and its adjoint
//! `f_rad(wo, wi) = f_imp(wi, wo)`.
//!
//! The layer stack is not exactly reciprocal: the Corrected model's multiple-reflection lobe
//! `q(wo)·T(wi)` and the conductors' energy compensation depend on `wo` differently than on `wi`
//! (docs/design.md §5.2 asks to measure and report by how much), and the Course model's `t` term (eq. 3.3)
//! uses `T21(wo)` only. The asymmetry is measured per catalogue material and model, printed, and
//! bounded slightly above today's values so that a regression fails. The Reference walk is
//! stochastic: its asymmetry is compared with its own noise floor, the same measure between two
//! independent evaluations of the same pair (seeds differ because the directions differ by a
//! rotation of 1e-5 rad about the normal).
//!
//! Run with the table printed: `cargo test --release --test reciprocity -- --nocapture`.

use glam::Vec3;
use lapidary::bsdf::TransportMode;
use lapidary::bsdf::measure::direction_deg;
use lapidary::bsdf::{
    Bxdf, Distribution, Fresnel, FresnelMode, Lambert, LayeredBsdf, Masking, Metal,
    MicrofacetDistribution, Model, OrenNayar, ReferenceParams, RoughDielectric, TorranceSparrow,
};
use lapidary::recipe::MaterialLibrary;
use lapidary::spectrum::RgbSample;
use rayon::prelude::*;

/// Relative tolerance of the reflection components (f32 rounding of half vectors and Fresnel
/// cosines; measured worst 4e-6).
const COMPONENT_TOL: f32 = 1e-4;
/// Relative tolerance of transmission: the generalised half vector `η wi + wo` and the denominator
/// `(wi·h + wo·h/η')²` (Walter et al. 2007, eqs. 16, 21) cancel in f32 for wide scattering angles;
/// measured worst 2.6e-4 (Blinn m = 30°, wo at 85°, wi 45° below at Δφ = 150°).
const TRANSMISSION_TOL: f32 = 5e-4;

/// Ordered pairs of upper-hemisphere directions: θ ∈ {5, 15, …, 85}° each, wo at azimuth 0 and wi
/// at several azimuths.
fn component_pairs() -> Vec<(Vec3, Vec3)> {
    let mut v = Vec::new();
    for a in 0..9 {
        for b in 0..9 {
            for phi in [0.0, 30.0, 90.0, 150.0, 179.0, 180.0, 250.0] {
                let (ta, tb) = (5.0 + 10.0 * a as f32, 5.0 + 10.0 * b as f32);
                v.push((direction_deg(ta, 0.0), direction_deg(tb, phi)));
            }
        }
    }
    v
}

/// Differences below this fraction of a component's largest value over the grid are ignored: in
/// the far tail of a narrow lobe (1e-7 of its peak and below) the f32 rounding of the half vector
/// is amplified by the steep exponent of `D`, and a half vector within rounding of a facet's
/// horizon can make one direction of a pair exactly 0 and the other ~1e-31.
const TAIL: f32 = 1e-7;

/// Checks that the two values `g(wo, wi)` returns agree channel by channel over the grid within
/// `tol · max(|a|, |b|) + TAIL · peak`; returns (worst relative difference among the
/// values above the tail, pairs where they are non-zero).
fn check_pairs(
    name: &str,
    tol: f32,
    g: &dyn Fn(Vec3, Vec3) -> (RgbSample, RgbSample),
) -> (f32, usize) {
    let values: Vec<(Vec3, Vec3, RgbSample, RgbSample)> = component_pairs()
        .into_iter()
        .map(|(wo, wi)| {
            let (a, b) = g(wo, wi);
            (wo, wi, a, b)
        })
        .collect();
    let peak = values
        .iter()
        .map(|v| v.2.max_channel().max(v.3.max_channel()))
        .fold(0.0f32, f32::max);
    let mut worst = 0.0f32;
    let mut nonzero = 0;
    for (wo, wi, a, b) in values {
        assert!(
            a.is_valid() && b.is_valid(),
            "{name}: {wo} {wi}: {a:?} {b:?}"
        );
        for c in 0..3 {
            let (x, y) = (a[c], b[c]);
            let m = x.abs().max(y.abs());
            assert!(
                (x - y).abs() <= tol * m + TAIL * peak,
                "{name}: {a:?} vs {b:?} at wo = {wo}, wi = {wi} (peak {peak})"
            );
            if m > TAIL * peak {
                worst = worst.max((x - y).abs() / m);
            }
        }
        nonzero += usize::from(a.max_channel() > 0.0);
    }
    (worst, nonzero)
}

#[test]
fn components_are_reciprocal() {
    let mut report = Vec::new();
    let mut run = |name: String, g: &dyn Fn(Vec3, Vec3) -> (RgbSample, RgbSample)| {
        let tol = if name.contains("trans.") {
            TRANSMISSION_TOL
        } else {
            COMPONENT_TOL
        };
        let (worst, nonzero) = check_pairs(&name, tol, g);
        // The test must have seen something (a narrow transmission lobe hits few grid pairs).
        assert!(nonzero >= 30, "{name}: only {nonzero} non-zero pairs");
        report.push(format!(
            "{name:<52} worst rel. difference {worst:.1e}, {nonzero} pairs > 0"
        ));
    };
    let sym = |f: &dyn Fn(Vec3, Vec3) -> RgbSample, a: Vec3, b: Vec3| (f(a, b), f(b, a));
    let lambert = Lambert {
        albedo: RgbSample::rgb(0.2, 0.5, 0.9),
    };
    run("Lambert".into(), &|a, b| {
        sym(&|x, y| lambert.eval(x, y), a, b)
    });
    for sigma in [0.0, 0.26, 0.5, 1.0] {
        let on = OrenNayar {
            albedo: RgbSample::rgb(0.8, 0.5, 0.3),
            sigma,
        };
        run(format!("Oren–Nayar σ={sigma}"), &|a, b| {
            sym(&|x, y| on.eval(x, y), a, b)
        });
    }
    let below = Vec3::new(1.0, 1.0, -1.0);
    let (eta, imp, rad) = (1.5f32, TransportMode::Importance, TransportMode::Radiance);
    let maskings = [Masking::VCavity, Masking::Smith, Masking::SmithSeparable];
    for (dist, masking) in [
        Distribution::Blinn,
        Distribution::Beckmann,
        Distribution::Ggx,
    ]
    .into_iter()
    .flat_map(|d| maskings.map(|m| (d, m)))
    {
        for m in [2.0, 10.0, 30.0] {
            let d = MicrofacetDistribution::new(dist, m).with_masking(masking);
            let dist = format!("{dist} {masking:?}");
            let diel = TorranceSparrow::new(d, Fresnel::dielectric(eta, FresnelMode::Exact));
            run(format!("TS dielectric {dist} m={m}°"), &|a, b| {
                sym(&|x, y| diel.eval(x, y), a, b)
            });
            for metal in [Metal::Gold, Metal::Aluminium] {
                let (n, k) = metal.nk();
                let cond = TorranceSparrow::new(
                    d,
                    Fresnel::conductor(n.into(), k.into(), FresnelMode::Exact),
                );
                run(
                    format!("TS conductor {} {dist} m={m}°", metal.name()),
                    &|a, b| sym(&|x, y| cond.eval(x, y), a, b),
                );
            }
            let glass = RoughDielectric::new(d, eta);
            let f = |x: Vec3, y: Vec3, mode| RgbSample::splat(glass.value(x, y, mode));
            run(
                format!("RoughDielectric refl. above {dist} m={m}°"),
                &|a, b| sym(&|x, y| f(x, y, rad), a, b),
            );
            run(
                format!("RoughDielectric refl. below {dist} m={m}°"),
                &|a, b| sym(&|x, y| f(x, y, rad), a * below, b * below),
            );
            // Transmission, radiance mode, wo above (η 1), wi below (η 1.5) and the reverse:
            // f(wo, wi)/η(wo)² = f(wi, wo)/η(wi)².
            run(
                format!("RoughDielectric trans. η² {dist} m={m}°"),
                &|a, b| {
                    let (wo, wi) = (a, b * below);
                    (f(wo, wi, rad) * (eta * eta), f(wi, wo, rad))
                },
            );
            // Adjoint: f_rad(wo, wi) = f_imp(wi, wo), with wo above and with wo below.
            run(
                format!("RoughDielectric trans. adjoint, wo above {dist} m={m}°"),
                &|a, b| (f(a, b * below, rad), f(b * below, a, imp)),
            );
            run(
                format!("RoughDielectric trans. adjoint, wo below {dist} m={m}°"),
                &|a, b| (f(a * below, b, rad), f(b, a * below, imp)),
            );
        }
    }
    for line in report {
        println!("{line}");
    }
}

/// Unordered pairs for the stack: θo < θi, both in {5, 15, …, 85}°, wi at azimuths
/// {0, 45, 90, 135, 180}° from wo (180 pairs).
fn stack_pairs() -> Vec<(Vec3, Vec3)> {
    let mut v = Vec::new();
    for a in 0..9 {
        for b in (a + 1)..9 {
            for phi in [0.0, 45.0, 90.0, 135.0, 180.0] {
                let (ta, tb) = (5.0 + 10.0 * a as f32, 5.0 + 10.0 * b as f32);
                v.push((direction_deg(ta, 0.0), direction_deg(tb, phi)));
            }
        }
    }
    v
}

/// Luminances below this (sr⁻¹) on both sides count as "both zero" and skip the pair.
const ZERO_LUM: f32 = 1e-6;

/// Asymmetry of a set of value pairs `(a, b, wo, wi)` (luminances):
/// mean of `|a − b| / (½ (a + b))` over pairs not both ~0, and the cosine-weighted relative L1
/// `Σ |a − b| cos θo cos θi / Σ ½ (a + b) cos θo cos θi`.
fn asymmetry(values: &[(f32, f32, Vec3, Vec3)]) -> (f32, f32) {
    let (mut rel, mut n, mut num, mut den) = (0.0f64, 0usize, 0.0f64, 0.0f64);
    for &(a, b, wo, wi) in values {
        if a < ZERO_LUM && b < ZERO_LUM {
            continue;
        }
        let (a, b, w) = (f64::from(a), f64::from(b), f64::from(wo.z * wi.z));
        rel += (a - b).abs() / (0.5 * (a + b));
        n += 1;
        num += (a - b).abs() * w;
        den += 0.5 * (a + b) * w;
    }
    (
        (rel / n.max(1) as f64) as f32,
        (num / den.max(1e-300)) as f32,
    )
}

/// Rotates a direction about the normal by 1e-5 rad: the same value of an isotropic BSDF, a
/// different seed for the Reference walk.
fn nudge(w: Vec3) -> Vec3 {
    let (s, c) = 1e-5f32.sin_cos();
    Vec3::new(c * w.x - s * w.y, s * w.x + c * w.y, w.z)
}

#[derive(Clone, Copy, Debug)]
struct Measured {
    rel: f32,
    l1: f32,
    /// Noise floor of the same measures (two independent evaluations of each pair), Reference only.
    noise: Option<(f32, f32)>,
}

fn measure_stack(b: &LayeredBsdf, stochastic: bool) -> Measured {
    let pairs = stack_pairs();
    let lum = |x: Vec3, y: Vec3| {
        let f = b.eval(x, y);
        assert!(f.is_valid(), "{x} {y}: {f:?}");
        f.luminance()
    };
    let sym: Vec<_> = pairs
        .iter()
        .map(|&(wo, wi)| (lum(wo, wi), lum(wi, wo), wo, wi))
        .collect();
    let (rel, l1) = asymmetry(&sym);
    let noise = stochastic.then(|| {
        let rep: Vec<_> = pairs
            .iter()
            .zip(&sym)
            .map(|(&(wo, wi), s)| (s.0, lum(nudge(wo), nudge(wi)), wo, wi))
            .collect();
        asymmetry(&rep)
    });
    Measured { rel, l1, noise }
}

#[test]
fn stack_asymmetry_table() {
    let lib = MaterialLibrary::course();
    let names: Vec<String> = lib.names().map(str::to_string).collect();
    let walk = Model::Reference(ReferenceParams {
        samples: 64,
        ..ReferenceParams::default()
    });
    let rows: Vec<[Measured; 3]> = names
        .par_iter()
        .map(|n| {
            let m = |model| lib.build(n, Some(model)).expect("builds");
            [
                measure_stack(&m(Model::Course), false),
                measure_stack(&m(Model::Corrected), false),
                measure_stack(&m(walk), true),
            ]
        })
        .collect();
    let mut out = String::from(
        "\nReciprocity of the stack: mean relative asymmetry |f(wo,wi) − f(wi,wo)| / mean (luminance) and\n\
         cosine-weighted relative L1, over 180 pairs (θo < θi in 5…85°, Δφ 0…180°). Reference: 64 walks\n\
         per eval, with its noise floor (two independent evaluations of the same pair) in brackets.\n",
    );
    out += &format!(
        "{:<24} {:>9} {:>9} {:>9} {:>9} {:>20} {:>20}\n",
        "material",
        "Course",
        "Course L1",
        "Corr.",
        "Corr. L1",
        "Reference [noise]",
        "Ref. L1 [noise]"
    );
    for (n, [c, k, r]) in names.iter().zip(&rows) {
        let (nr, nl) = r.noise.unwrap_or_default();
        out += &format!(
            "{n:<24} {:>9.5} {:>9.5} {:>9.5} {:>9.5} {:>20} {:>20}\n",
            c.rel,
            c.l1,
            k.rel,
            k.l1,
            format!("{:.4} [{:.4}]", r.rel, nr),
            format!("{:.4} [{:.4}]", r.l1, nl)
        );
    }
    print!("{out}");
    let mut failures = Vec::new();
    for (n, [c, k, r]) in names.iter().zip(&rows) {
        let Some(&(_, pinned)) = MEASURED.iter().find(|(m, _)| m == n) else {
            failures.push(format!("{n}: no measured asymmetry recorded"));
            continue;
        };
        let got = [c.rel, c.l1, k.rel, k.l1, r.rel, r.l1];
        for (i, (&g, &p)) in got.iter().zip(&pinned).enumerate() {
            // Analytic models: 10% above today's value; the Reference's measure is mostly its own
            // noise, which moves by ~±15% with the walk's random numbers: 35% above.
            let bound = if i < 4 {
                1.1 * p + 1e-4
            } else {
                1.35 * p + 1e-3
            };
            if !holds(g <= bound) {
                failures.push(format!("{n} {}: {g:.5} > bound {bound:.5}", COLUMNS[i]));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "asymmetry regressed:\n{}",
        failures.join("\n")
    );
}

const COLUMNS: [&str; 6] = [
    "Course rel",
    "Course L1",
    "Corrected rel",
    "Corrected L1",
    "Reference rel",
    "Reference L1",
];

/// Today's measured asymmetries (columns as [`COLUMNS`]); bounds are derived from them.
#[rustfmt::skip]
const MEASURED: [(&str, [f32; 6]); 11] = [
    ("garnet_red_spray_paint", [0.17290, 0.00543, 0.00000, 0.00000, 0.0189, 0.0014]),
    ("sugar", [0.16337, 0.02753, 0.00000, 0.00000, 0.0736, 0.0672]),
    ("green_latex", [0.15077, 0.02427, 0.00000, 0.00000, 0.0325, 0.0258]),
    ("brass", [0.11063, 0.00439, 0.00000, 0.00000, 0.5733, 0.0220]),
    ("blue_metallic_car_paint", [0.18040, 0.00675, 0.00308, 0.00132, 0.0237, 0.0035]),
    ("gold_car_paint", [0.18355, 0.01276, 0.00113, 0.00068, 0.0369, 0.0122]),
    ("blue_metallic_paint", [0.00001, 0.00013, 0.00000, 0.00000, 0.0522, 0.0478]),
    ("silver_paint", [0.18398, 0.00817, 0.00018, 0.00010, 0.3323, 0.0760]),
    ("light_blue_house_paint", [0.14015, 0.02263, 0.00000, 0.00000, 0.0263, 0.0220]),
    ("blue_glossy_ceramic", [0.18571, 0.03263, 0.00000, 0.00000, 0.0141, 0.0145]),
    ("red_glossy_ceramic", [0.18571, 0.03203, 0.00000, 0.00000, 0.0214, 0.0197]),
];

/// The Reference walk is reciprocal in expectation, without and with energy compensation: its
/// asymmetry, a mean of |differences of two estimates|, has the same expectation as its noise
/// floor. Over 180 pairs at 256 walks per evaluation the ratio of the two L1 measures is
/// 0.85–1.05 (off and on); a bound of 1.5 flags a non-reciprocity half the size of the noise.
/// (Compensation used to scale each interface event by `1/E(wo)`, which is not reciprocal:
/// garnet_red_spray_paint then showed 15× its noise. The interfaces' multiple-scattering lobe
/// (`bsdf::interface_energy`) keeps detailed balance; the conductor's Turquin factor, the one
/// per-`wo` factor left, is within the noise for silver_paint.)
#[test]
fn reference_is_reciprocal_within_noise() {
    let lib = MaterialLibrary::course();
    let names = [
        "garnet_red_spray_paint",
        "sugar",
        "silver_paint",
        "light_blue_house_paint",
    ];
    let rows: Vec<(Measured, Measured)> = names
        .par_iter()
        .map(|n| {
            let run = |compensation| {
                let mut d = lib.stack(n).expect("catalogue material");
                d.compensation = compensation;
                d.model = Model::Reference(ReferenceParams {
                    samples: 256,
                    ..ReferenceParams::default()
                });
                measure_stack(&LayeredBsdf::new(&d).expect("builds"), true)
            };
            (run(false), run(true))
        })
        .collect();
    let mut out = String::from(
        "\nReference (256 walks per eval) L1 asymmetry [noise floor], without and with compensation:\n",
    );
    let mut failures = Vec::new();
    for (n, (off, on)) in names.iter().zip(&rows) {
        let (noff, non) = (off.noise.unwrap_or_default(), on.noise.unwrap_or_default());
        out += &format!(
            "{n:<24} off {:.4} [{:.4}] (ratio {:.2})   on {:.4} [{:.4}] (ratio {:.2})\n",
            off.l1,
            noff.1,
            off.l1 / noff.1,
            on.l1,
            non.1,
            on.l1 / non.1
        );
        for (label, m, noise) in [("off", off, noff), ("on", on, non)] {
            if !holds(m.l1 <= 1.5 * noise.1) {
                failures.push(format!(
                    "{n} compensation {label}: L1 asymmetry {:.4} > 1.5 × noise {:.4}",
                    m.l1, noise.1
                ));
            }
        }
    }
    print!("{out}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// `cond`, spelled as a call so that a comparison involving NaN reads as a failure in
/// `if !holds(a <= b)` without tripping clippy's `neg_cmp_op_on_partial_ord`.
fn holds(cond: bool) -> bool {
    cond
}
