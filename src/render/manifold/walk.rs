//! The manifold walk: Newton's method on the direction at the vertex, and the measure of the
//! connection it finds (module docs in [`super`]).

use super::chain::{Chain, Entry, entry};
use super::exact::{self, Linearised};
use super::newton::{MAX_ITERATIONS, Stop, TOLERANCE, WalkEffort, det, step, turn};
use crate::bsdf::refract;
use crate::geometry::{Fan, Frame, StoneHit};
use crate::render::world::World;
use glam::{Vec2, Vec3};

/// Finite-difference step of the constraint's Jacobian, radians.
const FD_STEP: f32 = 1e-3;

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
    /// Length of the segment inside the body that ends at `x1`, world units: from the vertex
    /// ([`Chain::Out`]) or from the entry point ([`Chain::Through`]).
    pub t: f32,
    /// The refracted direction leaving `x1` outward (unit).
    pub out: Vec3,
    /// Cosine between the direction inside and `n` (> 0).
    pub cos_inside: f32,
    /// Where the path entered the body ([`Chain::Through`] only).
    pub entry: Option<Entry>,
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

/// The chain's last boundary point along direction `d` of the rays `from` the vertex (where it
/// leaves the body), the direction arriving there from inside, and the entry point of a
/// [`Chain::Through`].
#[inline]
pub(super) fn last(
    world: &World,
    from: &Fan,
    d: Vec3,
    eta: f32,
    chain: Chain,
) -> Option<(StoneHit, Vec3, Option<Entry>)> {
    match chain {
        Chain::Out => boundary(from, d).map(|(h, _)| (h, d, None)),
        Chain::Through => {
            let e = entry(from, d, eta)?;
            boundary(&world.stone.fan(e.origin), e.inside).map(|(h, _)| (h, e.inside, Some(e)))
        }
    }
}

/// Where the chain from `x0` along `d` leaves the body and the direction refracted out there;
/// `None` if it does not (no hit, it enters where it should leave, or total internal reflection).
///
/// # Arguments
/// * `eta` – IOR inside over outside.
pub fn exit(world: &World, x0: Vec3, d: Vec3, eta: f32, chain: Chain) -> Option<Exit> {
    exit_from(world, &world.stone.fan(x0), d, eta, chain)
}

/// [`exit`] along direction `d` of the rays `from` the vertex.
fn exit_from(world: &World, from: &Fan, d: Vec3, eta: f32, chain: Chain) -> Option<Exit> {
    let (h, inside, entry) = last(world, from, d, eta, chain)?;
    exit_of(h, inside, eta, entry)
}

/// The exit through boundary hit `h` of the direction `inside` arriving there from inside.
fn exit_of(h: StoneHit, inside: Vec3, eta: f32, entry: Option<Entry>) -> Option<Exit> {
    // `refract` takes the direction away from the surface on the incident side.
    let out = refract(-inside, h.ns, eta)?;
    Some(Exit {
        p: h.p,
        p_object: h.p_object,
        ng: h.ng,
        n: h.ns,
        t: h.t,
        out,
        cos_inside: h.ns.dot(inside),
        entry,
    })
}

/// The boundary point the ray along direction `d` of the rays `from` a point inside leaves the
/// stone through, and `cos` of `d` with its shading normal (> 0).
#[inline]
pub(super) fn boundary(from: &Fan, d: Vec3) -> Option<(StoneHit, f32)> {
    let h = from.intersect(d, f32::INFINITY)?;
    let c = h.ns.dot(d);
    (h.ng.dot(d) > 0.0 && c > 0.0).then_some((h, c))
}

/// One walk's problem: connect the vertex `x0` to the light point `x2` through `chain`, across a
/// boundary of index `eta` (inside over outside; the continuation varies it).
#[derive(Clone, Copy)]
struct Problem<'a> {
    world: &'a World,
    /// The stone's rays from `x0` (every step of the walk casts one).
    from: Fan<'a>,
    x2: Vec3,
    eta: f32,
    chain: Chain,
    /// Most halvings of a Newton step ([`WalkEffort::halvings`]).
    halvings: u32,
}

