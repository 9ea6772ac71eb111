//! The Reference model: a position-free Monte Carlo random walk through the stack (Guo, Hašan &
//! Zhao, "Position-free Monte Carlo simulation for arbitrary layered BSDFs", SIGGRAPH Asia 2018; the
//! estimator structure of pbrt-v4's `LayeredBxDF`, generalised here to any number of coats by
//! recursion: the "bottom" of coat `l` is the Reference walk of the stack below it).
//!
//! Each coat is a rough dielectric interface with transmission ([`RoughDielectric`](crate::bsdf::dielectric::RoughDielectric), Walter et al.
//! 2007, sharing the distribution and V-cavity `G` of the analytic models), its varnish absorbs
//! `exp(−α d / |cos θ|)` per traversal, and light bounces between the interface and the layers below
//! until it leaves or Russian roulette ends it.
//!
//! - `eval` averages `samples` walks. Each enters through the interface from `wo`, and at every
//!   upward scattering event at the bottom connects to `wi` by two strategies combined with the
//!   power heuristic: through a transmitted direction pre-sampled from `wi` (good for smooth
//!   interfaces), and by sampling the bottom and evaluating the interface's transmission (good for
//!   glossy bottoms). MIS weights use the same deterministic pdf functions in both strategies, so
//!   they sum to one and the estimator is unbiased. Its random numbers are seeded from a hash of
//!   `(wo, wi)`, so `eval` is repeatable.
//! - `sample` follows one walk and returns its unbiased weight.
//! - `pdf` is not the walk's density (which has no closed form): it is the Corrected model's
//!   mixture density for the same stack, mixed 9:1 with a cosine lobe so it is positive wherever the
//!   walk can exit. `sample` reports that pdf and `f = weight · pdf / cos θi`, so
//!   `weight = f cos/pdf` holds; chi-square tests do not apply to this model.

use super::{LayeredBsdf, ReferenceParams, corrected};
use crate::bsdf::dielectric::Lobes;
use crate::bsdf::{BsdfSample, Bxdf, Lobe, LobeKind, TransportMode, power_heuristic};
use crate::sampler::{Rng, hash_f32s};
use crate::spectrum::RgbSample;
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

/// Weight of the cosine lobe in the Reference model's pdf.
const COSINE_MIX: f32 = 0.1;

/// Russian roulette starts after this many bounces and kills walks whose weight, as it would be
/// outside the coat, is below 1/4.
const RR_DEPTH: u32 = 3;

/// `f(wo, wi)` of the Reference model.
pub fn eval(stack: &LayeredBsdf, p: ReferenceParams, wo: Vec3, wi: Vec3) -> RgbSample {
    let mut rng = Rng::new(hash_f32s(&[wo.x, wo.y, wo.z, wi.x, wi.y, wi.z]));
    eval_at(stack, p, 0, wo, wi, &mut rng)
}

/// The deterministic density used for MIS and reported by `sample` (module docs).
pub fn pdf(stack: &LayeredBsdf, wo: Vec3, wi: Vec3) -> f32 {
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return 0.0;
    }
    (1.0 - COSINE_MIX) * corrected::pdf(stack, 0, wo, wi, true) + COSINE_MIX * wi.z * FRAC_1_PI
}

/// One random walk from `wo`; returns its unbiased weight.
pub fn sample(
    stack: &LayeredBsdf,
    p: ReferenceParams,
    wo: Vec3,
    uc: f32,
    u: Vec2,
) -> Option<BsdfSample> {
    if wo.z <= 0.0 {
        return None;
    }
    let mut rng = Rng::new(hash_f32s(&[wo.x, wo.y, wo.z, uc, u.x, u.y]));
    let Walk {
        wi,
        weight,
        specular,
    } = walk_at(stack, p, 0, wo, Some((uc, u)), &mut rng)?;
    if specular {
        // The smooth top coat's mirror reflection: a delta, chosen with probability F(μo) by the
        // walk's first event; reported in the delta convention (pdf = that probability,
        // f = weight · pdf / |cos θi|, i.e. F/|cos θi|).
        let lobe = Lobe {
            kind: LobeKind::SpecularReflection,
            layer: 0,
        };
        let p = crate::bsdf::fresnel::dielectric(wo.z, stack.levels[0].eta);
        return BsdfSample::from_eval(wi, weight * (p / wi.z), p, lobe);
    }
    let pdf = pdf(stack, wo, wi);
    if !(pdf > 0.0) || !weight.is_valid() || wi.z <= 0.0 {
        return None;
    }
    let f = weight * (pdf / wi.z);
    let lobe = Lobe {
        kind: LobeKind::RandomWalk,
        layer: 0,
    };
    Some(BsdfSample {
        wi,
        f,
        pdf,
        weight,
        lobe,
        flags: lobe.kind.flags(),
        eta: 1.0,
        // The walk's density has no closed form: `pdf` is the mixture approximation of
        // [`pdf`], proportional in spirit only.
        pdf_is_proportional: true,
        terminate_secondary: false,
    })
}

