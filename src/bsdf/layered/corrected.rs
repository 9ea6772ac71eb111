//! The Corrected model (the default) and the sampling mixture shared with the Course model.
//!
//! `f = f_top + T(wi)·T(wo)/η² · a · f_rest(wo', wi') + f_multi(wo, wi)` with `T(w) = 1 − E_top(w)`
//! (the albedo coupling of Kelemen & Szirmay-Kalos, course ref. \[20\]) and the multiple-reflection
//! lobe `f_multi = M · q(wo) q(wi) / N`, `q(w) = T(w) · Q(cos θ')`, `M = ρ̄(1 − r_int)/(1 − ρ̄ r_int)`,
//! `N = ∫ q cos θ dω`, where
//! `Q(μ') = ∫ (1 − T_out(wi')) a f_rest cos θi' dωi'` is the energy the layers below send back up
//! that the interface returns (internal Fresnel reflection and total internal reflection), `ρ̄` the
//! cosine-weighted albedo of the layers below with absorption and `r_int = 1 − ∫ T cos/(πη²) dω` the
//! coat's internal diffuse reflectance. With a white Lambert base and no absorption this gives
//! albedo exactly `E_top + T = 1` (up to the tables' quadrature error).
//!
//! docs/design.md §5.2 writes the lobe as `q(wo) · ρ̄/(1 − ρ̄ r_int) · T(wi)/(π η²)`: trapped energy that
//! leaves with the distribution of diffuse inner light. Its albedo is `M q(wo)`, but it is not
//! reciprocal when `Q` varies with the angle (glossy bases). The form used here has the same
//! albedo `M q(wo)` for every `wo` (so the furnace property is unchanged), is symmetric in `wo`,
//! `wi`, and equals the DESIGN form exactly when `Q` is constant (diffuse bases): the light that
//! leaves toward `wi` after inner bounces is distributed like the light from `wi` that gets
//! trapped, as reciprocity requires. Sampling picks one of three lobes with weights that depend on `wo` only —
//! the top lobe's albedo, the single-scatter albedo `T(wo)·(A − Q)` and the multiple lobe's albedo —
//! so `pdf = Σ w_k p_k` (course eq. 3.6) is exact; the lower lobe's pdf carries the refraction
//! Jacobian `cos θi / (η² cos θi')`.

use super::lobes::{LobeWeights, WeightsMemo, cone_cosine_pdf, escape_cone, lobe_weights};
use super::{LayeredBsdf, course};
use crate::bsdf::{BsdfSample, Bxdf, Lobe, LobeKind, refract_macro, sample_cosine_hemisphere};
use crate::spectrum::RgbSample;
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

/// `f(wo, wi)` of the Corrected model at stack level `l` (`l == coats` = the base): the top lobe
/// plus the body, the body of the outermost level scaled by the stack's albedo calibration
/// `c(μo) c(μi)` when it has one ([`super::calibrate`]).
pub fn eval(stack: &LayeredBsdf, l: usize, wo: Vec3, wi: Vec3) -> RgbSample {
    let (top, body) = eval_parts(stack, l, wo, wi);
    match (&stack.calibration, l) {
        (Some(c), 0) if !body.is_black() => top + body * c.at(wo.z) * c.at(wi.z),
        _ => top + body,
    }
}

