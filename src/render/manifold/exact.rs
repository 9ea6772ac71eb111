//! The manifold walk with the exact Jacobian, on a stone that knows its curvature (a cabochon, a
//! faceted stone, a slab; [`Fan::intersect_curved`]): the constraint's derivative in closed form at every iterate, so
//! Newton's method converges quadratically with one chain traced per iteration and the measure
//! needs no finite differences (module docs in [`super`]).

use super::chain::{Chain, Entry, entry_at};
use super::newton::{MAX_ITERATIONS, Stop, step, turn};
use crate::geometry::{Curvature, CurvedHit, Fan, Frame, Stone, StoneHit};
use glam::{Vec2, Vec3, Vec3A};

/// The constraint at a direction with what its derivative needs ([`linearise`]).
#[derive(Clone, Copy)]
pub(super) struct Linearised {
    /// The constraint `C(d)`.
    pub c: Vec3,
    /// The exit hit `x1(d)`.
    pub hit: StoneHit,
    /// The direction `d` at the vertex (world, unit).
    pub d: Vec3,
    /// The direction arriving at `x1` from inside: `d` itself for [`Chain::Out`].
    pub w: Vec3,
    /// Where a [`Chain::Through`] enters the body, with what its derivative needs.
    front: Option<Front>,
    /// `n·w` at the exit (> 0).
    cos: f32,
    /// The unit direction `u` from `x1` to the light point.
    u: Vec3,
    /// `1 / |x2 − x1|`.
    inv_len: f32,
    /// `v = η w − u`.
    v: Vec3,
    /// `n·v`.
    vn: f32,
    /// The index ratio the constraint was formed with.
    eta: f32,
    /// The exit's curvature.
    curvature: Curvature,
}

/// The entry refraction of a [`Chain::Through`] at direction `d` from the vertex.
#[derive(Clone, Copy)]
struct Front {
    /// The entry record.
    entry: Entry,
    /// The direction from the vertex.
    d: Vec3,
    /// The entry point's unit normal and its curvature.
    n: Vec3,
    curvature: Curvature,
    /// `cos θi = −n·d` and `cos θt` of the refraction.
    cos_i: f32,
    cos_t: f32,
}

impl Linearised {
    /// The entry of a [`Chain::Through`].
    pub fn entry(&self) -> Option<Entry> {
        self.front.map(|f| f.entry)
    }

    /// `∂C/∂d · δd` (world; [`linearise`]). Computed in [`Vec3A`]s (one SSE operation per
    /// vector operation): the same IEEE operations in the same order as on [`Vec3`]s — a dot
    /// product is `(x·x' + y·y') + z·z'` either way — so the same bits.
    #[inline]
    pub fn derivative(&self, dd: Vec3) -> Vec3 {
        let a = Vec3A::from;
        let (dd, n, w) = (a(dd), a(self.hit.ns), a(self.w));
        let (dx, dw) = match &self.front {
            None => ((dd - w * (n.dot(dd) / self.cos)) * self.hit.t, dd),
            Some(f) => {
                // The entry point slides on the surface, its normal turns, and Snell's law
                // `w = r d + (r cos θi − cos θt) nₑ` (r = 1/η) moves the direction inside.
                let (fd, fn_) = (a(f.d), a(f.n));
                let dp = (dd + fd * (fn_.dot(dd) / f.cos_i)) * f.entry.t;
                let dne = f.curvature.turn_a(fn_, dp);
                let r = self.eta.recip();
                let dci = -(dd.dot(fn_) + fd.dot(dne));
                let dct = r * r * f.cos_i * dci / f.cos_t;
                let dw = dd * r + fn_ * (r * dci - dct) + dne * (r * f.cos_i - f.cos_t);
                let q = dp + dw * self.hit.t;
                (q - w * (n.dot(q) / self.cos), dw)
            }
        };
        let (u, v) = (a(self.u), a(self.v));
        let dn = self.curvature.turn_a(n, dx);
        let dv = dw * self.eta + (dx - u * u.dot(dx)) * self.inv_len;
        (dv - n * n.dot(dv) - dn * self.vn - n * v.dot(dn)).into()
    }
}

