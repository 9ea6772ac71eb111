//! Manifold next-event estimation through one refracting interface (Hanika, Droske & Fascione,
//! "Manifold Next Event Estimation", Computer Graphics Forum 34(4), EGSR 2015), issue 18.
//!
//! A platelet or a medium point inside a smooth-bodied stone cannot see a light: every path to a
//! light leaves through the boundary, which refracts it. Ordinary next-event estimation has no
//! shadow ray to trace, and BSDF sampling finds a *small* light through the boundary rarely —
//! the sparkle of a small hard light in a platelet is a firefly. The manifold walk finds the
//! refracted connection instead: given the vertex `x0` inside and a point `x2` sampled on a
//! light, it solves for the point `x1` on the boundary where Snell's law bends the ray from `x0`
//! onto `x2`.
//!
//! **The walk** (Hanika et al. §4, here parameterised by the direction at `x0`, which keeps `x1`
//! on the boundary by construction: `x1(d)` is the first boundary hit of the ray `(x0, d)`). The
//! constraint is their generalised half-vector: with `u` the unit direction from `x1` to `x2` and
//! `n` the shading normal at `x1`, Snell's law holds exactly where `η d − u` is parallel to `n`,
//! so `C(d)` is the tangential part of `η d − u` (in the tangent basis at `x1`). Unlike "the
//! refracted direction minus `u`", it is defined at every `d` that reaches the boundary, also
//! beyond the critical angle, so a walk can pass through directions that would be totally
//! reflected on its way to the solution (with the refracted form, walks from vertices near the
//! boundary stalled at the critical angle and the images of tests/platelets/manifold.rs came out
//! 5–6 % darker than BSDF sampling's; with this one they agree within noise). Newton's method on the two tangent coordinates of `d`,
//! seeded with the straight line `x0 → x2`, with the Jacobian by forward differences (the
//! boundary may be any solid or mesh, so its curvature is not available in closed form), a step
//! bounded by [`MAX_STEP`] and halved while the residual grows, at most [`MAX_ITERATIONS`]
//! iterations; if that fails, a continuation in the index from `η = 1` ([`solve`]). A solution
//! must refract onto the light (the refracted ray heads for `x2`). Light points no refracted ray
//! from `x0` reaches (near the boundary, many are: total internal reflection closes part of the
//! sky) have no solution and contribute nothing, as they should; a reachable point the walk misses
//! is the known bias of MNEE — measured in tests/platelets/manifold.rs: none missed there.
//!
//! **The measure.** The light is sampled by area, so the estimate needs `dω0/dA2`, the solid angle
//! at `x0` per unit area on the light along the refracted path (Hanika et al.'s generalised
//! geometry term). By the implicit function theorem on `C(d, x2) = 0`,
//! `|dω0/dA2| = |det ∂C/∂x2| / |det ∂C/∂d|`: `∂C/∂x2 = −P (I − u uᵀ)/L` on the light's plane
//! (`P` the tangential projection at `x1`, `L = |x2 − x1|`) in closed form, and `∂C/∂d` by
//! central differences at the solution (tangent coordinates of `d` measure solid angle there).
//! Without an interface (`η = 1`) this is exactly `cos θ_light / |x2 − x0|²` (tested), and through
//! a glass sphere its integral over a light equals the solid angle of the refracted rays that
//! reach it (tested by shooting).
//!
//! **Combination with BSDF sampling.** A path that BSDF sampling finds — vertex, one specular
//! refraction out through the boundary, light — is the same path the walk would have found; the
//! two are weighted by the power heuristic over the densities of the direction at `x0`: the
//! walk's `p_pick · p_A / |dω0/dA2|` and BSDF sampling's `p_bsdf(d) · (1 − F)` (the smooth
//! boundary picks transmission with probability `1 − F`). The BSDF side recomputes `|dω0/dA2|` at
//! the path it found ([`density`]).

use super::world::World;
use crate::bsdf::{fresnel, refract};
use crate::geometry::{Frame, Ray, StoneHit, offset_origin};
use crate::light::Area;
use crate::platelet::PlateletId;
use crate::spectrum::Spectral;
use glam::{Vec2, Vec3};

/// Most Newton iterations of one walk.
pub const MAX_ITERATIONS: u32 = 24;
/// Largest change of direction per Newton step, radians.
pub const MAX_STEP: f32 = 0.2;
/// The walk has converged when the refracted direction is within this angle (radians) of the
/// direction to the light point.
pub const TOLERANCE: f32 = 1e-5;
/// Finite-difference step of the constraint's Jacobian, radians.
const FD_STEP: f32 = 1e-3;
/// Most halvings of one Newton step while the residual grows.
const MAX_HALVINGS: u32 = 6;

