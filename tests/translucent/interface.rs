//! Claim 7, the rough boundary exactly as bodies build it (`scene::Body::boundary`: GGX, height-correlated
//! Smith, `RoughDielectric::with_energy_tables`) at the IORs of tourmaline-like and diamond-like
//! stones, η 1.55 and 2.4, with m 10° (α 0.176) and α 0.5 — the machinery of tests/dielectric.rs
//! and tests/interface_energy.rs (which cover η 1.5, 2.4 and 1/1.5, and GGX only at α 0.3)
//! applied to these four interfaces:
//!
//! - chi-square of `sample_mode` against `pdf` over the full sphere (48 × 96 bins, adaptive
//!   quadrature, pooling below 5, a failed-sample cell), every draw sampled in both transport modes
//!   and checked per sample (same direction, pdf and `eta`; `weight = f·|cos|/pdf`;
//!   `w_rad·η'² = w_imp`); views θo 0°, 40° and 85° (grazing) from the rare side, 20° (below the
//!   critical angle) and 60° and 85° (total internal reflection for the smooth interface:
//!   critical angles 40.2° and 24.6°) from the dense side; in CI 85° above and 60° below (8
//!   configurations, 100 000 draws each), in the `--ignored` run all 24 with 1 000 000; overall
//!   significance 0.01 (Šidák). Negative control: the uncompensated pdf is rejected.
//! - reciprocity over 20 000 random pairs per interface: `f_rad(wo, wi) = f_imp(wi, wo)` and
//!   `f_rad(wo, wi)/η(wo)² = f_rad(wi, wo)/η(wi)²` to 1e-3; the exchanged form is off by `η⁴`.
//! - importance-mode `R + T` = 1 within the documented table accuracy (0.005 + 3σ,
//!   tests/interface_energy.rs) at the same views, 50 000 draws each, and radiance-mode
//!   transmission = importance / η'².

use super::checks::rel;
use super::common::{par_map, sidak_alpha};
use super::measure::{RECIPROCITY_TOL, pairs};
use super::{chi, energy};
use glam::Vec3;
use lapidary::bsdf::measure::direction_deg;
use lapidary::bsdf::{Bsdf, Distribution, Masking, RoughDielectric};
use lapidary::sampler::hash_words;
use lapidary::scene::Body;

const ALPHA: f64 = 0.01;
const N_CHI: u64 = 100_000;
const N_PAIRS: u64 = 20_000;
const N_MEAN: u64 = 50_000;
/// Allowed `|R + T − 1|` beyond 3σ (tests/interface_energy.rs: the lobe returns `1 − E` of a
/// 64-entry Monte Carlo table).
const ENERGY_TOL: f64 = 0.005;
/// Views `(θo, φo, below)`, degrees.
const VIEWS: [(f32, f32, bool); 6] = [
    (0.0, 0.0, false),
    (40.0, 40.0, false),
    (85.0, 130.0, false),
    (20.0, 200.0, true),
    (60.0, 250.0, true),
    (85.0, 310.0, true),
];

/// `(label, compensated, uncompensated)` for η 1.55 and 2.4 × m 10° and α 0.5.
fn interfaces() -> Vec<(String, RoughDielectric, RoughDielectric)> {
    let mut v = Vec::new();
    for eta in [1.55f32, 2.4] {
        for (name, alpha) in [("m 10°", 10f32.to_radians().tan()), ("α 0.5", 0.5)] {
            let body = Body {
                ior: eta,
                dispersion: None,
                alpha,
                distribution: Distribution::Ggx,
                masking: Masking::Smith,
                compensation: true,
                medium: None,
                platelets: vec![],
                platelet_materials: vec![],
                crystal: None,
            };
            let Bsdf::Dielectric(full) = body.boundary() else {
                panic!("a rough body has a rough boundary")
            };
            assert!(
                full.energy.is_some(),
                "η {eta} {name}: no compensation lobe"
            );
            let plain = RoughDielectric {
                energy: None,
                ..full.clone()
            };
            v.push((format!("GGX+Smith {name} η {eta}"), full, plain));
        }
    }
    v
}