/// Density of the bottom of level `l` sampling `wi` from `wo`, as used in the MIS weights.
#[inline]
fn bottom_pdf(stack: &LayeredBsdf, l: usize, wo: Vec3, wi: Vec3) -> f32 {
    if l == stack.levels.len() {
        stack.base.pdf(wo, wi)
    } else {
        corrected::pdf(stack, l, wo, wi, true)
    }
}

/// Stochastic `f` of the stack from level `l` down.
fn eval_at(
    stack: &LayeredBsdf,
    p: ReferenceParams,
    l: usize,
    wo: Vec3,
    wi: Vec3,
    rng: &mut Rng,
) -> RgbSample {
    let Some(lv) = stack.levels.get(l) else {
        return stack.base.eval(wo, wi);
    };
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return RgbSample::ZERO;
    }
    if lv.index_matched {
        // An invisible interface: straight through, absorption both ways.
        let a = lv.transmit(wo.z) * lv.transmit(wi.z);
        return a * eval_at(stack, p, l + 1, wo, wi, rng);
    }
    let iface = &lv.interface;
    let f_top = RgbSample::splat(iface.value(wo, wi, TransportMode::Radiance));
    let mut acc = RgbSample::ZERO;
    for _ in 0..p.samples {
        let Some(wos) = iface.sample_lobes(
            wo,
            rng.uniform(),
            rng.uniform2(),
            TransportMode::Radiance,
            Lobes::Transmission,
        ) else {
            continue;
        };
        let Some(wis) = iface.sample_lobes(
            wi,
            rng.uniform(),
            rng.uniform2(),
            TransportMode::Importance,
            Lobes::Transmission,
        ) else {
            continue;
        };
        // `wis.f` in importance mode is the exit event's radiance BSDF f(wis.wi → wi).
        let exit_a = wis.f;
        let mut beta = wos.weight;
        let mut w = wos.wi; // travelling down
        let eta2 = lv.eta * lv.eta;
        for depth in 0..p.max_depth {
            let rr = beta.max_channel() * eta2;
            if depth > RR_DEPTH && rr < 0.25 {
                let q = (1.0 - rr).max(0.0);
                if rng.uniform() < q {
                    break;
                }
                beta = beta / (1.0 - q);
            }
            beta *= lv.transmit(w.z);
            // Strategy A: connect the bottom to the pre-sampled transmitted direction of wi.
            let up_light = -wis.wi;
            let fb = eval_at(stack, p, l + 1, -w, up_light, rng);
            if !fb.is_black() {
                // A delta exit cannot be found by the other strategy: it takes all the weight.
                let wt = if iface.is_delta() {
                    1.0
                } else {
                    power_heuristic(wis.pdf, bottom_pdf(stack, l + 1, -w, up_light))
                };
                acc += beta
                    * fb
                    * (up_light.z.abs() * wt / wis.pdf)
                    * lv.transmit(up_light.z)
                    * exit_a;
            }
            // Continue the walk at the bottom.
            let Some((wb, wtb, pdf_b)) = sample_bottom(stack, p, l + 1, -w, rng) else {
                break;
            };
            beta *= wtb;
            w = wb; // travelling up
            // Strategy B: evaluate the interface's transmission toward wi.
            let fe = iface.value(-w, wi, TransportMode::Radiance);
            if fe > 0.0 {
                let pa = iface.pdf_lobes(wi, -w, Lobes::Transmission);
                let wt = power_heuristic(pdf_b, pa);
                acc += beta * lv.transmit(w.z) * (fe * wt);
            }
            beta *= lv.transmit(w.z);
            // Internal reflection back down at the interface.
            let Some(rs) = iface.sample_lobes(
                -w,
                rng.uniform(),
                rng.uniform2(),
                TransportMode::Radiance,
                Lobes::Reflection,
            ) else {
                break;
            };
            beta *= rs.weight;
            w = rs.wi;
            if beta.is_black() {
                break;
            }
        }
    }
    let f = f_top + acc / p.samples as f32;
    if f.is_valid() { f } else { RgbSample::ZERO }
}

