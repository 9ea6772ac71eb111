//! The weight `sample()` returns equals `f·cos/pdf` from `eval()` and `pdf()` for the same
//! direction, and `s.f`, `s.pdf` equal `eval()`, `pdf()` there.

use glam::Vec3;
use lapidary::bsdf::Bxdf;
use lapidary::sampler::Rng;

/// Samples per configuration of the weight check.
pub const N_WEIGHT: u64 = 20_000;
/// Relative tolerance of the weight check, and its absolute floor.
pub const REL_TOL: f32 = 1e-3;
pub const ABS_FLOOR: f32 = 1e-6;

/// Worst relative deviations found in one configuration.
#[derive(Default)]
pub struct WeightStats {
    pub returned: u64,
    pub bad: u64,
    pub worst_weight: f32,
    pub worst_pdf: f32,
    pub worst_f: f32,
    pub first_bad: Option<String>,
}

fn rel_err(a: f32, b: f32) -> f32 {
    let d = (a - b).abs();
    if d <= ABS_FLOOR {
        0.0
    } else {
        d / a.abs().max(b.abs())
    }
}

/// Checks every returned sample of `bsdf` at `wo`: finite non-negative `f` and weight, `pdf > 0`,
/// `s.pdf` = `pdf(wo, s.wi)`, `s.f` = `eval(wo, s.wi)` and `s.weight` =
/// `eval(wo, s.wi)·|s.wi.z| / pdf(wo, s.wi)` per channel, relative 1e-3 above an absolute 1e-6.
pub fn weight_check(bsdf: &dyn Bxdf, wo: Vec3, n: u64, seed: u64) -> WeightStats {
    let mut st = WeightStats::default();
    let mut rng = Rng::new(seed);
    for _ in 0..n {
        let (uc, u) = (rng.uniform(), rng.uniform2());
        let Some(s) = bsdf.sample(wo, uc, u) else {
            continue;
        };
        st.returned += 1;
        let pdf = bsdf.pdf(wo, s.wi);
        let f = bsdf.eval(wo, s.wi);
        let mut ok = s.wi.is_finite()
            && s.f.is_valid()
            && s.weight.is_valid()
            && s.pdf > 0.0
            && s.pdf.is_finite()
            && pdf > 0.0;
        let ep = rel_err(s.pdf, pdf);
        st.worst_pdf = st.worst_pdf.max(ep);
        ok &= ep <= REL_TOL;
        for c in 0..3 {
            let expected = f[c] * s.wi.z.abs() / pdf;
            let ew = rel_err(s.weight[c], expected);
            let ef = rel_err(s.f[c], f[c]);
            st.worst_weight = st.worst_weight.max(ew);
            st.worst_f = st.worst_f.max(ef);
            ok &= ew <= REL_TOL && ef <= REL_TOL;
        }
        if !ok {
            st.bad += 1;
            if st.first_bad.is_none() {
                st.first_bad = Some(format!(
                    "uc={uc:e} u={u:?}: wi={:?} s.f={:?} s.pdf={:e} s.weight={:?} | eval={:?} \
                     pdf={pdf:e} f·cos/pdf={:?}",
                    s.wi,
                    s.f.0,
                    s.pdf,
                    s.weight.0,
                    f.0,
                    (f * (s.wi.z.abs() / pdf)).0
                ));
            }
        }
    }
    st
}
