//! Measurements of tests/interface_energy.rs: reciprocity over random pairs, single-scattering
//! tables at a chosen resolution, hemispherical transmittance by quadrature of an interface's own
//! tables, and per-lobe sums of sampled weights.

use super::checks::{rel, side_ior, uniform_sphere};
use glam::{DVec3, Vec3};
use lapidary::bsdf::dielectric::Lobes;
use lapidary::bsdf::interface_energy::InterfaceEnergy;
use lapidary::bsdf::table::Table;
use lapidary::bsdf::{Bxdf, RoughDielectric, TransportMode};
use lapidary::sampler::{Rng, hash_words};
use lapidary::spectrum::RgbSample;

/// Relative tolerance of the reciprocity relations (as tests/dielectric.rs).
pub const RECIPROCITY_TOL: f64 = 1e-3;
/// Transmission pairs whose generalised half vector is closer than this `|cos θh|` to the
/// surface plane are left out of the relations (and counted): there `MicrofacetDistribution::d`
/// flushes to 0 when `sin²θh` rounds to 1 in f32, in one argument order and not the other (the
/// known bug of `value_is_adjoint_at_a_half_vector_near_the_horizon`).
pub const HORIZON_H: f64 = 1e-3;

/// The value of `plain` plus `lobe` (the compensated interface when `lobe` is its own lobe).
pub fn value_with(
    plain: &RoughDielectric,
    lobe: &InterfaceEnergy,
    wo: Vec3,
    wi: Vec3,
    m: TransportMode,
) -> f64 {
    f64::from(plain.value(wo, wi, m)) + f64::from(lobe.value(wo, wi, m))
}

/// Worst relative errors and counts of [`pairs`].
#[derive(Debug)]
pub struct Pairs {
    /// `f_rad(wo, wi)` vs `f_imp(wi, wo)`.
    pub adjoint: f64,
    /// `f_rad(wo, wi)/η(wo)²` vs `f_rad(wi, wo)/η(wi)²`.
    pub general: f64,
    /// `full.value` vs `plain.value + lobe.value` (both modes; only for the interface's own lobe).
    pub lobe: f64,
    /// Smallest relative difference of the exchanged form on a transmission pair.
    pub swapped_min: f64,
    /// Transmission pairs checked.
    pub transmissions: u64,
    /// Pairs where the lobe is ≥ 1 % of `f`.
    pub lobe_pairs: u64,
    /// Transmission pairs left out ([`HORIZON_H`]).
    pub horizon: u64,
    /// The first failures.
    pub failures: Vec<String>,
}

/// `|cos θh|` of the generalised half vector `η(wi) wi + η(wo) wo` in f64 (1 for reflection).
fn half_cos(eta: f32, wo: Vec3, wi: Vec3) -> f64 {
    if wo.z * wi.z > 0.0 {
        return 1.0;
    }
    let side = |w: Vec3| f64::from(side_ior(w, eta));
    let h: DVec3 = wi.as_dvec3() * side(wi) + wo.as_dvec3() * side(wo);
    (h.z / h.length()).abs()
}

/// Draws `n` pairs (`wo` uniform on the sphere; `wi` uniform for even, sampled from `full` for odd
/// indices; `|cos| ≥ 0.01`) and checks the relations of `plain + lobe` to [`RECIPROCITY_TOL`]
/// above 1e-7 of the peak.
pub fn pairs(
    full: &RoughDielectric,
    plain: &RoughDielectric,
    lobe: &InterfaceEnergy,
    n: u64,
    seed: u64,
) -> Pairs {
    let (rad, imp) = (TransportMode::Radiance, TransportMode::Importance);
    let mut rng = Rng::new(seed);
    let mut list = Vec::new();
    while (list.len() as u64) < n {
        let wo = uniform_sphere(rng.uniform2());
        let wi = if list.len() % 2 == 0 {
            uniform_sphere(rng.uniform2())
        } else {
            match full.sample(wo, rng.uniform(), rng.uniform2()) {
                Some(s) => s.wi,
                None => continue,
            }
        };
        if wo.z.abs() >= 0.01 && wi.z.abs() >= 0.01 {
            list.push((wo, wi));
        }
    }
    let f = |a: Vec3, b: Vec3, m| value_with(plain, lobe, a, b, m);
    let peak = list
        .iter()
        .map(|&(wo, wi)| f(wo, wi, rad).max(f(wi, wo, rad)))
        .fold(0.0f64, f64::max);
    let floor = 1e-7 * peak;
    let mut p = Pairs {
        adjoint: 0.0,
        general: 0.0,
        lobe: 0.0,
        swapped_min: f64::INFINITY,
        transmissions: 0,
        lobe_pairs: 0,
        horizon: 0,
        failures: Vec::new(),
    };
    let own_lobe = full
        .energy
        .as_deref()
        .is_some_and(|e| std::ptr::eq(e, lobe));
    for &(wo, wi) in &list {
        if half_cos(full.eta, wo, wi) < HORIZON_H {
            p.horizon += 1;
            continue;
        }
        let (fr, bi, br) = (f(wo, wi, rad), f(wi, wo, imp), f(wi, wo, rad));
        let (eo, ei) = (
            f64::from(side_ior(wo, full.eta)),
            f64::from(side_ior(wi, full.eta)),
        );
        for (slot, what, a, b) in [
            (&mut p.adjoint, "f_rad(wo,wi) = f_imp(wi,wo)", fr, bi),
            (
                &mut p.general,
                "f_rad(wo,wi)/η(wo)² = f_rad(wi,wo)/η(wi)²",
                fr / (eo * eo),
                br / (ei * ei),
            ),
        ] {
            if a.abs().max(b.abs()) <= floor {
                continue;
            }
            *slot = slot.max(rel(a, b));
            if (a - b).abs() > RECIPROCITY_TOL * a.abs().max(b.abs()) + floor
                && p.failures.len() < 5
            {
                p.failures
                    .push(format!("{what}: {a:e} vs {b:e} at wo {wo}, wi {wi}"));
            }
        }
        if fr > floor && f64::from(lobe.value(wo, wi, rad)) >= 0.01 * fr {
            p.lobe_pairs += 1;
        }
        if wo.z * wi.z < 0.0 && fr > floor && br > floor {
            p.transmissions += 1;
            p.swapped_min = p.swapped_min.min(rel(fr / (ei * ei), br / (eo * eo)));
        }
        // The implemented value is single scattering plus this lobe.
        if own_lobe {
            for m in [rad, imp] {
                let (got, want) = (f64::from(full.value(wo, wi, m)), f(wo, wi, m));
                p.lobe = p.lobe.max(rel(got, want));
                if (got - want).abs() > 1e-5 * want.abs() + floor && p.failures.len() < 5 {
                    p.failures.push(format!(
                        "value {got:e} != single + lobe {want:e} at wo {wo}, wi {wi}"
                    ));
                }
            }
        }
    }
    p
}