impl Problem<'_> {
    /// The constraint at direction `d`: the tangential part (3-D, perpendicular to the shading
    /// normal at the chain's exit point `x1(d)`) of the generalised half-vector `η w − u`, with
    /// `w` the direction arriving at `x1` from inside (`d` itself for [`Chain::Out`]) and `u` the
    /// unit direction from `x1` to `x2` — zero exactly where Snell's law bends `w` onto `u` — and
    /// the exit hit. The entry refraction of a [`Chain::Through`] holds by construction (it is
    /// traced).
    #[inline]
    fn constraint(&self, d: Vec3) -> Option<(Vec3, StoneHit)> {
        let (h, w, _) = last(self.world, &self.from, d, self.eta, self.chain)?;
        let u = (self.x2 - h.p).try_normalize()?;
        let v = self.eta * w - u;
        Some((v - h.ns * v.dot(h.ns), h))
    }

    /// `∂C/∂a` in the coordinates `basis` at `a` in `frame`: columns for the two tangent
    /// directions, by forward (`c0` the constraint at `a`) or central differences. `None` if a
    /// perturbed ray does not leave the stone.
    fn jacobian_at(
        &self,
        frame: &Frame,
        a: Vec2,
        basis: (Vec3, Vec3),
        c0: Option<Vec3>,
    ) -> Option<[[f32; 2]; 2]> {
        let mut j = [[0.0; 2]; 2];
        for (col, dir) in [Vec2::X, Vec2::Y].into_iter().enumerate() {
            let plus = self.constraint(turn(frame, a + dir * FD_STEP))?.0;
            let diff = match c0 {
                Some(c0) => (plus - c0) / FD_STEP,
                None => {
                    let minus = self.constraint(turn(frame, a - dir * FD_STEP))?.0;
                    (plus - minus) / (2.0 * FD_STEP)
                }
            };
            j[0][col] = diff.dot(basis.0);
            j[1][col] = diff.dot(basis.1);
        }
        Some(j)
    }

    /// Newton's method on the direction at `x0` from `seed` (module docs) with Broyden's
    /// rank-one updates of the Jacobian (Broyden, "A class of methods for solving nonlinear
    /// simultaneous equations", Math. Comp. 19, 1965): the finite-difference Jacobian is taken
    /// once at the seed (two chain traces) and then updated from each step's change of the
    /// constraint, so an iteration costs one trace; where a step fails to lower the constraint
    /// even when halved, the Jacobian is taken afresh by differences, once per failure. The
    /// coordinates stay those of the seed: `d` in the tangent frame of `seed`, the constraint in
    /// the tangent basis of the seed's exit point. Returns the converged direction, or `None`.
    fn newton(&self, seed: Vec3, tolerance: f32) -> Option<Vec3> {
        let frame = Frame::from_normal(seed);
        let (mut c, h) = self.constraint(seed)?;
        let b = Frame::from_normal(h.ns);
        let basis = (b.s, b.t);
        let coords = |c: Vec3| Vec2::new(c.dot(basis.0), c.dot(basis.1));
        let mut a = Vec2::ZERO;
        let mut d = seed;
        let mut j = self.jacobian_at(&frame, a, basis, Some(c))?;
        let mut fresh = true;
        for _ in 0..MAX_ITERATIONS {
            if c.length() < tolerance {
                return Some(d);
            }
            let r = coords(c);
            let mut step = step(&j, r).unwrap_or(Vec2::ZERO);
            let mut accepted = None;
            if step.length() > 0.0 {
                for _ in 0..=self.halvings {
                    let trial = turn(&frame, a + step);
                    if let Some((ct, _)) = self.constraint(trial)
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
                    j = self.jacobian_at(&frame, a, basis, Some(c))?;
                    fresh = true;
                }
            }
        }
        (c.length() < tolerance).then_some(d)
    }

    /// `|dω0/dA2|` (world units⁻²) at the solution `d` whose exit point is `x1` with shading
    /// normal `n1` (module docs): `|det ∂C/∂x2| / |det ∂C/∂d|` in the tangent basis at `x1`,
    /// `∂C/∂x2` in closed form on the light's plane (unit normal `n_light`) and `∂C/∂d` from
    /// `exact` (the exact walk's linearisation at `d`) or else by central differences. `None` if a perturbed
    /// ray does not leave the stone or the map is singular.
    fn measure(
        &self,
        d: Vec3,
        n_light: Vec3,
        x1: Vec3,
        n1: Vec3,
        exact: Option<&Linearised>,
    ) -> Option<f32> {
        let to_light = self.x2 - x1;
        let l = to_light.length();
        let u = to_light / l;
        let b = Frame::from_normal(n1);
        let basis = (b.s, b.t);
        let jd = match exact {
            // Unit tangents of `d` measure solid angle at `d` as the differences' angles do.
            Some(lin) => {
                let f = Frame::from_normal(d);
                let (cs, ct) = (lin.derivative(f.s), lin.derivative(f.t));
                [
                    [cs.dot(basis.0), ct.dot(basis.0)],
                    [cs.dot(basis.1), ct.dot(basis.1)],
                ]
            }
            None => self.jacobian_at(&Frame::from_normal(d), Vec2::ZERO, basis, None)?,
        };
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
}

/// Stages of the continuation in the index.
pub const STAGES: u32 = 4;
/// Convergence of an intermediate stage.
const STAGE_TOLERANCE: f32 = 1e-3;

/// Solves for the refracted connection from `x0` through `chain` to `x2` (a light point whose
/// emitting plane has unit normal `n_light`); `None` if the walk does not converge.
///
/// Seeded with the straight line `x0 → x2`; if Newton's method fails from there, it follows the
/// solution from `η = 1`, where the straight line is exact, through [`STAGES`] increasing indices
/// to `eta` (a continuation: each stage starts from the last one's solution). The most thorough
/// walk ([`WalkEffort::THOROUGH`]); a render's walks try as hard as its knobs say
/// ([`solve_with_effort`]).
///
/// # Arguments
/// * `eta` – the boundary's IOR inside over outside.
pub fn solve(
    world: &World,
    x0: Vec3,
    x2: Vec3,
    n_light: Vec3,
    eta: f32,
    chain: Chain,
) -> Option<Connection> {
    solve_with(
        world,
        (x0, x2),
        n_light,
        eta,
        chain,
        true,
        WalkEffort::THOROUGH,
    )
}

