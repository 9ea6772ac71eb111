//! Manifold next-event estimation through a smooth boundary (Hanika, Droske & Fascione,
//! "Manifold Next Event Estimation", Computer Graphics Forum 34(4), EGSR 2015), issue 18, for two
//! chains ([`Chain`]): from a vertex inside the body, one refraction out (`manifold-nee`); from the
//! floor, a refraction into the body and one out of it — the caustic a small light throws
//! through the stone, which is also what a viewer sees of the floor through it
//! (`manifold-caustics`). The text below describes the first; the second is the same walk with
//! the entry refraction traced (Snell's law at the entry holds by construction, the constraint
//! sits at the exit), both crossings' `1 − F`, and no `η²` (the radiance enters and leaves).
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
//! seeded with the straight line `x0 → x2`, a step bounded by [`MAX_STEP`] and halved while the
//! residual grows — in a render at most `manifold-halvings` times (default once: a step that a
//! halving does not rescue has almost always crossed onto another facet or face, where halving
//! further only creeps toward the edge; measured, docs/accuracy.md), at most
//! [`MAX_ITERATIONS`] iterations; if that fails, a continuation in the index from `η = 1`
//! ([`solve`]) — in a render only with the `manifold-continuation` knob on
//! ([`solve_with_effort`]; off by default: the retries find few connections for their cost).
//! The MIS weight stays unbiased at any effort, its BSDF side running the same walk. On a cabochon, a sphere, a faceted stone or a slab the
//! Jacobian is exact at every iterate: the exit point's motion, the light direction's and the
//! normal's through the surface's shape operator (`geometry::Curvature`: the domes' and the
//! sphere's, zero on flat faces), and for a [`Chain::Through`] the entry point's and Snell's
//! law's there; one chain traced per iteration and none for the measure. A mesh's interpolated
//! normals have no closed-form curvature: there the Jacobian is taken by forward differences
//! once and carried by Broyden's updates ([`solve_by_differences`] runs that walk on any stone,
//! which the tests compare the exact one with). A solution
//! must refract onto the light (the refracted ray heads for `x2`). Light points no refracted ray
//! from `x0` reaches (near the boundary, many are: total internal reflection closes part of the
//! sky) have no solution and contribute nothing, as they should; a reachable point the walk misses
//! is the known bias of MNEE — measured in tests/platelets/manifold.rs: none missed there.
//!
//! **The measure.** The light is sampled by area, so the estimate needs `dω0/dA2`, the solid angle
//! at `x0` per unit area on the light along the refracted path (Hanika et al.'s generalised
//! geometry term). By the implicit function theorem on `C(d, x2) = 0`,
//! `|dω0/dA2| = |det ∂C/∂x2| / |det ∂C/∂d|`: `∂C/∂x2 = −P (I − u uᵀ)/L` on the light's plane
//! (`P` the tangential projection at `x1`, `L = |x2 − x1|`) in closed form, and `∂C/∂d` exact
//! (where the walk is) or by central differences at the solution (tangent coordinates of `d` measure solid angle there).
//! Without an interface (`η = 1`) this is exactly `cos θ_light / |x2 − x0|²` (tested), and through
//! a glass sphere its integral over a light equals the solid angle of the refracted rays that
//! reach it (tested by shooting).
//!
//! **Combination with BSDF sampling.** A path that BSDF sampling finds — vertex, the chain's
//! specular refractions through the boundary, light — may be the path the walk would have found;
//! the two are weighted by the power heuristic over the densities of the direction at `x0`: the
//! walk's `p_pick · p_A / |dω0/dA2|` and BSDF sampling's `p_bsdf(d) · Π (1 − F)` (the smooth
//! boundary picks transmission with probability `1 − F`). The BSDF side runs the walk to the
//! light point it reached ([`density`]): the walk is a deterministic function of the light point,
//! so where it converges to another connection (a lens has several for one light point: from the
//! floor under a glass sphere the walk returns about a third of the directions that reach the
//! light, tests/platelets/caustics.rs) the walk's density of this path is 0 and BSDF sampling
//! keeps it whole. The seed is the straight line, so a light point whose straight line misses
//! the body gets no walk from the floor (BSDF sampling alone finds those paths).
//!
//! Files: [`walk`] solves for the connection and its measure (`exact.rs` the walk with the
//! exact Jacobian, `newton.rs` what both walks share, `chain.rs` the chains and the entry
//! refraction); [`light`] turns a connection into a light
//! sample and gives the density the MIS weight needs.

mod chain;
mod exact;
pub mod light;
mod newton;
#[cfg(test)]
mod test_scene;
pub mod walk;

pub use chain::{Chain, Entry};
pub use light::{
    ManifoldLight, WALK_THRESHOLD, WalkNumbers, WalkVertex, density, sample_light, transmittance,
    walk_probability,
};
pub use newton::{MAX_HALVINGS, MAX_ITERATIONS, MAX_STEP, TOLERANCE, WalkEffort};
pub use walk::{Connection, Exit, STAGES, exit, solve, solve_by_differences, solve_with_effort};

use crate::light::Area;

/// What the walk needs of the scene: the boundary and the lights it connects to.
#[derive(Clone, Debug, PartialEq)]
pub struct ManifoldSetup {
    /// The boundary's IOR, inside over outside.
    pub eta: f32,
    /// The boundary's material index (what the surface map gives where it shows the body).
    pub boundary: u32,
    /// Area lights the walk connects to: index and selection probability (∝ power).
    pub lights: Vec<(usize, f32)>,
    /// Walks from platelets and medium points inside ([`Chain::Out`], effect `manifold-nee`).
    pub inside: bool,
    /// Walks from the floor through the stone ([`Chain::Through`], effect `manifold-caustics`).
    pub through: bool,
    /// How hard a walk tries (the `manifold-halvings` and `manifold-continuation` knobs;
    /// [`solve_with_effort`]).
    pub effort: WalkEffort,
    /// Every walk runs ([`walk_probability`] is 1 for every pair): the interior is so clear that
    /// its optical depth over the stone's longest chord keeps the transmittance above
    /// [`WALK_THRESHOLD`] ([`ManifoldSetup::with_clear_interior`]); false until shown.
    pub always: bool,
}

impl ManifoldSetup {
    /// The setup for a smooth boundary of relative IOR `eta` (material `boundary`) and the area
    /// lights of the scene, walking from `inside` and/or `through` the stone as hard as `effort`
    /// says; `None` when no light emits or neither kind of walk is wanted.
    pub fn new(
        eta: f32,
        boundary: u32,
        areas: &[Area],
        (inside, through): (bool, bool),
        effort: WalkEffort,
    ) -> Option<ManifoldSetup> {
        if !inside && !through {
            return None;
        }
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
            inside,
            through,
            effort,
            always: false,
        })
    }

    /// Sets [`always`](Self::always) for an interior whose collision rate is at most `sigma`
    /// (world units⁻¹, every channel and direction) in a stone whose chords are at most `chord`
    /// long (world units): then `exp(−σ t) / WALK_THRESHOLD ≥ 1` on every straight line inside,
    /// and the walk's probability is 1 without tracing it. The bound keeps a margin of 10⁻³ in
    /// the optical depth for the rounding of the traced one.
    pub fn with_clear_interior(mut self, sigma: f32, chord: f32) -> ManifoldSetup {
        let tau = sigma * chord;
        self.always = tau.is_finite() && tau * 1.001 + 1e-3 < (1.0 / WALK_THRESHOLD).ln();
        self
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
