//! A biaxial crystal (cordierite, the feldspars, peridot, topaz): three principal indices
//! `n_α ≤ n_β ≤ n_γ` along three orthogonal axes X, Y, Z, two optic axes in the XZ plane, and
//! along every other wave normal two waves — the fast one on the index surface's inner sheet and
//! the slow one on its outer sheet — whose energy leaves the wave normal (Born & Wolf,
//! *Principles of Optics*, 7th ed., §15.3; Yariv & Yeh, *Optical Waves in Crystals*, 1984, §4.2).
//!
//! Units as in [`super::uniaxial`]: a wave vector `k` in units of the vacuum wave number, `|k|`
//! the wave's index, non-magnetic media. With the relative permittivity `ε = Σ n_i² a_i a_iᵀ`
//! (`a_i` the principal axes) a plane wave's field solves `(k kᵀ − (k·k) I + ε) E = 0`, whose
//! determinant — Fresnel's equation of wave normals — is
//!
//! `F(k) = (k·k)(kᵀ ε k) − kᵀ (tr ε · ε − ε²) k + det ε = 0`
//!
//! (expand `det(D + k kᵀ) = det D (1 + kᵀ D⁻¹ k)` with `D = ε − (k·k) I`). Along a unit wave
//! normal `s` it is a quadratic in `n²`; on a boundary, with `k = t + u m`, a quartic in `u`
//! ([`super::quartic`]). The ray — the direction energy travels — is the index surface's normal
//! `∇F`, equal to the Poynting vector `E × (k × E)`.

use super::cvec::{CVec, cross as ccross, cv as complex, dot as cdot, norm as cnorm, real};
use glam::DVec3;
use num_complex::Complex64 as C;

/// A biaxial crystal at one wavelength.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Biaxial {
    /// Principal indices `[n_α, n_β, n_γ]`, each ≥ 1 (the order is not enforced here).
    pub n: [f64; 3],
    /// Principal axes X, Y, Z: orthonormal, the vibration directions of `n_α`, `n_β`, `n_γ`.
    pub axes: [DVec3; 3],
}

/// Components of `v` along the axes (complex).
#[cfg(test)]
fn along(axes: &[DVec3; 3], v: CVec) -> CVec {
    axes.map(|a| v[0] * a.x + v[1] * a.y + v[2] * a.z)
}

impl Biaxial {
    /// The principal permittivities `n_i²`.
    pub(super) fn eps(&self) -> [f64; 3] {
        self.n.map(|n| n * n)
    }

    /// The quadratic forms `kᵀ ε k` and `kᵀ (tr ε · ε − ε²) k` from the components along the
    /// axes, and `det ε` (the tests' complex reference for [`Biaxial::indices`]).
    #[cfg(test)]
    fn forms(&self, k: [C; 3]) -> (C, C, f64) {
        let e = self.eps();
        let tr = e[0] + e[1] + e[2];
        let mut a = C::from(0.0);
        let mut b = C::from(0.0);
        for i in 0..3 {
            let k2 = k[i] * k[i];
            a += e[i] * k2;
            b += e[i] * (tr - e[i]) * k2;
        }
        (a, b, e[0] * e[1] * e[2])
    }

    /// The two indices along the unit wave normal `s`, `[fast, slow]` (equal along an optic
    /// axis): the roots of `a N² − b N + det ε = 0` in `N = n²`, the slow one first and the fast
    /// one from the product of the roots (no cancellation).
    pub fn indices(&self, s: DVec3) -> [f64; 2] {
        // [`Biaxial::forms`] in real arithmetic: its operations on numbers whose imaginary parts
        // are zero, the same numbers bit for bit.
        let e = self.eps();
        let tr = e[0] + e[1] + e[2];
        let (mut a, mut b) = (0.0, 0.0);
        for (i, axis) in self.axes.iter().enumerate() {
            let along = s.x * axis.x + s.y * axis.y + s.z * axis.z;
            let k2 = along * along;
            a += e[i] * k2;
            b += e[i] * (tr - e[i]) * k2;
        }
        let c = e[0] * e[1] * e[2];
        let disc = (b * b - 4.0 * a * c).max(0.0);
        let slow = (b + disc.sqrt()) / (2.0 * a);
        let fast = c / (a * slow);
        [fast.sqrt(), slow.sqrt()]
    }