/// What the walk needs of the scene: the boundary and the lights it connects to.
#[derive(Clone, Debug, PartialEq)]
pub struct ManifoldSetup {
    /// The boundary's IOR, inside over outside.
    pub eta: f32,
    /// The boundary's material index (what the surface map gives where it shows the body).
    pub boundary: u32,
    /// Area lights the walk connects to: index and selection probability (∝ power).
    pub lights: Vec<(usize, f32)>,
}

impl ManifoldSetup {
    /// The setup for a smooth boundary of relative IOR `eta` (material `boundary`) and the area
    /// lights of the scene; `None` when no light emits.
    pub fn new(eta: f32, boundary: u32, areas: &[Area]) -> Option<ManifoldSetup> {
        let power: Vec<f32> = areas
            .iter()
            .map(|a| a.power())
            .map(|p| if p.is_finite() { p } else { 0.0 })
            .collect();
        let total: f32 = power.iter().sum();
        (total > 0.0).then(|| ManifoldSetup {
            eta,
            boundary,
            lights: power
                .iter()
                .enumerate()
                .filter(|(_, p)| **p > 0.0)
                .map(|(i, p)| (i, p / total))
                .collect(),
        })
    }

    /// Picks a light with `u ∈ [0, 1)`: its area-light index and probability.
    pub fn pick(&self, u: f32) -> Option<(usize, f32)> {
        let mut acc = 0.0;
        for &(i, p) in &self.lights {
            acc += p;
            if u < acc {
                return Some((i, p));
            }
        }
        self.lights.last().copied()
    }

    /// The probability [`pick`](Self::pick) gives area light `index`.
    pub fn probability(&self, index: usize) -> f32 {
        self.lights
            .iter()
            .find(|(i, _)| *i == index)
            .map_or(0.0, |(_, p)| *p)
    }
}

/// Where a direction from the vertex leaves the stone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Exit {
    /// The boundary point `x1`, world space.
    pub p: Vec3,
    /// Object-space `x1` (for the surface map).
    pub p_object: Vec3,
    /// Unit geometric normal at `x1`, out of the stone.
    pub ng: Vec3,
    /// Unit shading normal at `x1`, out of the stone (Snell's law uses it, as the boundary BSDF).
    pub n: Vec3,
    /// Distance from the vertex to `x1`, world units.
    pub t: f32,
    /// The refracted direction leaving `x1` outward (unit).
    pub out: Vec3,
    /// Cosine between the direction inside and `n` (> 0).
    pub cos_inside: f32,
}

/// A refracted connection from a vertex to a point on a light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Connection {
    /// Unit direction at the vertex, world space.
    pub d: Vec3,
    /// Where it leaves the stone.
    pub exit: Exit,
    /// Distance from `x1` to the light point, world units.
    pub dist: f32,
    /// `|dω0/dA2|`: solid angle at the vertex per unit light area, world units⁻².
    pub jacobian: f32,
}

/// The first boundary point along `(x0, d)` and the direction refracted out of it; `None` if the
/// ray does not leave the stone there (no hit, it enters instead, or total internal reflection).
///
/// # Arguments
/// * `eta` – IOR inside over outside.
pub fn exit(world: &World, x0: Vec3, d: Vec3, eta: f32) -> Option<Exit> {
    let (h, cos_inside) = boundary(world, x0, d)?;
    // `refract` takes the direction away from the surface on the incident side.
    let out = refract(-d, h.ns, eta)?;
    Some(Exit {
        p: h.p,
        p_object: h.p_object,
        ng: h.ng,
        n: h.ns,
        t: h.t,
        out,
        cos_inside,
    })
}

/// The boundary point the ray `(x0, d)` leaves the stone through, and `cos` of `d` with its
/// shading normal (> 0).
#[inline]
fn boundary(world: &World, x0: Vec3, d: Vec3) -> Option<(StoneHit, f32)> {
    let h = world.stone.intersect(&Ray::new(x0, d), f32::INFINITY)?;
    let c = h.ns.dot(d);
    (h.ng.dot(d) > 0.0 && c > 0.0).then_some((h, c))
}

/// The constraint at direction `d`: the tangential part (3-D, perpendicular to the shading normal
/// at `x1(d)`) of the generalised half-vector `η d − u`, with `u` the unit direction from `x1` to
/// `x2` — zero exactly where Snell's law bends `d` onto `u` — and the boundary hit.
#[inline]
fn constraint(world: &World, x0: Vec3, d: Vec3, x2: Vec3, eta: f32) -> Option<(Vec3, StoneHit)> {
    let (h, _) = boundary(world, x0, d)?;
    let u = (x2 - h.p).try_normalize()?;
    let v = eta * d - u;
    Some((v - h.ns * v.dot(h.ns), h))
}

