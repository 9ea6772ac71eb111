//! Reciprocity and adjoint relations of `RoughDielectric::value` over random direction pairs.
//!
//! With `η(w)` the IOR of `w`'s side (1 above, `eta` below) and `η' = η(wi)/η(wo)`:
//! - adjoint: `f_rad(wo, wi) = f_imp(wi, wo)` for every pair;
//! - reflection is mode-independent and reciprocal: `f_rad(wo, wi) = f_imp(wo, wi) = f_rad(wi, wo)`;
//! - transmission: `f_rad(wo, wi) = f_imp(wo, wi) / η'²`, and the generalised reciprocity
//!   `f_rad(wo, wi) / η(wo)² = f_rad(wi, wo) / η(wi)²` (Veach 1997, eq. 5.14 in this crate's
//!   convention; the unit test `adjoint_symmetry` in src/bsdf/dielectric.rs checks the same form:
//!   `f_rad(out → in) · 1.5² = f_rad(in → out)`). The form with the squares exchanged is off by
//!   `η⁴` and must be rejected on every transmission pair with `f > 0`;
//! - and `value` itself agrees, in both argument orders, with [`walter_f64`], an independent f64
//!   transcription of Walter et al. 2007 (eqs. 16, 20, 21) with the V-cavity `G`.

use super::checks::{rel, side_ior, uniform_sphere};
use glam::{DVec3, Vec3};
use lapidary::bsdf::{Bxdf, Distribution, RoughDielectric, TransportMode};
use lapidary::sampler::Rng;
use std::f64::consts::PI;

/// Exact unpolarised Fresnel reflectance in f64 (`cos_i` signed as in `lapidary::bsdf::fresnel`).
fn fresnel_f64(cos_i: f64, eta: f64) -> f64 {
    let (c, eta) = if cos_i < 0.0 {
        (-cos_i, 1.0 / eta)
    } else {
        (cos_i, eta)
    };
    let s2 = (1.0 - c * c) / (eta * eta);
    if s2 >= 1.0 {
        return 1.0;
    }
    let ct = (1.0 - s2).sqrt();
    let a = (eta * c - ct) / (eta * c + ct);
    let b = (c - eta * ct) / (c + eta * ct);
    0.5 * (a * a + b * b)
}

/// The generalised half vector `h ∝ η(wi) wi + η(wo) wo` facing `+z` in f64 (`None` unless both
/// directions are on its front), with `(η(wo), η(wi))`.
fn half_f64(eta: f32, wo: Vec3, wi: Vec3) -> (Option<DVec3>, (f64, f64)) {
    let eta = f64::from(eta);
    // Normalised in f64: near the critical angle `1 − F` seen from the dense side is sensitive
    // to the 1e-7 norm error of an f32 unit vector.
    let (wo, wi) = (wo.as_dvec3().normalize(), wi.as_dvec3().normalize());
    let side = |w: DVec3| if w.z > 0.0 { 1.0 } else { eta };
    let (no, ni) = (side(wo), side(wi));
    let mut h = (wi * ni + wo * no).normalize();
    if h.z < 0.0 {
        h = -h;
    }
    let ok = h.is_finite() && h.dot(wi) * wi.z > 0.0 && h.dot(wo) * wo.z > 0.0;
    (ok.then_some(h), (no, ni))
}