/// The constraint at `d` (the walk through `chain` from the vertex of the rays `from`, to the
/// light point `x2`, across index ratio `eta`) with its derivative `∂C/∂d` in closed form; `None`
/// if the chain is not traced there or `stone` does not know its curvature `S`. With `t` the
/// length of the segment inside to `x1` and `n` its unit normal, moving the direction inside `w`
/// by `δw` (and its start by `δp`) moves the exit point by
/// `δx1 = (I − w nᵀ/(n·w)) (δp + t δw)` (it stays on the surface), its normal by `δn = S δx1`,
/// and `u` by `−(I − u uᵀ) δx1 / L`; so `δv = η δw + (I − u uᵀ) δx1 / L`, and from
/// `C = v − n (n·v)`: `δC = (I − n nᵀ) δv − δn (n·v) − n (v·δn)`. Out of the body `w = d`,
/// `δp = 0`; through it, the entry point and Snell's law at the entry give `δp` and `δw`
/// ([`Linearised::derivative`]).
pub(super) fn linearise(
    stone: &Stone,
    from: &Fan,
    x2: Vec3,
    eta: f32,
    chain: Chain,
    d: Vec3,
) -> Option<Linearised> {
    let (w, front, CurvedHit { hit, curvature }) = match chain {
        Chain::Out => (d, None, from.intersect_curved(d, f32::INFINITY)?),
        Chain::Through => {
            let CurvedHit { hit: h, curvature } = from.intersect_curved(d, f32::INFINITY)?;
            let entry = entry_at(h, d, eta)?;
            let cos_i = entry.cos_outside;
            // cos θt from the refracted direction, as `refract` made it.
            let cos_t = -entry.inside.dot(h.ns);
            let front = Front {
                entry,
                d,
                n: h.ns,
                curvature: curvature?,
                cos_i,
                cos_t,
            };
            let inner = stone.fan(entry.origin);
            (
                entry.inside,
                Some(front),
                inner.intersect_curved(entry.inside, f32::INFINITY)?,
            )
        }
    };
    let curvature = curvature?;
    let n = hit.ns;
    let cos = n.dot(w);
    if !(hit.ng.dot(w) > 0.0 && cos > 0.0) {
        return None;
    }
    let to_light = x2 - hit.p;
    let u = to_light.try_normalize()?;
    let v = eta * w - u;
    let vn = v.dot(n);
    Some(Linearised {
        c: v - n * vn,
        hit,
        d,
        w,
        front,
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
/// but with the exact Jacobian of [`linearise`] at every iterate). Returns the linearisation at
/// the converged direction (its hit is the exit point; its derivative the measure's `∂C/∂d`),
/// or `None`.
///
/// # Arguments
/// * `stone`, `from` – the stone and the rays from the vertex.
/// * `(x2, eta, chain)` – the light point, the index ratio and the chain ([`linearise`]).
/// * `stop` – converged when `|C| <` its tolerance; gives up when a step halved as often as it
///   allows still does not lower `|C|`.
pub(super) fn newton(
    stone: &Stone,
    from: &Fan,
    (x2, eta, chain): (Vec3, f32, Chain),
    seed: Vec3,
    stop: Stop,
) -> Option<Linearised> {
    let linearise = |d: Vec3| linearise(stone, from, x2, eta, chain, d);
    let frame = Frame::from_normal(seed);
    let mut lin = linearise(seed)?;
    let b = Frame::from_normal(lin.hit.ns);
    let basis = (b.s, b.t);
    let coords = |c: Vec3| Vec2::new(c.dot(basis.0), c.dot(basis.1));
    let mut a = Vec2::ZERO;
    let mut d = seed;
    for _ in 0..MAX_ITERATIONS {
        if lin.c.length() < stop.tolerance {
            return Some(lin);
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
        for _ in 0..=stop.halvings {
            let trial = turn(&frame, a + step);
            if let Some(l) = linearise(trial)
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
    (lin.c.length() < stop.tolerance).then_some(lin)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::World;
    use crate::sampler::Rng;

    /// A clear body of IOR 1.5 in the stone `shape`, under a disc light at height 4.
    fn world(shape: &str) -> World {
        super::super::test_scene::test_world(shape, "(ior: 1.5)")
    }

    /// A cabochon with a domed base.
    const CABOCHON: &str = "Cabochon(radius: (1.1, 0.9), height: 0.95, base: 0.5)";
    /// A box resting on y = 0 (flat faces: the curvature is zero).
    const SLAB: &str = "Slab(size: (1.6, 1.2, 1.4))";
    /// A sphere placed by a turn, a scale and a shift (its curvature is `1 / (1.3 · 0.8)`).
    const SPHERE: &str = "Sphere(radius: 0.8), transform: (translate: (0.1, 0.3, -0.1), \
                          rotate: (20.0, 35.0, 0.0), scale: 1.3)";

    /// The exact derivative against central differences of the constraint (step 5·10⁻⁴ rad,
    /// `f32`: their own error is up to ~2·10⁻³ of the derivative's size from truncation where the
    /// chain bends sharply, plus ~10⁻³ from the constraint's rounding, ~10⁻⁶, over the step;
    /// a wrong term would be off by its whole size) for `chain` out of or through the stone
    /// `shape` from vertices `vertex` draws, along random directions (exits through every face);
    /// at least `least` checked.
    fn derivative_matches_differences(
        shape: &str,
        chain: Chain,
        vertex: impl Fn(&mut Rng) -> Vec3,
        least: u32,
    ) {
        let world = world(shape);
        let mut rng = Rng::new(3);
        let mut checked = 0;
        for _ in 0..20_000 {
            let x0 = vertex(&mut rng);
            let d = Vec3::new(
                rng.uniform() - 0.5,
                rng.uniform() - 0.5,
                rng.uniform() - 0.5,
            )
            .normalize();
            let x2 = Vec3::new(rng.uniform() - 0.5, 4.0, rng.uniform() - 0.5);
            if world.stone.contains(x0) != (chain == Chain::Out) {
                continue;
            }
            let from = world.stone.fan(x0);
            let lin = |d: Vec3| linearise(&world.stone, &from, x2, 1.5, chain, d);
            let Some(at) = lin(d) else {
                continue;
            };
            // Grazing crossings, the rim: the differences cross onto another piece.
            let grazing =
                |h: &StoneHit, w: Vec3| h.ns.dot(w).abs() < 0.2 || h.p_object.y.abs() < 0.05;
            if grazing(&at.hit, at.w)
                || at
                    .front
                    .is_some_and(|f| f.cos_i < 0.2 || f.entry.p_object.y.abs() < 0.05)
            {
                continue;
            }
            let f = Frame::from_normal(d);
            for e in [f.s, f.t] {
                let h = 5e-4;
                let (Some(a), Some(b)) = (lin(d + e * h), lin(d - e * h)) else {
                    continue;
                };
                // A difference across an edge onto another face.
                let normal = |x: &Linearised| (x.hit.ng, x.front.map(|f| f.n));
                let apart = |x: &Linearised| {
                    let ((n, m), (n0, m0)) = (normal(x), normal(&at));
                    (n - n0).length() > 0.05
                        || m.zip(m0).is_some_and(|(m, m0)| (m - m0).length() > 0.05)
                };
                if apart(&a) || apart(&b) {
                    continue;
                }
                let fd = (a.c - b.c) / (2.0 * h);
                let exact = at.derivative(e);
                let scale = [Vec3::X, Vec3::Y, Vec3::Z]
                    .map(|k| at.derivative(k).length())
                    .iter()
                    .sum::<f32>();
                assert!(
                    (fd - exact).length() < 4e-3 * scale + 5e-3,
                    "{chain:?} x0 {x0} d {d}: {exact} vs {fd} (exit {})",
                    at.hit.p
                );
                checked += 1;
            }
        }
        assert!(checked > least, "{checked}");
    }

    #[test]
    fn derivative_out_of_the_body_matches_differences() {
        let inside = |rng: &mut Rng| {
            Vec3::new(
                rng.uniform() - 0.5,
                rng.uniform() * 0.9 - 0.4,
                rng.uniform() - 0.5,
            )
        };
        derivative_matches_differences(CABOCHON, Chain::Out, inside, 2000);
        let in_slab = |rng: &mut Rng| {
            Vec3::new(
                rng.uniform() - 0.5,
                rng.uniform() * 0.8 + 0.1,
                rng.uniform() - 0.5,
            ) * 1.3
        };
        derivative_matches_differences(SLAB, Chain::Out, in_slab, 2000);
        derivative_matches_differences(SPHERE, Chain::Out, inside, 2000);
    }

    #[test]
    fn derivative_through_the_body_matches_differences() {
        let outside = |rng: &mut Rng| {
            Vec3::new(
                rng.uniform() - 0.5,
                rng.uniform() - 0.5,
                rng.uniform() - 0.5,
            ) * 5.0
        };
        derivative_matches_differences(CABOCHON, Chain::Through, outside, 1000);
        derivative_matches_differences(SLAB, Chain::Through, outside, 1000);
        derivative_matches_differences(SPHERE, Chain::Through, outside, 1000);
    }
}
