//! Oren–Nayar reflection, the full model of Oren & Nayar, "Generalization of Lambert's reflectance
//! model", SIGGRAPH 1994, eqs. 30 (direct, with the C1, C2, C3 terms) and 31 (the interreflection
//! term L2). `σ` is the standard deviation of facet slopes in radians (0 … 1). Sampling is cosine
//! weighted.
//!
//! The qualitative model can go negative for extreme grazing back-scattering geometry (the C2 term
//! with `cos Δφ < 0` and `tan β → ∞`); the result is clamped at 0, which is then also what `eval`
//! reports for such directions.

use super::{
    Bsdf, BsdfSample, Bxdf, Lobe, LobeFlags, LobeKind, TransportMode, sample_cosine_hemisphere,
    sin2_theta,
};
use crate::spectrum::RgbSample;
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI};

/// Oren–Nayar rough diffuse reflector.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrenNayar {
    /// Albedo ρ per channel.
    pub albedo: RgbSample,
    /// Facet slope standard deviation σ in radians.
    pub sigma: f32,
}

impl OrenNayar {
    /// The part of `f` that multiplies `ρ/π` (direct term) and `ρ²/π` (interreflection), as a pair.
    #[inline]
    pub(crate) fn factors(&self, wo: Vec3, wi: Vec3) -> (f32, f32) {
        let s2 = self.sigma * self.sigma;
        let (st_i, st_o) = (sin2_theta(wi).sqrt(), sin2_theta(wo).sqrt());
        let (ti, to) = (st_i.atan2(wi.z), st_o.atan2(wo.z));
        let (alpha, beta) = (ti.max(to), ti.min(to));
        // cos(φr − φi) from the projected directions; 0 when an azimuth is undefined.
        let cos_dphi = if st_i > 1e-7 && st_o > 1e-7 {
            ((wi.x * wo.x + wi.y * wo.y) / (st_i * st_o)).clamp(-1.0, 1.0)
        } else {
            0.0
        };
        let c1 = 1.0 - 0.5 * s2 / (s2 + 0.33);
        let two_beta_pi = 2.0 * beta / PI;
        let c2 = if cos_dphi >= 0.0 {
            0.45 * s2 / (s2 + 0.09) * alpha.sin()
        } else {
            0.45 * s2 / (s2 + 0.09) * (alpha.sin() - two_beta_pi.powi(3))
        };
        let c3 = 0.125 * s2 / (s2 + 0.09) * (4.0 * alpha * beta / (PI * PI)).powi(2);
        // tan β and tan((α+β)/2) from sines and cosines, finite for θ → 90°.
        let tan_beta = if ti < to {
            st_i / wi.z.max(1e-7)
        } else {
            st_o / wo.z.max(1e-7)
        };
        let tan_half = ((alpha + beta) * 0.5).tan().min(1e7);
        let direct = c1 + cos_dphi * c2 * tan_beta + (1.0 - cos_dphi.abs()) * c3 * tan_half;
        let inter = 0.17 * s2 / (s2 + 0.13) * (1.0 - cos_dphi * two_beta_pi * two_beta_pi);
        (direct, inter)
    }
}

impl Bxdf for OrenNayar {
    #[inline]
    fn flags(&self) -> LobeFlags {
        LobeFlags::REFLECTION | LobeFlags::DIFFUSE
    }
    #[inline]
    fn eval_mode(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> RgbSample {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return RgbSample::ZERO;
        }
        let (direct, inter) = self.factors(wo, wi);
        let f = self
            .albedo
            .map(|r| (r * FRAC_1_PI * (direct + r * inter)).max(0.0));
        if f.is_finite() { f } else { RgbSample::ZERO }
    }
    #[inline]
    fn sample_mode(&self, wo: Vec3, _uc: f32, u: Vec2, _mode: TransportMode) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = sample_cosine_hemisphere(u)?;
        BsdfSample::from_eval(
            wi,
            self.eval(wo, wi),
            self.pdf(wo, wi),
            Lobe {
                kind: LobeKind::Diffuse,
                layer: 0,
            },
        )
    }
    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            0.0
        } else {
            wi.z * FRAC_1_PI
        }
    }
}

impl From<OrenNayar> for Bsdf {
    fn from(o: OrenNayar) -> Bsdf {
        Bsdf::OrenNayar(o)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::spherical_direction;

    #[test]
    fn sigma_zero_is_lambert() {
        let on = OrenNayar {
            albedo: RgbSample::splat(0.8),
            sigma: 0.0,
        };
        for i in 0..9 {
            let wo = spherical_direction(i as f32 * 0.17, 0.2);
            let wi = spherical_direction(0.3 + i as f32 * 0.1, 2.0);
            assert!((on.eval(wo, wi)[0] - 0.8 / PI).abs() < 1e-6);
        }
    }

    #[test]
    fn rough_surface_back_scatters() {
        let on = OrenNayar {
            albedo: RgbSample::ONE,
            sigma: 0.5,
        };
        let wo = spherical_direction(1.2, 0.0);
        let back = on.eval(wo, spherical_direction(1.2, 0.0))[0];
        let fwd = on.eval(wo, spherical_direction(1.2, PI))[0];
        assert!(back > fwd, "retro-reflection: {back} vs {fwd}");
        // Reciprocal by construction (symmetric in α, β and Δφ).
        let a = spherical_direction(0.3, 0.5);
        let b = spherical_direction(1.1, 2.5);
        assert!((on.eval(a, b)[0] - on.eval(b, a)[0]).abs() < 1e-6);
    }

    #[test]
    fn grazing_is_finite_and_non_negative() {
        let on = OrenNayar {
            albedo: RgbSample::ONE,
            sigma: 1.0,
        };
        let g = Vec3::new(1.0, 0.0, 1e-7).normalize();
        for w in [
            g,
            -Vec3::new(g.x, g.y, -g.z),
            Vec3::Z,
            Vec3::new(0.0, 1.0, 1e-7).normalize(),
        ] {
            let f = on.eval(g, w);
            assert!(f.is_valid(), "{f:?}");
        }
    }
}
