//! Smooth dielectric interface: mirror reflection and refraction, both Dirac deltas (the limit of
//! [`super::RoughDielectric`] as the roughness goes to 0; pbrt-v4 §9.5 "Specular reflection and
//! transmission" gives the same weights).
//!
//! With `F = F_dielectric(cos θo, η)` (Born & Wolf §1.5.2, [`super::fresnel::dielectric`]) the
//! interface reflects `F` and transmits `1 − F` of the incident flux. `uc` picks reflection with
//! probability `F` (so the path weight is 1 in importance mode); the transmitted weight in radiance
//! mode carries the `1/η'²` compression of solid angle (Veach 1997, eq. 5.12), where `η'` is the
//! IOR of the side `wi` is on over that of `wo`'s side. Directions may lie on either side; `eta` is
//! the relative IOR of the side below the macro normal (`z < 0`) over the side above, as for the
//! rough interface. `eval` and `pdf` are 0: a delta is only reached by sampling.

use super::dispersion::Dispersion;
use super::{BsdfSample, Bxdf, Lobe, LobeFlags, LobeKind, TransportMode, fresnel, refract};
use crate::spectrum::RgbSample;
use glam::{Vec2, Vec3};

/// A smooth dielectric interface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SmoothDielectric {
    /// Relative IOR, below / above (> 0); for a dispersive interface its value at the d line.
    pub eta: f32,
    /// The interface's dispersion, used by spectral paths (`None`: the same `eta` at every
    /// wavelength).
    pub dispersion: Option<Dispersion>,
}

impl SmoothDielectric {
    /// An interface with relative IOR `eta` (below / above).
    pub fn new(eta: f32) -> Self {
        SmoothDielectric {
            eta,
            dispersion: None,
        }
    }

    /// The same interface with the relative index `law.eta_at(λ)` for spectral paths (and its
    /// value at the d line for RGB paths).
    pub fn with_dispersion(mut self, law: Dispersion) -> Self {
        if law.inside.is_dispersive() {
            self.eta = law.eta_at(super::dispersion::LAMBDA_D);
            self.dispersion = Some(law);
        }
        self
    }
}

impl Bxdf for SmoothDielectric {
    #[inline]
    fn flags(&self) -> LobeFlags {
        if self.eta == 1.0 {
            LobeFlags::TRANSMISSION | LobeFlags::SPECULAR
        } else {
            LobeFlags::REFLECTION | LobeFlags::TRANSMISSION | LobeFlags::SPECULAR
        }
    }
    #[inline]
    fn eval_mode(&self, _wo: Vec3, _wi: Vec3, _mode: TransportMode) -> RgbSample {
        RgbSample::ZERO
    }
    fn sample_mode(&self, wo: Vec3, uc: f32, _u: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        if wo.z == 0.0 || !wo.is_finite() {
            return None;
        }
        let r = fresnel::dielectric(wo.z, self.eta);
        let t = 1.0 - r;
        if uc < r || t <= 0.0 {
            // Mirror about the macro normal; weight F/pr = 1.
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            return delta(wi, r, r, LobeKind::SpecularReflection, 1.0);
        }
        let wi = refract(wo, Vec3::Z, self.eta)?;
        if wi.z * wo.z >= 0.0 {
            return None;
        }
        let etap = if wo.z > 0.0 { self.eta } else { 1.0 / self.eta };
        let ft = match mode {
            TransportMode::Radiance => t / (etap * etap),
            TransportMode::Importance => t,
        };
        delta(wi, ft, t, LobeKind::SpecularTransmission, etap)
    }
    #[inline]
    fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
        0.0
    }
}

/// A delta sample whose lobe carries `value` of the flux and was chosen with probability `prob`:
/// `f = value / |cos θi|`, so that `weight = f |cos θi| / prob = value / prob`.
#[inline]
fn delta(wi: Vec3, value: f32, prob: f32, kind: LobeKind, eta: f32) -> Option<BsdfSample> {
    let cos = wi.z.abs();
    if !(cos > 0.0 && prob > 0.0) {
        return None;
    }
    let f = RgbSample::splat(value / cos);
    BsdfSample::from_eval(wi, f, prob, Lobe { kind, layer: 0 }).map(|s| s.with_eta(eta))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::spherical_direction;

    #[test]
    fn weights_are_fresnel_split_and_snell_holds() {
        let g = SmoothDielectric::new(1.5);
        let wo = spherical_direction(0.6, 0.3);
        let r = fresnel::dielectric(wo.z, 1.5);
        let refl = g
            .sample_mode(wo, 0.0, Vec2::ZERO, TransportMode::Radiance)
            .unwrap();
        assert!(
            refl.flags
                .contains(LobeFlags::REFLECTION | LobeFlags::SPECULAR)
        );
        assert!((refl.pdf - r).abs() < 1e-6 && (refl.weight[0] - 1.0).abs() < 1e-5);
        assert!((refl.wi - Vec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-6);
        let tr = g
            .sample_mode(wo, 0.999, Vec2::ZERO, TransportMode::Radiance)
            .unwrap();
        assert!(tr.flags.is_transmission() && tr.wi.z < 0.0 && tr.eta == 1.5);
        // Radiance weight 1/η²; importance weight 1.
        assert!((tr.weight[0] - 1.0 / 2.25).abs() < 1e-5, "{}", tr.weight[0]);
        let ti = g
            .sample_mode(wo, 0.999, Vec2::ZERO, TransportMode::Importance)
            .unwrap();
        assert!((ti.weight[0] - 1.0).abs() < 1e-5);
        let s_o = (1.0 - wo.z * wo.z).sqrt();
        let s_i = (1.0 - tr.wi.z * tr.wi.z).sqrt();
        assert!((s_o - 1.5 * s_i).abs() < 1e-5);
        assert_eq!(g.pdf(wo, tr.wi), 0.0);
        assert_eq!(g.eval(wo, tr.wi), RgbSample::ZERO);
    }

    #[test]
    fn total_internal_reflection_always_reflects() {
        let g = SmoothDielectric::new(1.5);
        // From inside at 60°: beyond the critical angle asin(1/1.5) ≈ 41.8°.
        let wo = -spherical_direction(60f32.to_radians(), 1.0);
        for uc in [0.0, 0.5, 0.999_999] {
            let s = g
                .sample_mode(wo, uc, Vec2::ZERO, TransportMode::Radiance)
                .unwrap();
            assert_eq!(s.lobe.kind, LobeKind::SpecularReflection);
            assert!(s.wi.z < 0.0 && (s.weight[0] - 1.0).abs() < 1e-6);
        }
    }

    #[test]
    fn index_matched_interface_passes_straight_through() {
        let g = SmoothDielectric::new(1.0);
        let wo = spherical_direction(1.2, 2.0);
        let s = g
            .sample_mode(wo, 0.3, Vec2::ZERO, TransportMode::Radiance)
            .unwrap();
        assert!((s.wi + wo).length() < 1e-5 && (s.weight[0] - 1.0).abs() < 1e-6);
        assert!(!g.flags().contains(LobeFlags::REFLECTION));
    }
}
