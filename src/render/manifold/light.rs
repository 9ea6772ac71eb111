//! The walk as a light sample: picking the light and the point, occlusion, transmittance and the
//! density of the direction (module docs in [`super`]).

use super::ManifoldSetup;
use super::chain::Chain;
use super::walk::{last, solve_with_effort};
use crate::bsdf::fresnel;
use crate::geometry::{Ray, offset_origin};
use crate::platelet::PlateletId;
use crate::render::world::World;
use crate::spectrum::Spectral;
use glam::{Vec2, Vec3};

/// Light reaching a vertex through the boundary from one sampled light point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ManifoldLight<S> {
    /// Unit direction at the vertex toward the boundary point (world space).
    pub d: Vec3,
    /// The radiance arriving along `d` divided by [`pdf`](Self::pdf): transmittance of the
    /// interior, the boundary's `1 − F` at each crossing (and `η²` where the path ends inside),
    /// the light's radiance.
    pub value: S,
    /// Density of `d` per steradian with which the walk produced it:
    /// `q · p_pick / (A · |dω0/dA2|)`.
    pub pdf: f32,
    /// The product of the boundary's transmittances `1 − F` over the crossings: the probability
    /// with which BSDF sampling continues the path through them (for the MIS weight).
    pub cross: f32,
}

/// Where a walk starts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WalkVertex {
    /// The vertex: inside the body kept off the boundary; outside, the surface point.
    pub p: Vec3,
    /// [`Chain::Out`] from inside the body, [`Chain::Through`] from a surface outside it.
    pub chain: Chain,
    /// The platelet `p` lies on (it cannot occlude its own light).
    pub skip: Option<PlateletId>,
    /// Outside: the surface's unit geometric normal at `p` (the occlusion ray to the entry point
    /// leaves from `p` moved along it); unused inside.
    pub ng: Vec3,
}

/// The random numbers of one walk.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WalkNumbers {
    /// Picks the light.
    pub light: f32,
    /// The point on it.
    pub point: Vec2,
    /// The map's switch numbers at the exit and entry points (a stochastic blend may show an
    /// opaque cell there, which blocks the light).
    pub map: [f32; 2],
    /// Decides whether the walk runs ([`walk_probability`]).
    pub walk: f32,
}

/// Manifold next-event estimation from `v`: picks an area light, a point on it, walks to the
/// refracted connection and returns the light it brings, unoccluded (no platelet on the segment
/// inside, nothing outside between the vertex and the entry or between the exit and the light),
/// or `None`.
///
/// # Arguments
/// * `lambda` – the path's wavelengths.
pub fn sample_light<S: Spectral>(
    world: &World,
    setup: &ManifoldSetup,
    v: &WalkVertex,
    u: &WalkNumbers,
    lambda: &S::Wavelengths,
) -> Option<ManifoldLight<S>> {
    let (index, p_pick) = setup.pick(u.light)?;
    let light = &world.areas[index];
    let x2 = light.sample_point(u.point);
    let q = walk_probability(world, setup, v.p, x2, v.chain);
    if !(u.walk < q) {
        return None;
    }
    let c = solve_with_effort(
        world,
        (v.p, x2),
        light.normal(),
        setup.eta,
        v.chain,
        setup.effort,
    )?;
    let x1 = c.exit.p;
    let u_out = (x2 - x1) / c.dist;
    let le = light.emitted(-u_out);
    if le.is_black() {
        return None;
    }
    // The segment inside the body: from the vertex, or from the entry point. No platelet may
    // lie on it; tested first, as it turns away more connections than the map below for less
    // work per connection (each test only refuses, so their order changes no result).
    let (start, dir) = match c.exit.entry {
        None => (v.p, c.d),
        Some(e) => (e.origin, e.inside),
    };
    if !world.platelets.is_empty()
        && world
            .platelet_hit(&Ray::new(start, dir), c.exit.t, v.skip)
            .is_some()
    {
        return None;
    }
    // The map must show the bare boundary where the path crosses it (no opaque cell, no facet).
    let bare = |p_object: Vec3, u_map: f32| {
        let look = world.map.lookup(p_object, u_map);
        look.material == setup.boundary && !(world.facet_bump && look.facet.is_some())
    };
    if !bare(c.exit.p_object, u.map[0]) {
        return None;
    }
    if let Some(e) = c.exit.entry {
        if !bare(e.p_object, u.map[1]) {
            return None;
        }
        if blocked(world, offset_origin(v.p, v.ng, c.d), e.p) {
            return None;
        }
    }
    if blocked(world, offset_origin(x1, c.exit.ng, u_out), x2) {
        return None;
    }
    let mut tr = if world.medium {
        world.media[usize::from(world.interior.0)].transmittance::<S>(c.exit.t, lambda)
    } else {
        S::ONE
    };
    if let Some(flakes) = &world.flakes {
        tr *= (-flakes.optical_depth(start, dir, c.exit.t)).exp();
    }
    let out = transmittance(c.exit.cos_inside, setup.eta);
    // Radiance entering the body is scaled by η², leaving it by 1/η² (pbrt-v4 §9.5.2).
    let (cross, scale) = match c.exit.entry {
        None => (out, setup.eta * setup.eta),
        Some(e) => (
            out * (1.0 - fresnel::dielectric(e.cos_outside, setup.eta)),
            1.0,
        ),
    };
    let pdf = q * p_pick / (light.area() * c.jacobian);
    let value = tr * light.emission::<S>(le, lambda) * (cross * scale / pdf);
    (pdf.is_finite() && pdf > 0.0 && value.is_valid()).then_some(ManifoldLight {
        d: c.d,
        value,
        pdf,
        cross,
    })
}

