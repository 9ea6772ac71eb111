//! The fluorescent lobe of a stack whose Lambertian base fluoresces (issue 20; course §5.2.2,
//! fig. 5.4; Wilkie, Weidlich, Larboulette & Purgathofer, GRAPHITE 2006).
//!
//! "Fluorescence only takes place for those rays that come in contact with the base layer"
//! (course fig. 5.4): light refracts through every coat, reaches the base at `λi`, is re-radiated
//! at `λo` by the colorant's kernel `K(λi → λo)` ([`crate::spectrum::fluorescence`]) with the
//! Lambertian `1/π`, and refracts back out. With the Corrected model's transmissions
//! `T(w) = 1 − E_top(w)` and the `1/η²` solid-angle compression of each coat (course eq. 3.1's
//! structure, [`super::corrected`]) the lobe is
//!
//! `f_fl(wo, wi; λi → λo) = K(λi → λo) · D(wo, wi)`,
//! `D(wo, wi) = (1/π) Π_coats T(wo_l) T(wi_l) / η_l²`,
//!
//! with `wo_l`, `wi_l` the directions refracted through the macro normal down to coat `l`. `D`
//! is achromatic (coats over a fluorescent base must not absorb: the compiler refuses it) and
//! symmetric. What it leaves out: light the coats' undersides return to the base is not
//! re-radiated again (the Corrected model's multiple-reflection lobe is elastic only), so the
//! fluorescent part is a lower bound — energy is never created (`∫ D cos dωi ≤ 1`, tested).
//!
//! A path picks this lobe or the elastic stack at the vertex ([`crate::render::integrator`]);
//! here the lobe's value, density and sample: cosine sampling in the outer frame, whose density
//! is positive wherever `D` is.

use super::LayeredBsdf;
use crate::bsdf::{LobeFlags, refract_macro, sample_cosine_hemisphere};
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI};

/// A direction sampled from the fluorescent lobe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FluorescentSample {
    /// Unit direction toward the light, local frame (`z > 0`).
    pub wi: Vec3,
    /// `D(wo, wi)`, sr⁻¹.
    pub value: f32,
    /// Density per steradian, `cos θi / π`.
    pub pdf: f32,
}

impl LayeredBsdf {
    /// The colorant of a fluorescent base, if the stack has one.
    #[inline]
    pub fn fluorescence(&self) -> Option<&crate::spectrum::fluorescence::Fluorescence> {
        self.fluorescence.as_deref()
    }

    /// `D(wo, wi)` (module docs), sr⁻¹, for local directions (`z` along the macro normal): 0
    /// unless both lie above the surface.
    pub fn fluorescent_value(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !(wo.z > 0.0 && wi.z > 0.0) {
            return 0.0;
        }
        let (mut o, mut i, mut d) = (wo, wi, FRAC_1_PI);
        for lv in self.levels.iter() {
            let (Some(o_in), Some(i_in)) = (refract_macro(o, lv.eta), refract_macro(i, lv.eta))
            else {
                return 0.0;
            };
            d *= lv.t(o.z) * lv.t(i.z) / (lv.eta * lv.eta);
            (o, i) = (o_in, i_in);
        }
        d
    }

