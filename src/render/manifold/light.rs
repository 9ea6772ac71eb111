//! The walk as a light sample: picking the light and the point, occlusion, transmittance and the
//! density of the direction (module docs in [`super`]).

use super::ManifoldSetup;
use super::walk::{boundary, jacobian, solve};
use crate::bsdf::fresnel;
use crate::geometry::{Ray, offset_origin};
use crate::platelet::PlateletId;
use crate::render::world::World;
use crate::spectrum::Spectral;
use glam::{Vec2, Vec3};

/// Light reaching a vertex inside the stone through the boundary from one sampled light point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ManifoldLight<S> {
    /// Unit direction at the vertex toward the boundary point (world space).
    pub d: Vec3,
    /// The radiance arriving along `d` divided by [`pdf`](Self::pdf): transmittance of the
    /// interior, `(1 − F) η²` of the boundary, the light's radiance.
    pub value: S,
    /// Density of `d` per steradian with which the walk produced it:
    /// `p_pick / (A · |dω0/dA2|)`.
    pub pdf: f32,
    /// The boundary's transmittance `1 − F`: the probability with which BSDF sampling continues
    /// the path through the boundary (for the MIS weight).
    pub cross: f32,
}

/// Manifold next-event estimation from the vertex `x0` inside the stone: picks an area light,
/// a point on it, walks to the refracted connection and returns the light it brings, unoccluded
/// (no platelet between `x0` and the boundary, nothing outside between the boundary and the
/// light), or `None`.
///
/// # Arguments
/// * `skip` – the platelet `x0` lies on (it cannot occlude its own light).
/// * `u_light` – picks the light; `u_point` – the point on it.
/// * `u_map` – the map's switch number at the boundary point (a stochastic blend may show an
///   opaque cell there, which blocks the light).
/// * `lambda` – the path's wavelengths.
#[allow(clippy::too_many_arguments)]
pub fn sample_light<S: Spectral>(
    world: &World,
    setup: &ManifoldSetup,
    x0: Vec3,
    skip: Option<PlateletId>,
    u_light: f32,
    u_point: Vec2,
    u_map: f32,
    u_walk: f32,
    lambda: &S::Wavelengths,
) -> Option<ManifoldLight<S>> {
    let (index, p_pick) = setup.pick(u_light)?;
    let light = &world.areas[index];
    let x2 = light.sample_point(u_point);
    let q = walk_probability(world, x0, x2);
    if !(u_walk < q) {
        return None;
    }
    let c = solve(world, x0, x2, light.normal(), setup.eta)?;
    let x1 = c.exit.p;
    let u = (x2 - x1) / c.dist;
    let le = light.emitted(-u);
    if le.is_black() {
        return None;
    }
    // The map must show the bare boundary there (no opaque cell, no facet).
    let look = world.map.lookup(c.exit.p_object, u_map);
    if look.material != setup.boundary || (world.facet_bump && look.facet.is_some()) {
        return None;
    }
    if !world.platelets.is_empty()
        && world
            .platelet_hit(&Ray::new(x0, c.d), c.exit.t, skip)
            .is_some()
    {
        return None;
    }
    let origin = offset_origin(x1, c.exit.ng, u);
    let t_max = (c.dist - (origin - x1).length()) * (1.0 - 1e-4);
    if world.occluded(&Ray::new(origin, u), t_max) {
        return None;
    }
    let mut tr = if world.medium {
        world.media[usize::from(world.interior.0)].transmittance::<S>(c.exit.t, lambda)
    } else {
        S::ONE
    };
    if let Some(flakes) = &world.flakes {
        tr *= (-flakes.optical_depth(x0, c.d, c.exit.t)).exp();
    }
    let cross = transmittance(c.exit.cos_inside, setup.eta);
    let pdf = q * p_pick / (light.area() * c.jacobian);
    let value = tr * S::from_unbounded(le, lambda) * (cross * setup.eta * setup.eta / pdf);
    (pdf.is_finite() && pdf > 0.0 && value.is_valid()).then_some(ManifoldLight {
        d: c.d,
        value,
        pdf,
        cross,
    })
}

/// The density per steradian with which [`sample_light`] would produce the direction `d` at
/// `x0` that reaches point `x2` on area light `index` through the boundary (for the MIS weight of
/// the same path found by BSDF sampling); 0 if the walk's measure cannot be computed there.
pub fn density(
    world: &World,
    setup: &ManifoldSetup,
    x0: Vec3,
    d: Vec3,
    x2: Vec3,
    index: usize,
) -> f32 {
    let light = &world.areas[index];
    let p_pick = setup.probability(index);
    if !(p_pick > 0.0) {
        return 0.0;
    }
    match jacobian(world, x0, d, x2, light.normal(), setup.eta) {
        Some(j) => {
            let p = walk_probability(world, x0, x2) * p_pick / (light.area() * j);
            if p.is_finite() { p } else { 0.0 }
        }
        None => 0.0,
    }
}

/// Transmittance below which the walk is run only sometimes ([`walk_probability`]).
pub const WALK_THRESHOLD: f32 = 0.05;

/// The probability with which the walk runs from `x0` toward the light point `x2`: 1 unless the
/// interior in front of it is thick — `min(1, T/`[`WALK_THRESHOLD`]`)`, with `T` the largest
/// per-channel transmittance (medium and statistical platelets) over the straight line to the
/// boundary. A walk costs tens of ray casts and deep in a dense medium brings next to nothing
/// (the milky stone scatters every 0.05 units); running it with probability `q` and dividing by
/// `q` keeps the estimate unbiased, and `q` enters its density for the MIS weight.
pub fn walk_probability(world: &World, x0: Vec3, x2: Vec3) -> f32 {
    if !world.medium && world.flakes.is_none() {
        return 1.0;
    }
    let Some(d) = (x2 - x0).try_normalize() else {
        return 1.0;
    };
    let Some((h, _)) = boundary(world, x0, d) else {
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
}