/// `d` turned by the tangent coordinates `a` (radians, small) in `frame` (whose normal is `d`).
#[inline]
fn turn(frame: &Frame, a: Vec2) -> Vec3 {
    (frame.n + frame.s * a.x + frame.t * a.y).normalize()
}

/// `∂C/∂a` in the coordinates `basis`: columns for the two tangent directions of `d`, by forward
/// (`central: false`, with `c0` the constraint at `d`) or central differences. `None` if a
/// perturbed ray does not leave the stone.
#[allow(clippy::too_many_arguments)]
fn constraint_jacobian(
    world: &World,
    x0: Vec3,
    d: Vec3,
    x2: Vec3,
    eta: f32,
    basis: (Vec3, Vec3),
    c0: Vec3,
    central: bool,
) -> Option<[[f32; 2]; 2]> {
    let f = Frame::from_normal(d);
    let mut j = [[0.0; 2]; 2];
    for (col, dir) in [Vec2::X, Vec2::Y].into_iter().enumerate() {
        let plus = constraint(world, x0, turn(&f, dir * FD_STEP), x2, eta)?.0;
        let diff = if central {
            let minus = constraint(world, x0, turn(&f, -dir * FD_STEP), x2, eta)?.0;
            (plus - minus) / (2.0 * FD_STEP)
        } else {
            (plus - c0) / FD_STEP
        };
        j[0][col] = diff.dot(basis.0);
        j[1][col] = diff.dot(basis.1);
    }
    Some(j)
}

#[inline]
fn det(j: &[[f32; 2]; 2]) -> f32 {
    j[0][0] * j[1][1] - j[0][1] * j[1][0]
}

/// Solves for the refracted connection from `x0` (inside the stone) to `x2` (a light point whose
/// emitting plane has unit normal `n_light`); `None` if the walk does not converge.
///
/// Seeded with the straight line `x0 → x2`; if Newton's method fails from there, it follows the
/// solution from `η = 1`, where the straight line is exact, through [`STAGES`] increasing indices
/// to `eta` (a continuation: each stage starts from the last one's solution).
///
/// # Arguments
/// * `eta` – the boundary's IOR inside over outside.
pub fn solve(world: &World, x0: Vec3, x2: Vec3, n_light: Vec3, eta: f32) -> Option<Connection> {
    let seed = (x2 - x0).try_normalize()?;
    let d = match newton(world, x0, x2, eta, seed, TOLERANCE) {
        Some(d) => d,
        None => {
            let mut d = seed;
            for k in 1..=STAGES {
                let eta_k = 1.0 + (eta - 1.0) * k as f32 / STAGES as f32;
                let tol = if k == STAGES {
                    TOLERANCE
                } else {
                    STAGE_TOLERANCE
                };
                d = newton(world, x0, x2, eta_k, d, tol)?;
            }
            d
        }
    };
    let e = exit(world, x0, d, eta)?;
    let to_light = x2 - e.p;
    let dist = to_light.length();
    // Snell's law holds and the refracted ray really heads for the light.
    if e.out.dot(to_light) < dist * (1.0 - 1e-3) {
        return None;
    }
    let jacobian = jacobian(world, x0, d, x2, n_light, eta)?;
    Some(Connection {
        d,
        exit: e,
        dist,
        jacobian,
    })
}

/// Stages of the continuation in the index.
pub const STAGES: u32 = 4;
/// Convergence of an intermediate stage.
const STAGE_TOLERANCE: f32 = 1e-3;

