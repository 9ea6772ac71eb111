//! The Corrected model's value and density for one pair of directions at once: next-event
//! estimation needs both `f(wo, wi)` and the density with which sampling would have produced `wi`
//! (for the MIS weight), and the two share the top lobe's half vector and `D`, the refraction of
//! `wi` into the coat and, level by level, the same recursion down the stack.
//!
//! [`eval_pdf`] returns bit for bit what [`super::corrected::eval`] and
//! [`super::corrected::pdf`] return separately (tested): the same operations in the same order on
//! the same numbers, only the shared ones done once.

use super::lobes::{LobeWeights, WeightsMemo, cone_cosine_pdf, escape_cone, lobe_weights};
use super::{LayeredBsdf, Level};
use crate::bsdf::{Bxdf, TransportMode, refract_macro};
use crate::spectrum::RgbSample;
use glam::Vec3;
use std::f32::consts::FRAC_1_PI;

/// [`eval_pdf`] at the top level, with the lobe weights from `memo`.
#[inline]
pub fn eval_pdf_memo(
    stack: &LayeredBsdf,
    wo: Vec3,
    wi: Vec3,
    memo: &WeightsMemo,
) -> (RgbSample, f32) {
    if stack.levels.is_empty() || wo.z <= 0.0 || wi.z <= 0.0 {
        return eval_pdf(stack, 0, wo, wi);
    }
    eval_pdf_weighted(stack, 0, wo, wi, memo.get(stack, wo))
}

/// `(corrected::eval(stack, l, wo, wi), corrected::pdf(stack, l, wo, wi, true))`.
///
/// # Arguments
/// * `stack` – the layer stack.
/// * `l` – the level (`stack.levels.len()` is the base).
/// * `wo`, `wi` – unit directions in the level's local frame, `z` along the macro normal.
pub fn eval_pdf(stack: &LayeredBsdf, l: usize, wo: Vec3, wi: Vec3) -> (RgbSample, f32) {
    if l >= stack.levels.len() {
        // At the base `eval` is the base's value plus an empty body, `pdf` the base's density.
        let (f, p) = stack.base.eval_pdf_mode(wo, wi, TransportMode::Radiance);
        return (f + RgbSample::ZERO, p);
    }
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return (RgbSample::ZERO, 0.0);
    }
    eval_pdf_weighted(stack, l, wo, wi, lobe_weights(stack, l, wo, true))
}

/// [`eval_pdf`] at a level that exists, for `wo.z > 0`, given the level's [`lobe_weights`] for
/// `wo` (a sample evaluates the direction it drew with the weights it chose its lobe with).
pub(super) fn eval_pdf_weighted(
    stack: &LayeredBsdf,
    l: usize,
    wo: Vec3,
    wi: Vec3,
    (w, wo_in): LobeWeights,
) -> (RgbSample, f32) {
    let lv = &stack.levels[l];
    if wi.z <= 0.0 {
        return (RgbSample::ZERO, 0.0);
    }
    // The top lobe (a smooth coat's reflection is a delta: no value, no density).
    let (top, top_pdf) = if lv.smooth {
        (RgbSample::ZERO, 0.0)
    } else {
        let ms = lv.top_energy.as_ref().map_or(0.0, |e| {
            e.value(wo, wi, crate::bsdf::TransportMode::Radiance)
        });
        let (f, p) = lv.top.eval_pdf(wo, wi);
        (f + RgbSample::splat(ms), p)
    };
    let mut p = 0.0;
    if w[0] > 0.0 && !lv.smooth {
        p += w[0] * top_pdf;
    }
    let mut body = RgbSample::ZERO;
    if let Some(wo_in) = wo_in
        && let Some(wi_in) = refract_macro(wi, lv.eta)
    {
        let (to, ti) = (lv.t(wo.z), lv.t(wi.z));
        let (rest, rest_pdf) = match escape_cone(stack, l) {
            // (At the base, `eval_pdf`'s value is `corrected::eval`'s: the base's own.)
            Some(r2) => (
                eval_pdf(stack, l + 1, wo_in, wi_in).0,
                cone_cosine_pdf(wi_in, r2),
            ),
            None => eval_pdf(stack, l + 1, wo_in, wi_in),
        };
        body = lv.body(stack.t_term(), rest, (wo, wi), (wo_in, wi_in), (to, ti));
        if w[1] > 0.0 {
            let jacobian = wi.z / (lv.eta * lv.eta * wi_in.z);
            p += w[1] * rest_pdf * jacobian;
        }
    }
    p += w[2] * wi.z * FRAC_1_PI;
    let p = if p.is_finite() { p } else { 0.0 };
    let f = match (&stack.calibration, l) {
        (Some(c), 0) if !body.is_black() => top + body * c.at(wo.z) * c.at(wi.z),
        _ => top + body,
    };
    (f, p)
}

