//! The boundary of a biaxial crystal ([`super::boundary::Boundary`] with
//! [`super::optics::Optics::Biaxial`]): which of the quartic's four roots leave into the crystal
//! and what they are called.

use super::biaxial::Biaxial;
use super::boundary::{Boundary, Mode, Wave};
use super::cvec::{add, cv, norm, scale};
use super::quartic;
use glam::DVec3;
use num_complex::Complex64 as C;

/// The four roots of a boundary's quartic ([`Biaxial::normal_components`]) with the quartic,
/// which tells the side a real root's ray takes.
#[derive(Clone, Copy, Debug)]
pub struct NormalComponents {
    /// The roots `u` (complex where the wave is evanescent).
    pub u: [C; 4],
    /// The monic quartic's coefficients `[c0, c1, c2, c3]` (`u⁴ + c3 u³ + … + c0`).
    c: [f64; 4],
    /// `kᵀ ε k = kek[0] + kek[1] u + kek[2] u²`.
    kek: [f64; 3],
    /// `|t|²`.
    tt: f64,
    /// `det ε`.
    det: f64,
}

impl NormalComponents {
    /// A number with the sign of the ray's component along the boundary normal `m` for the real
    /// root `u` — [`Biaxial::ray_side`] of `t + u m` — from the quartic alone: `dF/du = ∇F · m`
    /// (the quartic is `F(t + u m)` over its positive leading coefficient), turned to point along
    /// the ray by the sign of `k · ∇F`, which on the index surface `F = 0` is `2 (A − det ε)` with
    /// `A = (k·k)(kᵀεk)` (Euler: `F(λk) = λ⁴ A − λ² B + det ε` and `B = A + det ε`). At a conical
    /// point, where the gradient vanishes, the wave vector's own side `u`.
    pub fn ray_side(&self, u: f64) -> f64 {
        let c = self.c;
        let slope = ((4.0 * u + 3.0 * c[3]) * u + 2.0 * c[2]) * u + c[1];
        let kek = self.kek[0] + u * (self.kek[1] + u * self.kek[2]);
        let outward = (self.tt + u * u) * kek - self.det;
        if slope == 0.0 || outward == 0.0 {
            u
        } else if outward < 0.0 {
            -slope
        } else {
            slope
        }
    }
}

impl Biaxial {
    /// The normal components `u` of the four waves `k = t + u m` with tangential wave vector `t`
    /// on a boundary with unit normal `m` (`t · m = 0`): the roots of the quartic `F(t + u m)`.
    pub fn normal_components(&self, t: DVec3, m: DVec3) -> Option<NormalComponents> {
        let e = self.eps();
        let tr = e[0] + e[1] + e[2];
        let tc = self.axes.map(|a| a.dot(t));
        let mc = self.axes.map(|a| a.dot(m));
        // kᵀεk = a0 + a1 u + a2 u², kᵀ(tr ε ε − ε²)k = b0 + b1 u + b2 u².
        let (mut a, mut b) = ([0.0; 3], [0.0; 3]);
        for i in 0..3 {
            let w = [e[i], e[i] * (tr - e[i])];
            for (f, wi) in [(&mut a, w[0]), (&mut b, w[1])] {
                f[0] += wi * tc[i] * tc[i];
                f[1] += 2.0 * wi * tc[i] * mc[i];
                f[2] += wi * mc[i] * mc[i];
            }
        }
        let tt = t.length_squared();
        let det = e[0] * e[1] * e[2];
        // (tt + u²)(a0 + a1 u + a2 u²) − (b0 + b1 u + b2 u²) + det.
        let c4 = a[2];
        if !(c4 > 0.0) {
            return None;
        }
        let c = [
            (tt * a[0] - b[0] + det) / c4,
            (tt * a[1] - b[1]) / c4,
            (a[0] + tt * a[2] - b[2]) / c4,
            a[1] / c4,
        ];
        // Start from each sheet's index along the wave an isotropic medium of index n_β would
        // carry, up and down (imaginary when evanescent): within about Δn × walk-off of the
        // roots. Durand–Kerner's starts (where the factor does not settle: near grazing, where
        // up and down waves meet) are tilted off the real axis so that no two coincide.
        let q = |n: f64| C::from(n * n - tt).sqrt();
        let qb = q(self.n[1]).re;
        let guess = |up: bool| -> [C; 2] {
            let d = t + if up { qb } else { -qb } * m;
            let sheets = d.try_normalize().map_or(self.n, |d| {
                let [f, s] = self.indices(d);
                [f, s, 0.0]
            });
            let sign = if up { 1.0 } else { -1.0 };
            [sign * q(sheets[0]), sign * q(sheets[1])]
        };
        let ([uf, us], [df, ds]) = (guess(true), guess(false));
        // A real quadratic factor to start Bairstow's method from: the two up waves when both
        // propagate, else an evanescent sheet's decaying and growing pair (conjugates).
        let pair = |a: C, b: C| (-(a + b).re, (a * b).re);
        let (r, s) = if uf.im == 0.0 && us.im == 0.0 {
            pair(uf, us)
        } else if uf.im != 0.0 {
            pair(uf, df)
        } else {
            pair(us, ds)
        };
        let found = |u: [C; 4]| NormalComponents {
            u,
            c,
            kek: a,
            tt,
            det,
        };
        if let Some(u) = quartic::factored(c, r, s) {
            return Some(found(u));
        }
        let start = [
            uf * C::new(1.0, 1e-3),
            df * C::new(1.0, 2e-3),
            us * C::new(1.0, -1e-3) + C::new(1e-4, 0.0),
            ds * C::new(1.0, -2e-3) - C::new(1e-4, 0.0),
        ];
        quartic::roots(c, Some(start)).map(found)
    }
}

