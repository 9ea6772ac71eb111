//! The lane path loop: a packet of camera paths traced bounce by bounce in phases
//! (docs/design.md §13). Every lane runs the scalar integrator's steps
//! ([`crate::render::camera_path::trace_at`]) for an opaque RGB scene in the same order on its own
//! numbers, so each lane's sample is bit for bit the scalar one.

use super::draws::{Draws, bounce_draws, leading_field};
use super::simd::{F, L, M, V3};
use crate::bsdf::power_heuristic;
use crate::geometry::{MediumId, Ray, offset_origin};
use crate::light::LightSample;
use crate::render::camera::CameraRays;
use crate::render::direct::{Strategy, area_emission_weight, emission_weight};
use crate::render::filter::FilterSampler;
use crate::render::integrator::RR_DEPTH;
use crate::render::path::{PathSample, PathState};
use crate::render::shading::{SurfaceBsdf, shade};
use crate::render::world::{Hit, LightRef, World};
use crate::sampler::{PixelSampler, SamplerKind, pairs_side_by_side, slots};
use crate::spectrum::{RgbSample, RgbWavelengths, Spectral};
use crate::texture::field::FieldId;
use crate::texture::map::MapQuery;
use glam::Vec2;

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
    /// The map's leading field ([`crate::texture::map::Map::leading_field`]), evaluated for all
    /// the lanes at a stone at once.
    pub leading_field: Option<FieldId>,
}

/// The samplers of a packet's pixels ([`trace_packet`] restarts them at its sample), made once
/// for all the samples of the pixels.
pub fn packet_samplers(setup: &Setup, packet: Packet) -> [PixelSampler; L] {
    std::array::from_fn(|i| {
        let x = packet.x0 + (i as u32).min(packet.count - 1);
        let pixel = u64::from(packet.y) * u64::from(setup.width) + u64::from(x);
        PixelSampler::new(setup.sampler, setup.seed, pixel, packet.sample)
    })
}