/// `f(wo, wi)` of a rough dielectric in f64, written from the paper: the generalised half vector
/// `h ∝ η(wi) wi + η(wo) wo` facing `+z`, both directions on the front of `h`; reflection
/// `F D G / (4 |cos θo cos θi|)`; transmission
/// `(1 − F) D G |wi·h| |wo·h| η(wo)² / (|cos θo cos θi| (η(wi) wi·h + η(wo) wo·h)²)` in radiance
/// mode, with `η(wi)²` in the numerator in importance mode. `D` normalised Blinn or Beckmann with
/// `α = tan m`; `G = min(1, 2 cos θh |cos θ|/|w·h|)` over both directions.
pub fn walter_f64(
    kind: Distribution,
    m_deg: f64,
    eta: f32,
    wo: Vec3,
    wi: Vec3,
    mode: TransportMode,
) -> f64 {
    let (Some(h), (no, ni)) = half_f64(eta, wo, wi) else {
        return 0.0;
    };
    let eta = f64::from(eta);
    // Normalised in f64: near the critical angle `1 − F` seen from the dense side is sensitive
    // to the 1e-7 norm error of an f32 unit vector.
    let (wo, wi) = (wo.as_dvec3().normalize(), wi.as_dvec3().normalize());
    let a = m_deg.to_radians().tan();
    let c = h.z;
    let d = match kind {
        Distribution::Blinn => {
            let e = 2.0 / (a * a) - 2.0;
            (e + 2.0) / (2.0 * PI) * c.powf(e)
        }
        Distribution::Beckmann => {
            let t2 = (1.0 - c * c) / (c * c);
            (-t2 / (a * a)).exp() / (PI * a * a * c.powi(4))
        }
        // Walter et al. 2007 eq. 33.
        Distribution::Ggx => {
            let t2 = (1.0 - c * c) / (c * c);
            a * a / (PI * c.powi(4) * (a * a + t2).powi(2))
        }
    };
    let g1 = |w: DVec3| (2.0 * h.z * w.z.abs() / w.dot(h).abs()).min(1.0);
    let g = g1(wo).min(g1(wi));
    let f = fresnel_f64(wo.dot(h), eta);
    let cos2 = (wo.z * wi.z).abs();
    if wo.z * wi.z > 0.0 {
        return f * d * g / (4.0 * cos2);
    }
    let num = match mode {
        TransportMode::Radiance => no * no,
        TransportMode::Importance => ni * ni,
    };
    let den = (ni * wi.dot(h) + no * wo.dot(h)).powi(2);
    (1.0 - f) * d * g * (wi.dot(h) * wo.dot(h)).abs() * num / (cos2 * den)
}

/// Values below this fraction of the configuration's largest `f` are not compared relatively
/// (tests/reciprocity.rs: f32 rounding of the half vector is amplified by the steep exponent of
/// `D` deep in a narrow lobe's tail).
pub const TAIL: f64 = 1e-7;
/// Directions closer to the surface plane than this `|cos θ|` are not drawn (the grazing limit
/// is covered by tests/hard_cases.rs; here `1/|cos|` would only amplify rounding).
pub const MIN_COS: f32 = 1e-2;

/// Worst relative differences per relation, and how many pairs each was measured on.
#[derive(Default, Debug, Clone)]
pub struct Measured {
    /// `f_rad(wo, wi)` vs `f_imp(wi, wo)`, reflection pairs.
    pub adjoint_refl: (f64, u64),
    /// The same, transmission pairs.
    pub adjoint_trans: (f64, u64),
    /// `f(wo, wi)` vs `f(wi, wo)`, reflection, wo above.
    pub refl_above: (f64, u64),
    /// The same, both below.
    pub refl_below: (f64, u64),
    /// `f_rad(wo, wi)/η(wo)²` vs `f_rad(wi, wo)/η(wi)²`, wo above.
    pub trans_above: (f64, u64),
    /// The same, wo below.
    pub trans_below: (f64, u64),
    /// `f_rad · η'²` vs `f_imp`, transmission.
    pub mode_ratio: (f64, u64),
    /// `value` in both orders and modes against [`walter_f64`].
    pub reference: (f64, u64),
    /// Pairs left out of the reference comparison (a direction within 1e-3 of grazing `h`).
    pub reference_skipped: u64,
    /// Smallest relative difference of the exchanged form on a transmission pair (must be large).
    pub swapped_min: f64,
    /// Failures (pair and relation).
    pub failures: Vec<String>,
}

fn note(slot: &mut (f64, u64), e: f64) {
    slot.0 = slot.0.max(e);
    slot.1 += 1;
}

