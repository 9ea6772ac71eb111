//! A coat's interface as the Reference walk and the adding solution see it: a rough dielectric
//! (Walter et al. 2007, with its multiple-scattering lobe when the stack compensates) or a
//! perfectly smooth one, whose reflection and refraction are Dirac deltas.
//!
//! A smooth interface follows the delta convention of [`SmoothDielectric`](crate::bsdf::SmoothDielectric):
//! `value` and `pdf_lobes` are 0 (a delta is reached only by sampling), a sample carries
//! `f = value/|cos θi|` and `pdf` = the probability of the choice made, so that
//! `weight = f |cos θi| / pdf` is the lobe's flux share (times `1/η'²` for radiance transmission).
//! Callers that combine a sampled direction with another strategy by MIS must give the delta
//! strategy weight 1 ([`CoatInterface::is_delta`]).

use crate::bsdf::dielectric::Lobes;
use crate::bsdf::{BsdfSample, Lobe, LobeKind, RoughDielectric, TransportMode, fresnel, refract};
use crate::spectrum::RgbSample;
use glam::{Vec2, Vec3};

/// The interface of one coat.
#[derive(Clone, Debug, PartialEq)]
pub struct CoatInterface {
    /// The rough interface (for a smooth coat: a placeholder that holds the relative IOR).
    pub rough: RoughDielectric,
    /// Perfectly smooth: reflection and refraction are deltas.
    pub smooth: bool,
}

impl CoatInterface {
    /// Whether the interface scatters only into deltas.
    #[inline]
    pub fn is_delta(&self) -> bool {
        self.smooth
    }

    /// The same interface with the rough interface's multiple-scattering lobe (a smooth one
    /// loses nothing and stays as it is).
    pub fn with_energy_tables(self) -> Self {
        if self.smooth || self.rough.energy.is_some() {
            self
        } else {
            CoatInterface {
                rough: self.rough.with_energy_tables(),
                smooth: false,
            }
        }
    }

    /// `f(wo, wi)` in sr⁻¹ for directions on either side; 0 for a smooth interface.
    #[inline]
    pub fn value(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> f32 {
        if self.smooth {
            0.0
        } else {
            self.rough.value(wo, wi, mode)
        }
    }

    /// Density of sampling `wi` from `wo` with `lobes`; 0 for a smooth interface.
    #[inline]
    pub fn pdf_lobes(&self, wo: Vec3, wi: Vec3, lobes: Lobes) -> f32 {
        if self.smooth {
            0.0
        } else {
            self.rough.pdf_lobes(wo, wi, lobes)
        }
    }

    /// Samples `wi` from `wo` (either side) with the lobes allowed.
    #[inline]
    pub fn sample_lobes(
        &self,
        wo: Vec3,
        uc: f32,
        u: Vec2,
        mode: TransportMode,
        lobes: Lobes,
    ) -> Option<BsdfSample> {
        if self.smooth {
            self.sample_smooth(wo, uc, mode, lobes)
        } else {
            self.rough.sample_lobes(wo, uc, u, mode, lobes)
        }
    }

    /// The smooth interface's deltas: mirror reflection with `F`, refraction with `1 − F`
    /// (Born & Wolf §1.5.2), `uc` choosing between them when both are allowed.
    fn sample_smooth(
        &self,
        wo: Vec3,
        uc: f32,
        mode: TransportMode,
        lobes: Lobes,
    ) -> Option<BsdfSample> {
        if wo.z == 0.0 || !wo.is_finite() {
            return None;
        }
        let eta = self.rough.eta;
        let r = fresnel::dielectric(wo.z, eta);
        let t = 1.0 - r;
        let (pr, pt) = match lobes {
            Lobes::All => (r, t),
            Lobes::Reflection => (r, 0.0),
            Lobes::Transmission => (0.0, t),
        };
        if pr + pt <= 0.0 {
            return None;
        }
        let prob_r = pr / (pr + pt);
        if uc < prob_r || pt <= 0.0 {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            return delta(wi, r, prob_r, LobeKind::SpecularReflection, 1.0);
        }
        let wi = refract(wo, Vec3::Z, eta)?;
        if wi.z * wo.z >= 0.0 {
            return None;
        }
        let etap = if wo.z > 0.0 { eta } else { 1.0 / eta };
        let value = match mode {
            TransportMode::Radiance => t / (etap * etap),
            TransportMode::Importance => t,
        };
        delta(
            wi,
            value,
            1.0 - prob_r,
            LobeKind::SpecularTransmission,
            etap,
        )
    }
}

/// A delta sample carrying `value` of the flux, chosen with probability `prob`.
#[inline]
fn delta(wi: Vec3, value: f32, prob: f32, kind: LobeKind, eta: f32) -> Option<BsdfSample> {
    let cos = wi.z.abs();
    if !(cos > 0.0 && prob > 0.0) {
        return None;
    }
    BsdfSample::from_eval(
        wi,
        RgbSample::splat(value / cos),
        prob,
        Lobe { kind, layer: 0 },
    )
    .map(|s| s.with_eta(eta))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::{Distribution, MicrofacetDistribution, spherical_direction};

    fn smooth(eta: f32) -> CoatInterface {
        CoatInterface {
            rough: RoughDielectric::new(
                MicrofacetDistribution::new(Distribution::Blinn, 0.01),
                eta,
            ),
            smooth: true,
        }
    }

    #[test]
    fn smooth_weights_are_the_fresnel_shares() {
        let i = smooth(1.5);
        let wo = spherical_direction(0.7, 0.2);
        let f = fresnel::dielectric(wo.z, 1.5);
        let m = TransportMode::Importance;
        let r = i
            .sample_lobes(wo, 0.5, Vec2::ZERO, m, Lobes::Reflection)
            .unwrap();
        assert!((r.weight[0] - f).abs() < 1e-6 && r.wi.z > 0.0);
        let t = i
            .sample_lobes(wo, 0.5, Vec2::ZERO, m, Lobes::Transmission)
            .unwrap();
        assert!((t.weight[0] - (1.0 - f)).abs() < 1e-6 && t.wi.z < 0.0);
        let tr = i
            .sample_lobes(
                wo,
                0.5,
                Vec2::ZERO,
                TransportMode::Radiance,
                Lobes::Transmission,
            )
            .unwrap();
        assert!((tr.weight[0] - (1.0 - f) / 2.25).abs() < 1e-6);
        // All lobes: reflection with probability F, each weight 1 in importance mode.
        let a = i.sample_lobes(wo, 0.0, Vec2::ZERO, m, Lobes::All).unwrap();
        assert!(a.wi.z > 0.0 && (a.weight[0] - 1.0).abs() < 1e-5);
        let b = i
            .sample_lobes(wo, 0.999, Vec2::ZERO, m, Lobes::All)
            .unwrap();
        assert!(b.wi.z < 0.0 && (b.weight[0] - 1.0).abs() < 1e-5);
        assert_eq!(i.value(wo, b.wi, m), 0.0);
        assert_eq!(i.pdf_lobes(wo, b.wi, Lobes::All), 0.0);
        // Total internal reflection from below: transmission impossible.
        let below = -spherical_direction(1.2, 0.0);
        assert!(
            i.sample_lobes(below, 0.5, Vec2::ZERO, m, Lobes::Transmission)
                .is_none()
        );
    }
}