/// Traces the packet; lane `i` holds pixel `x0 + i`'s sample (lanes past `count` are empty).
/// `samplers` are the packet's pixels' ([`packet_samplers`]).
#[inline(always)]
pub fn trace_packet(
    world: &World,
    setup: &Setup,
    packet: Packet,
    samplers: &mut [PixelSampler; L],
) -> [PathSample; L] {
    let live = M::from_fn(|i| (i as u32) < packet.count);
    for s in samplers.iter_mut() {
        s.restart(packet.sample);
    }
    // Camera rays (the render loop's slots: filter offset, then lens).
    let film_u = pairs_side_by_side(samplers, [slots::FILM; L], live.0);
    let lens_u = pairs_side_by_side(samplers, [slots::LENS; L], live.0);
    let mut origin = V3::splat(glam::Vec3::ZERO);
    let mut dir = V3::splat(glam::Vec3::ZERO);
    for i in 0..L {
        let (offset, lens) = (setup.filter.sample(film_u[i]), lens_u[i]);
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
        // Phase 1: intersect, and the bounce's numbers of every lane.
        for i in alive.lanes() {
            out[i].rays += 1;
        }
        let found = intersect(world, alive, origin, dir);
        // Only a lane at a surface draws (one that left the scene or met a light ends).
        let surface =
            alive & M::from_fn(|i| matches!(found[i], Some(Hit::Stone(_) | Hit::Ground { .. })));
        let mut draws = bounce_draws(samplers, &paths, surface);
        if let Some((field, values)) = leading_field(world, setup.leading_field, &found, alive) {
            for (d, v) in draws.iter_mut().zip(values) {
                d.known = Some((field, v));
            }
        }
        // Phases 2–4, lane by lane: emission, shading, the light sample and its BSDF value.
        let mut vertices: [Option<Vertex>; L] = std::array::from_fn(|_| None);
        let mut shadow_o = V3::splat(glam::Vec3::ZERO);
        let mut shadow_d = V3::splat(glam::Vec3::ZERO);
        let mut shadow_t = F::splat(0.0);
        let mut shadowed = M::splat(false);
        for i in alive.lanes() {
            let ray = Ray::new(origin.at(i), dir.at(i));
            vertices[i] = vertex(
                world,
                setup,
                &draws[i],
                &mut paths[i],
                &mut out[i],
                ray,
                found[i],
            );
            match &vertices[i] {
                None => alive.0[i] = false,
                Some(v) => {
                    if let Some(n) = &v.nee {
                        out[i].rays += 1;
                        shadow_o.set(i, n.ray.origin);
                        shadow_d.set(i, n.ray.dir);
                        shadow_t.0[i] = n.t_max;
                        shadowed.0[i] = true;
                    }
                }
            }
        }
        // Phase 5: the shadow rays.
        let occluded = occluded(world, shadowed, shadow_o, shadow_d, shadow_t);
        // Phase 6, lane by lane: the light sample's contribution, the BSDF sample, Russian
        // roulette and the next ray.
        for i in alive.lanes() {
            let v = vertices[i].as_ref().expect("a live lane has a vertex");
            if let Some(n) = &v.nee
                && !occluded.0[i]
            {
                gather(world, setup.strategy, v, n, &mut paths[i]);
            }
            match continue_path(world, v, &draws[i], &mut paths[i]) {
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

/// The first hit of each live lane's ray (unit direction) within `(0, ∞)`: the stone, the floor,
/// then the area lights, each closer than the last (as [`World::intersect`]).
#[inline(always)]
fn intersect(world: &World, live: M, o: V3, d: V3) -> [Option<Hit>; L] {
    let (hit, stone) = super::stone::intersect(&world.stone, live, o, d);
    let mut t_best = F::from_fn(|i| if hit.0[i] { stone[i].t } else { f32::INFINITY });
    let mut kind = [0u8; L]; // 0 nothing, 1 stone, 2 floor, 3 light
    for i in hit.lanes() {
        kind[i] = 1;
    }
    let mut ground_t = F::splat(0.0);
    if let Some((h, _)) = world.ground {
        let t = (h - o.y) / d.y;
        let closer = t.gt(F::splat(0.0)) & t.lt(t_best) & live;
        t_best = F::select(closer, t, t_best);
        ground_t = t;
        for i in closer.lanes() {
            kind[i] = 2;
        }
    }
    let mut light = [0usize; L];
    for (index, a) in world.areas.iter().enumerate() {
        for i in live.lanes() {
            if let Some(t) = a.intersect(&Ray::new(o.at(i), d.at(i)), t_best.at(i)) {
                t_best.0[i] = t;
                kind[i] = 3;
                light[i] = index;
            }
        }
    }
    std::array::from_fn(|i| match kind[i] {
        1 => Some(Hit::Stone(stone[i])),
        2 => {
            let t = ground_t.at(i);
            Some(Hit::Ground {
                t,
                p: Ray::new(o.at(i), d.at(i)).at(t),
            })
        }
        3 => Some(Hit::Light {
            index: light[i],
            t: t_best.at(i),
        }),
        _ => None,
    })
}

/// A lane's surface vertex between the phases of a bounce.
#[derive(Clone)]
struct Vertex<'a> {
    /// The BSDF at the hit.
    sb: SurfaceBsdf<'a>,
    /// `wo` in its shading frame.
    wo_local: glam::Vec3,
    /// Whether next-event estimation ran here (a light was looked for).
    looked: bool,
    /// The light sample waiting for its shadow ray.
    nee: Option<LightPath>,
}

/// A light sample whose contribution waits for its shadow ray (the scalar `direct_light`, split
/// at the shadow test).
#[derive(Clone, Copy)]
struct LightPath {
    /// The shadow ray and its extent.
    ray: Ray,
    t_max: f32,
    /// The chosen light.
    light: LightRef,
    /// Probability of the light times the sample's density.
    p_light: f32,
    /// The sample.
    sample: LightSample,
    /// `wi` in the shading frame and `f(wo, wi)`.
    wi_local: glam::Vec3,
    f: RgbSample,
}

/// One lane's bounce up to the shadow test: emission of a miss or a light (the path then ends:
/// `None`), shading, the depth limit, the light sample and its BSDF value (the scalar
/// integrator's steps for an opaque RGB scene, in its order).
#[inline(always)]
fn vertex<'a>(
    world: &'a World,
    setup: &Setup,
    draws: &Draws,
    path: &mut PathState<RgbSample>,
    out: &mut PathSample,
    ray: Ray,
    found: Option<Hit>,
) -> Option<Vertex<'a>> {
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
            let w = area_emission_weight(world, strategy, path, &ray, (index, t));
            path.add_emission(le, w);
            if path.depth == 0 {
                out.depth = Some(t);
            }
            return None;
        }
        Some(h) => h,
    };
    let wo = -ray.dir;
    let sb = shade(
        world,
        &hit,
        wo,
        MapQuery {
            u: draws.switch,
            known: draws.known,
        },
        path.lambda,
        path.depth == 0,
        out,
    )?;
    if path.bounces() >= setup.max_depth {
        return None;
    }
    let wo_local = sb.frame.to_local(wo);
    let (u_light, u_point) = (draws.light, draws.point);
    let looked = strategy != Strategy::BsdfOnly && !sb.flags().is_specular_only();
    let nee = if looked {
        light_path(world, &sb, wo_local, u_light, u_point)
    } else {
        None
    };
    Some(Vertex {
        sb,
        wo_local,
        looked,
        nee,
    })
}

