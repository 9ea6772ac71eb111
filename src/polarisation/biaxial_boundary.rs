//! The boundary of a biaxial crystal ([`super::boundary::Boundary`] with
//! [`super::optics::Optics::Biaxial`]): which of the quartic's four roots leave into the crystal
//! and what they are called.

use super::biaxial::Biaxial;
use super::boundary::{Boundary, Mode, Wave};
use super::cvec::{add, cv, norm, scale};
use glam::DVec3;
use num_complex::Complex64 as C;

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
        roots: [C; 4],
    ) -> Option<[Wave; 2]> {
        let n = self.normal;
        let mut down = [(C::from(0.0), false); 2];
        let mut count = 0;
        for u in roots {
            let real = u.im.abs() <= 1e-9 * (1.0 + u.re.abs());
            let goes_down = if real {
                x.ray_side(t + u.re * n, n) < 0.0
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
