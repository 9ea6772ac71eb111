//! The lane path loop: a packet of camera paths traced bounce by bounce in phases
//! (docs/design.md §13). Every lane runs the scalar integrator's steps
//! ([`crate::render::integrator::trace_at`]) for an opaque RGB scene in the same order on its own
//! numbers, so each lane's sample is bit for bit the scalar one.

use super::simd::{L, M, V3};
use crate::geometry::{MediumId, Ray, offset_origin};
use crate::render::camera::CameraRays;
use crate::render::direct::{Strategy, direct_light, emission_weight};
use crate::render::filter::FilterSampler;
use crate::render::path::{PathSample, PathState};
use crate::render::shading::shade;
use crate::render::world::{Hit, LightRef, World};
use crate::sampler::{PixelSampler, SamplerKind, slots};
use crate::spectrum::{RgbSample, RgbWavelengths, Spectral};
use glam::Vec2;

/// Bounces after which Russian roulette may end a path (as the scalar integrator).
const RR_DEPTH: u32 = 3;

/// What a packet traces: pixels `x0 .. x0 + count` of row `y`, sample `sample` of each.
#[derive(Clone, Copy, Debug)]
pub struct Packet {
    /// First pixel's column.
    pub x0: u32,
    /// The row.
    pub y: u32,
    /// Pixels in the packet (1 ..= [`L`]).
    pub count: u32,
    /// The sample index.
    pub sample: u32,
}

/// How the packet's samples are drawn and its rays made.
pub struct Setup<'a> {
    /// Camera rays of the image.
    pub rays: &'a CameraRays,
    /// The pixel filter's sampler.
    pub filter: &'a FilterSampler,
    /// Sampler kind and the render's seed.
    pub sampler: SamplerKind,
    /// The render's seed.
    pub seed: u64,
    /// Image width in pixels (pixel index = `y · width + x`).
    pub width: u32,
    /// Most scattering events.
    pub max_depth: u32,
    /// Direct-light estimators.
    pub strategy: Strategy,
}

/// Traces the packet; lane `i` holds pixel `x0 + i`'s sample (lanes past `count` are empty).
#[inline(always)]
pub fn trace_packet(world: &World, setup: &Setup, packet: Packet) -> [PathSample; L] {
    let live = M::from_fn(|i| (i as u32) < packet.count);
    let mut samplers: [PixelSampler; L] = std::array::from_fn(|i| {
        let x = packet.x0 + (i as u32).min(packet.count - 1);
        let pixel = u64::from(packet.y) * u64::from(setup.width) + u64::from(x);
        PixelSampler::new(setup.sampler, setup.seed, pixel, packet.sample)
    });
    // Camera rays (the render loop's order: filter offset, then lens).
    let mut origin = V3::splat(glam::Vec3::ZERO);
    let mut dir = V3::splat(glam::Vec3::ZERO);
    for (i, s) in samplers.iter_mut().enumerate() {
        let offset = setup.filter.sample(s.get2d());
        let lens = s.get2d();
        let x = packet.x0 + (i as u32).min(packet.count - 1);
        let film = Vec2::new(x as f32 + 0.5, packet.y as f32 + 0.5) + offset;
        let r = setup.rays.ray(film, lens);
        origin.set(i, r.origin);
        dir.set(i, r.dir);
    }
    let mut out: [PathSample; L] = std::array::from_fn(|_| PathSample {
        material: -2,
        ..PathSample::default()
    });
    let mut paths: [PathState<RgbSample>; L] =
        std::array::from_fn(|_| PathState::new(RgbWavelengths, MediumId::OUTSIDE));
    let mut alive = live;
    while alive.any() {
        // Phase 1: intersect.
        let mut found: [Option<Hit>; L] = [None; L];
        for i in alive.lanes() {
            samplers[i].skip_to(slots::bounce(paths[i].depth));
            out[i].rays += 1;
            found[i] = world.intersect(&Ray::new(origin.at(i), dir.at(i)), f32::INFINITY);
        }
        // Phases 2–6, lane by lane.
        for i in alive.lanes() {
            let next = bounce(
                world,
                setup,
                &mut samplers[i],
                &mut paths[i],
                &mut out[i],
                Ray::new(origin.at(i), dir.at(i)),
                found[i],
            );
            match next {
                Some(r) => {
                    origin.set(i, r.origin);
                    dir.set(i, r.dir);
                }
                None => alive.0[i] = false,
            }
        }
    }
    for i in live.lanes() {
        out[i].radiance = paths[i].l.to_rgb(&paths[i].film);
    }
    out
}

/// One bounce of one lane after its intersection: emission, shading, next-event estimation, the
/// BSDF sample and Russian roulette (the scalar integrator's steps for an opaque RGB scene). The
/// next ray, or `None` when the path ends.
#[inline(always)]
fn bounce(
    world: &World,
    setup: &Setup,
    sampler: &mut PixelSampler,
    path: &mut PathState<RgbSample>,
    out: &mut PathSample,
    ray: Ray,
    found: Option<Hit>,
) -> Option<Ray> {
    let strategy = setup.strategy;
    let hit = match found {
        None => {
            let le = RgbSample::from_illuminant(world.environment.radiance(ray.dir), &path.lambda);
            let w = emission_weight(world, strategy, path, || {
                (LightRef::Environment, world.environment.pdf(ray.dir))
            });
            path.add_emission(le, w);
            return None;
        }
        Some(Hit::Light { index, t }) => {
            let le = world.areas[index]
                .emission::<RgbSample>(world.areas[index].emitted(-ray.dir), &path.lambda);
            let w = emission_weight(world, strategy, path, || {
                let origin = path.prev.map_or(ray.origin, |v| v.p);
                (
                    LightRef::Area(index),
                    world.areas[index].pdf(origin, ray.dir, t),
                )
            });
            path.add_emission(le, w);
            if path.depth == 0 {
                out.depth = Some(t);
            }
            return None;
        }
        Some(h) => h,
    };
    let wo = -ray.dir;
    let u_switch = sampler.get1d();
    let sb = shade(world, &hit, wo, u_switch, path.lambda, path.depth == 0, out)?;
    if path.bounces() >= setup.max_depth {
        return None;
    }
    let wo_local = sb.frame.to_local(wo);
    let u_light = sampler.get1d();
    let u_point = sampler.get2d();
    let nee = strategy != Strategy::BsdfOnly && !sb.flags().is_specular_only();
    if nee {
        direct_light(world, strategy, &sb, wo_local, u_light, u_point, path, out);
    }
    let uc = sampler.get1d();
    let u = sampler.get2d();
    let bs = sb.sample::<RgbSample>(wo_local, uc, u, &path.lambda)?;
    if world.transmission_off && bs.flags.is_transmission() {
        return None;
    }
    path.scatter(&bs, sb.p, sb.inside);
    if !nee && let Some(v) = path.prev.as_mut() {
        v.nee = false;
    }
    if path.depth >= RR_DEPTH {
        let q = path.survival();
        if !(sampler.get1d() < q) {
            return None;
        }
        path.beta *= 1.0 / q;
    }
    if !path.alive() {
        return None;
    }
    let origin = offset_origin(sb.p, sb.ng, bs.wi);
    Some(Ray::in_medium(origin, bs.wi, path.medium))
}
