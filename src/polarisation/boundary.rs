//! The boundary between an isotropic medium and a uniaxial or biaxial crystal: the two reflected
//! and two transmitted waves of any incident wave, from the continuity of the tangential electric
//! and magnetic fields (Born & Wolf, *Principles of Optics*, 7th ed., §1.1.3; Yariv & Yeh,
//! *Optical Waves in Crystals*, 1984, §4.7, whose 4 × 4 boundary problem this solves directly).
//! A uniaxial crystal's waves have closed forms; a biaxial crystal's normal components are the
//! roots of a quartic ([`super::biaxial::Biaxial::normal_components`]), sorted by the direction
//! their energy or their decay takes.
//!
//! Units: wave vectors in units of the vacuum wave number (`|k|` is a wave's index), non-magnetic
//! media, so a plane wave's magnetic field is `H = k × E` and its power flux through the boundary
//! `Re(E × H*) · n`. Every wave shares the incident wave's tangential wave vector (phase matching);
//! its normal component solves the medium's dispersion relation — complex for an evanescent wave,
//! which carries no power. The isotropic side's fields use the s/p frames of
//! [`super`] (`x` along s, `y = d × s`), so its amplitudes are Jones components.
//!
//! Checked against the Fresnel equations (an index-matched crystal is isotropic), the
//! normal-incidence reflectance along and across an optic axis in the surface, energy
//! conservation for random crystals, axes and directions, reciprocity, and a biaxial crystal with
//! two equal indices against the uniaxial closed forms.

use super::cvec::{CVec, add, cross, cv, dot, is_real, real, scale, solve4, solve4_real};
pub use super::optics::Mode;
use super::optics::Optics;
use glam::DVec3;
use num_complex::Complex64 as C;

/// A plane wave at the boundary.
#[derive(Clone, Copy, Debug)]
pub struct Wave {
    /// Its kind.
    pub mode: Mode,
    /// Wave vector (complex normal component when evanescent).
    pub k: CVec,
    /// Electric field for unit amplitude (unit length where the wave is propagating).
    pub e: CVec,
    /// Magnetic field `k × e`.
    pub h: CVec,
}

impl Wave {
    #[inline(always)]
    pub(super) fn new(mode: Mode, k: CVec, e: CVec) -> Wave {
        // A propagating wave's product in real arithmetic: the complex product's operations on
        // numbers whose imaginary parts are zero, the same real parts bit for bit.
        let h = if is_real(k) && is_real(e) {
            cv(real(k).cross(real(e)))
        } else {
            cross(k, e)
        };
        Wave { mode, k, e, h }
    }

    /// Whether its fields are real (a propagating wave's; then so is its wave vector).
    #[inline(always)]
    fn is_real(&self) -> bool {
        is_real(self.e) && is_real(self.h)
    }

    /// Power flux of unit amplitude through the boundary along the unit `n`.
    pub fn flux(&self, n: DVec3) -> f64 {
        if self.is_real() {
            return real(self.e).cross(real(self.h)).dot(n);
        }
        let s = cross(self.e, self.h.map(|c| c.conj()));
        real(s).dot(n)
    }

    /// Whether it propagates (a real wave vector).
    pub fn propagating(&self) -> bool {
        self.k
            .iter()
            .all(|c| c.im.abs() <= 1e-12 * (1.0 + c.re.abs()))
    }

    /// Its unit wave-vector direction (real part).
    pub fn direction(&self) -> DVec3 {
        real(self.k).normalize_or_zero()
    }
}

/// One outgoing wave of a solved boundary problem.
#[derive(Clone, Copy, Debug)]
pub struct Outgoing {
    /// The wave (unit-amplitude fields).
    pub wave: Wave,
    /// Its complex amplitude for a unit-amplitude incident wave.
    pub amplitude: C,
    /// Its share of the incident power (0 when evanescent).
    pub power: f64,
}

