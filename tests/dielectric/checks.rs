//! Per-sample invariants of the two dielectric interfaces, shared by every test of the suite:
//! what a returned [`BsdfSample`] must say about itself (flags, lobe, `eta`, `f`, `pdf`, `weight`)
//! and how the radiance and importance samples drawn with the same random numbers relate.

use glam::{Vec2, Vec3};
use lapidary::bsdf::{
    BsdfSample, Bxdf, LobeFlags, LobeKind, RoughDielectric, SmoothDielectric, TransportMode,
};
use std::f32::consts::PI;

/// Relative tolerance of quantities that are recomputed from the same formulas (`s.f` against
/// `value`, `s.pdf` against `pdf`, `s.eta` against the side IORs).
pub const SAME_TOL: f64 = 1e-6;
/// Relative tolerance of products recomputed in another order (`weight` against `f·|cos|/pdf`,
/// the `η'²` between the modes): a few f32 roundings.
pub const WEIGHT_TOL: f64 = 1e-5;

/// IOR of the side `w` lies on, relative to the upper side, for an interface of relative IOR
/// `eta` (below / above): 1 above, `eta` below.
pub fn side_ior(w: Vec3, eta: f32) -> f32 {
    if w.z > 0.0 { 1.0 } else { eta }
}

/// `|a − b| / max(|a|, |b|)`, 0 when both are 0, in f64.
pub fn rel(a: f64, b: f64) -> f64 {
    let m = a.abs().max(b.abs());
    if m == 0.0 { 0.0 } else { (a - b).abs() / m }
}

/// A uniform direction on the whole sphere.
pub fn uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (s, c) = (2.0 * PI * u.y).sin_cos();
    Vec3::new(r * c, r * s, z)
}

/// Tallies of the per-sample checks of one configuration.
#[derive(Default, Debug)]
pub struct SampleStats {
    /// Calls that returned a sample (in both modes).
    pub returned: u64,
    /// Returned reflection samples.
    pub reflected: u64,
    /// Returned transmission samples.
    pub transmitted: u64,
    /// Samples that broke an invariant.
    pub bad: u64,
    /// The first broken invariant, for the failure message.
    pub first_bad: Option<String>,
    /// Worst relative deviation of `weight` from `f·|cos|/pdf` (both modes).
    pub worst_weight: f64,
    /// Worst relative deviation of `weight_rad · η'²` from `weight_imp` (transmission).
    pub worst_scaling: f64,
}

impl SampleStats {
    fn fail(&mut self, msg: String) {
        self.bad += 1;
        if self.first_bad.is_none() {
            self.first_bad = Some(msg);
        }
    }

    /// Adds another configuration's tallies.
    pub fn merge(&mut self, o: &SampleStats) {
        self.returned += o.returned;
        self.reflected += o.reflected;
        self.transmitted += o.transmitted;
        self.bad += o.bad;
        if self.first_bad.is_none() {
            self.first_bad.clone_from(&o.first_bad);
        }
        self.worst_weight = self.worst_weight.max(o.worst_weight);
        self.worst_scaling = self.worst_scaling.max(o.worst_scaling);
    }
}

/// Which of the two interfaces produced a sample (the flags and the lobe kinds differ).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Spread {
    Glossy,
    Specular,
}

/// The invariants of one sample taken in `mode`: unit `wi` off the surface plane; reflection
/// samples on `wo`'s side with exactly the reflection flags and `eta == 1`; transmission samples on
/// the other side with the transmission flags and `eta = η(wi side) / η(wo side)`. For the rough
/// interface also `s.f = value(wo, wi, mode)`, `s.pdf = pdf(wo, wi)` and
/// `s.weight = value · |wi.z| / pdf` recomputed in f64; for the smooth one `weight = f·|cos|/pdf`.
fn check_one(
    wo: Vec3,
    s: &BsdfSample,
    mode: TransportMode,
    eta: f32,
    spread: Spread,
    rough: Option<&RoughDielectric>,
) -> Result<f64, String> {
    let at = || format!("{mode:?} sample at wo {wo:?}: {s:?}");
    if !(s.wi.is_finite() && (s.wi.length() - 1.0).abs() < 1e-4) {
        return Err(format!("{}: wi not a unit vector", at()));
    }
    if s.wi.z * wo.z == 0.0 {
        return Err(format!("{}: wi in the surface plane", at()));
    }
    let (spread_flag, refl_kind, trans_kind) = match spread {
        Spread::Glossy => (LobeFlags::GLOSSY, LobeKind::Glossy, LobeKind::Transmission),
        Spread::Specular => (
            LobeFlags::SPECULAR,
            LobeKind::SpecularReflection,
            LobeKind::SpecularTransmission,
        ),
    };
    if s.wi.z * wo.z > 0.0 {
        if s.flags != (LobeFlags::REFLECTION | spread_flag) || s.flags.is_transmission() {
            return Err(format!("{}: reflection with flags {:?}", at(), s.flags));
        }
        if s.lobe.kind != refl_kind || s.eta != 1.0 {
            return Err(format!("{}: reflection lobe or eta wrong", at()));
        }
    } else {
        if s.flags != (LobeFlags::TRANSMISSION | spread_flag) || !s.flags.is_transmission() {
            return Err(format!("{}: transmission with flags {:?}", at(), s.flags));
        }
        let expected = side_ior(s.wi, eta) / side_ior(wo, eta);
        if s.lobe.kind != trans_kind || rel(f64::from(s.eta), f64::from(expected)) > SAME_TOL {
            return Err(format!(
                "{}: transmission lobe or eta wrong (expected eta {expected})",
                at()
            ));
        }
    }
    if !(s.pdf > 0.0 && s.pdf.is_finite() && s.f.is_valid() && s.weight.is_valid()) {
        return Err(format!("{}: invalid f, pdf or weight", at()));
    }
    let cos = f64::from(s.wi.z.abs());
    let (f, pdf) = match rough {
        Some(d) => {
            let f = d.value(wo, s.wi, mode);
            let via_trait = d.eval_mode(wo, s.wi, mode);
            let pdf = d.pdf(wo, s.wi);
            if (0..3).any(|c| via_trait[c] != f || rel(f64::from(s.f[c]), f64::from(f)) > SAME_TOL)
            {
                return Err(format!("{}: s.f != value(wo, wi) = {f}", at()));
            }
            if rel(f64::from(s.pdf), f64::from(pdf)) > SAME_TOL {
                return Err(format!("{}: s.pdf != pdf(wo, wi) = {pdf}", at()));
            }
            (f64::from(f), f64::from(pdf))
        }
        None => (f64::from(s.f[0]), f64::from(s.pdf)),
    };
    let expected = f * cos / pdf;
    let mut worst = 0.0f64;
    for c in 0..3 {
        let e = rel(f64::from(s.weight[c]), expected);
        worst = worst.max(e);
        if e > WEIGHT_TOL {
            return Err(format!("{}: weight != f·|cos|/pdf = {expected}", at()));
        }
    }
    Ok(worst)
}

