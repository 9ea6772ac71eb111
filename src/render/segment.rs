//! What one segment of a camera path meets first (module docs of [`super::integrator`]): the
//! world's surfaces, and inside the body the platelets and the statistical flakes ahead of the
//! boundary; with a medium, the segment's numbers for its free flight, and at a scattering point
//! inside the body the light a manifold walk finds through the boundary.

use super::direct::{Strategy, manifold_weight};
use super::manifold::{self, Chain, ManifoldSetup, WalkNumbers, WalkVertex};
use super::path::{ManifoldVertex, PathState};
use super::polarised::{StokesAov, stokes_add};
use super::world::{Hit, World};
use crate::geometry::Ray;
use crate::medium::phase::{HenyeyGreenstein, PhaseSample};
use crate::platelet::PlateletId;
use crate::sampler::{PixelSampler, slots};
use crate::spectrum::Spectral;
use glam::{Vec2, Vec3};

/// What [`meet`] found along a segment besides its nearest hit.
pub(super) struct Meeting {
    /// The boundary ahead when a platelet or a flake hides it.
    pub hidden: Option<Hit>,
    /// With a medium, the segment's numbers for its free flight: the pair of
    /// [`slots::medium`] and the hero channel (chosen by the first segment from that pair's `x`).
    pub flight: Option<(Vec2, usize)>,
}

/// The nearest hit of `ray` (the path's segment at `path.depth`) into `found`, which holds the
/// world's surface hit, and what the segment needs for its free flight; sets the path's hero
/// channel on its first segment in a medium.
///
/// Platelets are walked only up to the boundary (a ray inside the body that meets no boundary is
/// outside the stone by rounding, where the population's discs are not part of it). The medium's
/// numbers are addressed by slot, so drawing them before the walk changes nothing; without
/// statistical flakes the walk also stops at the medium's sampled collision
/// ([`crate::medium::Medium::collision`]): a platelet beyond it is never met first, as the free
/// flight scatters before it either way.
#[inline(always)]
pub(super) fn meet<S: Spectral>(
    world: &World,
    ray: &Ray,
    path: &mut PathState<S>,
    sampler: &PixelSampler,
    found: &mut Option<Hit>,
) -> Meeting {
    let mut hidden: Option<Hit> = None;
    let flight = world.medium.then(|| {
        let u = sampler.get2d_at(slots::medium(path.depth));
        let hero = *path
            .hero
            .get_or_insert(((u.x * S::CHANNELS as f32) as usize).min(S::CHANNELS - 1));
        (u, hero)
    });
    let inside = path.medium == world.interior;
    let collision = match flight {
        Some((u, hero)) if world.flakes.is_none() && !world.platelets.is_empty() => {
            world.media[usize::from(path.medium.0)].collision::<S>(hero, u.y, &path.lambda)
        }
        _ => f32::INFINITY,
    };
    if !world.platelets.is_empty()
        && inside
        && let Some(t_max) = found.as_ref().map(Hit::t)
        && let Some(h) = world.platelet_hit(ray, t_max.min(collision), path.platelet)
    {
        hidden = found.replace(h);
    }
    if let Some(flakes) = &world.flakes
        && inside
        && let Some(t_max) = found.as_ref().map(Hit::t)
    {
        let u = sampler.get2d_at(slots::platelet(path.depth));
        if let Some(c) = flakes.collide(ray.origin, ray.dir, t_max, u) {
            hidden = found.replace(Hit::Platelet {
                t: c.t,
                p: ray.at(c.t),
                n: c.normal,
                material: c.material,
                id: PlateletId {
                    population: u32::MAX,
                    cell: [0; 3],
                    index: 0,
                },
            });
        }
    }
    Meeting { hidden, flight }
}

/// Manifold next-event estimation from a medium scattering point inside the body: one walk out
/// through the boundary ([`manifold::sample_light`]) from `p` for the segment arriving along
/// `dir`, its light weighted by the phase function `phase` against the continuation `ps`
/// ([`manifold_weight`]) and added to the path (and the Stokes AOVs with `STOKES`). Returns the
/// vertex the continuation keeps, so that a light it reaches is weighted against the walk.
///
/// # Arguments
/// * `world`, `setup`, `strategy` – the scene, its walks and the direct-light estimators.
/// * `sampler` – the path's sampler, at the vertex's light numbers (one 1-D and two 2-D draws).
/// * `(p, dir)` – the scattering point and the unit direction of the segment arriving there.
/// * `phase`, `ps` – the medium's phase function and the continuation it sampled.
/// * `path`, `aov` – the path's state and its Stokes AOVs.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn medium_vertex_light<S: Spectral, const STOKES: bool>(
    world: &World,
    setup: &ManifoldSetup,
    strategy: Strategy,
    sampler: &mut PixelSampler,
    (p, dir): (Vec3, Vec3),
    phase: &HenyeyGreenstein,
    ps: &PhaseSample,
    path: &mut PathState<S>,
    aov: &mut Option<StokesAov<S>>,
) -> ManifoldVertex {
    let (u_light, u_point, u_more) = (sampler.get1d(), sampler.get2d(), sampler.get2d());
    let v = WalkVertex {
        p,
        chain: Chain::Out,
        skip: None,
        ng: Vec3::ZERO,
    };
    let u = WalkNumbers {
        light: u_light,
        point: u_point,
        map: [u_more.x; 2],
        walk: u_more.y,
    };
    if let Some(ml) = manifold::sample_light::<S>(world, setup, &v, &u, &path.lambda) {
        let f = phase.value(-dir, ml.d);
        let w = manifold_weight(strategy, ml.pdf, f * ml.cross, true);
        let c = path.throughput() * ml.value * (f * w);
        if c.is_valid() {
            let added = path.gather(c);
            if STOKES {
                stokes_add(aov, added);
            }
        }
    }
    ManifoldVertex {
        p,
        d: ps.wi,
        pdf: ps.pdf,
        chain: Chain::Out,
        crossings: 0,
    }
}