    /// The unit ray (the index surface's normal) of the real wave vector `k` on the surface;
    /// `k`'s direction at a conical point, where the normal is not defined.
    pub fn ray(&self, k: DVec3) -> DVec3 {
        let g = self.ray_unnormalised(k);
        g.try_normalize().unwrap_or_else(|| k.normalize())
    }

    /// A number with the sign of [`Biaxial::ray`]`(k) · n`, without the normalisation.
    pub fn ray_side(&self, k: DVec3, n: DVec3) -> f64 {
        let g = self.ray_unnormalised(k);
        let finite = g.length_squared() > 0.0 && g.is_finite();
        if finite { g } else { k }.dot(n)
    }

    /// The index surface's normal at `k`, oriented along `k`, not normalised.
    fn ray_unnormalised(&self, k: DVec3) -> DVec3 {
        let e = self.eps();
        let tr = e[0] + e[1] + e[2];
        let kk = k.length_squared();
        let c = self.axes.map(|a| a.dot(k));
        let kek: f64 = (0..3).map(|i| e[i] * c[i] * c[i]).sum();
        // ∇F / 2 = (kᵀεk) k + (k·k) ε k − (tr ε · ε − ε²) k.
        let mut g = kek * k;
        for i in 0..3 {
            g += (kk * e[i] - e[i] * (tr - e[i])) * c[i] * self.axes[i];
        }
        if g.dot(k) < 0.0 { -g } else { g }
    }

    /// The unit wave normal of the wave on sheet `slow` (false: the fast wave) whose ray is the
    /// unit `ray`, in closed form by duality (Born & Wolf §15.2.4): the ray surface — the ray
    /// velocities `v_r t` along unit rays `t` — is the index surface of the crystal with indices
    /// `1/nᵢ`, and a wave normal is that surface's normal, as the ray is the index surface's.
    /// Each of the ray surface's two sheets gives a normal; the sheets do not pair with the index
    /// surface's everywhere (near an optic axis, the cone of internal conical refraction crosses
    /// a ray axis where the ray sheets touch), so the normal kept is the one whose own ray on
    /// sheet `slow` is `ray`. At a conical point of the ray surface (a ray along a ray axis,
    /// which belongs to a cone of normals) the ray itself.
    pub fn wave_of_ray(&self, ray: DVec3, slow: bool) -> DVec3 {
        let dual = Biaxial {
            n: self.n.map(|n| 1.0 / n),
            axes: self.axes,
        };
        let v = dual.indices(ray);
        let miss =
            |s: DVec3| (self.ray(self.indices(s)[usize::from(slow)] * s) - ray).length_squared();
        // The sheet that pairs with `slow` away from the optic axes first (the slow wave has the
        // smaller ray velocity); the other only if that one's ray misses.
        let first = dual.ray(v[usize::from(!slow)] * ray);
        let m = miss(first);
        if m <= 1e-24 {
            return first;
        }
        let second = dual.ray(v[usize::from(slow)] * ray);
        if m <= miss(second) { first } else { second }
    }

    /// The rows of `M = k kᵀ − (k·k) I + ε`, whose null vectors are the fields of a wave with
    /// wave vector `k`.
    fn rows(&self, k: CVec) -> [CVec; 3] {
        let e = self.eps();
        let kk = cdot(k, k);
        std::array::from_fn(|j| {
            let mut r = [k[j] * k[0], k[j] * k[1], k[j] * k[2]];
            r[j] -= kk;
            // + ε_j· = Σ_i n_i² a_ij a_i·
            for (i, a) in self.axes.iter().enumerate() {
                let (aj, al) = (a.to_array()[j], a.to_array());
                for (l, v) in r.iter_mut().enumerate() {
                    *v += e[i] * aj * al[l];
                }
            }
            r
        })
    }