/// Draws `n` pairs for `d`: `wo` uniform on the sphere; `wi` uniform on the sphere for even `k`,
/// sampled from `d` at `wo` for odd `k` (so that narrow lobes are hit), each reversed too. Checks
/// every relation of the module docs with relative tolerance `tol` above [`TAIL`] of the peak.
pub fn measure(
    d: &RoughDielectric,
    kind: Distribution,
    m_deg: f32,
    n: u64,
    seed: u64,
    tol: f64,
) -> Measured {
    let mut rng = Rng::new(seed);
    let mut pairs = Vec::with_capacity(n as usize);
    while (pairs.len() as u64) < n {
        let wo = uniform_sphere(rng.uniform2());
        let wi = if pairs.len() % 2 == 0 {
            uniform_sphere(rng.uniform2())
        } else {
            match d.sample(wo, rng.uniform(), rng.uniform2()) {
                Some(s) => s.wi,
                None => continue,
            }
        };
        if wo.z.abs() >= MIN_COS && wi.z.abs() >= MIN_COS {
            pairs.push((wo, wi));
        }
    }
    let (rad, imp) = (TransportMode::Radiance, TransportMode::Importance);
    let vals: Vec<[f64; 4]> = pairs
        .iter()
        .map(|&(wo, wi)| {
            [
                f64::from(d.value(wo, wi, rad)),
                f64::from(d.value(wo, wi, imp)),
                f64::from(d.value(wi, wo, rad)),
                f64::from(d.value(wi, wo, imp)),
            ]
        })
        .collect();
    let peak = vals.iter().flatten().fold(0.0f64, |a, &b| a.max(b));
    let floor = TAIL * peak;
    let mut m = Measured {
        swapped_min: f64::INFINITY,
        ..Measured::default()
    };
    let check =
        |slot: &mut (f64, u64), fails: &mut Vec<String>, what: &str, a: f64, b: f64, at: &str| {
            let big = a.abs().max(b.abs());
            if big <= floor {
                return;
            }
            let e = rel(a, b);
            note(slot, e);
            if (a - b).abs() > tol * big + floor {
                fails.push(format!("{what}: {a:e} vs {b:e} (rel {e:.2e}) at {at}"));
            }
        };
    for (&(wo, wi), v) in pairs.iter().zip(&vals) {
        let [fr, fi, br, bi] = *v;
        if !v.iter().all(|x| x.is_finite() && *x >= 0.0) {
            m.failures
                .push(format!("non-finite or negative f at {wo} {wi}: {v:?}"));
            continue;
        }
        let at = format!("wo {wo}, wi {wi}");
        let reflect = wo.z * wi.z > 0.0;
        let fails = &mut m.failures;
        // Against the f64 reference only where `h` is not within 1e-3 of grazing either
        // direction: there `(1 − F)·|w·h|` vanishes like `(w·h)²` and the f32 rounding of `h`
        // (1e-7) is amplified without bound — a set of measure zero that carries no energy.
        let (hd, _) = half_f64(d.eta, wo, wi);
        let grazing = |h: DVec3| h.dot(wo.as_dvec3()).abs().min(h.dot(wi.as_dvec3()).abs()) <= 1e-3;
        if hd.is_some_and(grazing) {
            m.reference_skipped += 1;
        } else {
            let exact =
                |a: Vec3, b: Vec3, mode| walter_f64(kind, f64::from(m_deg), d.eta, a, b, mode);
            for (got, a, b, mode) in [
                (fr, wo, wi, rad),
                (fi, wo, wi, imp),
                (br, wi, wo, rad),
                (bi, wi, wo, imp),
            ] {
                check(
                    &mut m.reference,
                    fails,
                    "value vs f64 reference",
                    got,
                    exact(a, b, mode),
                    &at,
                );
            }
        }
        if reflect {
            check(&mut m.adjoint_refl, fails, "adjoint (refl.)", fr, bi, &at);
            if fr != fi {
                fails.push(format!(
                    "reflection depends on the mode: {fr} vs {fi} at {at}"
                ));
            }
            let slot = if wo.z > 0.0 {
                &mut m.refl_above
            } else {
                &mut m.refl_below
            };
            check(slot, fails, "reciprocity (refl.)", fr, br, &at);
        } else {
            check(&mut m.adjoint_trans, fails, "adjoint (trans.)", fr, bi, &at);
            let (eo, ei) = (
                f64::from(side_ior(wo, d.eta)),
                f64::from(side_ior(wi, d.eta)),
            );
            let slot = if wo.z > 0.0 {
                &mut m.trans_above
            } else {
                &mut m.trans_below
            };
            check(
                slot,
                fails,
                "f_rad(wo,wi)/η(wo)² = f_rad(wi,wo)/η(wi)²",
                fr / (eo * eo),
                br / (ei * ei),
                &at,
            );
            let etap2 = (ei / eo) * (ei / eo);
            check(
                &mut m.mode_ratio,
                fails,
                "f_rad·η'² = f_imp",
                fr * etap2,
                fi,
                &at,
            );
            if fr.max(br) > floor && fr > 0.0 && br > 0.0 {
                m.swapped_min = m.swapped_min.min(rel(fr / (ei * ei), br / (eo * eo)));
            }
        }
    }
    m
}