/// The two parts of the Corrected `f` at level `l`, uncalibrated: the top interface's reflection
/// and the body (single-scatter lobe of the layers below plus the multiple-reflection lobe). At the
/// base, everything is "top".
pub(super) fn eval_parts(
    stack: &LayeredBsdf,
    l: usize,
    wo: Vec3,
    wi: Vec3,
) -> (RgbSample, RgbSample) {
    let Some(lv) = stack.levels.get(l) else {
        return (stack.base.eval(wo, wi), RgbSample::ZERO);
    };
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return (RgbSample::ZERO, RgbSample::ZERO);
    }
    // A smooth coat's reflection is a delta: never reached by evaluation. A compensated rough
    // coat reflects its multiple-scattering lobe's share too (`Level::top_energy`).
    let top = if lv.smooth {
        RgbSample::ZERO
    } else {
        let ms = lv.top_energy.as_ref().map_or(0.0, |e| {
            e.value(wo, wi, crate::bsdf::TransportMode::Radiance)
        });
        lv.top.eval(wo, wi) + RgbSample::splat(ms)
    };
    let Some(wo_in) = refract_macro(wo, lv.eta) else {
        return (top, RgbSample::ZERO);
    };
    let (to, ti) = (lv.t(wo.z), lv.t(wi.z));
    let Some(wi_in) = refract_macro(wi, lv.eta) else {
        return (top, RgbSample::ZERO);
    };
    let rest = eval(stack, l + 1, wo_in, wi_in);
    let body = lv.body(stack.t_term(), rest, (wo, wi), (wo_in, wi_in), (to, ti));
    (top, body)
}

/// Evaluates level `l` under the analytic model selected by `corrected`.
#[inline]
fn eval_model(stack: &LayeredBsdf, l: usize, wo: Vec3, wi: Vec3, corrected: bool) -> RgbSample {
    if corrected {
        eval(stack, l, wo, wi)
    } else {
        course::eval(stack, l, wo, wi)
    }
}

/// Cosine-weighted sampling restricted to the cone `sin²θ < r2`: Malley's method on the disk of
/// radius `√r2`. Density `cos θ / (π r2)` inside the cone.
#[inline]
fn sample_cone_cosine(u: Vec2, r2: f32) -> Option<Vec3> {
    let d = sample_cosine_hemisphere(u)?;
    let r = r2.sqrt();
    let (x, y) = (d.x * r, d.y * r);
    let z = (1.0 - x * x - y * y).max(0.0).sqrt();
    (z > 0.0).then(|| Vec3::new(x, y, z))
}

/// Density of the shared mixture at level `l`.
pub fn pdf(stack: &LayeredBsdf, l: usize, wo: Vec3, wi: Vec3, corrected: bool) -> f32 {
    if l >= stack.levels.len() {
        return stack.base.pdf(wo, wi); // pdf is unaffected by compensation
    }
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return 0.0;
    }
    pdf_weighted(
        stack,
        l,
        wo,
        wi,
        lobe_weights(stack, l, wo, corrected),
        corrected,
    )
}

/// [`pdf`] at a level that exists, for `wo.z > 0` and `wi.z > 0`, given the level's
/// [`lobe_weights`] for `wo` (a sample reuses those it chose its lobe with).
fn pdf_weighted(
    stack: &LayeredBsdf,
    l: usize,
    wo: Vec3,
    wi: Vec3,
    (w, wo_in): LobeWeights,
    corrected: bool,
) -> f32 {
    let lv = &stack.levels[l];
    let mut p = 0.0;
    if w[0] > 0.0 && !lv.smooth {
        p += w[0] * lv.top.pdf(wo, wi);
    }
    if w[1] > 0.0
        && let (Some(wo_in), Some(wi_in)) = (wo_in, refract_macro(wi, lv.eta))
    {
        let jacobian = wi.z / (lv.eta * lv.eta * wi_in.z);
        let rest = match escape_cone(stack, l) {
            // wi_in came from refracting an outside direction, so it lies in the cone by
            // construction; testing sin²θ against 1/η² again could fail by rounding at grazing.
            Some(r2) => cone_cosine_pdf(wi_in, r2),
            None => pdf(stack, l + 1, wo_in, wi_in, corrected),
        };
        p += w[1] * rest * jacobian;
    }
    p += w[2] * wi.z * FRAC_1_PI;
    if p.is_finite() { p } else { 0.0 }
}

