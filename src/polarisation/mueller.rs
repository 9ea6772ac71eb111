//! Mueller matrices: composition, frame rotations, ideal polarisers and retarders, and the matrix
//! of a Jones matrix.

use super::Stokes;
use glam::DVec3;
use num_complex::Complex64;

/// A 4 × 4 Mueller matrix, row-major (see the module docs of [`super`] for frames).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mueller(pub [[f64; 4]; 4]);

impl Mueller {
    /// The identity: light passes unchanged.
    pub const IDENTITY: Mueller = Mueller([
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ]);

    /// A depolarising element of transmittance `t`: its output is unpolarised (the course's model
    /// of a layered material).
    pub fn depolariser(t: f64) -> Mueller {
        let mut m = [[0.0; 4]; 4];
        m[0][0] = t;
        Mueller(m)
    }

    /// The light leaving this element when `s` enters it.
    pub fn apply(&self, s: Stokes) -> Stokes {
        Stokes(std::array::from_fn(|i| {
            (0..4).map(|j| self.0[i][j] * s.0[j]).sum()
        }))
    }

    /// `self · other`: `other` acts first.
    pub fn then_after(&self, other: &Mueller) -> Mueller {
        Mueller(std::array::from_fn(|i| {
            std::array::from_fn(|j| (0..4).map(|k| self.0[i][k] * other.0[k][j]).sum())
        }))
    }