/// The scalar `direct_light` up to its shadow test: a light picked and sampled, the sample
/// admitted by the surface, its BSDF value non-zero, and the shadow ray.
#[inline(always)]
fn light_path(
    world: &World,
    sb: &SurfaceBsdf,
    wo_local: glam::Vec3,
    u_light: f32,
    u_point: Vec2,
) -> Option<LightPath> {
    let (light, p_pick) = world.pick_light(u_light)?;
    let sample = match light {
        LightRef::Area(i) => world.areas[i].sample(sb.p, u_point),
        LightRef::Environment => world.environment.sample(u_point),
    }?;
    if !sb.admits(sample.wi) || (world.transmission_off && sample.wi.dot(sb.ng) < 0.0) {
        return None;
    }
    let (wi_local, f) = sb.eval::<RgbSample>(wo_local, sample.wi, &RgbWavelengths);
    if f.is_black() {
        return None;
    }
    let origin = offset_origin(sb.p, sb.ng, sample.wi);
    let t_max = if sample.dist.is_finite() {
        (sample.dist - (origin - sb.p).length()) * (1.0 - 1e-4)
    } else {
        f32::INFINITY
    };
    Some(LightPath {
        ray: Ray::new(origin, sample.wi),
        t_max,
        light,
        p_light: p_pick * sample.pdf,
        sample,
        wi_local,
        f,
    })
}

/// The rest of `direct_light` for an unoccluded light sample: its MIS weight and contribution.
#[inline(always)]
fn gather(
    world: &World,
    strategy: Strategy,
    v: &Vertex,
    n: &LightPath,
    path: &mut PathState<RgbSample>,
) {
    let w = match strategy {
        Strategy::Mis => power_heuristic(
            n.p_light,
            v.sb.pdf::<RgbSample>(v.wo_local, n.wi_local, &RgbWavelengths),
        ),
        _ => 1.0,
    };
    let radiance = match n.light {
        LightRef::Area(i) => {
            world.areas[i].emission::<RgbSample>(n.sample.radiance, &RgbWavelengths)
        }
        LightRef::Environment => RgbSample::from_illuminant(n.sample.radiance, &RgbWavelengths),
    };
    let c = path.throughput() * n.f * radiance * (n.wi_local.z.abs() * w / n.p_light);
    if c.is_valid() {
        path.gather(c);
    }
}

/// The BSDF sample, Russian roulette and the next ray of a lane (`None`: the path ends).
#[inline(always)]
fn continue_path(
    world: &World,
    v: &Vertex,
    draws: &Draws,
    path: &mut PathState<RgbSample>,
) -> Option<Ray> {
    let (uc, u) = (draws.uc, draws.u);
    let bs = v.sb.sample::<RgbSample>(v.wo_local, uc, u, &path.lambda)?;
    if world.transmission_off && bs.flags.is_transmission() {
        return None;
    }
    path.scatter(&bs, v.sb.p, v.sb.inside);
    if !v.looked
        && let Some(prev) = path.prev.as_mut()
    {
        prev.nee = false;
    }
    if path.depth >= RR_DEPTH {
        let q = path.survival();
        if !(draws.roulette < q) {
            return None;
        }
        path.beta *= 1.0 / q;
    }
    if !path.alive() {
        return None;
    }
    let origin = offset_origin(v.sb.p, v.sb.ng, bs.wi);
    Some(Ray::in_medium(origin, bs.wi, path.medium))
}

/// Whether anything blocks each shadowed lane's ray before its `t_max` (as [`World::occluded`]:
/// the floor, the area lights, the stone).
#[inline(always)]
fn occluded(world: &World, live: M, o: V3, d: V3, t_max: F) -> M {
    let mut blocked = M::splat(false);
    if let Some((h, _)) = world.ground {
        let t = (h - o.y) / d.y;
        blocked = t.gt(F::splat(0.0)) & t.lt(t_max);
    }
    let mut open = live.and_not(blocked);
    for a in &world.areas {
        for i in open.lanes() {
            if a.intersect(&Ray::new(o.at(i), d.at(i)), t_max.at(i))
                .is_some()
            {
                blocked.0[i] = true;
            }
        }
        open = live.and_not(blocked);
    }
    for i in open.lanes() {
        if world
            .stone
            .occluded(&Ray::new(o.at(i), d.at(i)), t_max.at(i))
        {
            blocked.0[i] = true;
        }
    }
    blocked & live
}
