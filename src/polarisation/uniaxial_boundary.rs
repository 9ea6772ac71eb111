//! The boundary of a uniaxial crystal ([`super::boundary::Boundary`] with
//! [`super::optics::Optics::Uniaxial`]): the ordinary and extraordinary waves with a given
//! tangential wave vector, in closed form (Yariv & Yeh, *Optical Waves in Crystals*, 1984, §4.7):
//! the ordinary wave's normal component from `n_o`, the extraordinary one's from the index
//! ellipsoid's quadratic along the normal.

use super::boundary::{Boundary, Mode, Wave};
use super::cvec::{add, cross, cv, dot, norm, scale};
use super::uniaxial::Uniaxial;
use glam::DVec3;
use num_complex::Complex64 as C;

impl Boundary {
    /// The crystal's wave of `mode` with tangential `t`, going away from the boundary (down,
    /// decaying into the crystal when evanescent) or toward it (`up`, propagating).
    pub(super) fn crystal_wave(
        &self,
        x: &Uniaxial,
        t: DVec3,
        mode: Mode,
        up: bool,
        s: DVec3,
    ) -> Wave {
        self.crystal_wave_real(x, t, mode, up, s)
            .unwrap_or_else(|| self.crystal_wave_complex(x, t, mode, up, s))
    }

    /// The quadratic `qa u² + qb u + qc = 0` of the extraordinary wave's normal component `u`
    /// (`k = t + u n`): `(a + u b)² / n_o² + (|t|² + u² − (a + u b)²) / n_e² = 1` with `a = t·c`,
    /// `b = n·c`; the root with `+√` carries energy along `+n` (the index surface's normal has
    /// n-component `u·qa + qb/2`).
    fn extraordinary_quadratic(&self, x: &Uniaxial, t: DVec3) -> [f64; 3] {
        let (io, ie) = (1.0 / (x.no * x.no), 1.0 / (x.ne * x.ne));
        let (a, b) = (t.dot(x.axis), self.normal.dot(x.axis));
        [
            b * b * (io - ie) + ie,
            2.0 * a * b * (io - ie),
            a * a * (io - ie) + t.length_squared() * ie - 1.0,
        ]
    }

    /// [`Boundary::crystal_wave`] in complex arithmetic (any wave, evanescent ones too).
    fn crystal_wave_complex(&self, x: &Uniaxial, t: DVec3, mode: Mode, up: bool, s: DVec3) -> Wave {
        let (n, c) = (self.normal, x.axis);
        let (io, ie) = (1.0 / (x.no * x.no), 1.0 / (x.ne * x.ne));
        // The normal component u of k = t + u n.
        let u = match mode {
            Mode::O => {
                let q = C::from(x.no * x.no - t.length_squared()).sqrt();
                if up { q } else { -q }
            }
            _ => {
                let [qa, qb, qc] = self.extraordinary_quadratic(x, t);
                let root = C::from(qb * qb - 4.0 * qa * qc).sqrt();
                let root = if up { root } else { -root };
                (root - qb) / (2.0 * qa)
            }
        };
        let k = add(cv(t), scale(cv(n), u));
        let cc = cv(c);
        let kc = cross(k, cc);
        // Along the axis both waves are ordinary: take the s direction for one and the field
        // across it for the other.
        let degenerate = norm(kc) <= 1e-9 * norm(k);
        let e = match mode {
            Mode::O if degenerate => cv(s),
            Mode::O => scale(kc, C::from(1.0 / norm(kc))),
            _ => {
                let d = if degenerate {
                    cross(k, cv(s))
                } else {
                    // D ⟂ k in the plane of k and c; E = ε⁻¹ D.
                    add(scale(cc, dot(k, k)), scale(k, -dot(k, cc)))
                };
                let e = add(scale(d, C::from(io)), scale(cc, dot(cc, d) * (ie - io)));
                scale(e, C::from(1.0 / norm(e).max(f64::MIN_POSITIVE)))
            }
        };
        Wave::new(mode, k, e)
    }