impl Boundary {
    /// A biaxial crystal's two waves with tangential `t` that leave the boundary into the
    /// crystal, `[fast, slow]`: of the quartic's four roots, the real ones whose ray goes down
    /// and the complex ones that decay downward. Two propagating waves are named by their
    /// indices; beside an evanescent one the propagating wave is the slow one (the line of
    /// constant `t` misses the inner sheet first); two roots within 1e-6 are one wave along an
    /// optic axis, given two orthogonal fields. `None` if the roots do not split two and two (a
    /// wave grazing the boundary).
    pub(super) fn biaxial_down(
        &self,
        x: &Biaxial,
        t: DVec3,
        s: DVec3,
        roots: &NormalComponents,
    ) -> Option<[Wave; 2]> {
        let n = self.normal;
        let mut down = [(C::from(0.0), false); 2];
        let mut count = 0;
        for u in roots.u {
            let real = u.im.abs() <= 1e-9 * (1.0 + u.re.abs());
            let goes_down = if real {
                roots.ray_side(u.re) < 0.0
            } else {
                u.im < 0.0
            };
            if goes_down {
                if count == 2 {
                    return None;
                }
                down[count] = (if real { C::from(u.re) } else { u }, real);
                count += 1;
            }
        }
        if count != 2 {
            return None;
        }
        let k = |u: C| add(cv(t), scale(cv(n), u));
        let index = |u: C| norm(k(u));
        let [(a, ra), (b, rb)] = down;
        // Fast first.
        let (fast, slow) = match (ra, rb) {
            (true, true) if index(a) > index(b) => (b, a),
            (true, false) => (b, a),
            _ => (a, b),
        };
        let degenerate = ra && rb && (fast - slow).norm_sqr() <= 1e-12 * (1.0 + fast.norm_sqr());
        let (fast, slow) = if degenerate {
            let mid = 0.5 * (fast + slow);
            (mid, mid)
        } else {
            (fast, slow)
        };
        let (kf, ks) = (k(fast), k(slow));
        let [ef, es] = if degenerate {
            x.degenerate_fields(kf, s)
        } else {
            [x.field(kf, s, false), x.field(ks, s, false)]
        };
        Some([Wave::new(Mode::Fast, kf, ef), Wave::new(Mode::Slow, ks, es)])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::polarisation::boundary::Incident;
    use crate::polarisation::boundary::tests::assert_reciprocal;
    use crate::polarisation::optics::Optics;
    use crate::polarisation::uniaxial::Uniaxial;
    use crate::sampler::Rng;

    use crate::polarisation::biaxial::tests::{IOLITE, STRONG, random_axes, random_unit};

    fn boundary(n: [f64; 3], axes: [DVec3; 3]) -> Boundary {
        Boundary {
            crystal: Optics::Biaxial(Biaxial { n, axes }),
            n1: 1.0,
            normal: DVec3::Z,
        }
    }

    /// An incident wave from outside (`S`/`P`) or inside (one of the crystal's waves whose
    /// energy reaches the boundary), drawn at random.
    fn incident(b: &Boundary, rng: &mut Rng, inside: bool) -> Option<Incident> {
        let mut d = random_unit(rng);
        if inside {
            d.z = d.z.abs();
            let mode = b.crystal.modes()[usize::from(rng.uniform() < 0.5)];
            (b.crystal.ray(d, mode).z > 1e-6).then_some(Incident::Inside { dir: d, mode })
        } else {
            d.z = -d.z.abs();
            let mode = if rng.uniform() < 0.5 {
                Mode::S
            } else {
                Mode::P
            };
            Some(Incident::Outside { dir: d, mode })
        }
    }

    /// The side of a real root's ray read from the quartic is the side of the ray itself
    /// ([`Biaxial::ray_side`], the index surface's gradient) for iolite and a strongly biaxial
    /// crystal, random axes, normals and tangential wave vectors from normal to beyond `n_α`
    /// (where some waves are evanescent), wherever the ray is not within 10⁻⁶ of the boundary.
    #[test]
    fn the_quartic_tells_the_side_of_each_ray() {
        let mut rng = Rng::new(77);
        let mut compared = 0;
        for n in [IOLITE, STRONG] {
            for _ in 0..2000 {
                let x = Biaxial {
                    n,
                    axes: random_axes(&mut rng),
                };
                let m = random_unit(&mut rng);
                let t = 1.7 * f64::from(rng.uniform()) * m.any_orthonormal_vector();
                let Some(roots) = x.normal_components(t, m) else {
                    continue;
                };
                for u in roots.u.into_iter().filter(|u| u.im.abs() < 1e-9) {
                    let k = t + u.re * m;
                    if x.ray(k).dot(m).abs() < 1e-6 {
                        continue;
                    }
                    let want = x.ray_side(k, m);
                    let got = roots.ray_side(u.re);
                    assert_eq!(want < 0.0, got < 0.0, "{n:?} {k} {want} {got}");
                    compared += 1;
                }
            }
        }
        assert!(compared > 8000, "{compared}");
    }

    /// With two equal indices the biaxial boundary is the uniaxial one: the same powers into
    /// the same waves (fast = ordinary for a positive crystal, extraordinary for a negative
    /// one), from outside and from inside, over random axes and directions.
    #[test]
    fn two_equal_indices_give_the_uniaxial_boundary() {
        let mut rng = Rng::new(31);
        let mut compared = 0;
        for i in 0..2000 {
            let axes = random_axes(&mut rng);
            let positive = i % 2 == 0;
            let (n, u) = if positive {
                (
                    [1.5, 1.5, 1.7],
                    Uniaxial {
                        no: 1.5,
                        ne: 1.7,
                        axis: axes[2],
                    },
                )
            } else {
                (
                    [1.5, 1.7, 1.7],
                    Uniaxial {
                        no: 1.7,
                        ne: 1.5,
                        axis: axes[0],
                    },
                )
            };
            let bx = boundary(n, axes);
            let bu = Boundary {
                crystal: Optics::Uniaxial(u),
                ..bx
            };
            let map = |m: Mode| match (m, positive) {
                (Mode::Fast, true) | (Mode::Slow, false) => Mode::O,
                (Mode::Fast, false) | (Mode::Slow, true) => Mode::E,
                (m, _) => m,
            };
            let Some(inc) = incident(&bx, &mut rng, i % 4 >= 2) else {
                continue;
            };
            let inc_u = match inc {
                Incident::Inside { dir, mode } => Incident::Inside {
                    dir,
                    mode: map(mode),
                },
                o => o,
            };
            let (Some(x), Some(y)) = (bx.solve(inc, DVec3::X), bu.solve(inc_u, DVec3::X)) else {
                continue;
            };
            for o in &x {
                let twin = y.iter().find(|w| w.wave.mode == map(o.wave.mode)).unwrap();
                assert!(
                    (o.power - twin.power).abs() < 1e-7,
                    "{inc:?} {:?}: {} vs {}",
                    o.wave.mode,
                    o.power,
                    twin.power
                );
            }
            compared += 1;
        }
        assert!(compared > 1800, "{compared}");
    }

    /// Energy is conserved for every incident wave, crystal and axes, inside and out (total
    /// internal reflection of either wave included), for iolite and a strongly biaxial
    /// crystal.
    #[test]
    fn power_is_conserved() {
        let mut rng = Rng::new(32);
        let mut solved = 0;
        for i in 0..4000 {
            let n = if i % 2 == 0 { IOLITE } else { STRONG };
            let b = boundary(n, random_axes(&mut rng));
            let Some(inc) = incident(&b, &mut rng, i % 4 >= 2) else {
                continue;
            };
            let Some(out) = b.solve(inc, DVec3::X) else {
                continue;
            };
            solved += 1;
            let total: f64 = out.iter().map(|o| o.power).sum();
            assert!((total - 1.0).abs() < 1e-7, "{inc:?}: {total} {out:?}");
            assert!(out.iter().all(|o| o.power >= -1e-12));
        }
        assert!(solved > 3500, "{solved}");
    }

    /// Reciprocity: what an s or p wave from outside sends into a crystal wave equals what
    /// that wave, reversed, sends into the reversed s or p wave.
    #[test]
    fn transmission_is_reciprocal() {
        let mut rng = Rng::new(33);
        let mut checked = 0;
        for i in 0..600 {
            let n = if i % 2 == 0 { IOLITE } else { STRONG };
            let b = boundary(n, random_axes(&mut rng));
            let mut d = random_unit(&mut rng);
            d.z = -d.z.abs().max(0.05);
            checked += assert_reciprocal(&b, d.normalize());
        }
        assert!(checked > 2000, "{checked}");
    }
}
