//! The manifold walk with the exact Jacobian, out of a stone that knows its curvature (a
//! cabochon; [`Fan::intersect_curved`]): the constraint's derivative in closed form at every
//! iterate, so Newton's method converges quadratically with one ray cast per iteration and the
//! measure needs no finite differences (module docs in [`super`]).

use super::newton::{MAX_HALVINGS, MAX_ITERATIONS, step, turn};
use crate::geometry::{Curvature, Fan, Frame, StoneHit};
use glam::{Vec2, Vec3};

/// The constraint at a direction with what its derivative needs ([`linearise`]).
#[derive(Clone, Copy)]
pub(super) struct Linearised {
    /// The constraint `C(d)`.
    pub c: Vec3,
    /// The exit hit `x1(d)`.
    pub hit: StoneHit,
    /// The direction `d`.
    d: Vec3,
    /// `n·d` at the exit (> 0).
    cos: f32,
    /// The unit direction `u` from `x1` to the light point.
    u: Vec3,
    /// `1 / |x2 − x1|`.
    inv_len: f32,
    /// `v = η d − u`.
    v: Vec3,
    /// `n·v`.
    vn: f32,
    /// The index ratio the constraint was formed with.
    eta: f32,
    /// The exit's curvature.
    curvature: Curvature,
}

impl Linearised {
    /// `∂C/∂d · δd` (world; [`linearise`]).
    #[inline]
    pub fn derivative(&self, dd: Vec3) -> Vec3 {
        let n = self.hit.ns;
        let dx = (dd - self.d * (n.dot(dd) / self.cos)) * self.hit.t;
        let dn = self.curvature.turn(n, dx);
        let dv = dd * self.eta + (dx - self.u * self.u.dot(dx)) * self.inv_len;
        dv - n * n.dot(dv) - dn * self.vn - n * self.v.dot(dn)
    }
}

/// The constraint at `d` (a [`super::Chain::Out`] walk from the vertex of the rays `from`, to the
/// light point `x2`, across index ratio `eta`) with its derivative `∂C/∂d` in closed form; `None`
/// if the ray does not leave the stone there or the stone does not know its curvature `S`. With
/// `t` the distance to `x1` and `n` its unit normal, moving `d` by `δd` moves the exit point by
/// `δx1 = t (δd − d (n·δd)/(n·d))` (it stays on the surface), its normal by `δn = S δx1`, and `u`
/// by `−(I − u uᵀ) δx1 / L`; so `δv = η δd + (I − u uᵀ) δx1 / L`, and from `C = v − n (n·v)`:
/// `δC = (I − n nᵀ) δv − δn (n·v) − n (v·δn)` ([`Linearised::derivative`]).
pub(super) fn linearise(from: &Fan, x2: Vec3, eta: f32, d: Vec3) -> Option<Linearised> {
    let (hit, curvature) = from.intersect_curved(d, f32::INFINITY)?;
    let curvature = curvature?;
    let n = hit.ns;
    let cos = n.dot(d);
    if !(hit.ng.dot(d) > 0.0 && cos > 0.0) {
        return None;
    }
    let to_light = x2 - hit.p;
    let u = to_light.try_normalize()?;
    let v = eta * d - u;
    let vn = v.dot(n);
    Some(Linearised {
        c: v - n * vn,
        hit,
        d,
        cos,
        u,
        inv_len: to_light.length().recip(),
        v,
        vn,
        eta,
        curvature,
    })
}

