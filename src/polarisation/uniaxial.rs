//! Refraction into a uniaxial crystal: the ordinary and extraordinary waves, their wave vectors,
//! the extraordinary ray's walk-off and the waves' polarisations (Born & Wolf, *Principles of
//! Optics*, 7th ed., §15.3; Yariv & Yeh, *Optical Waves in Crystals*, 1984, ch. 4).
//!
//! Directions are unit vectors; a wave vector `K` is written in units of the vacuum wave number,
//! so `|K|` is the wave's index. The extraordinary wave's `K` lies on the index surface
//! `(K·c)²/n_o² + |K × c|²/n_e² = 1` (`c` the optic axis): along the axis its index is `n_o`,
//! across it `n_e`. Its energy travels along the surface's normal — the ray — which leaves `K`
//! by the walk-off angle `ρ`.

use glam::DVec3;

/// A uniaxial crystal at one wavelength.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Uniaxial {
    /// Ordinary index `n_o`.
    pub no: f64,
    /// Extraordinary index `n_e` (for waves across the axis).
    pub ne: f64,
    /// Unit optic axis `c` (its sign does not matter).
    pub axis: DVec3,
}

/// A wave refracted into the crystal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wave {
    /// Wave vector in units of the vacuum wave number (`|k|` is the wave's index).
    pub k: DVec3,
    /// Unit direction the energy travels (the ray); equals `k`'s direction for the ordinary wave.
    pub ray: DVec3,
}

impl Uniaxial {
    /// The extraordinary index of a wave travelling along the unit `dir`:
    /// `1/n² = cos²θ/n_o² + sin²θ/n_e²`, `θ` its angle to the axis.
    pub fn extraordinary_index(&self, dir: DVec3) -> f64 {
        let c2 = dir.dot(self.axis).powi(2);
        1.0 / (c2 / (self.no * self.no) + (1.0 - c2) / (self.ne * self.ne)).sqrt()
    }

    /// The extraordinary ray direction of a wave vector `k`: the normal of the index surface,
    /// `(K·c) c / n_o² + (K − (K·c) c) / n_e²`, normalised.
    pub fn ray(&self, k: DVec3) -> DVec3 {
        let along = k.dot(self.axis) * self.axis;
        (along / (self.no * self.no) + (k - along) / (self.ne * self.ne)).normalize()
    }

    /// The ordinary wave refracted from a medium of index `n1` along the unit `d` through a
    /// boundary whose unit normal `m` points into the crystal (`d · m > 0`); `None` under total
    /// internal reflection.
    pub fn ordinary(&self, d: DVec3, m: DVec3, n1: f64) -> Option<Wave> {
        let t = n1 * (d - d.dot(m) * m);
        let q2 = self.no * self.no - t.length_squared();
        (q2 > 0.0).then(|| {
            let k = t + q2.sqrt() * m;
            Wave {
                k,
                ray: k.normalize(),
            }
        })
    }

    /// The extraordinary wave refracted likewise: its wave vector `K = T + q m` keeps the incident
    /// tangential component `T = n1 (d − (d·m) m)` (phase matching along the boundary) and lies on
    /// the index surface, a quadratic in `q` whose root with `q > 0` travels into the crystal;
    /// `None` under total internal reflection.
    pub fn extraordinary(&self, d: DVec3, m: DVec3, n1: f64) -> Option<Wave> {
        let t = n1 * (d - d.dot(m) * m);
        let c = self.axis;
        let (io, ie) = (1.0 / (self.no * self.no), 1.0 / (self.ne * self.ne));
        let diff = io - ie;
        let (a, b) = (t.dot(c), m.dot(c));
        // (a + q b)² diff + (|T|² + q²) ie = 1.
        let qa = b * b * diff + ie;
        let qb = 2.0 * a * b * diff;
        let qc = a * a * diff + t.length_squared() * ie - 1.0;
        let disc = qb * qb - 4.0 * qa * qc;
        if disc < 0.0 {
            return None;
        }
        let q = (-qb + disc.sqrt()) / (2.0 * qa);
        (q > 0.0).then(|| {
            let k = t + q * m;
            Wave {
                k,
                ray: self.ray(k),
            }
        })
    }

    /// Unit electric field of the ordinary wave travelling along `dir`: across the plane of the
    /// wave and the axis (`None` along the axis, where every polarisation is ordinary).
    pub fn ordinary_polarisation(&self, dir: DVec3) -> Option<DVec3> {
        dir.cross(self.axis).try_normalize()
    }

