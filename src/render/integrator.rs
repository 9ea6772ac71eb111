//! Unidirectional path tracing with next-event estimation and multiple importance sampling
//! (Veach & Guibas, "Optimally Combining Sampling Techniques for Monte Carlo Rendering",
//! SIGGRAPH 1995: power heuristic, β = 2), Russian roulette, and the map tree choosing the layered
//! BSDF and facet normal at every hit on the stone.
//!
//! **Depth.** `max_depth` counts scattering events: 1 is direct lighting only (light seen by the
//! camera, plus one bounce to a light), as in pbrt.
//!
//! **Facets.** Where the map gives a facet normal, the BSDF is evaluated in the facet's frame
//! ([`facet_frame`]); directions below the *unbumped* shading surface or the geometric surface
//! are dropped (the rule of [`crate::texture::bump`]), so a facet never gains energy.
//!
//! **Sample dimensions.** Slots 0–1 are the film and lens; bounce `b` owns slots
//! `2 + 6b … 7 + 6b` (switch, light choice, light point, lobe, direction, roulette) whether or not
//! it draws them, so an optional draw never shifts the numbers of later ones.

use super::world::{Hit, LightRef, World};
use crate::bsdf::{Bsdf, Bxdf, power_heuristic};
use crate::color::Spectrum;
use crate::geometry::{Frame, Ray, offset_origin};
use crate::sampler::PixelSampler;
use crate::texture::bump::facet_frame;
use glam::Vec3;

/// Which estimators of direct light are used.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Strategy {
    /// Light sampling and BSDF sampling, combined by the power heuristic.
    #[default]
    Mis,
    /// Light sampling only: light reached by a BSDF-sampled ray is ignored (except from the
    /// camera).
    LightOnly,
    /// BSDF sampling only: no shadow rays.
    BsdfOnly,
}

/// Slots per bounce (module docs).
const SLOTS_PER_BOUNCE: u32 = 6;
/// Bounces after which Russian roulette may end a path.
const RR_DEPTH: u32 = 3;

/// Radiance and first-hit data of one camera path.
#[derive(Clone, Copy, Debug, Default)]
pub struct PathSample {
    /// Radiance along the camera ray.
    pub radiance: Spectrum,
    /// Albedo at the first hit (0 where the ray leaves the scene or meets a light).
    pub albedo: Spectrum,
    /// World shading normal at the first hit (facet normal on glitter), 0 if none.
    pub normal: Vec3,
    /// Distance to the first hit along the camera ray, if any.
    pub depth: Option<f32>,
    /// Material index at the first hit: ≥ 0 the stone's material, −1 the floor, −2 nothing or a
    /// light.
    pub material: i32,
    /// Rays traced (camera, extension and shadow rays).
    pub rays: u32,
}

/// The shading point of a surface hit.
struct Shading<'a> {
    p: Vec3,
    ng: Vec3,
    /// Unbumped shading normal.
    ns: Vec3,
    frame: Frame,
    bsdf: &'a Bsdf,
}

/// Traces one camera path.
///
/// # Arguments
/// * `world` – the scene.
/// * `ray` – the camera ray (unit direction).
/// * `sampler` – positioned after the camera's slots (slot 2).
/// * `max_depth` – most scattering events.
/// * `strategy` – direct-light estimators.
pub fn trace(
    world: &World,
    mut ray: Ray,
    sampler: &mut PixelSampler,
    max_depth: u32,
    strategy: Strategy,
) -> PathSample {
    let mut out = PathSample {
        material: -2,
        ..PathSample::default()
    };
    let mut beta = Spectrum::ONE;
    let mut l = Spectrum::ZERO;
    // Solid-angle density of the BSDF sample that produced `ray` (None from the camera) and the
    // point it left.
    let mut prev: Option<(f32, Vec3)> = None;
    let mut depth = 0u32;
    loop {
        sampler.skip_to(2 + SLOTS_PER_BOUNCE * depth);
        out.rays += 1;
        let hit = world.intersect(&ray, f32::INFINITY);
        let hit = match hit {
            None => {
                let le = world.environment.radiance(ray.dir);
                let w = emission_weight(world, strategy, prev, || {
                    (LightRef::Environment, world.environment.pdf(ray.dir))
                });
                l += beta * le * w;
                break;
            }
            Some(Hit::Light { index, t }) => {
                let le = world.areas[index].emitted(-ray.dir);
                let w = emission_weight(world, strategy, prev, || {
                    let origin = prev.map_or(ray.origin, |(_, p)| p);
                    (
                        LightRef::Area(index),
                        world.areas[index].pdf(origin, ray.dir, t),
                    )
                });
                l += beta * le * w;
                if depth == 0 {
                    out.depth = Some(t);
                }
                break;
            }
            Some(h) => h,
        };
        let wo = -ray.dir;
        let u_switch = sampler.get1d();
        let Some(sh) = shade(world, &hit, wo, u_switch, depth == 0, &mut out) else {
            break;
        };
        if depth >= max_depth {
            break;
        }
        let wo_local = sh.frame.to_local(wo);

        // Next-event estimation.
        let u_light = sampler.get1d();
        let u_point = sampler.get2d();
        if strategy != Strategy::BsdfOnly
            && let Some((light, p_pick)) = world.pick_light(u_light)
        {
            let sample = match light {
                LightRef::Area(i) => world.areas[i].sample(sh.p, u_point),
                LightRef::Environment => world.environment.sample(u_point),
            };
            if let Some(ls) = sample
                && above_both(&sh, ls.wi)
            {
                let wi_local = sh.frame.to_local(ls.wi);
                let f = sh.bsdf.eval(wo_local, wi_local);
                if !f.is_black() {
                    let origin = offset_origin(sh.p, sh.ng, ls.wi);
                    let t_max = if ls.dist.is_finite() {
                        (ls.dist - (origin - sh.p).length()) * (1.0 - 1e-4)
                    } else {
                        f32::INFINITY
                    };
                    out.rays += 1;
                    if !world.occluded(&Ray::new(origin, ls.wi), t_max) {
                        let p_light = p_pick * ls.pdf;
                        let w = match strategy {
                            Strategy::Mis => {
                                power_heuristic(p_light, sh.bsdf.pdf(wo_local, wi_local))
                            }
                            _ => 1.0,
                        };
                        let c = beta * f * ls.radiance * (wi_local.z.abs() * w / p_light);
                        if c.is_valid() {
                            l += c;
                        }
                    }
                }
            }
        }

        // Continue the path by sampling the BSDF.
        let uc = sampler.get1d();
        let u = sampler.get2d();
        let Some(bs) = sh.bsdf.sample(wo_local, uc, u) else {
            break;
        };
        let wi = sh.frame.to_world(bs.wi).normalize();
        if !above_both(&sh, wi) {
            break;
        }
        beta *= bs.weight;
        depth += 1;
        if depth >= RR_DEPTH {
            let q = beta.max_channel().min(1.0);
            if !(sampler.get1d() < q) {
                break;
            }
            beta *= 1.0 / q;
        }
        if !beta.is_valid() || beta.is_black() {
            break;
        }
        prev = Some((bs.pdf, sh.p));
        ray = Ray::new(offset_origin(sh.p, sh.ng, wi), wi);
    }
    out.radiance = l;
    out
}