fn view(theta: f32, phi: f32, below: bool) -> (Vec3, (f32, f32)) {
    let w = direction_deg(theta, phi);
    if below {
        (Vec3::new(w.x, w.y, -w.z), (180.0 - theta, phi))
    } else {
        (w, (theta, phi))
    }
}

/// Chi-square views: all of [`VIEWS`] (`full`), or in CI the grazing one from the rare side and
/// the one from the dense side at 60°, beyond the critical angle.
fn chi_configs(full_set: bool) -> Vec<chi::Config> {
    let mut v = Vec::new();
    for (label, full, _) in interfaces() {
        for &(t, p, below) in &VIEWS {
            let ci_view = (t == 85.0 && !below) || (below && t == 60.0);
            if !(full_set || ci_view) {
                continue;
            }
            let (wo, wo_deg) = view(t, p, below);
            v.push(chi::Config {
                label: label.clone(),
                bsdf: full.clone(),
                wo,
                wo_deg,
            });
        }
    }
    v
}

/// Chi-square, both modes, grazing and total internal reflection (module docs).
fn run_chi(full_set: bool, n: u64) {
    let configs = chi_configs(full_set);
    let alpha = sidak_alpha(ALPHA, configs.len());
    let rows = par_map(&configs, |c| chi::run(c, &c.bsdf, n));
    let failures = chi::report("body boundary (compensated), full sphere", &rows, alpha);
    let worst = rows
        .iter()
        .min_by(|a, b| a.chi.p_value.total_cmp(&b.chi.p_value))
        .expect("rows");
    println!(
        "worst p = {:.3e} ({} at θo {}°)",
        worst.chi.p_value, worst.label, worst.wo_deg.0
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // Not vacuous: transmissions from below beyond the critical angle exist (the rough surface
    // lets some out) but are rarer than reflections, and both lobes were sampled in bulk.
    for r in rows
        .iter()
        .filter(|r| r.wo_deg.0 > 90.0 && r.wo_deg.0 < 150.0)
    {
        assert!(
            r.stats.reflected > r.stats.transmitted && r.stats.transmitted > 0,
            "{} θo {}: {} reflections, {} transmissions",
            r.label,
            r.wo_deg.0,
            r.stats.reflected,
            r.stats.transmitted
        );
    }
    let t: u64 = rows.iter().map(|r| r.stats.transmitted).sum();
    assert!(t > n, "{t} transmissions");
}

/// CI: 8 configurations (each interface at θo 85° above and 60° below: grazing, and beyond the
/// critical angle), 100 000 draws each, overall significance 0.01.
#[test]
fn chi_square_of_the_body_boundary_both_modes() {
    run_chi(false, N_CHI);
}

/// All 24 configurations with 1 000 000 draws each (≈ 2 min on two cores).
#[test]
#[ignore = "slow: cargo test --release --test translucent chi_square_of_the_body_boundary_full -- --ignored"]
fn chi_square_of_the_body_boundary_full() {
    run_chi(true, 10 * N_CHI);
}

/// Negative control: the compensated sampler does not fit the uncompensated pdf (α 0.5, η 1.55,
/// θo 120°: 60° below, beyond the critical angle).
#[test]
fn chi_square_rejects_the_uncompensated_pdf_of_the_body_boundary() {
    let alpha = sidak_alpha(ALPHA, chi_configs(false).len());
    let all = interfaces();
    let (label, full, plain) = &all[1];
    assert!(label.contains("α 0.5 η 1.55"), "{label}");
    let (wo, wo_deg) = view(60.0, 250.0, true);
    let c = chi::Config {
        label: label.clone(),
        bsdf: full.clone(),
        wo,
        wo_deg,
    };
    let wrong = chi::run(&c, plain, N_CHI);
    println!(
        "{label} θo {}: uncompensated pdf chi² {:.1} dof {} p {:.3e}",
        wo_deg.0, wrong.chi.chi2, wrong.chi.dof, wrong.chi.p_value
    );
    assert!(!wrong.chi.passes(alpha), "uncompensated pdf accepted");
}

/// Reciprocity of the full value (single scattering + lobe), module docs.
#[test]
fn reciprocity_of_the_body_boundary() {
    let cases = interfaces();
    let results = par_map(&cases, |(label, full, plain)| {
        let lobe = full.energy.as_deref().expect("lobe");
        let seed = hash_words(&label.bytes().map(u64::from).collect::<Vec<_>>());
        pairs(full, plain, lobe, N_PAIRS, seed)
    });
    let mut failures = Vec::new();
    for ((label, full, _), r) in cases.iter().zip(&results) {
        println!(
            "{label:<24} adjoint {:.1e} η² reciprocity {:.1e} ss+lobe {:.1e}; {} transmission \
             pairs, {} with lobe ≥ 1 %, {} near the horizon left out; exchanged form off by {:.3}",
            r.adjoint, r.general, r.lobe, r.transmissions, r.lobe_pairs, r.horizon, r.swapped_min
        );
        failures.extend(r.failures.iter().map(|f| format!("{label}: {f}")));
        if r.transmissions < 500 || r.lobe_pairs < 100 {
            failures.push(format!(
                "{label}: only {} transmission and {} lobe pairs",
                r.transmissions, r.lobe_pairs
            ));
        }
        let e4 = f64::from(full.eta).powi(4);
        if (r.swapped_min - (1.0 - 1.0 / e4)).abs() > 1e-2 {
            failures.push(format!(
                "{label}: the exchanged η² form differs by {} (expected {})",
                r.swapped_min,
                1.0 - 1.0 / e4
            ));
        }
        if r.adjoint.max(r.general) > RECIPROCITY_TOL {
            failures.push(format!("{label}: worst relative difference {}", r.general));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Importance-mode `R + T` and the radiance scaling at every view (module docs).
#[test]
fn body_boundary_conserves_energy_at_every_view() {
    let cases: Vec<(String, RoughDielectric, (f32, f32, bool))> = interfaces()
        .into_iter()
        .flat_map(|(l, f, _)| VIEWS.map(|v| (l.clone(), f.clone(), v)))
        .collect();
    let means = par_map(&cases, |(label, d, (t, p, below))| {
        let (wo, _) = view(*t, *p, *below);
        let s = hash_words(&[
            0xb0d1,
            u64::from(t.to_bits()),
            u64::from(*below),
            label.len() as u64,
        ]);
        energy::at_wo(d, Some(d), d.eta, wo, N_MEAN, s)
    });
    let mut failures = Vec::new();
    for ((label, d, (t, _, below)), m) in cases.iter().zip(&means) {
        let theta = if *below { 180.0 - t } else { *t };
        let total = m.r + m.t_imp;
        let etap = if *below { 1.0 / d.eta } else { d.eta };
        let ratio = m.t_rad / m.t_imp;
        println!(
            "{label:<24} θo {theta:>5.0}: R {:.5} T {:.5} R+T {total:.5} ± {:.5}; T_rad/T_imp \
             {ratio:.5} (1/η'² {:.5})",
            m.r,
            m.t_imp,
            m.se,
            1.0 / (etap * etap)
        );
        if (total - 1.0).abs() > ENERGY_TOL + 3.0 * m.se {
            failures.push(format!("{label} θo {theta}: R + T = {total} ± {}", m.se));
        }
        if m.t_imp > 0.0 && rel(ratio * f64::from(etap * etap), 1.0) > 1e-5 {
            failures.push(format!("{label} θo {theta}: T_rad/T_imp = {ratio}"));
        }
        if m.stats.bad > 0 {
            failures.push(format!(
                "{label} θo {theta}: {}",
                m.stats.first_bad.as_deref().unwrap_or("")
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
