//! The Reference model (position-free random walk, Guo et al. 2018; docs/design.md §5.2): its `sample`
//! and its `eval` are two independent estimators of the same BSDF and must agree in the mean; its
//! `eval` is repeatable and seeded by the directions; huge absorption leaves only the top
//! interface's reflection.
//!
//! Agreement: the directional albedo as the mean sample weight (`albedo_by_sampling`) and as the
//! integral of `eval` against a fixed proposal (`albedo_by_eval`, half cosine, half the Corrected
//! model's sampler of the same stack) are independent Monte Carlo estimates; their difference is
//! tested against `3 σ_combined + 1e-3` per channel, `σ_combined = sqrt(σ_s² + σ_e²)` (two-sided
//! 3σ: 0.27% per comparison for normal means; 36 comparisons here, so a family-wise ~9% chance of
//! a false alarm for a correct estimator, before the 1e-3 allowance for table quadrature).
//!
//! Run with the table printed: `cargo test --release --test reference -- --nocapture`.

use glam::Vec3;
use lapidary::bsdf::dielectric::Lobes;
use lapidary::bsdf::measure::{Estimate, albedo_by_eval, albedo_by_sampling, direction_deg};
use lapidary::bsdf::{
    Base, Bxdf, Coat, Distribution, Fresnel, FresnelMode, LayeredBsdf, MicrofacetDistribution,
    Model, ReferenceParams, RoughDielectric, StackDesc, TorranceSparrow, TransportMode,
};
use lapidary::color::Rgb;
use lapidary::recipe::MaterialLibrary;
use lapidary::sampler::{Rng, hash_words};
use lapidary::spectrum::RgbSample;
use rayon::prelude::*;

const SAMPLING_N: u64 = 200_000;
/// Evaluations per integrated-eval estimate; the glossy conductor needs more (its 4-walk `eval`
/// is noisier under a narrow lobe).
fn eval_n(material: &str) -> u64 {
    if material == "silver_paint" {
        120_000
    } else {
        20_000
    }
}

fn reference() -> Model {
    Model::Reference(ReferenceParams::default())
}

fn cell(e: &Estimate) -> String {
    let c = (0..3)
        .max_by(|&a, &b| e.mean[a].total_cmp(&e.mean[b]))
        .unwrap_or(0);
    format!("{:.4}±{:.4}", e.mean[c], e.std_error[c])
}