/// Samples `wo` with `(uc, u)` in both modes and checks both samples ([`check_one`]) and their
/// relation: the same `wi` (bit for bit: the direction does not depend on the mode), the same `pdf`
/// and `eta`; the same weight for reflection; `weight_rad · η'² = weight_imp` for transmission,
/// with `η' = s.eta`. Returns the sample of each mode when both are valid.
pub fn check_modes(
    bsdf: &dyn Bxdf,
    rough: Option<&RoughDielectric>,
    eta: f32,
    wo: Vec3,
    uc: f32,
    u: Vec2,
    st: &mut SampleStats,
) -> Option<(BsdfSample, BsdfSample)> {
    let spread = if rough.is_some() {
        Spread::Glossy
    } else {
        Spread::Specular
    };
    let sr = bsdf.sample_mode(wo, uc, u, TransportMode::Radiance);
    let si = bsdf.sample_mode(wo, uc, u, TransportMode::Importance);
    let (sr, si) = match (sr, si) {
        (None, None) => return None,
        (Some(a), Some(b)) => (a, b),
        (a, b) => {
            st.fail(format!(
                "uc {uc} u {u:?} wo {wo:?}: one mode failed: radiance {a:?}, importance {b:?}"
            ));
            return None;
        }
    };
    st.returned += 1;
    for (s, mode) in [
        (&sr, TransportMode::Radiance),
        (&si, TransportMode::Importance),
    ] {
        match check_one(wo, s, mode, eta, spread, rough) {
            Ok(w) => st.worst_weight = st.worst_weight.max(w),
            Err(e) => {
                st.fail(format!("uc {uc} u {u:?}: {e}"));
                return None;
            }
        }
    }
    let bits = |w: Vec3| [w.x.to_bits(), w.y.to_bits(), w.z.to_bits()];
    if bits(sr.wi) != bits(si.wi) || sr.pdf != si.pdf || sr.eta != si.eta || sr.flags != si.flags {
        st.fail(format!(
            "uc {uc} u {u:?} wo {wo:?}: the modes sampled differently: {sr:?} vs {si:?}"
        ));
        return None;
    }
    let e2 = f64::from(sr.eta) * f64::from(sr.eta);
    if sr.flags.is_transmission() {
        st.transmitted += 1;
        let e = rel(f64::from(sr.weight[0]) * e2, f64::from(si.weight[0]));
        st.worst_scaling = st.worst_scaling.max(e);
        if e > WEIGHT_TOL {
            st.fail(format!(
                "uc {uc} u {u:?} wo {wo:?}: weight_rad · η'² = {} != weight_imp = {} (η' = {})",
                f64::from(sr.weight[0]) * e2,
                si.weight[0],
                sr.eta
            ));
            return None;
        }
    } else {
        st.reflected += 1;
        if rel(f64::from(sr.weight[0]), f64::from(si.weight[0])) > SAME_TOL {
            st.fail(format!(
                "uc {uc} u {u:?} wo {wo:?}: reflection weights differ between the modes: \
                 {sr:?} vs {si:?}"
            ));
            return None;
        }
    }
    Some((sr, si))
}

/// [`check_modes`] for the rough interface.
pub fn check_rough(
    d: &RoughDielectric,
    wo: Vec3,
    uc: f32,
    u: Vec2,
    st: &mut SampleStats,
) -> Option<(BsdfSample, BsdfSample)> {
    check_modes(d, Some(d), d.eta, wo, uc, u, st)
}

/// [`check_modes`] for the smooth interface.
pub fn check_smooth(
    g: &SmoothDielectric,
    wo: Vec3,
    uc: f32,
    u: Vec2,
    st: &mut SampleStats,
) -> Option<(BsdfSample, BsdfSample)> {
    check_modes(g, None, g.eta, wo, uc, u, st)
}