/// Samples a direction from the mixture at level `l` (no evaluation).
pub(super) fn sample_dir(
    stack: &LayeredBsdf,
    l: usize,
    wo: Vec3,
    uc: f32,
    u: Vec2,
    corrected: bool,
) -> Option<(Vec3, Lobe)> {
    if l >= stack.levels.len() {
        let s = stack.base.sample(wo, uc, u)?;
        return Some((
            s.wi,
            Lobe {
                kind: s.lobe.kind,
                layer: l as u8,
            },
        ));
    }
    if wo.z <= 0.0 {
        return None;
    }
    sample_dir_weighted(
        stack,
        l,
        wo,
        uc,
        u,
        lobe_weights(stack, l, wo, corrected),
        corrected,
    )
}

/// [`sample_dir`] at a level that exists, for `wo.z > 0`, given the level's [`lobe_weights`]
/// for `wo`.
fn sample_dir_weighted(
    stack: &LayeredBsdf,
    l: usize,
    wo: Vec3,
    uc: f32,
    u: Vec2,
    (w, wo_in): LobeWeights,
    corrected: bool,
) -> Option<(Vec3, Lobe)> {
    let lv = &stack.levels[l];
    let uc = uc.clamp(0.0, 1.0);
    if uc < w[0] || (w[1] == 0.0 && w[2] == 0.0) {
        if w[0] == 0.0 {
            return None;
        }
        if lv.smooth {
            return Some((
                Vec3::new(-wo.x, -wo.y, wo.z),
                Lobe {
                    kind: LobeKind::SpecularReflection,
                    layer: l as u8,
                },
            ));
        }
        let s = lv.top.sample(wo, (uc / w[0]).min(1.0), u)?;
        return Some((
            s.wi,
            Lobe {
                kind: LobeKind::Glossy,
                layer: l as u8,
            },
        ));
    }
    if uc < w[0] + w[1] || w[2] == 0.0 {
        let uc2 = ((uc - w[0]) / w[1]).clamp(0.0, 1.0);
        let (wi_in, lobe) = match escape_cone(stack, l) {
            Some(r2) => {
                let kind = LobeKind::Diffuse;
                (
                    sample_cone_cosine(u, r2)?,
                    Lobe {
                        kind,
                        layer: (l + 1) as u8,
                    },
                )
            }
            None => sample_dir(stack, l + 1, wo_in?, uc2, u, corrected)?,
        };
        let wi = refract_macro(wi_in, 1.0 / lv.eta)?;
        return Some((wi, lobe));
    }
    let wi = sample_cosine_hemisphere(u)?;
    Some((
        wi,
        Lobe {
            kind: LobeKind::Multiple,
            layer: l as u8,
        },
    ))
}

/// Samples the analytic model (`corrected` selects Corrected vs Course evaluation) at level `l`.
pub fn sample(
    stack: &LayeredBsdf,
    l: usize,
    wo: Vec3,
    uc: f32,
    u: Vec2,
    corrected: bool,
) -> Option<BsdfSample> {
    if corrected && stack.levels.is_empty() {
        // A stack without coats is its base, whose own sample already carries the `f` and `pdf`
        // that the general path below would evaluate again (at the base, `eval` is the base's
        // `f` — no calibration, whose body is black there — and `pdf` its density): the same
        // record bit for bit (tested), unless the flush of tiny values would change its `f`.
        let s = stack.base.sample(wo, uc, u)?;
        if crate::bsdf::flush_tiny(s.f) == s.f {
            return Some(s);
        }
    }
    sample_general(stack, l, wo, uc, u, corrected, None)
}

/// [`sample`] of the Corrected model at the top level, with the lobe weights from `memo` (a
/// vertex's, shared with its next-event estimation).
pub fn sample_memo(
    stack: &LayeredBsdf,
    wo: Vec3,
    uc: f32,
    u: Vec2,
    memo: &WeightsMemo,
) -> Option<BsdfSample> {
    if stack.levels.is_empty() {
        return sample(stack, 0, wo, uc, u, true);
    }
    sample_general(stack, 0, wo, uc, u, true, Some(memo))
}

