//! Lambertian reflection `f = ρ/π` with cosine-weighted sampling.

use super::{
    Bsdf, BsdfSample, Bxdf, Lobe, LobeFlags, LobeKind, TransportMode, sample_cosine_hemisphere,
};
use crate::spectrum::RgbSample;
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

/// An ideal diffuse reflector with albedo `ρ` per channel (0 … 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lambert {
    /// Hemispherical albedo per channel.
    pub albedo: RgbSample,
}

impl Bxdf for Lambert {
    #[inline]
    fn flags(&self) -> LobeFlags {
        LobeFlags::REFLECTION | LobeFlags::DIFFUSE
    }
    #[inline]
    fn eval_mode(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> RgbSample {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return RgbSample::ZERO;
        }
        self.albedo * FRAC_1_PI
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

impl From<Lambert> for Bsdf {
    fn from(l: Lambert) -> Bsdf {
        Bsdf::Lambert(l)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weight_is_albedo() {
        let l = Lambert {
            albedo: RgbSample::rgb(0.2, 0.5, 0.9),
        };
        let s = l.sample(Vec3::Z, 0.0, Vec2::new(0.1, 0.7)).unwrap();
        assert!((s.weight - l.albedo).map(f32::abs).max_channel() < 1e-6);
        assert!(l.sample(-Vec3::Z, 0.0, Vec2::new(0.1, 0.7)).is_none());
    }
}