/// Newton's method on the direction at the vertex from `seed` (as the finite-difference walk,
/// but with the exact Jacobian of [`linearise`] at every iterate). Returns the converged
/// direction with the linearisation there (its hit is the exit point; its derivative the
/// measure's `∂C/∂d`), or `None`.
pub(super) fn newton(
    from: &Fan,
    x2: Vec3,
    eta: f32,
    seed: Vec3,
    tolerance: f32,
) -> Option<(Vec3, Linearised)> {
    let frame = Frame::from_normal(seed);
    let mut lin = linearise(from, x2, eta, seed)?;
    let b = Frame::from_normal(lin.hit.ns);
    let basis = (b.s, b.t);
    let coords = |c: Vec3| Vec2::new(c.dot(basis.0), c.dot(basis.1));
    let mut a = Vec2::ZERO;
    let mut d = seed;
    for _ in 0..MAX_ITERATIONS {
        if lin.c.length() < tolerance {
            return Some((d, lin));
        }
        // ∂d/∂a of `turn`: the frame's tangents projected off `d`, over |n + s a.x + t a.y|.
        let m = (frame.n + frame.s * a.x + frame.t * a.y).length();
        let cols = [frame.s, frame.t].map(|e| lin.derivative((e - d * d.dot(e)) / m));
        let j = [
            [cols[0].dot(basis.0), cols[1].dot(basis.0)],
            [cols[0].dot(basis.1), cols[1].dot(basis.1)],
        ];
        let mut step = step(&j, coords(lin.c))?;
        let mut accepted = None;
        for _ in 0..=MAX_HALVINGS {
            let trial = turn(&frame, a + step);
            if let Some(l) = linearise(from, x2, eta, trial)
                && l.c.length() < lin.c.length()
            {
                accepted = Some((trial, l));
                break;
            }
            step *= 0.5;
        }
        // The exact Jacobian's step cannot lower the constraint: give up.
        let (trial, l) = accepted?;
        (a, d, lin) = (a + step, trial, l);
    }
    (lin.c.length() < tolerance).then_some((d, lin))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::World;

    /// A cabochon (domed base, turned and moved by the stage) holding a clear body.
    fn cabochon_world() -> World {
        let text = "(materials: { \"m\": (coats: [], base: Lambert(albedo: Gray(0.5))) },
            body: (ior: 1.5), surface: Body,
            stage: (shape: Cabochon(radius: (1.1, 0.9), height: 0.95, base: 0.5),
                    lights: [Disc(center: (0.0, 4.0, 0.0), target: (0.0, 0.0, 0.0), radius: 0.5,
                                  radiance: Gray(20.0))]))";
        let scene = crate::recipe::GemRecipe::parse("t.ron", text)
            .unwrap()
            .compile()
            .unwrap();
        World::new(&scene).unwrap()
    }

    /// The exact derivative `G` against central differences of the constraint (step 10⁻³ rad,
    /// `f32`; their own error is ~10⁻⁴ of the largest entry) for random vertices inside and
    /// directions that leave through either dome or the base.
    #[test]
    fn exact_derivative_matches_differences() {
        let world = cabochon_world();
        let mut rng = crate::sampler::Rng::new(3);
        let mut checked = 0;
        for _ in 0..4000 {
            let x0 = Vec3::new(
                rng.uniform() - 0.5,
                rng.uniform() * 0.9 - 0.4,
                rng.uniform() - 0.5,
            );
            let d = Vec3::new(
                rng.uniform() - 0.5,
                rng.uniform() - 0.5,
                rng.uniform() - 0.5,
            )
            .normalize();
            let x2 = Vec3::new(rng.uniform() - 0.5, 4.0, rng.uniform() - 0.5);
            let from = world.stone.fan(x0);
            if !world.stone.contains(x0) {
                continue;
            }
            let Some(lin) = linearise(&from, x2, 1.5, d) else {
                continue;
            };
            if lin.hit.ns.dot(d) < 0.2 || lin.hit.p_object.y.abs() < 0.05 {
                continue; // grazing exits, the rim: the differences cross onto another piece
            }
            let f = Frame::from_normal(d);
            for e in [f.s, f.t] {
                let h = 1e-3;
                let (Some(a), Some(b)) = (
                    linearise(&from, x2, 1.5, d + e * h),
                    linearise(&from, x2, 1.5, d - e * h),
                ) else {
                    continue;
                };
                let fd = (a.c - b.c) / (2.0 * h);
                let exact = lin.derivative(e);
                let scale = [Vec3::X, Vec3::Y, Vec3::Z]
                    .map(|k| lin.derivative(k).length())
                    .iter()
                    .sum::<f32>();
                assert!(
                    (fd - exact).length() < 1e-3 * scale,
                    "x0 {x0} d {d}: {exact} vs {fd} (exit {})",
                    lin.hit.p
                );
                checked += 1;
            }
        }
        assert!(checked > 2000, "{checked}");
    }
}
