//! The Course model: course eqs. 3.1–3.3 exactly as published.
//!
//! `f = f_top(wo, wi) + T12(wi) · f_rest(wo', wi') · a · t`, with `T12 = 1 − F(cos θi)` at the macro
//! normal, `a` from eq. 3.2 and `t = (1 − G) + T21(wo) · G` (eq. 3.3, when the `t` term is on). It
//! lacks the `1/η²` compression of solid angle, so a glossy base under a coat gains energy (≈ η²);
//! the albedo tests pin that departure. Sampling and pdf are the shared mixture in
//! [`super::corrected`] without the multiple-reflection lobe.

use super::LayeredBsdf;
use crate::bsdf::{Bxdf, refract_macro};
use crate::spectrum::RgbSample;
use glam::Vec3;

/// `f(wo, wi)` of the Course model at stack level `l` (0 = top coat; `l == coats` = the base).
pub fn eval(stack: &LayeredBsdf, l: usize, wo: Vec3, wi: Vec3) -> RgbSample {
    let Some(lv) = stack.levels.get(l) else {
        return stack.base_plain.eval(wo, wi);
    };
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return RgbSample::ZERO;
    }
    let mut f = if lv.smooth {
        RgbSample::ZERO
    } else {
        lv.top.eval(wo, wi)
    };
    let (Some(wo_in), Some(wi_in)) = (refract_macro(wo, lv.eta), refract_macro(wi, lv.eta)) else {
        return f;
    };
    let rest = eval(stack, l + 1, wo_in, wi_in);
    if rest.is_black() {
        return f;
    }
    let t12 = 1.0 - lv.fresnel.eval(wi.z)[0];
    let t = if stack.t_term() {
        let h = (wo + wi).normalize_or_zero();
        let g = if h.z > 0.0 && !lv.smooth {
            lv.top.distribution.g(wo, wi, h)
        } else {
            1.0
        };
        let t21 = 1.0 - lv.fresnel.eval(wo.z)[0];
        (1.0 - g) + t21 * g
    } else {
        1.0
    };
    f += rest * lv.absorb(wo_in.z, wi_in.z) * (t12 * t);
    f
}