/// The body of a coat level's Corrected `f`, shared by [`super::corrected::eval`] and
/// [`eval_pdf`].
impl Level {
    /// The body of the Corrected `f` at this level ([`super::corrected`]'s module docs): the layers
    /// below, whose value at the refracted pair is `rest`, seen through the coat, plus the
    /// symmetric multiple-reflection lobe `M · q(wo) q(wi) / ∫q cos` (`q(wi) = 0` where `wi`
    /// cannot be reached from inside).
    ///
    /// # Arguments
    /// * `t_term` – the stack's internal-reflection term ([`LayeredBsdf::t_term`]).
    /// * `(wo, wi)` – the pair outside, `(wo_in, wi_in)` refracted into the coat.
    /// * `(to, ti)` – the coat's transmission [`Level::t`] at `wo` and `wi`.
    #[inline]
    pub(crate) fn body(
        &self,
        t_term: bool,
        rest: RgbSample,
        (wo, wi): (Vec3, Vec3),
        (wo_in, wi_in): (Vec3, Vec3),
        (to, ti): (f32, f32),
    ) -> RgbSample {
        let mut body = RgbSample::ZERO;
        if !rest.is_black() {
            let exit = if t_term {
                let h = (wo + wi).normalize_or_zero();
                let g = if h.z > 0.0 && !self.smooth {
                    self.top.distribution.g(wo, wi, h)
                } else {
                    1.0
                };
                (1.0 - g) + to * g
            } else {
                to
            };
            body = rest * self.absorb(wo_in.z, wi_in.z) * (ti * exit / (self.eta * self.eta));
        }
        let qi = self.trapped.at(wi_in.z) * ti;
        body + self.trapped.at(wo_in.z) * qi * self.multi_scale * to
    }
}

#[cfg(test)]
mod tests {
    use super::super::corrected;
    use super::*;
    use crate::bsdf::layered::{Base, Coat, ConductorIor, StackDesc};
    use crate::bsdf::{Distribution, Masking, spherical_direction};
    use crate::color::Rgb;
    use crate::sampler::Rng;

    fn coat(ior: f32, roughness: f32, absorption: f32) -> Coat {
        Coat {
            ior,
            roughness,
            absorption: Rgb::new(absorption, 0.5 * absorption, 0.1),
            thickness: 1.0,
        }
    }

    /// Stacks that take every branch: a diffuse base under one coat (the escape cone), two coats
    /// over Oren–Nayar (the recursion), a smooth coat over a conductor (no top lobe, a glossy
    /// base), the internal-reflection term with GGX and Smith masking.
    fn stacks() -> Vec<(&'static str, LayeredBsdf)> {
        let metal = Base::Conductor {
            ior: ConductorIor::Complex {
                n: Rgb::new(0.2, 0.9, 1.1),
                k: Rgb::new(3.0, 2.5, 2.2),
            },
            roughness: 12.0,
        };
        let lambert = Base::Lambert {
            albedo: Rgb::new(0.5, 0.2, 0.9),
        };
        let oren = Base::OrenNayar {
            albedo: Rgb::new(0.7, 0.6, 0.1),
            sigma: 0.3,
        };
        let mut t_term = StackDesc::new(vec![coat(1.7, 20.0, 0.0)], metal);
        t_term.t_term = Some(true);
        t_term.distribution = Distribution::Ggx;
        t_term.masking = Masking::Smith;
        [
            (
                "coat over Lambert",
                StackDesc::new(vec![coat(1.5, 8.0, 1.0)], lambert),
            ),
            (
                "two coats over Oren-Nayar",
                StackDesc::new(vec![coat(1.4, 5.0, 0.5), coat(1.9, 25.0, 2.0)], oren),
            ),
            (
                "smooth coat over metal",
                StackDesc::new(vec![coat(1.5, 0.0, 0.3)], metal),
            ),
            ("t term, GGX, Smith", t_term),
        ]
        .into_iter()
        .map(|(name, d)| (name, LayeredBsdf::new(&d).unwrap()))
        .collect()
    }