/// The boundary: an isotropic medium of index `n1` on the side the unit `normal` points to, the
/// crystal on the other.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Boundary {
    /// The crystal.
    pub crystal: Optics,
    /// Index of the isotropic medium.
    pub n1: f64,
    /// Unit normal pointing into the isotropic medium.
    pub normal: DVec3,
}

/// The incident wave of a boundary problem.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Incident {
    /// From the isotropic side along the unit `dir` (toward the crystal), polarised `mode`
    /// (`S` or `P`).
    Outside {
        /// Propagation direction, unit, `dir · normal < 0`.
        dir: DVec3,
        /// `Mode::S` or `Mode::P`.
        mode: Mode,
    },
    /// From inside the crystal: the wave of `mode` (one of the crystal's) whose wave vector points along
    /// the unit `dir` (toward the boundary, `dir · normal > 0`).
    Inside {
        /// Wave-vector direction, unit.
        dir: DVec3,
        /// One of the crystal's [`Optics::modes`].
        mode: Mode,
    },
}

impl Boundary {
    /// The s direction for tangential wave vector `t`: `normal × t`, or `reference` (made
    /// tangential) at normal incidence.
    pub fn s_axis(&self, t: DVec3, reference: DVec3) -> DVec3 {
        let n = self.normal;
        n.cross(t).try_normalize().unwrap_or_else(|| {
            (reference - n * reference.dot(n))
                .try_normalize()
                .unwrap_or_else(|| n.any_orthonormal_vector())
        })
    }

    /// The isotropic side's wave of `mode` with tangential `t`, going away from the boundary
    /// (`up`) or toward it.
    fn isotropic(&self, t: DVec3, s: DVec3, mode: Mode, up: bool) -> Wave {
        let q2 = self.n1 * self.n1 - t.length_squared();
        if q2 >= 0.0 {
            // Propagating: the complex path's operations in real arithmetic (the same numbers
            // but for the sign of a zero).
            let q = if up { q2.sqrt() } else { -q2.sqrt() };
            let k = t + self.normal * q;
            let e = match mode {
                Mode::S => s,
                _ => k.cross(s) * (1.0 / self.n1),
            };
            return Wave::new(mode, cv(k), cv(e));
        }
        let q = C::from(q2).sqrt();
        let q = if up { q } else { -q };
        let k = add(cv(t), scale(cv(self.normal), q));
        let e = match mode {
            Mode::S => cv(s),
            _ => scale(cross(k, cv(s)), C::from(1.0 / self.n1)),
        };
        Wave::new(mode, k, e)
    }

    /// Solves the boundary for `incident`: the two waves leaving on the isotropic side (`S`,
    /// `P`) and the two leaving into the crystal (`O`, `E`), in that order, with amplitudes and
    /// power shares; `reference` fixes the s axis at normal incidence. `None` if the problem is
    /// singular (a grazing wave).
    pub fn solve(&self, incident: Incident, reference: DVec3) -> Option<[Outgoing; 4]> {
        let (t, s, index) = self.tangential(incident, reference);
        let out = self.outgoing(t, s)?;
        self.amplitudes([incident], index, t, s, &out).map(|[o]| o)
    }

    /// [`Boundary::solve`] for an s and a p wave from outside along the unit `dir` (toward the
    /// crystal), `[s, p]` — the outgoing waves, which depend only on the tangential wave vector,
    /// found once.
    pub fn solve_sp(&self, dir: DVec3, reference: DVec3) -> Option<[[Outgoing; 4]; 2]> {
        let inc = |mode| Incident::Outside { dir, mode };
        let (t, s, index) = self.tangential(inc(Mode::S), reference);
        let out = self.outgoing(t, s)?;
        self.amplitudes([inc(Mode::S), inc(Mode::P)], index, t, s, &out)
    }