    /// The electric field of a wave with wave vector `k` (complex when evanescent): the null
    /// vector of `M`, the largest cross product of two of its rows; where `M` has rank one (the
    /// two waves coincide: along an optic axis) the first of [`Biaxial::degenerate_fields`].
    pub fn field(&self, k: CVec, reference: DVec3, second: bool) -> CVec {
        if k.iter().all(|c| c.im == 0.0)
            && let Some(e) = self.real_field(real(k))
        {
            return complex(e);
        }
        let rows = self.rows(k);
        let scale = self.n.iter().fold(0.0f64, |m, v| m.max(v * v)).powi(2);
        // The largest by its squared length (one square root, for the one kept).
        let norm2 = |v: &CVec| v.iter().map(|c| c.norm_sqr()).sum::<f64>();
        let mut best = ccross(rows[0], rows[1]);
        let mut best2 = norm2(&best);
        for cand in [ccross(rows[1], rows[2]), ccross(rows[2], rows[0])] {
            let cand2 = norm2(&cand);
            if cand2 > best2 {
                (best, best2) = (cand, cand2);
            }
        }
        let nb = best2.sqrt();
        if nb > 1e-7 * scale {
            best.map(|c| c / nb)
        } else {
            self.degenerate_fields(k, reference)[usize::from(second)]
        }
    }

    /// [`Biaxial::field`] of a propagating wave (real `k`) in real arithmetic: the complex path's
    /// operations on numbers whose imaginary parts are zero, so the same field bit for bit
    /// (tested). `None` where the rows have rank one (the complex path's degenerate fields).
    fn real_field(&self, k: DVec3) -> Option<DVec3> {
        let e = self.eps();
        let k = k.to_array();
        let kk = k[0] * k[0] + k[1] * k[1] + k[2] * k[2];
        let rows: [DVec3; 3] = std::array::from_fn(|j| {
            let mut r = [k[j] * k[0], k[j] * k[1], k[j] * k[2]];
            r[j] -= kk;
            for (i, a) in self.axes.iter().enumerate() {
                let (aj, al) = (a.to_array()[j], a.to_array());
                for (l, v) in r.iter_mut().enumerate() {
                    *v += e[i] * aj * al[l];
                }
            }
            DVec3::from_array(r)
        });
        // glam's cross and squared length form the same products and sums as the complex
        // path's.
        let scale = self.n.iter().fold(0.0f64, |m, v| m.max(v * v)).powi(2);
        let mut best = rows[0].cross(rows[1]);
        let mut best2 = best.length_squared();
        for cand in [rows[1].cross(rows[2]), rows[2].cross(rows[0])] {
            let cand2 = cand.length_squared();
            if cand2 > best2 {
                (best, best2) = (cand, cand2);
            }
        }
        let nb = best2.sqrt();
        (nb > 1e-7 * scale).then(|| best / nb)
    }

    /// Two orthogonal fields of a wave along an optic axis, where every field across `M`'s one
    /// independent row `r` is a wave: `reference` made across `r`, then `r ×` that.
    pub fn degenerate_fields(&self, k: CVec, reference: DVec3) -> [CVec; 2] {
        let r = self
            .rows(k)
            .into_iter()
            .max_by(|a, b| cnorm(*a).total_cmp(&cnorm(*b)))
            .unwrap_or([C::from(0.0); 3]);
        let rr = cdot(r, r);
        let x = complex(reference);
        let first = if rr.norm() > 0.0 {
            let f = cdot(r, x) / rr;
            [x[0] - f * r[0], x[1] - f * r[1], x[2] - f * r[2]]
        } else {
            x
        };
        let unit = |v: CVec| {
            let nv = cnorm(v);
            if nv > 0.0 { v.map(|c| c / nv) } else { x }
        };
        [unit(first), unit(ccross(r, first))]
    }