/// [`solve`] with `effort`'s halvings of a Newton step, and the continuation in the index only
/// if `effort` says so (the render's `manifold-halvings` and `manifold-continuation` knobs):
/// the renderer's walks, on the light side and on the BSDF side of the MIS weight alike, so the
/// combination stays unbiased at any effort (a connection the walk does not find is left whole
/// to BSDF sampling).
///
/// # Arguments
/// As [`solve`], and `effort` – how hard the walk tries.
pub fn solve_with_effort(
    world: &World,
    (x0, x2): (Vec3, Vec3),
    n_light: Vec3,
    eta: f32,
    chain: Chain,
    effort: WalkEffort,
) -> Option<Connection> {
    solve_with(world, (x0, x2), n_light, eta, chain, true, effort)
}

/// [`solve`] by finite differences and Broyden's updates even where the stone knows its
/// curvature: the walk a mesh takes, and what the exact walk is tested against.
///
/// # Arguments
/// As [`solve`].
pub fn solve_by_differences(
    world: &World,
    x0: Vec3,
    x2: Vec3,
    n_light: Vec3,
    eta: f32,
    chain: Chain,
) -> Option<Connection> {
    solve_with(
        world,
        (x0, x2),
        n_light,
        eta,
        chain,
        false,
        WalkEffort::THOROUGH,
    )
}

/// [`solve`], with the exact Jacobian where the stone knows its curvature if `exact`, trying as
/// hard as `effort` says.
fn solve_with(
    world: &World,
    (x0, x2): (Vec3, Vec3),
    n_light: Vec3,
    eta: f32,
    chain: Chain,
    exact: bool,
    effort: WalkEffort,
) -> Option<Connection> {
    let seed = (x2 - x0).try_normalize()?;
    let problem = Problem {
        world,
        from: world.stone.fan(x0),
        x2,
        eta,
        chain,
        halvings: effort.halvings,
    };
    // Where the stone knows its curvature the walk takes the exact Jacobian (no finite
    // differences); elsewhere Broyden's updates.
    if exact && problem.from.has_shape_operator() {
        let stone = &world.stone;
        let walk = |p: &Problem, seed, tolerance| {
            let stop = Stop {
                tolerance,
                halvings: p.halvings,
            };
            exact::newton(stone, &p.from, (p.x2, p.eta, p.chain), seed, stop)
        };
        let lin = continued(
            &problem,
            seed,
            walk,
            |l: &Linearised| l.d,
            effort.continuation,
        )?;
        let e = exit_of(lin.hit, lin.w, eta, lin.entry())?;
        return connect(&problem, lin.d, e, n_light, Some(&lin));
    }
    let walk = |p: &Problem, seed, tol| p.newton(seed, tol);
    let d = continued(&problem, seed, walk, |d: &Vec3| *d, effort.continuation)?;
    let e = exit_from(world, &problem.from, d, eta, chain)?;
    connect(&problem, d, e, n_light, None)
}

/// Newton's method by `walk` from `seed`, else the continuation in the index from `η = 1`
/// through [`STAGES`] stages ([`solve`]) if `stages`; `dir` reads the converged direction off a
/// walk's answer.
fn continued<T>(
    problem: &Problem,
    seed: Vec3,
    walk: impl Fn(&Problem, Vec3, f32) -> Option<T>,
    dir: impl Fn(&T) -> Vec3,
    stages: bool,
) -> Option<T> {
    if let Some(found) = walk(problem, seed, TOLERANCE) {
        return Some(found);
    }
    if !stages {
        return None;
    }
    let mut d = seed;
    for k in 1..=STAGES {
        let eta_k = 1.0 + (problem.eta - 1.0) * k as f32 / STAGES as f32;
        let stage = Problem {
            eta: eta_k,
            ..*problem
        };
        if k == STAGES {
            return walk(&stage, d, TOLERANCE);
        }
        d = dir(&walk(&stage, d, STAGE_TOLERANCE)?);
    }
    None
}

/// The connection along the converged direction `d` leaving through `e`, with its measure
/// (`exact`: the exact walk's linearisation at `d`); `None` unless the refracted ray heads for
/// the light.
fn connect(
    problem: &Problem,
    d: Vec3,
    e: Exit,
    n_light: Vec3,
    exact: Option<&Linearised>,
) -> Option<Connection> {
    let to_light = problem.x2 - e.p;
    let dist = to_light.length();
    // Snell's law holds and the refracted ray really heads for the light.
    if e.out.dot(to_light) < dist * (1.0 - 1e-3) {
        return None;
    }
    let jacobian = problem.measure(d, n_light, e.p, e.n, exact)?;
    Some(Connection {
        d,
        exit: e,
        dist,
        jacobian,
    })
}