    /// Unit displacement `D` of the extraordinary wave along `dir`: in the plane of the wave and
    /// the axis, across the wave.
    pub fn extraordinary_polarisation(&self, dir: DVec3) -> Option<DVec3> {
        dir.cross(dir.cross(self.axis)).try_normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::Rng;

    /// Calcite at 589.3 nm (Hecht, *Optics*, 4th ed., table 8.1): n_o 1.6584, n_e 1.4864.
    fn calcite(axis: DVec3) -> Uniaxial {
        Uniaxial {
            no: 1.6584,
            ne: 1.4864,
            axis: axis.normalize(),
        }
    }

    fn random_unit(rng: &mut Rng) -> DVec3 {
        let z = 2.0 * f64::from(rng.uniform()) - 1.0;
        let phi = std::f64::consts::TAU * f64::from(rng.uniform());
        let r = (1.0 - z * z).sqrt();
        DVec3::new(r * phi.cos(), r * phi.sin(), z)
    }

    /// The walk-off between wave vector and ray against its closed form
    /// `tan ρ = ½ n(θ)² (1/n_e² − 1/n_o²) sin 2θ` (Yariv & Yeh eq. 4.3-14), and calcite's largest,
    /// at θ = 45°, the textbook 6.2° of a cleavage rhomb's double image.
    #[test]
    fn walk_off_follows_the_index_ellipsoid() {
        let mut rng = Rng::new(40);
        for _ in 0..2000 {
            let x = calcite(random_unit(&mut rng));
            let dir = random_unit(&mut rng);
            let n = x.extraordinary_index(dir);
            let rho = x.ray(n * dir).angle_between(dir);
            let theta = dir.dot(x.axis).clamp(-1.0, 1.0).acos();
            let want =
                (0.5 * n * n * (1.0 / (x.ne * x.ne) - 1.0 / (x.no * x.no)) * (2.0 * theta).sin())
                    .atan()
                    .abs();
            assert!((rho - want).abs() < 1e-9, "θ {theta}: {rho} vs {want}");
        }
        let x = calcite(DVec3::new(1.0, 0.0, 1.0));
        let rho = x
            .ray(x.extraordinary_index(DVec3::Z) * DVec3::Z)
            .angle_between(DVec3::Z);
        assert!(
            (rho.to_degrees() - 6.22).abs() < 0.01,
            "{}",
            rho.to_degrees()
        );
    }

    /// Refraction: the ordinary wave obeys Snell's law with `n_o`; the extraordinary wave keeps the
    /// tangential component, lies on the index surface and enters the crystal; at normal incidence
    /// it goes straight in and its ray walks off; with the axis along the normal both waves are one.
    #[test]
    fn both_waves_match_the_boundary_and_their_surfaces() {
        let mut rng = Rng::new(41);
        let m = DVec3::Z;
        for _ in 0..2000 {
            let x = calcite(random_unit(&mut rng));
            let mut d = random_unit(&mut rng);
            if d.z < 0.0 {
                d.z = -d.z;
            }
            let o = x
                .ordinary(d, m, 1.0)
                .expect("air to calcite always refracts");
            let e = x
                .extraordinary(d, m, 1.0)
                .expect("air to calcite always refracts");
            let (sin_i, sin_o) = (d.cross(m).length(), o.k.normalize().cross(m).length());
            assert!((sin_i - x.no * sin_o).abs() < 1e-9, "Snell");
            for w in [o, e] {
                let tangential = w.k - w.k.dot(m) * m;
                assert!((tangential - (d - d.dot(m) * m)).length() < 1e-9);
                assert!(w.k.z > 0.0 && w.ray.z > 0.0);
            }
            let n = e.k.length();
            assert!((n - x.extraordinary_index(e.k.normalize())).abs() < 1e-9);
            let (po, pe) = (
                x.ordinary_polarisation(o.ray).unwrap(),
                x.extraordinary_polarisation(e.k.normalize()).unwrap(),
            );
            assert!(po.dot(o.ray).abs() < 1e-9 && pe.dot(e.k).abs() < 1e-9);
        }
        let x = calcite(DVec3::new(1.0, 0.0, 1.0));
        let e = x.extraordinary(m, m, 1.0).unwrap();
        assert!(e.k.normalize().cross(m).length() < 1e-12, "straight in");
        assert!((e.ray.angle_between(m).to_degrees() - 6.22).abs() < 0.01);
        let along = calcite(m);
        let (o, e) = (
            along.ordinary(m, m, 1.0).unwrap(),
            along.extraordinary(m, m, 1.0).unwrap(),
        );
        assert!((o.k - e.k).length() < 1e-12);
        // From inside toward air beyond the critical angle: no wave leaves.
        let steep = DVec3::new(0.9, 0.0, 0.1).normalize();
        let air = Uniaxial {
            no: 1.0,
            ne: 1.0,
            axis: DVec3::X,
        };
        assert!(air.ordinary(steep, m, 1.6584).is_none());
        assert!(air.extraordinary(steep, m, 1.6584).is_none());
    }
}