/// Whether anything blocks the segment from `origin` to just short of `target` (1e-3 of its
/// length), aimed at `target`: the surface `target` lies on must not count. The ray is aimed at
/// the target, not cast along the walk's direction: the origin is offset along a normal, and
/// over the 0.002 film of air under a gem a ray along the walk's direction from the offset
/// origin met the base 2.5e-5 early, inside any margin short of the target, so the base
/// occluded its own entry point (tests/platelets/caustics.rs,
/// `walk_through_a_cabochon_on_a_film_of_air`).
#[inline]
fn blocked(world: &World, origin: Vec3, target: Vec3) -> bool {
    let to = target - origin;
    let dist = to.length();
    dist > 0.0 && world.occluded(&Ray::new(origin, to / dist), dist * (1.0 - 1e-3))
}

/// The density per steradian with which [`sample_light`] would produce the direction `d` at
/// `x0` that reaches point `x2` on area light `index` through `chain` (for the MIS weight of the
/// same path found by BSDF sampling). The walk is run from `x0` to `x2`: a walk is a
/// deterministic function of the light point, so where it converges to another connection (a
/// chain through a lens can have several) or to none, it never produces this path and the
/// density is 0 — which keeps the weights of the two techniques summing to one.
pub fn density(
    world: &World,
    setup: &ManifoldSetup,
    x0: Vec3,
    d: Vec3,
    x2: Vec3,
    index: usize,
    chain: Chain,
) -> f32 {
    let light = &world.areas[index];
    let p_pick = setup.probability(index);
    if !(p_pick > 0.0) {
        return 0.0;
    }
    match solve_with_effort(
        world,
        (x0, x2),
        light.normal(),
        setup.eta,
        chain,
        setup.effort,
    ) {
        Some(c) if c.d.dot(d) > 1.0 - SAME_DIRECTION => {
            let p = walk_probability(world, setup, x0, x2, chain) * p_pick
                / (light.area() * c.jacobian);
            if p.is_finite() { p } else { 0.0 }
        }
        _ => 0.0,
    }
}

/// `1 − cos` of the largest angle (≈ 4.5 mrad) between the walk's solution and a BSDF-sampled
/// direction that counts as the same connection (the walk converges to 1e-5; distinct solutions
/// of one chain lie much further apart).
const SAME_DIRECTION: f32 = 1e-5;

/// Transmittance below which the walk is run only sometimes ([`walk_probability`]).
pub const WALK_THRESHOLD: f32 = 0.05;

