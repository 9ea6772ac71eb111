//! Deliberately wrong samplers, for the self-test that the chi-square machinery can fail.

use super::subjects::SharedBxdf;
use glam::{Vec2, Vec3};
use lapidary::bsdf::{BsdfSample, Bxdf, Lambert, LobeFlags, TransportMode};
use lapidary::spectrum::RgbSample;

/// A BSDF whose `sample` draws from one model and whose `pdf` reports another's density, or
/// whose sampler misbehaves in a controlled way: the machinery must reject every one of them.
pub struct Wrong {
    pub sampler: SharedBxdf,
    pub claimed: SharedBxdf,
    /// Every `1/below_every`-th sample is mirrored below the horizon (0 = never).
    pub below_every: u64,
    /// A sample fails when `uc < fail_share` (Lambert ignores `uc`, so the surviving directions keep
    /// their distribution) although the claimed pdf integrates to 1.
    pub fail_share: f32,
}

impl Bxdf for Wrong {
    fn flags(&self) -> LobeFlags {
        LobeFlags::REFLECTION | LobeFlags::DIFFUSE
    }
    fn eval_mode(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> RgbSample {
        self.claimed.eval(wo, wi)
    }
    fn sample_mode(&self, wo: Vec3, uc: f32, u: Vec2, _mode: TransportMode) -> Option<BsdfSample> {
        if uc < self.fail_share {
            return None;
        }
        let mut s = self.sampler.sample(wo, uc, u)?;
        if self.below_every > 0 && ((uc * 1e6) as u64).is_multiple_of(self.below_every) {
            s.wi.z = -s.wi.z;
        }
        Some(s)
    }
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.claimed.pdf(wo, wi)
    }
}

/// A Lambert that claims a uniform-hemisphere pdf while sampling cosine-weighted directions.
pub struct UniformClaim;

impl Bxdf for UniformClaim {
    fn flags(&self) -> LobeFlags {
        LobeFlags::REFLECTION | LobeFlags::DIFFUSE
    }
    fn eval_mode(&self, _wo: Vec3, wi: Vec3, _mode: TransportMode) -> RgbSample {
        RgbSample::splat(if wi.z > 0.0 { 0.5 } else { 0.0 })
    }
    fn sample_mode(&self, wo: Vec3, uc: f32, u: Vec2, _mode: TransportMode) -> Option<BsdfSample> {
        Lambert {
            albedo: RgbSample::ONE,
        }
        .sample(wo, uc, u)
    }
    fn pdf(&self, _wo: Vec3, wi: Vec3) -> f32 {
        if wi.z > 0.0 {
            0.5 * std::f32::consts::FRAC_1_PI
        } else {
            0.0
        }
    }
}