    /// Density of `wi` under [`LayeredBsdf::fluorescent_sample`], per steradian.
    #[inline]
    pub fn fluorescent_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z > 0.0 && wi.z > 0.0 {
            wi.z * FRAC_1_PI
        } else {
            0.0
        }
    }

    /// Samples the lobe by the cosine; `None` when `wo` is below the surface or the sample is
    /// on the rim.
    #[inline]
    pub fn fluorescent_sample(&self, wo: Vec3, u: Vec2) -> Option<FluorescentSample> {
        if !(wo.z > 0.0) {
            return None;
        }
        let wi = sample_cosine_hemisphere(u)?;
        let value = self.fluorescent_value(wo, wi);
        let pdf = wi.z * FRAC_1_PI;
        (value > 0.0 && pdf > 0.0).then_some(FluorescentSample { wi, value, pdf })
    }

    /// The lobe's flags: diffuse reflection.
    #[inline]
    pub fn fluorescent_flags(&self) -> LobeFlags {
        LobeFlags::DIFFUSE | LobeFlags::REFLECTION
    }

    /// `∫ D(wo, wi) cos θi dωi` by the midpoint rule in `cos² θi` (`n` strata): the lobe's albedo
    /// for `wo`, per unit re-radiated light.
    pub fn fluorescent_albedo(&self, wo: Vec3, n: usize) -> f32 {
        // cos θ dω = π d(cos² θ) / π · dφ/(2π)·2π…: with x = cos² θ, ∫ D cos dω = π ∫₀¹ D dx for
        // a D that does not depend on φ (it does not: the macro refraction is isotropic).
        let mut sum = 0.0f64;
        for k in 0..n {
            let x = (k as f32 + 0.5) / n as f32;
            let c = x.sqrt();
            let wi = Vec3::new((1.0 - x).max(0.0).sqrt(), 0.0, c);
            sum += f64::from(self.fluorescent_value(wo, wi));
        }
        (PI as f64 * sum / n as f64) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Base, Coat, StackDesc};
    use super::*;
    use crate::color::Rgb;

    fn stack(coats: Vec<Coat>) -> LayeredBsdf {
        LayeredBsdf::new(&StackDesc::new(
            coats,
            Base::Lambert {
                albedo: Rgb::splat(0.5),
            },
        ))
        .unwrap()
    }

    fn varnish(roughness: f32) -> Coat {
        Coat {
            ior: 1.5,
            roughness,
            absorption: Rgb::ZERO,
            thickness: 0.0,
        }
    }

    /// Energy: the lobe never reflects more than the light it re-radiates, at any angle, for a
    /// rough (the course's m = 17°), a near-mirror and a smooth varnish, and it is symmetric.
    #[test]
    fn the_lobe_conserves_energy_and_is_reciprocal() {
        for coats in [
            vec![],
            vec![varnish(17.0)],
            vec![varnish(0.5)],
            vec![varnish(0.0)],
        ] {
            let s = stack(coats.clone());
            for k in 0..=18 {
                let theta = (k as f32 * 5.0).min(89.9).to_radians();
                let wo = Vec3::new(theta.sin(), 0.0, theta.cos());
                let a = s.fluorescent_albedo(wo, 4000);
                assert!((0.0..=1.0 + 1e-3).contains(&a), "{coats:?} {k}: {a}");
                if coats.is_empty() {
                    assert!((a - 1.0).abs() < 1e-3, "bare base: {a}");
                } else if k <= 12 {
                    // A varnish returns some light to the surface and traps some inside.
                    assert!(a < 0.97 && a > 0.3, "{coats:?} {k}: {a}");
                }
                let wi = Vec3::new(0.3, -0.4, 0.866).normalize();
                let (x, y) = (s.fluorescent_value(wo, wi), s.fluorescent_value(wi, wo));
                assert!((x - y).abs() <= 1e-6 * x.max(1e-6), "{x} vs {y}");
            }
        }
    }

    /// At grazing incidence the varnish sends less light to the base (Fresnel): the fluorescent
    /// share falls, the effect course fig. 5.5 shows.
    #[test]
    fn grazing_light_reaches_the_base_less() {
        let s = stack(vec![varnish(17.0)]);
        let up = Vec3::Z;
        let d = |deg: f32| {
            let t = deg.to_radians();
            s.fluorescent_value(up, Vec3::new(t.sin(), 0.0, t.cos()))
        };
        assert!(
            d(0.0) > d(60.0) && d(60.0) > d(85.0),
            "{} {} {}",
            d(0.0),
            d(60.0),
            d(85.0)
        );
        assert_eq!(s.fluorescent_value(up, Vec3::new(1.0, 0.0, -0.1)), 0.0);
        // Sampling: the density is the cosine's and the value matches the evaluation.
        let fs = s.fluorescent_sample(up, Vec2::new(0.3, 0.7)).unwrap();
        assert!((fs.pdf - s.fluorescent_pdf(up, fs.wi)).abs() < 1e-6);
        assert!((fs.value - s.fluorescent_value(up, fs.wi)).abs() < 1e-7);
    }
}