#[test]
fn sample_weight_matches_integrated_eval() {
    let lib = MaterialLibrary::course();
    let names = [
        "light_blue_house_paint", // two coats (index-matched), Oren–Nayar base
        "silver_paint",           // conductor base
        "garnet_red_spray_paint", // Lambert base, absorbing coat
        "sugar",                  // Oren–Nayar base under a very rough coat
    ];
    let jobs: Vec<(usize, f32)> = (0..names.len())
        .flat_map(|m| [0.0f32, 45.0, 80.0].map(|th| (m, th)))
        .collect();
    let results: Vec<(Estimate, Estimate)> = jobs
        .par_iter()
        .map(|&(m, th)| {
            let walk = lib.build(names[m], Some(reference())).expect("builds");
            let proposal = walk.with_model(Model::Corrected);
            let wo = direction_deg(th, 0.0);
            let seed = hash_words(&[m as u64, u64::from(th.to_bits())]);
            (
                albedo_by_sampling(&walk, wo, SAMPLING_N, seed),
                albedo_by_eval(&walk, &proposal, wo, eval_n(names[m]), seed),
            )
        })
        .collect();
    let mut out = format!(
        "\nReference albedo, max channel: mean sample weight ({SAMPLING_N}) vs integrated eval (20000, silver_paint\n60000; 4 walks each)\n{:<24} {:>5} {:>15} {:>15} {:>7}\n",
        "material", "θo", "sampling", "eval", "|z|max"
    );
    let mut failures = Vec::new();
    for (&(m, th), (s, e)) in jobs.iter().zip(&results) {
        let mut zmax = 0.0f32;
        for c in 0..3 {
            let sigma = s.std_error[c].hypot(e.std_error[c]);
            let d = (s.mean[c] - e.mean[c]).abs();
            zmax = zmax.max(d / sigma.max(1e-9));
            if !holds(d < 3.0 * sigma + 1e-3) {
                failures.push(format!("{} θo={th}° ch{c}: {s:?} vs {e:?}", names[m]));
            }
            // The comparison must be able to see a discrepancy of 0.01 + 2% of the albedo.
            if !holds(3.0 * sigma < 0.01 + 0.02 * s.mean[c]) {
                failures.push(format!("{} θo={th}° ch{c}: σ {sigma} too large", names[m]));
            }
        }
        out += &format!(
            "{:<24} {th:>4}° {:>15} {:>15} {zmax:>7.2}\n",
            names[m],
            cell(s),
            cell(e)
        );
    }
    print!("{out}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

fn bits(s: RgbSample) -> [u32; 3] {
    s.0.map(f32::to_bits)
}

/// Rotates a direction about the normal by `k`·1e-5 rad: the same expected value for an isotropic
/// BSDF, a different seed for the walk.
fn nudge(w: Vec3, k: u32) -> Vec3 {
    let (s, c) = (k as f32 * 1e-5).sin_cos();
    Vec3::new(c * w.x - s * w.y, s * w.x + c * w.y, w.z)
}

#[test]
fn eval_is_repeatable() {
    let lib = MaterialLibrary::course();
    for name in ["sugar", "silver_paint", "light_blue_house_paint"] {
        let walk = lib.build(name, Some(reference())).expect("builds");
        let copy = walk.with_model(reference());
        let rebuilt = lib.build(name, Some(reference())).expect("builds");
        let pairs = [
            (direction_deg(10.0, 0.0), direction_deg(40.0, 170.0)),
            (direction_deg(60.0, 0.0), direction_deg(75.0, 90.0)),
            (direction_deg(85.0, 0.0), direction_deg(30.0, 180.0)),
        ];
        let first: Vec<[u32; 3]> = pairs.iter().map(|&(o, i)| bits(walk.eval(o, i))).collect();
        // Other evaluations in between must not change anything (no hidden state).
        for (o, i) in pairs.iter().rev() {
            walk.eval(*i, *o);
        }
        for (k, &(o, i)) in pairs.iter().enumerate() {
            let f = walk.eval(o, i);
            assert!(f.is_valid() && f.max_channel() > 0.0, "{name}: {f:?}");
            assert_eq!(bits(f), first[k], "{name}: eval not repeatable at {o} {i}");
            assert_eq!(bits(copy.eval(o, i)), first[k], "{name}: copy differs");
            assert_eq!(
                bits(rebuilt.eval(o, i)),
                first[k],
                "{name}: rebuild differs"
            );
        }
        // sample() is repeatable for the same random numbers too.
        let wo = pairs[0].0;
        let (a, b) = (
            walk.sample(wo, 0.3, glam::Vec2::new(0.6, 0.2)),
            walk.sample(wo, 0.3, glam::Vec2::new(0.6, 0.2)),
        );
        assert_eq!(
            a.map(|s| (s.wi.to_array().map(f32::to_bits), bits(s.weight))),
            b.map(|s| (s.wi.to_array().map(f32::to_bits), bits(s.weight))),
            "{name}: sample not repeatable"
        );
    }
}

/// Different directions get independent noise: 64 evaluations at directions rotated by multiples
/// of 1e-5 rad (the same expected value) are all different, and their mean agrees with a
/// 1024-walk evaluation within 4 standard errors (σ from the 64 values' spread). Were the noise
/// shared, the mean would keep a single evaluation's error, 8× the standard error of the mean.
#[test]
fn noise_is_seeded_by_the_directions() {
    let lib = MaterialLibrary::course();
    for name in ["sugar", "light_blue_house_paint", "silver_paint"] {
        let walk = lib.build(name, Some(reference())).expect("builds");
        let fine = walk.with_model(Model::Reference(ReferenceParams {
            samples: 1024,
            ..ReferenceParams::default()
        }));
        let (wo, wi) = (direction_deg(30.0, 0.0), direction_deg(50.0, 160.0));
        let values: Vec<f32> = (0..64)
            .map(|k| walk.eval(nudge(wo, k), nudge(wi, k)).luminance())
            .collect();
        let mut sorted = values.clone();
        sorted.sort_by(f32::total_cmp);
        sorted.dedup();
        assert_eq!(
            sorted.len(),
            64,
            "{name}: repeated noise among nudged directions"
        );
        let n = values.len() as f64;
        let mean = values.iter().map(|&v| f64::from(v)).sum::<f64>() / n;
        let var = values
            .iter()
            .map(|&v| (f64::from(v) - mean).powi(2))
            .sum::<f64>()
            / (n - 1.0);
        let target = f64::from(fine.eval(wo, wi).luminance());
        // The fine value's own noise is 1/√(1024/4) = 1/16 of one evaluation's: add it.
        let se = (var / n + var / 256.0).sqrt();
        println!("{name}: mean of 64 nudged {mean:.5} ± {se:.5}, 1024 walks {target:.5}");
        assert!(var > 0.0, "{name}: no noise at all?");
        assert!(
            (mean - target).abs() < 4.0 * se,
            "{name}: mean {mean} vs {target} (se {se})"
        );
    }
}

/// With absorption α·d = 1e3 nothing comes back from below the top interface: the Reference's
/// `eval` is exactly the interface's reflection — the Torrance–Sparrow lobe, plus the
/// multiple-scattering lobe when the stack compensates — every result is finite, and the sampled
/// albedo is the interface's reflection albedo.
#[test]
fn huge_absorption_leaves_only_the_top_reflection() {
    let m = 10.0;
    let coat = Coat {
        ior: 1.5,
        roughness: m,
        absorption: Rgb::splat(1e3),
        thickness: 1.0,
    };
    let dist = MicrofacetDistribution::new(Distribution::Blinn, m);
    let top = TorranceSparrow::new(dist, Fresnel::dielectric(1.5, FresnelMode::Exact));
    let bases = [
        Base::Lambert { albedo: Rgb::ONE },
        Base::OrenNayar {
            albedo: Rgb::splat(0.8),
            sigma: 0.3,
        },
    ];
    for base in bases {
        for compensation in [false, true] {
            let mut d = StackDesc::new(vec![coat], base).with_model(reference());
            d.compensation = compensation;
            let walk = LayeredBsdf::new(&d).expect("builds");
            let iface = if compensation {
                RoughDielectric::new(dist, 1.5).with_energy_tables()
            } else {
                RoughDielectric::new(dist, 1.5)
            };
            for th_o in [0.0f32, 30.0, 60.0, 85.0, 89.99] {
                let wo = direction_deg(th_o, 0.0);
                for th_i in [0.0f32, 10.0, 30.0, 45.0, 60.0, 85.0, 89.99] {
                    for phi in [0.0f32, 90.0, 180.0] {
                        let wi = direction_deg(th_i, phi);
                        let f = walk.eval(wo, wi);
                        let ctx =
                            format!("{base:?} comp {compensation} θo={th_o} θi={th_i} φ={phi}");
                        assert!(f.is_valid(), "{ctx}: {f:?}");
                        assert!(f[0] == f[1] && f[1] == f[2], "{ctx}: grey coat, {f:?}");
                        let want = iface.value(wo, wi, TransportMode::Radiance);
                        assert!(
                            (f[0] - want).abs() <= 1e-5 * want + 1e-9,
                            "{ctx}: {f:?} vs {want}"
                        );
                        if !compensation {
                            let t = top.eval(wo, wi)[0];
                            assert!((f[0] - t).abs() <= 1e-5 * t + 1e-9, "{ctx}: {f:?} vs {t}");
                        }
                    }
                }
                // Sampling returns only top reflections: its albedo is the interface's reflection
                // albedo. 3σ + 1e-3, 100000 samples each.
                if th_o < 89.0 {
                    let seed = hash_words(&[u64::from(th_o.to_bits()), u64::from(compensation)]);
                    let s = albedo_by_sampling(&walk, wo, 100_000, seed);
                    let mut rng = Rng::new(seed ^ 1);
                    let (mut sum, mut sum2, n) = (0.0f64, 0.0f64, 100_000);
                    for _ in 0..n {
                        let w = iface
                            .sample_lobes(
                                wo,
                                rng.uniform(),
                                rng.uniform2(),
                                TransportMode::Radiance,
                                Lobes::Reflection,
                            )
                            .map_or(0.0, |s| f64::from(s.weight[0]));
                        sum += w;
                        sum2 += w * w;
                    }
                    let mean = sum / n as f64;
                    let se = ((sum2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt();
                    let sigma = f64::from(s.std_error[0]).hypot(se);
                    assert!(s.mean.is_valid(), "{s:?}");
                    assert!(
                        (f64::from(s.mean[0]) - mean).abs() < 3.0 * sigma + 1e-3,
                        "{base:?} comp {compensation} θo={th_o}: {s:?} vs interface {mean} ± {se}"
                    );
                }
            }
        }
    }
}

/// `cond`, spelled as a call so that a comparison involving NaN reads as a failure in
/// `if !holds(a <= b)` without tripping clippy's `neg_cmp_op_on_partial_ord`.
fn holds(cond: bool) -> bool {
    cond
}