    /// The tangential wave vector of `incident`, the s axis and the incident wave's index.
    fn tangential(&self, incident: Incident, reference: DVec3) -> (DVec3, DVec3, f64) {
        let n = self.normal;
        let index = match incident {
            Incident::Outside { .. } => self.n1,
            Incident::Inside { dir, mode } => self.crystal.index(dir, mode),
        };
        let dir = match incident {
            Incident::Outside { dir, .. } | Incident::Inside { dir, .. } => dir,
        };
        let t = index * (dir - n * dir.dot(n));
        (t, self.s_axis(t, reference), index)
    }

    /// The four waves leaving the boundary with tangential `t` (s axis `s`): `S`, `P` on the
    /// isotropic side, then the crystal's two.
    fn outgoing(&self, t: DVec3, s: DVec3) -> Option<[Wave; 4]> {
        let [c0, c1] = match &self.crystal {
            Optics::Uniaxial(x) => [
                self.crystal_wave(x, t, Mode::O, false, s),
                self.crystal_wave(x, t, Mode::E, false, s),
            ],
            Optics::Biaxial(x) => {
                let u = x.normal_components(t, self.normal)?;
                self.biaxial_down(x, t, s, &u)?
            }
        };
        Some([
            self.isotropic(t, s, Mode::S, true),
            self.isotropic(t, s, Mode::P, true),
            c0,
            c1,
        ])
    }