    /// Re-expresses a Stokes vector in a frame whose `x` axis is the old one turned by `angle`
    /// radians toward `y` (Collett 2005, eq. 2.47): `S1, S2` turn by `2 angle`.
    pub fn rotator(angle: f64) -> Mueller {
        let (s, c) = (2.0 * angle).sin_cos();
        Mueller([
            [1.0, 0.0, 0.0, 0.0],
            [0.0, c, s, 0.0],
            [0.0, -s, c, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ])
    }

    /// The rotator from a frame with axis `from_x` to one with axis `to_x`, both unit and
    /// orthogonal to the propagation direction `d` (unit).
    pub fn frame_change(from_x: DVec3, to_x: DVec3, d: DVec3) -> Mueller {
        let angle = from_x.cross(to_x).dot(d).atan2(from_x.dot(to_x));
        Mueller::rotator(angle)
    }

    /// An ideal linear polariser whose transmission axis lies at `angle` radians from `x`.
    pub fn linear_polariser(angle: f64) -> Mueller {
        let p = Mueller([
            [0.5, 0.5, 0.0, 0.0],
            [0.5, 0.5, 0.0, 0.0],
            [0.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, 0.0],
        ]);
        Mueller::rotator(-angle)
            .then_after(&p)
            .then_after(&Mueller::rotator(angle))
    }

    /// An ideal linear retarder: the polarisation along its slow axis, at `axis` radians from `x`,
    /// lags the one across it by `delta` radians (a birefringent plate of retardation
    /// `δ = 2π d Δn / λ`).
    pub fn linear_retarder(delta: f64, axis: f64) -> Mueller {
        let jones =
            Mueller::diagonal_jones(Complex64::new(1.0, 0.0), Complex64::from_polar(1.0, delta));
        Mueller::rotator(-axis)
            .then_after(&jones)
            .then_after(&Mueller::rotator(axis))
    }

    /// The Mueller matrix of a general Jones matrix `j` (`j[out][in]`, amplitudes along `x` and
    /// `y`), column by column: each basis Stokes vector as a coherency matrix
    /// `C = [[S0 + S1, S2 − i S3], [S2 + i S3, S0 − S1]] / 2` (the sign of `S3` of
    /// [`super`]'s convention), carried to `J C J†` and read back (Collett 2005, §4.4).
    pub fn from_jones(j: [[Complex64; 2]; 2]) -> Mueller {
        let i = Complex64::i();
        let mut m = [[0.0; 4]; 4];
        for col in 0..4 {
            let mut s = [0.0; 4];
            s[col] = 1.0;
            let c = [
                [
                    Complex64::from(0.5 * (s[0] + s[1])),
                    (s[2] - i * s[3]) * 0.5,
                ],
                [
                    (s[2] + i * s[3]) * 0.5,
                    Complex64::from(0.5 * (s[0] - s[1])),
                ],
            ];
            // J C J†.
            let jc: [[Complex64; 2]; 2] = std::array::from_fn(|r| {
                std::array::from_fn(|k| j[r][0] * c[0][k] + j[r][1] * c[1][k])
            });
            let out: [[Complex64; 2]; 2] = std::array::from_fn(|r| {
                std::array::from_fn(|k| jc[r][0] * j[k][0].conj() + jc[r][1] * j[k][1].conj())
            });
            let col_s = [
                (out[0][0] + out[1][1]).re,
                (out[0][0] - out[1][1]).re,
                2.0 * out[0][1].re,
                -2.0 * out[0][1].im,
            ];
            for r in 0..4 {
                m[r][col] = col_s[r];
            }
        }
        Mueller(m)
    }

    /// The Mueller matrix of the diagonal Jones matrix `diag(jx, jy)` (amplitudes along `x` and
    /// `y`): Collett 2005, eq. 4.38. `C = Re(jx jy*)` couples `S2, S3` as a retarder of phase
    /// `arg(jx jy*)`; `A ± B` are the intensity transmittances along `x` and `y`.
    pub fn diagonal_jones(jx: Complex64, jy: Complex64) -> Mueller {
        let (x2, y2) = (jx.norm_sqr(), jy.norm_sqr());
        let (a, b) = (0.5 * (x2 + y2), 0.5 * (x2 - y2));
        let z = jx * jy.conj();
        let (c, s) = (z.re, z.im);
        Mueller([
            [a, b, 0.0, 0.0],
            [b, a, 0.0, 0.0],
            [0.0, 0.0, c, s],
            [0.0, 0.0, -s, c],
        ])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The general conversion agrees with the diagonal formula, and a rotated polariser's Jones
    /// matrix gives the rotated polariser's Mueller matrix.
    #[test]
    fn general_jones_agrees_with_the_closed_forms() {
        let (a, b) = (
            Complex64::from_polar(0.8, 0.3),
            Complex64::from_polar(0.5, -1.1),
        );
        let z = Complex64::from(0.0);
        let g = Mueller::from_jones([[a, z], [z, b]]);
        let d = Mueller::diagonal_jones(a, b);
        for r in 0..4 {
            for c in 0..4 {
                assert!((g.0[r][c] - d.0[r][c]).abs() < 1e-12, "{g:?} {d:?}");
            }
        }
        let t = 0.37f64;
        let (s, c) = t.sin_cos();
        let pol = Mueller::from_jones([
            [Complex64::from(c * c), Complex64::from(c * s)],
            [Complex64::from(c * s), Complex64::from(s * s)],
        ]);
        let want = Mueller::linear_polariser(t);
        for r in 0..4 {
            for k in 0..4 {
                assert!(
                    (pol.0[r][k] - want.0[r][k]).abs() < 1e-12,
                    "{pol:?} {want:?}"
                );
            }
        }
    }
    use std::f64::consts::{FRAC_PI_2, PI};

    /// Malus's law: unpolarised light through two polarisers at `θ` to each other keeps
    /// `½ cos² θ` of its intensity, and leaves polarised along the second.
    #[test]
    fn malus_law_through_two_polarisers() {
        for k in 0..=36 {
            let theta = PI * k as f64 / 36.0;
            for first in [0.0, 0.4, 1.3] {
                let out = Mueller::linear_polariser(first + theta)
                    .then_after(&Mueller::linear_polariser(first))
                    .apply(Stokes::unpolarised(1.0));
                let want = 0.5 * theta.cos().powi(2);
                assert!((out.intensity() - want).abs() < 1e-12, "θ {theta}: {out:?}");
                if want > 1e-9 {
                    let along = Stokes::linear(out.intensity(), first + theta);
                    for i in 0..4 {
                        assert!((out.0[i] - along.0[i]).abs() < 1e-12, "{out:?} {along:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn rotating_the_frame_turns_linear_polarisation_back() {
        let s = Stokes::linear(1.0, 0.3);
        // In a frame turned by 0.3 the light lies along the new x.
        let r = Mueller::rotator(0.3).apply(s);
        assert!((r.0[1] - 1.0).abs() < 1e-12 && r.0[2].abs() < 1e-12);
        // A quarter turn swaps x and y.
        let q = Mueller::rotator(FRAC_PI_2).apply(Stokes::linear(1.0, 0.0));
        assert!((q.0[1] + 1.0).abs() < 1e-12);
        // In 3D: from x to y about z is a quarter turn.
        let m = Mueller::frame_change(DVec3::X, DVec3::Y, DVec3::Z);
        let q3 = m.apply(Stokes::linear(1.0, 0.0));
        assert!((q3.0[1] + 1.0).abs() < 1e-12);
        // Turning there and back is the identity.
        let back = Mueller::frame_change(DVec3::Y, DVec3::X, DVec3::Z).then_after(&m);
        for i in 0..4 {
            for j in 0..4 {
                assert!((back.0[i][j] - Mueller::IDENTITY.0[i][j]).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn a_quarter_wave_retarder_makes_45_degree_light_circular() {
        // Jones diag(1, i): y leads x by 90°; with the e^{−iωt} convention of the module docs the
        // output is circular with |S3| = 1.
        let m = Mueller::diagonal_jones(Complex64::new(1.0, 0.0), Complex64::new(0.0, 1.0));
        let out = m.apply(Stokes::linear(1.0, PI / 4.0));
        assert!(
            (out.0[3].abs() - 1.0).abs() < 1e-12 && out.0[1].abs() < 1e-12,
            "{out:?}"
        );
        assert!((out.degree() - 1.0).abs() < 1e-12);
        assert_eq!(
            Mueller::depolariser(0.5).apply(out),
            Stokes::unpolarised(0.5)
        );
    }
}