    /// The unit displacement `D = ε E` (across the wave normal) of a real field `e`.
    pub fn displacement(&self, e: DVec3) -> DVec3 {
        let eps = self.eps();
        let d: DVec3 = (0..3)
            .map(|i| eps[i] * self.axes[i].dot(e) * self.axes[i])
            .sum();
        d.normalize_or_zero()
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::polarisation::uniaxial::Uniaxial;
    use crate::sampler::Rng;

    /// A random unit vector.
    pub(in crate::polarisation) fn random_unit(rng: &mut Rng) -> DVec3 {
        let z = 2.0 * f64::from(rng.uniform()) - 1.0;
        let phi = std::f64::consts::TAU * f64::from(rng.uniform());
        let r = (1.0 - z * z).sqrt();
        DVec3::new(r * phi.cos(), r * phi.sin(), z)
    }

    /// A random orthonormal frame.
    pub(in crate::polarisation) fn random_axes(rng: &mut Rng) -> [DVec3; 3] {
        let x = random_unit(rng);
        let y = x.cross(random_unit(rng)).normalize();
        [x, y, x.cross(y)]
    }

    /// Cordierite (iolite) at the d line, mid-range of its published indices (Deer, Howie &
    /// Zussman, *Rock-Forming Minerals* vol. 1B, 1986: n_α 1.522–1.560, n_β 1.524–1.574,
    /// n_γ 1.527–1.578); a strongly birefringent made-up crystal beside it for larger walk-offs.
    pub(in crate::polarisation) const IOLITE: [f64; 3] = [1.537, 1.542, 1.546];
    /// A strongly biaxial made-up crystal.
    pub(in crate::polarisation) const STRONG: [f64; 3] = [1.5, 1.65, 1.72];

    /// With two equal indices the crystal is uniaxial: the indices and rays equal
    /// [`Uniaxial`]'s ordinary and extraordinary ones (positive: axis Z; negative: axis X).
    #[test]
    fn two_equal_indices_are_uniaxial() {
        let mut rng = Rng::new(1);
        for _ in 0..500 {
            let axes = random_axes(&mut rng);
            let s = random_unit(&mut rng);
            for (n, axis, o_fast) in [
                ([1.5, 1.5, 1.7], axes[2], true),
                ([1.5, 1.7, 1.7], axes[0], false),
            ] {
                let b = Biaxial { n, axes };
                let u = Uniaxial {
                    no: if o_fast { 1.5 } else { 1.7 },
                    ne: if o_fast { 1.7 } else { 1.5 },
                    axis,
                };
                let [fast, slow] = b.indices(s);
                let (no, ne) = (u.no, u.extraordinary_index(s));
                let (want_fast, want_slow) = if o_fast { (no, ne) } else { (ne, no) };
                assert!((fast - want_fast).abs() < 1e-12 && (slow - want_slow).abs() < 1e-12);
                // The extraordinary sheet's ray (the slow sheet where the ordinary is fast).
                let e_slow = o_fast;
                let k = ne * s;
                let r = b.ray(b.indices(s)[usize::from(e_slow)] * s);
                assert!((r - u.ray(k)).length() < 1e-9, "{r} vs {}", u.ray(k));
            }
        }
    }

    /// Both indices of every wave normal satisfy Fresnel's equation, and along an optic axis —
    /// in the XZ plane at `V` from Z, `tan V = (n_γ/n_α) √((n_β² − n_α²)/(n_γ² − n_β²))` (Born &
    /// Wolf §15.3.3, eq. 25) — the two coincide.
    #[test]
    fn indices_solve_fresnels_equation_and_meet_on_the_optic_axes() {
        let mut rng = Rng::new(2);
        for n in [IOLITE, STRONG] {
            let b = Biaxial {
                n,
                axes: random_axes(&mut rng),
            };
            for _ in 0..200 {
                let s = random_unit(&mut rng);
                // The real forms are the complex ones bit for bit.
                let (a, bb, c) = b.forms(along(&b.axes, complex(s)));
                let (a, bb) = (a.re, bb.re);
                let slow = (bb + (bb * bb - 4.0 * a * c).max(0.0).sqrt()) / (2.0 * a);
                let reference = [(c / (a * slow)).sqrt(), slow.sqrt()];
                assert_eq!(b.indices(s).map(f64::to_bits), reference.map(f64::to_bits));
                for idx in b.indices(s) {
                    assert!((n[0] - 1e-12..=n[2] + 1e-12).contains(&idx));
                    let (a, bb, c) = b.forms(along(&b.axes, complex(idx * s)));
                    let f = idx * idx * a - bb + c;
                    assert!(f.norm() < 1e-10, "{f}");
                }
            }
            let [a, bb, g] = n.map(|v| v * v);
            let v = ((g / a) * ((bb - a) / (g - bb))).sqrt().atan();
            let axis = v.cos() * b.axes[2] + v.sin() * b.axes[0];
            let [fast, slow] = b.indices(axis);
            assert!((fast - n[1]).abs() < 1e-7 && (slow - n[1]).abs() < 1e-7);
            let off = (v + 0.05).cos() * b.axes[2] + (v + 0.05).sin() * b.axes[0];
            let [f2, s2] = b.indices(off);
            assert!(s2 - f2 > 1e-5, "{f2} {s2}");
        }
    }

    /// The ray is the Poynting vector `E × (k × E)` of the wave's own field, and inverting it
    /// gives a wave normal of the same sheet with that ray — the normal itself except near an
    /// optic axis.
    #[test]
    fn the_ray_is_the_poynting_vector_and_inverts() {
        let mut rng = Rng::new(3);
        let (mut tried, mut same) = (0, 0);
        for _ in 0..1000 {
            let b = Biaxial {
                n: STRONG,
                axes: random_axes(&mut rng),
            };
            let s = random_unit(&mut rng);
            for slow in [false, true] {
                let k = b.indices(s)[usize::from(slow)] * s;
                let e = b.field(complex(k), DVec3::X, false);
                let e = DVec3::new(e[0].re, e[1].re, e[2].re);
                let poynting = (e.cross(k.cross(e))).normalize();
                let r = b.ray(k);
                // Skip the few normals within a degree of an optic axis (the field is
                // undefined there).
                let [f, sl] = b.indices(s);
                if sl - f < 1e-3 {
                    continue;
                }
                assert!((r - poynting).length() < 1e-8, "{r} {poynting}");
                let back = b.wave_of_ray(r, slow);
                let again = b.ray(b.indices(back)[usize::from(slow)] * back);
                assert!((again - r).length() < 1e-9, "{again} vs {r}");
                tried += 1;
                same += usize::from((back - s).length() < 1e-9);
            }
        }
        // Near an optic axis the outer sheet is not convex and two normals share a ray: either
        // is a wave with that ray. Elsewhere the normal itself comes back.
        assert!(same as f64 > 0.97 * tried as f64, "{same} of {tried}");
    }

    /// A propagating wave's field in real arithmetic is the complex path's bit for bit.
    #[test]
    fn the_real_field_is_the_complex_one() {
        let mut rng = Rng::new(8);
        for _ in 0..2000 {
            let b = Biaxial {
                n: STRONG,
                axes: random_axes(&mut rng),
            };
            let s = random_unit(&mut rng);
            let reference = random_unit(&mut rng);
            for (sheet, second) in [(0, false), (1, true)] {
                let k = complex(b.indices(s)[sheet] * s);
                let fast = b.field(k, reference, second);
                // An imaginary part that is zero but not exactly takes the complex path.
                let mut tiny = k;
                tiny[0].im = 1e-300;
                let slow = b.field(tiny, reference, second);
                assert_eq!(fast.map(|c| c.re.to_bits()), slow.map(|c| c.re.to_bits()));
            }
        }
    }

    /// The boundary quartic's real roots are waves on the index surface with the given
    /// tangential component.
    #[test]
    fn boundary_roots_lie_on_the_index_surface() {
        let mut rng = Rng::new(4);
        for _ in 0..500 {
            let b = Biaxial {
                n: STRONG,
                axes: random_axes(&mut rng),
            };
            let m = random_unit(&mut rng);
            let t = 1.3 * f64::from(rng.uniform()) * m.any_orthonormal_vector();
            let roots = b.normal_components(t, m).unwrap().u;
            for u in roots {
                let k = [0, 1, 2].map(|i| C::from(t.to_array()[i]) + u * m.to_array()[i]);
                let (a, bb, c) = b.forms(along(&b.axes, k));
                let f = cdot(k, k) * a - bb + c;
                assert!(f.norm() < 1e-8, "{u}: {f}");
            }
            // |t| < n_α: all four waves propagate.
            assert!(roots.iter().all(|u| u.im.abs() < 1e-9), "{roots:?}");
            // The reversed problem's roots are these negated (F is even in k).
            let back = b.normal_components(-t, m).unwrap().u;
            for u in roots {
                assert!(back.iter().any(|v| (*v + u).norm() < 1e-10), "{u} {back:?}");
            }
        }
    }
}