    /// [`Boundary::crystal_wave`] of a propagating wave (the normal component's discriminant
    /// not negative) in real arithmetic: the complex path's operations on numbers whose
    /// imaginary parts are zero, the same wave bit for bit (tested). `None` for an evanescent
    /// wave.
    fn crystal_wave_real(
        &self,
        x: &Uniaxial,
        t: DVec3,
        mode: Mode,
        up: bool,
        s: DVec3,
    ) -> Option<Wave> {
        let (n, c) = (self.normal, x.axis);
        let (io, ie) = (1.0 / (x.no * x.no), 1.0 / (x.ne * x.ne));
        let u = match mode {
            Mode::O => {
                let q2 = x.no * x.no - t.length_squared();
                if !(q2 >= 0.0) {
                    return None;
                }
                if up { q2.sqrt() } else { -q2.sqrt() }
            }
            _ => {
                let [qa, qb, qc] = self.extraordinary_quadratic(x, t);
                let disc = qb * qb - 4.0 * qa * qc;
                if !(disc >= 0.0) {
                    return None;
                }
                let root = if up { disc.sqrt() } else { -disc.sqrt() };
                (root - qb) / (2.0 * qa)
            }
        };
        let k = t + n * u;
        let kc = k.cross(c);
        let degenerate = kc.length() <= 1e-9 * k.length();
        let e = match mode {
            Mode::O if degenerate => s,
            Mode::O => kc * (1.0 / kc.length()),
            _ => {
                let d = if degenerate {
                    k.cross(s)
                } else {
                    c * k.dot(k) + k * -k.dot(c)
                };
                let e = d * io + c * (c.dot(d) * (ie - io));
                e * (1.0 / e.length().max(f64::MIN_POSITIVE))
            }
        };
        Some(Wave::new(mode, cv(k), cv(e)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::polarisation::biaxial::tests::random_unit;
    use crate::polarisation::optics::Optics;
    use crate::sampler::Rng;

    /// The real path's waves are the complex path's bit for bit: each propagating wave built
    /// both ways (the complex path called directly), for calcite-like and strongly positive
    /// crystals, random axes, normals and tangential vectors up to beyond `n_o` and `n_e`.
    #[test]
    fn the_real_path_is_the_complex_one() {
        let mut rng = Rng::new(13);
        let mut compared = 0;
        for (no, ne) in [(1.6584, 1.4864), (1.925, 1.984), (1.544, 1.553)] {
            for _ in 0..3000 {
                let x = Uniaxial {
                    no,
                    ne,
                    axis: random_unit(&mut rng),
                };
                let normal = random_unit(&mut rng);
                let b = Boundary {
                    crystal: Optics::Uniaxial(x),
                    n1: 1.0,
                    normal,
                };
                let t = 2.1 * f64::from(rng.uniform()) * normal.any_orthonormal_vector();
                let s = b.s_axis(t, DVec3::X);
                for mode in [Mode::O, Mode::E] {
                    for up in [false, true] {
                        let Some(fast) = b.crystal_wave_real(&x, t, mode, up, s) else {
                            continue;
                        };
                        let slow = b.crystal_wave_complex(&x, t, mode, up, s);
                        let bits = |v: [C; 3]| v.map(|c| c.re.to_bits());
                        assert_eq!(bits(fast.k), bits(slow.k), "{mode:?} {up}");
                        assert_eq!(bits(fast.e), bits(slow.e), "{mode:?} {up}");
                        assert_eq!(bits(fast.h), bits(slow.h), "{mode:?} {up}");
                        assert!(slow.e.iter().chain(&slow.k).all(|c| c.im == 0.0));
                        compared += 1;
                    }
                }
            }
        }
        assert!(compared > 20_000, "{compared}");
    }
}