/// Whether `wi` leaves above both the geometric and the unbumped shading surface (reflection
/// only: the stone and floor are opaque).
#[inline]
fn above_both(sh: &Shading, wi: Vec3) -> bool {
    wi.dot(sh.ng) > 0.0 && wi.dot(sh.ns) > 0.0
}

/// MIS weight of emission reached by a BSDF-sampled ray (`prev` = its pdf and origin; `None` for
/// a camera ray, weight 1). `light_pdf` gives the light and its solid-angle density for the
/// direction.
#[inline]
fn emission_weight(
    world: &World,
    strategy: Strategy,
    prev: Option<(f32, Vec3)>,
    light_pdf: impl FnOnce() -> (LightRef, f32),
) -> f32 {
    let Some((bsdf_pdf, _)) = prev else {
        return 1.0;
    };
    match strategy {
        Strategy::BsdfOnly => 1.0,
        Strategy::LightOnly => 0.0,
        Strategy::Mis => {
            let (light, pdf) = light_pdf();
            let p_light = world.light_probability(light) * pdf;
            power_heuristic(bsdf_pdf, p_light)
        }
    }
}

/// The shading point of a stone or floor hit; records the first-hit AOVs when `first`.
fn shade<'a>(
    world: &'a World,
    hit: &Hit,
    wo: Vec3,
    u_switch: f32,
    first: bool,
    out: &mut PathSample,
) -> Option<Shading<'a>> {
    match *hit {
        Hit::Stone(h) => {
            // Meshes may be open or wound inconsistently: face the normals toward the viewer.
            let (ng, ns) = if wo.dot(h.ng) < 0.0 {
                (-h.ng, -h.ns)
            } else {
                (h.ng, h.ns)
            };
            let ns = if wo.dot(ns) > 0.0 { ns } else { ng };
            let look = world.map.lookup(h.p_object, u_switch);
            let bsdf = world.materials.get(look.material as usize)?.as_ref()?;
            let base = Frame::from_normal(ns);
            let frame = match look.facet {
                Some(facet) if world.facet_bump => facet_frame(&base, facet, wo),
                _ => base,
            };
            if first {
                out.albedo = world.albedo[look.material as usize];
                out.normal = frame.n;
                out.depth = Some(h.t);
                out.material = look.material as i32;
            }
            Some(Shading {
                p: h.p,
                ng,
                ns,
                frame,
                bsdf,
            })
        }
        Hit::Ground { t, p } => {
            let (_, bsdf) = world.ground.as_ref()?;
            let n = if wo.y >= 0.0 { Vec3::Y } else { Vec3::NEG_Y };
            if first {
                if let Bsdf::Lambert(b) = bsdf {
                    out.albedo = b.albedo;
                }
                out.normal = n;
                out.depth = Some(t);
                out.material = -1;
            }
            Some(Shading {
                p,
                ng: n,
                ns: n,
                frame: Frame::from_normal(n),
                bsdf,
            })
        }
        Hit::Light { .. } => None,
    }
}