/// The probability with which the walk runs from `x0` toward the light point `x2`: 1 unless the
/// interior in front of it is thick — `min(1, T/`[`WALK_THRESHOLD`]`)`, with `T` the largest
/// per-channel transmittance (medium and statistical platelets) over the straight line's
/// segment inside the body. A walk costs tens of ray casts and deep in a dense medium brings next to nothing
/// (the milky stone scatters every 0.05 units); running it with probability `q` and dividing by
/// `q` keeps the estimate unbiased, and `q` enters its density for the MIS weight. 1 without
/// tracing the line where no line inside can be that thick ([`ManifoldSetup::always`]).
pub fn walk_probability(
    world: &World,
    setup: &ManifoldSetup,
    x0: Vec3,
    x2: Vec3,
    chain: Chain,
) -> f32 {
    if setup.always || (!world.medium && world.flakes.is_none()) {
        return 1.0;
    }
    let Some(d) = (x2 - x0).try_normalize() else {
        return 1.0;
    };
    // The straight line's segment inside the body (η = 1: no bending).
    let Some((h, _, _)) = last(world, &world.stone.fan(x0), d, 1.0, chain) else {
        return 1.0;
    };
    let mut tau = if world.medium {
        world.media[usize::from(world.interior.0)].min_extinction() * h.t
    } else {
        0.0
    };
    if let Some(flakes) = &world.flakes {
        // The majorant (cheap); `q` is a heuristic: any `q > 0` keeps the estimate unbiased.
        tau += flakes.sigma(d) * h.t;
    }
    ((-tau).exp() / WALK_THRESHOLD).clamp(1e-6, 1.0)
}

/// Fresnel transmittance `1 − F` of the boundary for a direction inside meeting it at
/// `cos_inside` (`eta` inside over outside).
#[inline]
pub fn transmittance(cos_inside: f32, eta: f32) -> f32 {
    1.0 - fresnel::dielectric(-cos_inside, eta)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transmittance_is_one_minus_fresnel_inside() {
        // Normal incidence from glass n = 1.5: F = ((1.5 − 1)/(1.5 + 1))² = 0.04.
        assert!((transmittance(1.0, 1.5) - 0.96).abs() < 1e-6);
        // Beyond the critical angle (41.8° for 1.5) nothing leaves.
        assert_eq!(transmittance(40f32.to_radians().sin(), 1.5), 0.0);
    }

    /// A sphere of radius 1 (longest chord 2, bounds diagonal 2√3) whose medium keeps `colour`
    /// over `distance`, under a disc light.
    fn world(colour: f32, distance: f32) -> World {
        let body = format!("(ior: 1.5, medium: (colour: Gray({colour}), distance: {distance}))");
        super::super::test_scene::test_world("Sphere(radius: 1.0)", &body)
    }

    /// Where the bound says every walk runs, tracing the straight line gives probability 1 for
    /// every pair too (2 000 pairs out of and through the sphere); a medium whose longest chord is
    /// thicker than the threshold (σ = 2 per unit: τ up to 4 > ln 20) is left to the trace, and
    /// a clear one (σ ≈ 0.03: the GemCad quartz's) is not.
    #[test]
    fn the_clear_interior_bound_agrees_with_the_traced_probability() {
        let clear = world(0.95, 1.6);
        let setup = clear.manifold.clone().expect("walks");
        assert!(setup.always);
        let traced = ManifoldSetup {
            always: false,
            ..setup.clone()
        };
        let mut rng = crate::sampler::Rng::new(5);
        let mut inside = 0;
        for _ in 0..2_000 {
            let p = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 4.0 - Vec3::splat(2.0);
            let x2 = Vec3::new(rng.uniform() - 0.5, 4.0, rng.uniform() - 0.5);
            let chain = if clear.stone.contains(p) {
                inside += 1;
                Chain::Out
            } else {
                Chain::Through
            };
            assert_eq!(walk_probability(&clear, &traced, p, x2, chain), 1.0);
            assert_eq!(walk_probability(&clear, &setup, p, x2, chain), 1.0);
        }
        assert!(inside > 100, "{inside}");
        let dense = world((-4.0f32).exp(), 2.0);
        let setup = dense.manifold.clone().expect("walks");
        assert!(!setup.always);
        // Through the centre the line is 2 long: τ = 4, so q = e⁻⁴ / 0.05 < 1.
        let q = walk_probability(
            &dense,
            &setup,
            Vec3::new(0.0, -3.0, 0.0),
            Vec3::new(0.0, 4.0, 0.0),
            Chain::Through,
        );
        assert!(q < 0.5, "{q}");
    }
}
