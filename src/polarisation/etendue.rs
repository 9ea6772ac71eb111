//! The radiance invariant of a crystal's wave: how radiance scales across a boundary into or out
//! of an anisotropic medium.
//!
//! A bundle of plane waves that share a boundary keeps its tangential wave vectors (phase
//! matching), so the element `d²k∥` of tangential wave vector is what crosses unchanged. On the
//! isotropic side of index `n` it spans `n² cos θ dΩ` of directions. In the crystal a wave's
//! energy follows its ray, the normal of the wave-vector surface at its `k`; the rays of the
//! bundle fill the solid angle the surface's Gauss map makes of the surface element above
//! `d²k∥`: `dΩ_ray cos θ_ray = |K| d²k∥`, with `K` the surface's Gaussian curvature at `k`
//! (the Gauss map's Jacobian is `K`, and the surface element projects onto the boundary by the
//! cosine of its normal, the ray). A power `T dΦ` carried through the boundary therefore leaves
//! with radiance `L_t = T L_i |K_i| / |K_t|`: the invariant is `L |K|`, and Veach's `L / n²`
//! (Veach 1997, eq. 5.12) is its isotropic case, a sphere of radius `n` having `K = 1/n²`.
//!
//! [`index2`] is `1/|K|`, "the square of the wave's radiance index". For the ordinary wave it is
//! `n_o²`; for the extraordinary wave the surface is the ellipsoid `k_a²/n_o² + k_⊥²/n_e² = 1`,
//! whose curvature at the pole makes it `n_e⁴ / n_o²` although the wave's phase index there is
//! `n_o`; for a biaxial crystal it is the curvature of Fresnel's quartic surface (Goldman 2005,
//! "Curvature formulas for implicit curves and surfaces", CAGD 22: `K = ∇F adj(H) ∇Fᵀ / |∇F|⁴`
//! for a surface `F = 0` with Hessian `H`). The phase index's square misses this by the walk-off
//! and, more, by the surface's shape; along one straight ray a wave keeps its `k`, so the error
//! cancels on a single pass and shows only where internal reflection changes the wave.

use super::optics::{Mode, Optics};
use glam::DVec3;