/// Where a walk leaves the stack and with what weight.
struct Walk {
    /// Exit direction, above the level the walk started at.
    wi: Vec3,
    /// Unbiased weight `f cos θi / p` of the walk.
    weight: RgbSample,
    /// The walk left by a smooth top interface's mirror reflection at its first event (a delta).
    specular: bool,
}

/// Samples the bottom of a level: the base exactly, or a deeper walk. Returns the direction, the
/// weight and the MIS density ([`bottom_pdf`]).
fn sample_bottom(
    stack: &LayeredBsdf,
    p: ReferenceParams,
    l: usize,
    wo: Vec3,
    rng: &mut Rng,
) -> Option<(Vec3, RgbSample, f32)> {
    if l == stack.levels.len() {
        let s = stack.base.sample(wo, rng.uniform(), rng.uniform2())?;
        return Some((s.wi, s.weight, s.pdf));
    }
    let Walk { wi, weight, .. } = walk_at(stack, p, l, wo, None, rng)?;
    let pdf = bottom_pdf(stack, l, wo, wi);
    (pdf > 0.0).then_some((wi, weight, pdf))
}

/// One random walk through the stack from level `l` down; `first` supplies the random numbers of
/// the first interface event (so `sample`'s `uc, u` stratify it).
fn walk_at(
    stack: &LayeredBsdf,
    p: ReferenceParams,
    l: usize,
    wo: Vec3,
    first: Option<(f32, Vec2)>,
    rng: &mut Rng,
) -> Option<Walk> {
    let walk = |wi, weight| {
        Some(Walk {
            wi,
            weight,
            specular: false,
        })
    };
    let Some(lv) = stack.levels.get(l) else {
        let (uc, u) = first.unwrap_or_else(|| (rng.uniform(), rng.uniform2()));
        let s = stack.base.sample(wo, uc, u)?;
        return walk(s.wi, s.weight);
    };
    if lv.index_matched {
        let w = walk_at(stack, p, l + 1, wo, first, rng)?;
        return walk(w.wi, w.weight * lv.transmit(wo.z) * lv.transmit(w.wi.z));
    }
    let iface = &lv.interface;
    let (uc, u) = first.unwrap_or_else(|| (rng.uniform(), rng.uniform2()));
    let s = iface.sample_lobes(wo, uc, u, TransportMode::Radiance, Lobes::All)?;
    if s.wi.z > 0.0 {
        return Some(Walk {
            wi: s.wi,
            weight: s.weight,
            specular: iface.is_delta(),
        });
    }
    let mut beta = s.weight;
    let mut w = s.wi;
    let eta2 = lv.eta * lv.eta;
    for depth in 0..p.max_depth {
        // Roulette on the weight the walk will have outside: inside the coat `beta` carries the
        // entering refraction's 1/η², which leaving undoes (pbrt-v4's `etaScale`, §14.1.5).
        let rr = beta.max_channel() * eta2;
        if depth > RR_DEPTH && rr < 0.25 {
            let q = (1.0 - rr).max(0.0);
            if rng.uniform() < q {
                return None;
            }
            beta = beta / (1.0 - q);
        }
        beta *= lv.transmit(w.z);
        let (wb, wtb, _) = sample_bottom(stack, p, l + 1, -w, rng)?;
        beta *= wtb * lv.transmit(wb.z);
        let s = iface.sample_lobes(
            -wb,
            rng.uniform(),
            rng.uniform2(),
            TransportMode::Radiance,
            Lobes::All,
        )?;
        beta *= s.weight;
        if s.wi.z > 0.0 {
            return walk(s.wi, beta);
        }
        w = s.wi;
        if beta.is_black() {
            return None;
        }
    }
    None
}