    /// The amplitudes and powers of the `out` waves for `R` incident waves (of index `index`) with
    /// the same tangential wave vector: one
    /// elimination of the boundary's matrix with `R` right-hand sides (each column's numbers are
    /// those of its own elimination); `None` if any of them fails.
    fn amplitudes<const R: usize>(
        &self,
        incidents: [Incident; R],
        index: f64,
        t: DVec3,
        s: DVec3,
        out: &[Wave; 4],
    ) -> Option<[[Outgoing; 4]; R]> {
        let n = self.normal;
        let inc = incidents.map(|incident| match (incident, &self.crystal) {
            (Incident::Outside { mode, .. }, _) => self.isotropic(t, s, mode, false),
            (Incident::Inside { mode, .. }, Optics::Uniaxial(x)) => {
                self.crystal_wave(x, t, mode, true, s)
            }
            (Incident::Inside { dir, mode }, Optics::Biaxial(x)) => {
                let k = cv(index * dir);
                Wave::new(mode, k, x.field(k, s, mode == Mode::Slow))
            }
        });
        // Tangential E and H continuous: Σ(isotropic side) = Σ(crystal side). Unknowns: the four
        // outgoing amplitudes; the incident wave sits on its own side.
        let t2 = n.cross(s);
        let out_sign = |j: usize| if j < 2 { 1.0 } else { -1.0 };
        let inc_sign = |incident: &Incident| match incident {
            Incident::Outside { .. } => -1.0,
            Incident::Inside { .. } => 1.0,
        };
        let x = if out.iter().chain(&inc).all(Wave::is_real) {
            // Every wave propagating: the complex rows' and elimination's operations on numbers
            // whose imaginary parts are zero, in real arithmetic (the same numbers bit for bit).
            let rows = |w: &Wave| {
                let (e, h) = (real(w.e), real(w.h));
                [e.dot(s), e.dot(t2), h.dot(s), h.dot(t2)]
            };
            let mut a = [[0.0; 4]; 4];
            for (j, w) in out.iter().enumerate() {
                for (i, v) in rows(w).into_iter().enumerate() {
                    a[i][j] = v * out_sign(j);
                }
            }
            let mut b = [[0.0; R]; 4];
            for (k, (incident, w)) in incidents.iter().zip(&inc).enumerate() {
                for (i, v) in rows(w).into_iter().enumerate() {
                    b[i][k] = v * inc_sign(incident);
                }
            }
            solve4_real(a, b)?.map(|xk| xk.map(C::from))
        } else {
            let (t1, t2) = (cv(s), cv(t2));
            let rows = |w: &Wave| [dot(w.e, t1), dot(w.e, t2), dot(w.h, t1), dot(w.h, t2)];
            let mut a = [[C::from(0.0); 4]; 4];
            for (j, w) in out.iter().enumerate() {
                for (i, v) in rows(w).into_iter().enumerate() {
                    a[i][j] = v * out_sign(j);
                }
            }
            let mut b = [[C::from(0.0); R]; 4];
            for (k, (incident, w)) in incidents.iter().zip(&inc).enumerate() {
                for (i, v) in rows(w).into_iter().enumerate() {
                    b[i][k] = v * inc_sign(incident);
                }
            }
            solve4(a, b)?
        };
        let flux_in = inc.map(|w| w.flux(n).abs());
        if !flux_in.iter().all(|f| *f > 0.0) {
            return None;
        }
        Some(std::array::from_fn(|k| {
            std::array::from_fn(|j| {
                let w = out[j];
                let power = if w.propagating() {
                    x[k][j].norm_sqr() * w.flux(n).abs() / flux_in[k]
                } else {
                    0.0
                };
                Outgoing {
                    wave: w,
                    amplitude: x[k][j],
                    power,
                }
            })
        }))
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::polarisation::biaxial::tests::random_unit;
    use crate::polarisation::fresnel;
    use crate::polarisation::uniaxial::Uniaxial;
    use crate::sampler::Rng;

    /// Reciprocity of boundary `b` for the s and p waves from outside along `d` (downward):
    /// what each sends into a propagating crystal wave equals what that wave, reversed, sends
    /// into the reversed s or p wave, to 10⁻⁷ (the symmetric scattering matrix of a lossless
    /// reciprocal boundary). Returns the pairs checked.
    pub(in crate::polarisation) fn assert_reciprocal(b: &Boundary, d: DVec3) -> u32 {
        let mut checked = 0;
        for mode in [Mode::S, Mode::P] {
            let fwd = b
                .solve(Incident::Outside { dir: d, mode }, DVec3::X)
                .unwrap();
            for j in [2, 3] {
                let w = fwd[j].wave;
                if !w.propagating() || fwd[j].power < 1e-9 {
                    continue;
                }
                let back = b
                    .solve(
                        Incident::Inside {
                            dir: -w.direction(),
                            mode: w.mode,
                        },
                        DVec3::X,
                    )
                    .unwrap();
                let i = if mode == Mode::S { 0 } else { 1 };
                assert!(
                    (back[i].power - fwd[j].power).abs() < 1e-7,
                    "{mode:?}→{:?}: {} vs {}",
                    w.mode,
                    fwd[j].power,
                    back[i].power
                );
                checked += 1;
            }
        }
        checked
    }

    fn boundary(no: f64, ne: f64, axis: DVec3) -> Boundary {
        Boundary {
            crystal: Optics::Uniaxial(Uniaxial {
                no,
                ne,
                axis: axis.normalize(),
            }),
            n1: 1.0,
            normal: DVec3::Z,
        }
    }

    /// With `n_o = n_e` the crystal is isotropic glass: reflected s and p powers are Fresnel's
    /// (scalar formulas of `fresnel::amplitudes`), nothing converts s into p, and the crystal's
    /// two waves share the transmitted power.
    #[test]
    fn an_index_matched_crystal_is_fresnel() {
        let mut rng = Rng::new(5);
        for _ in 0..200 {
            let b = boundary(1.6, 1.6, random_unit(&mut rng));
            let cos = 0.02 + 0.97 * f64::from(rng.uniform());
            let dir = DVec3::new((1.0 - cos * cos).sqrt(), 0.0, -cos);
            let amp = fresnel::amplitudes(cos, C::from(1.6));
            for (mode, r) in [(Mode::S, amp.rs), (Mode::P, amp.rp)] {
                let out = b.solve(Incident::Outside { dir, mode }, DVec3::X).unwrap();
                let (same, other) = if mode == Mode::S { (0, 1) } else { (1, 0) };
                assert!(
                    (out[same].power - r.norm_sqr()).abs() < 1e-9,
                    "{cos} {mode:?}"
                );
                assert!(out[other].power < 1e-12);
                let t = out[2].power + out[3].power;
                assert!((t + r.norm_sqr() - 1.0).abs() < 1e-9, "{cos}: {t}");
            }
        }
    }

    /// At normal incidence on a crystal cut parallel to its axis, light polarised along the axis
    /// meets `n_e` and across it `n_o`: `R = ((n − 1)/(n + 1))²` each, and nothing converts.
    #[test]
    fn normal_incidence_along_and_across_the_axis() {
        let (no, ne) = (1.6584, 1.4864);
        let b = boundary(no, ne, DVec3::X);
        let dir = DVec3::NEG_Z;
        // s along the reference X: along the axis.
        let along = b
            .solve(Incident::Outside { dir, mode: Mode::S }, DVec3::X)
            .unwrap();
        let want = ((ne - 1.0) / (ne + 1.0)).powi(2);
        assert!((along[0].power - want).abs() < 1e-12, "{}", along[0].power);
        assert!(along[2].power < 1e-12 && (along[3].power - (1.0 - want)).abs() < 1e-12);
        let across = b
            .solve(Incident::Outside { dir, mode: Mode::S }, DVec3::Y)
            .unwrap();
        let want = ((no - 1.0) / (no + 1.0)).powi(2);
        assert!(
            (across[0].power - want).abs() < 1e-12,
            "{}",
            across[0].power
        );
        assert!(across[3].power < 1e-12 && (across[2].power - (1.0 - want)).abs() < 1e-12);
    }

    /// Energy is conserved for every incident wave, crystal and axis, inside and out (calcite and
    /// a positive crystal), total internal reflection included.
    #[test]
    fn power_is_conserved() {
        let mut rng = Rng::new(9);
        let mut solved = 0;
        for i in 0..4000 {
            let (no, ne) = if i % 2 == 0 {
                (1.6584, 1.4864)
            } else {
                (1.544, 1.553)
            };
            let b = boundary(no, ne, random_unit(&mut rng));
            let mut d = random_unit(&mut rng);
            let inside = i % 4 >= 2;
            let incident = if inside {
                d.z = d.z.abs();
                let mode = if rng.uniform() < 0.5 {
                    Mode::O
                } else {
                    Mode::E
                };
                // An e wave vector whose energy does not reach the boundary is not incident.
                if mode == Mode::E && b.crystal.ray(d, Mode::E).z <= 1e-6 {
                    continue;
                }
                Incident::Inside { dir: d, mode }
            } else {
                d.z = -d.z.abs();
                let mode = if rng.uniform() < 0.5 {
                    Mode::S
                } else {
                    Mode::P
                };
                Incident::Outside { dir: d, mode }
            };
            let Some(out) = b.solve(incident, DVec3::X) else {
                continue;
            };
            solved += 1;
            let total: f64 = out.iter().map(|o| o.power).sum();
            assert!((total - 1.0).abs() < 1e-8, "{incident:?}: {total} {out:?}");
        }
        assert!(solved > 3500, "{solved}");
    }

    /// Reciprocity: the power an s or p wave from outside sends into an ordinary or
    /// extraordinary wave equals what that crystal wave, reversed, sends into the reversed s or
    /// p wave (the symmetric scattering matrix of a lossless reciprocal boundary).
    #[test]
    fn transmission_is_reciprocal() {
        let mut rng = Rng::new(21);
        for _ in 0..500 {
            let b = boundary(1.6584, 1.4864, random_unit(&mut rng));
            let mut d = random_unit(&mut rng);
            d.z = -d.z.abs().max(0.05);
            assert_reciprocal(&b, d.normalize());
        }
    }
}