/// The single-scattering `(R, T)` table (channels 0, 1) of `plain` from above (`sign` 1) or below,
/// as `RoughDielectric::with_energy_tables` measures it, on a `grid² · 4` stratified grid per entry.
pub fn single_table(plain: &RoughDielectric, sign: f32, grid: usize) -> Table {
    Table::by_sampling(
        grid,
        hash_words(&[0x7ab1e, u64::from(sign.to_bits()), grid as u64]),
        |wo, uc, u| {
            let wo = Vec3::new(wo.x, wo.y, sign * wo.z);
            let w = |lobes| {
                plain
                    .sample_lobes(wo, uc, u, TransportMode::Importance, lobes)
                    .map_or(0.0, |s| s.weight[0])
            };
            RgbSample([w(Lobes::Reflection), w(Lobes::Transmission), 0.0])
        },
    )
}

/// `plain` with a lobe built from single-scattering tables measured on a `grid² · 4` grid.
pub fn with_tables(plain: &RoughDielectric, grid: usize) -> RoughDielectric {
    let mut d = plain.clone();
    d.energy = InterfaceEnergy::new(
        single_table(plain, 1.0, grid),
        single_table(plain, -1.0, grid),
        plain.eta,
    )
    .map(std::sync::Arc::new);
    d
}

/// Which transmittance [`hemispherical_by_tables`] integrates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rule {
    /// Single scattering alone, `T_s(μ)`.
    Single,
    /// The lobe's transmission alone.
    Lobe,
    /// The old compensation: `T_s(μ) / E_s(μ)`.
    Old,
}

/// `(t̄(above), t̄(below))`, `t̄ = 2 ∫₀¹ T(μ) μ dμ`, by the midpoint rule over an interface's own
/// single-scattering tables and lobe (deterministic).
pub fn hemispherical_by_tables(e: &InterfaceEnergy, rule: Rule) -> (f64, f64) {
    let k = 20_000;
    let t = |below: bool| {
        (0..k)
            .map(|i| {
                let mu = (i as f32 + 0.5) / k as f32;
                let w = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, if below { -mu } else { mu });
                let (r, t) = e.single(w);
                let tt = match rule {
                    Rule::Single => t,
                    Rule::Lobe => e.split(w).1,
                    Rule::Old => t / (r + t),
                };
                2.0 * f64::from(mu) * f64::from(tt)
            })
            .sum::<f64>()
            / k as f64
    };
    (t(false), t(true))
}

/// Sums of the weights of `n` calls of `sample_lobes(wo, .., lobes, mode)`, split by the side of
/// `wi`: `[(reflection sum, sum of squares), (transmission ..)]`.
pub fn lobe_sums(
    d: &RoughDielectric,
    wo: Vec3,
    lobes: Lobes,
    mode: TransportMode,
    n: u64,
    seed: u64,
) -> [(f64, f64); 2] {
    let mut rng = Rng::new(seed);
    let mut s = [(0.0, 0.0); 2];
    for _ in 0..n {
        if let Some(x) = d.sample_lobes(wo, rng.uniform(), rng.uniform2(), mode, lobes) {
            let w = f64::from(x.weight[0]);
            let k = usize::from(x.wi.z * wo.z < 0.0);
            s[k].0 += w;
            s[k].1 += w * w;
        }
    }
    s
}