/// Newton's method on the direction at `x0` from `seed` (module docs) with Broyden's rank-one
/// updates of the Jacobian (Broyden, "A class of methods for solving nonlinear simultaneous
/// equations", Math. Comp. 19, 1965): the finite-difference Jacobian is taken once at the seed
/// (two ray casts) and then updated from each step's change of the constraint, so an iteration
/// costs one cast; where a step fails to lower the constraint even when halved, the Jacobian is
/// taken afresh by differences, once per failure. The coordinates stay those of the seed: `d` in
/// the tangent frame of `seed`, the constraint in the tangent basis of the seed's boundary point.
/// Returns the converged direction, or `None`.
fn newton(world: &World, x0: Vec3, x2: Vec3, eta: f32, seed: Vec3, tolerance: f32) -> Option<Vec3> {
    let frame = Frame::from_normal(seed);
    let (mut c, h) = constraint(world, x0, seed, x2, eta)?;
    let b = Frame::from_normal(h.ns);
    let basis = (b.s, b.t);
    let coords = |c: Vec3| Vec2::new(c.dot(basis.0), c.dot(basis.1));
    let mut a = Vec2::ZERO;
    let mut d = seed;
    let mut j = constraint_jacobian(world, x0, d, x2, eta, basis, c, false)?;
    let mut fresh = true;
    for _ in 0..MAX_ITERATIONS {
        if c.length() < tolerance {
            return Some(d);
        }
        let dt = det(&j);
        let r = coords(c);
        let mut step = if dt.abs() > 1e-12 && dt.is_finite() {
            -Vec2::new(j[1][1] * r.x - j[0][1] * r.y, j[0][0] * r.y - j[1][0] * r.x) / dt
        } else {
            Vec2::ZERO
        };
        if step.length() > MAX_STEP {
            step *= MAX_STEP / step.length();
        }
        let mut accepted = None;
        if step.length() > 0.0 {
            for _ in 0..=MAX_HALVINGS {
                let trial = turn(&frame, a + step);
                if let Some((ct, _)) = constraint(world, x0, trial, x2, eta)
                    && ct.length() < c.length()
                {
                    accepted = Some((trial, ct));
                    break;
                }
                step *= 0.5;
            }
        }
        match accepted {
            Some((trial, ct)) => {
                // Broyden: J += (Δr − J Δa) Δaᵀ / |Δa|².
                let dr = coords(ct) - r;
                let jda = Vec2::new(
                    j[0][0] * step.x + j[0][1] * step.y,
                    j[1][0] * step.x + j[1][1] * step.y,
                );
                let k = (dr - jda) / step.length_squared();
                j[0][0] += k.x * step.x;
                j[0][1] += k.x * step.y;
                j[1][0] += k.y * step.x;
                j[1][1] += k.y * step.y;
                (a, d, c) = (a + step, trial, ct);
                fresh = false;
            }
            // A step from a fresh Jacobian that cannot lower the constraint: give up.
            None if fresh => return None,
            None => {
                j = finite_difference_at(world, x0, &frame, a, x2, eta, basis, c)?;
                fresh = true;
            }
        }
    }
    (c.length() < tolerance).then_some(d)
}

/// The forward-difference Jacobian of the constraint in the seed's coordinates at `a` (the
/// constraint there is `c`).
#[allow(clippy::too_many_arguments)]
fn finite_difference_at(
    world: &World,
    x0: Vec3,
    frame: &Frame,
    a: Vec2,
    x2: Vec3,
    eta: f32,
    basis: (Vec3, Vec3),
    c: Vec3,
) -> Option<[[f32; 2]; 2]> {
    let mut j = [[0.0; 2]; 2];
    for (col, dir) in [Vec2::X, Vec2::Y].into_iter().enumerate() {
        let plus = constraint(world, x0, turn(frame, a + dir * FD_STEP), x2, eta)?.0;
        let diff = (plus - c) / FD_STEP;
        j[0][col] = diff.dot(basis.0);
        j[1][col] = diff.dot(basis.1);
    }
    Some(j)
}

/// `|dω0/dA2|` (world units⁻²) of the refracted path from `x0` along `d` to the light point `x2`
/// (module docs): `|det ∂C/∂x2| / |det ∂C/∂d|` in the tangent basis at `x1`, `∂C/∂x2` in closed
/// form on the light's plane and `∂C/∂d` by central differences. `None` if a perturbed ray does
/// not leave the stone or the map is singular.
pub fn jacobian(
    world: &World,
    x0: Vec3,
    d: Vec3,
    x2: Vec3,
    n_light: Vec3,
    eta: f32,
) -> Option<f32> {
    let (h, _) = boundary(world, x0, d)?;
    let to_light = x2 - h.p;
    let l = to_light.length();
    let u = to_light / l;
    let b = Frame::from_normal(h.ns);
    let basis = (b.s, b.t);
    let jd = constraint_jacobian(world, x0, d, x2, eta, basis, Vec3::ZERO, true)?;
    // ∂C/∂x2 = −P_tangent (I − u uᵀ) / L on the light's plane (axes a, b).
    let light = Frame::from_normal(n_light);
    let col = |e: Vec3| -(e - u * u.dot(e)) / l;
    let (ca, cb) = (col(light.s), col(light.t));
    let jx = [
        [ca.dot(basis.0), cb.dot(basis.0)],
        [ca.dot(basis.1), cb.dot(basis.1)],
    ];
    let jac = det(&jx).abs() / det(&jd).abs();
    (jac.is_finite() && jac > 0.0).then_some(jac)
}

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

    #[test]
    fn turn_moves_by_the_tangent_angle() {
        let f = Frame::from_normal(Vec3::new(0.3, -0.2, 0.9).normalize());
        let d = turn(&f, Vec2::new(1e-3, 0.0));
        // The angle from its sine (acos near 1 loses the digits in f32).
        let angle = d.cross(f.n).length().asin();
        assert!((angle - 1e-3).abs() < 2e-6, "{angle}");
        assert!(d.dot(f.s) > 0.0);
    }
}