/// [`sample`] without the coat-less shortcut; the top level's Corrected weights from `memo` when
/// given.
fn sample_general(
    stack: &LayeredBsdf,
    l: usize,
    wo: Vec3,
    uc: f32,
    u: Vec2,
    corrected: bool,
    memo: Option<&WeightsMemo>,
) -> Option<BsdfSample> {
    let Some(lv) = stack.levels.get(l).filter(|_| wo.z > 0.0) else {
        // The base alone, or `wo` below the coat (no direction then).
        let (wi, lobe) = sample_dir(stack, l, wo, uc, u, corrected)?;
        let f = crate::bsdf::flush_tiny(eval_model(stack, l, wo, wi, corrected));
        return BsdfSample::from_eval(wi, f, pdf(stack, l, wo, wi, corrected), lobe);
    };
    // The lobe weights for `wo`, once for the choice and the density (the same numbers as
    // `sample_dir` and `pdf` would find each).
    let weights = match memo {
        Some(m) if l == 0 && corrected => m.get(stack, wo),
        _ => lobe_weights(stack, l, wo, corrected),
    };
    let (wi, lobe) = sample_dir_weighted(stack, l, wo, uc, u, weights, corrected)?;
    if lobe.kind == LobeKind::SpecularReflection {
        // The smooth top coat's delta: it carries F(μo) of the flux and was chosen with the
        // top lobe's weight; f = F/|cos θi| so that weight = f |cos θi| / pdf (the delta
        // convention of `SmoothDielectric`).
        let value = lv.fresnel.eval(wo.z)[0];
        return BsdfSample::from_eval(wi, RgbSample::splat(value / wi.z), weights.0[0], lobe);
    }
    let (f, pdf) = if corrected {
        // The value and the density together (the top lobe's `D`, the refraction of `wi`).
        super::joint::eval_pdf_weighted(stack, l, wo, wi, weights)
    } else {
        let f = course::eval(stack, l, wo, wi);
        let pdf = if wi.z > 0.0 {
            pdf_weighted(stack, l, wo, wi, weights, corrected)
        } else {
            0.0
        };
        (f, pdf)
    };
    BsdfSample::from_eval(wi, crate::bsdf::flush_tiny(f), pdf, lobe)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::layered::{Base, ConductorIor, StackDesc};
    use crate::color::Rgb;

    /// A coat-less stack's shortcut returns the record of the general path bit for bit, for
    /// every kind of base (Lambert, Oren–Nayar, a rough conductor with compensation), 20 000
    /// samples each over the whole hemisphere (grazing included).
    #[test]
    fn a_coatless_stack_samples_as_the_general_path() {
        let bases = [
            Base::Lambert {
                albedo: Rgb::new(0.5, 0.2, 0.9),
            },
            Base::OrenNayar {
                albedo: Rgb::new(0.7, 0.6, 0.1),
                sigma: 0.3,
            },
            Base::Conductor {
                ior: ConductorIor::Complex {
                    n: Rgb::new(0.2, 0.9, 1.1),
                    k: Rgb::new(3.0, 2.5, 2.2),
                },
                roughness: 12.0,
            },
        ];
        let mut rng = crate::sampler::Rng::new(29);
        for base in bases {
            let stack = LayeredBsdf::new(&StackDesc::new(vec![], base)).unwrap();
            let mut some = 0;
            for _ in 0..20_000 {
                let wo = crate::bsdf::spherical_direction(
                    rng.uniform() * std::f32::consts::FRAC_PI_2,
                    rng.uniform() * 6.3,
                );
                let (uc, u) = (rng.uniform(), rng.uniform2());
                let fast = sample(&stack, 0, wo, uc, u, true);
                let general = sample_general(&stack, 0, wo, uc, u, true, None);
                assert_eq!(format!("{fast:?}"), format!("{general:?}"), "{base:?} {wo}");
                some += usize::from(fast.is_some());
            }
            assert!(some > 15_000, "{base:?}: {some}");
        }
    }
}