    /// Every stack above, at directions over both hemispheres, grazing ones and mirror pairs, at
    /// every level: the joint result is the separate calls' bit for bit.
    #[test]
    fn eval_pdf_is_eval_and_pdf_bit_for_bit() {
        let mut rng = Rng::new(23);
        let mut with_density = 0;
        for (name, stack) in stacks() {
            for k in 0..4000 {
                let mut dir = || {
                    let u = rng.uniform2();
                    // A third of the directions within 10⁻⁴ of grazing.
                    let cos = if k % 3 == 0 {
                        1e-4 * u.x
                    } else {
                        2.0 * u.x - 1.0
                    };
                    spherical_direction(cos.acos(), std::f32::consts::TAU * u.y)
                };
                let wo = dir();
                let wi = if k % 7 == 0 {
                    Vec3::new(-wo.x, -wo.y, wo.z)
                } else {
                    dir()
                };
                for l in 0..=stack.levels.len() {
                    let (f, p) = eval_pdf(&stack, l, wo, wi);
                    let (f0, p0) = (
                        corrected::eval(&stack, l, wo, wi),
                        corrected::pdf(&stack, l, wo, wi, true),
                    );
                    assert_eq!(
                        (f.0.map(f32::to_bits), p.to_bits()),
                        (f0.0.map(f32::to_bits), p0.to_bits()),
                        "{name}, level {l}: wo {wo:?} wi {wi:?}"
                    );
                    with_density += usize::from(p > 0.0);
                }
            }
        }
        assert!(
            with_density > 10_000,
            "only {with_density} pairs with a density"
        );
    }

    /// A sample's value and density (found together from its lobe weights) are the separate
    /// evaluation's and density's of the direction it drew, bit for bit, on every stack and for
    /// every lobe but the smooth coat's delta.
    #[test]
    fn a_sample_records_eval_and_pdf_bit_for_bit() {
        let mut rng = Rng::new(31);
        let mut checked = 0;
        for (name, stack) in stacks() {
            for _ in 0..20_000 {
                let u = rng.uniform2();
                let wo = spherical_direction(
                    u.x * std::f32::consts::FRAC_PI_2,
                    std::f32::consts::TAU * u.y,
                );
                let Some(s) = corrected::sample(&stack, 0, wo, rng.uniform(), rng.uniform2(), true)
                else {
                    continue;
                };
                if s.lobe.kind == crate::bsdf::LobeKind::SpecularReflection {
                    continue;
                }
                let f = crate::bsdf::flush_tiny(corrected::eval(&stack, 0, wo, s.wi));
                let p = corrected::pdf(&stack, 0, wo, s.wi, true);
                assert_eq!(
                    (s.f.0.map(f32::to_bits), s.pdf.to_bits()),
                    (f.0.map(f32::to_bits), p.to_bits()),
                    "{name}: wo {wo:?} wi {:?}",
                    s.wi
                );
                checked += 1;
            }
        }
        assert!(checked > 40_000, "only {checked} samples");
    }

    /// A vertex's memo changes no bit: its light sample's value and density, then its
    /// continuation sample (which reuse the weights), then a query for another `wo` on the same
    /// memo (which must not reuse them) are the plain calls' results.
    #[test]
    fn a_vertex_memo_changes_no_bit() {
        let mut rng = Rng::new(37);
        let bits = |(f, p): (RgbSample, f32)| (f.0.map(f32::to_bits), p.to_bits());
        for (name, stack) in stacks() {
            for _ in 0..5000 {
                let mut dir = || {
                    let u = rng.uniform2();
                    spherical_direction(
                        u.x * std::f32::consts::FRAC_PI_2,
                        std::f32::consts::TAU * u.y,
                    )
                };
                let (wo, wi, other) = (dir(), dir(), dir());
                let memo = WeightsMemo::default();
                assert_eq!(
                    bits(eval_pdf_memo(&stack, wo, wi, &memo)),
                    bits(eval_pdf(&stack, 0, wo, wi)),
                    "{name}"
                );
                let (uc, u) = (rng.uniform(), rng.uniform2());
                assert_eq!(
                    format!("{:?}", corrected::sample_memo(&stack, wo, uc, u, &memo)),
                    format!("{:?}", corrected::sample(&stack, 0, wo, uc, u, true)),
                    "{name}"
                );
                assert_eq!(
                    bits(eval_pdf_memo(&stack, other, wi, &memo)),
                    bits(eval_pdf(&stack, 0, other, wi)),
                    "{name}"
                );
            }
        }
    }
}