/// `1/|K|` of the wave `mode` with the real wave vector `k` (in units of the vacuum wave number,
/// `|k|` its phase index): `n²` for an isotropic medium, the radiance scaling of the module docs.
/// Where the curvature is not defined (a conical point of a biaxial surface, where the two
/// sheets meet) or vanishes, the phase index's square (a set of directions of measure zero).
pub fn index2(optics: &Optics, k: DVec3, mode: Mode) -> f64 {
    let fallback = k.length_squared();
    let v = match optics {
        Optics::Uniaxial(x) => match mode {
            Mode::E => {
                // Ellipsoid with semi-axes n_e, n_e, n_o (the last along the axis c):
                // K = 1 / (a²b²c² (x²/a⁴ + y²/b⁴ + z²/c⁴)²).
                let along = k.dot(x.axis);
                let across2 = (k.length_squared() - along * along).max(0.0);
                let (ne2, no2) = (x.ne * x.ne, x.no * x.no);
                let s = across2 / (ne2 * ne2) + along * along / (no2 * no2);
                ne2 * ne2 * no2 * s * s
            }
            _ => x.no * x.no,
        },
        Optics::Biaxial(x) => {
            // Fresnel's equation F(k) = (k·k)(kᵀεk) − kᵀ(tr ε·ε − ε²)k + det ε along the
            // principal axes (components c_i, ε_i = n_i²); half its gradient is g_i = c_i d_i with
            // d_i = kᵀεk + (k·k) ε_i − ε_i (tr ε − ε_i), half its Hessian
            // H_ij = δ_ij d_i + 2 c_i c_j (ε_i + ε_j). A common factor cancels in K.
            let e = x.n.map(|n| n * n);
            let tr = e[0] + e[1] + e[2];
            let c = x.axes.map(|a| a.dot(k));
            let kek: f64 = (0..3).map(|i| e[i] * c[i] * c[i]).sum();
            let kk = k.length_squared();
            let d: [f64; 3] = std::array::from_fn(|i| kek + kk * e[i] - e[i] * (tr - e[i]));
            let g: [f64; 3] = std::array::from_fn(|i| c[i] * d[i]);
            let h = |i: usize, j: usize| {
                let diag = if i == j { d[i] } else { 0.0 };
                diag + 2.0 * c[i] * c[j] * (e[i] + e[j])
            };
            // gᵀ adj(H) g for the symmetric H: the cofactors.
            let cof = |i: usize, j: usize| {
                let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
                let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
                h(i1, j1) * h(i2, j2) - h(i1, j2) * h(i2, j1)
            };
            let mut num = 0.0;
            for i in 0..3 {
                for j in 0..3 {
                    num += g[i] * cof(i, j) * g[j];
                }
            }
            let gg: f64 = g.iter().map(|v| v * v).sum();
            gg * gg / num.abs()
        }
    };
    if v.is_finite() && v > 0.0 {
        v
    } else {
        fallback
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::polarisation::biaxial::Biaxial;
    use crate::polarisation::biaxial::tests::{random_axes, random_unit};
    use crate::polarisation::uniaxial::Uniaxial;
    use crate::sampler::Rng;

    /// `|K|` measured from the surface itself: the solid angle of the rays over the area of a
    /// small triangle of wave vectors on the surface around the unit wave normal `s` (the Gauss
    /// map's Jacobian), with `point(s)` the surface point along `s` and `ray(k)` its normal.
    fn measured_curvature(
        s: DVec3,
        point: impl Fn(DVec3) -> DVec3,
        ray: impl Fn(DVec3) -> DVec3,
    ) -> f64 {
        let h = 1e-6;
        let (a, b) = s.any_orthonormal_pair();
        // A triangle centred on s, so the first-order errors cancel.
        let dirs = [0.0f64, 2.0, 4.0].map(|t| {
            let ang = t * std::f64::consts::PI / 3.0;
            (s + h * (ang.cos() * a + ang.sin() * b)).normalize()
        });
        let k = dirs.map(&point);
        let r = k.map(&ray);
        let area = 0.5 * (k[1] - k[0]).cross(k[2] - k[0]).length();
        // The rays' spherical triangle, small: its planar area on the unit sphere.
        let solid = 0.5 * (r[1] - r[0]).cross(r[2] - r[0]).length();
        solid / area
    }

    #[test]
    fn isotropic_limits_give_the_index_squared() {
        let mut rng = Rng::new(3);
        for _ in 0..200 {
            let (axis, s) = (random_unit(&mut rng), random_unit(&mut rng));
            let n = 1.3 + f64::from(rng.uniform());
            let u = Optics::Uniaxial(Uniaxial { no: n, ne: n, axis });
            for mode in [Mode::O, Mode::E] {
                let got = index2(&u, n * s, mode);
                assert!((got / (n * n) - 1.0).abs() < 1e-12, "{mode:?} {got} {n}");
            }
        }
    }

    #[test]
    fn the_extraordinary_ellipsoid_has_its_pole_and_equator_curvatures() {
        // Calcite (Hecht, Optics, 4th ed., table 8.1).
        let (no, ne) = (1.6584, 1.4864);
        let c = DVec3::new(0.3, -0.5, 0.8).normalize();
        let u = Optics::Uniaxial(Uniaxial { no, ne, axis: c });
        // At the pole (k along the axis, |k| = n_o) the radii of curvature are n_e²/n_o.
        let pole = index2(&u, no * c, Mode::E);
        assert!(
            (pole / (ne.powi(4) / (no * no)) - 1.0).abs() < 1e-12,
            "{pole}"
        );
        // On the equator (|k| = n_e) the radii are n_e and n_o²/n_e: 1/K = n_o².
        let across = c.any_orthonormal_vector();
        let eq = index2(&u, ne * across, Mode::E);
        assert!((eq / (no * no) - 1.0).abs() < 1e-12, "{eq}");
    }

    #[test]
    fn the_curvature_is_the_gauss_maps_jacobian() {
        let mut rng = Rng::new(17);
        let mut worst: f64 = 0.0;
        for _ in 0..300 {
            let s = random_unit(&mut rng);
            let axis = random_unit(&mut rng);
            let x = Uniaxial {
                no: 1.6584,
                ne: 1.4864,
                axis,
            };
            let u = Optics::Uniaxial(x);
            let k = x.extraordinary_index(s) * s;
            let want = measured_curvature(s, |d| x.extraordinary_index(d) * d, |k| x.ray(k));
            let got = 1.0 / index2(&u, k, Mode::E);
            worst = worst.max((got / want - 1.0).abs());
            // A strongly biaxial crystal, both sheets, away from the optic axes.
            let b = Biaxial {
                n: [1.5, 1.65, 1.72],
                axes: random_axes(&mut rng),
            };
            let o = Optics::Biaxial(b);
            let [f, sl] = b.indices(s);
            if (sl - f) < 1e-2 {
                continue;
            }
            for (sheet, mode) in [(0, Mode::Fast), (1, Mode::Slow)] {
                let want = measured_curvature(s, |d| b.indices(d)[sheet] * d, |k| b.ray(k)).abs();
                let k = b.indices(s)[sheet] * s;
                let got = 1.0 / index2(&o, k, mode);
                worst = worst.max((got / want - 1.0).abs());
            }
        }
        eprintln!("worst relative error {worst:.2e}");
        assert!(worst < 1e-4, "worst relative error {worst}");
    }

    #[test]
    fn a_biaxial_crystal_with_two_equal_indices_is_uniaxial() {
        let mut rng = Rng::new(29);
        for _ in 0..200 {
            let axes = random_axes(&mut rng);
            // n_α = n_β: the optic axis along Z, n_o = 1.5, n_e = 1.7 (positive).
            let b = Optics::Biaxial(Biaxial {
                n: [1.5, 1.5, 1.7],
                axes,
            });
            let u = Optics::Uniaxial(Uniaxial {
                no: 1.5,
                ne: 1.7,
                axis: axes[2],
            });
            let s = random_unit(&mut rng);
            if s.dot(axes[2]).abs() > 0.99 {
                continue;
            }
            let ne = match u {
                Optics::Uniaxial(x) => x.extraordinary_index(s),
                _ => unreachable!(),
            };
            let want = index2(&u, ne * s, Mode::E);
            let got = index2(&b, ne * s, Mode::Slow);
            assert!((got / want - 1.0).abs() < 1e-9, "{got} {want}");
        }
    }
}
