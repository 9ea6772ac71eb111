//! Both lobes of a rough dielectric interface sampled at once, with their weights in closed form:
//! the estimator of the albedo tables (`R` and `T` of an interface, module
//! `bsdf::layered::adding` and [`super::RoughDielectric::with_energy_tables`]).

use super::{Lobes, RoughDielectric};
use crate::bsdf::{TransportMode, fresnel, reflect, refract};
use glam::{Vec2, Vec3};

impl RoughDielectric {
    /// `sample_lobes(wo, uc, u, mode, Lobes::Reflection)` and `(…, Lobes::Transmission)` at once,
    /// as `(wi, weight)` pairs (`None` where the sample fails): one micro-normal for both, and
    /// for an interface without its multiple-scattering lobe the weights in closed form —
    /// `F G ⟨wo·h⟩ / (|cos θo| · pdf_visible/D)` and the same with `1 − F` (over `η'²` for
    /// radiance) — without evaluating `D`: the same estimators for the tables at a fraction of
    /// the cost (they differ from the samples' weights only by rounding).
    pub fn sample_split(
        &self,
        wo: Vec3,
        uc: f32,
        u: Vec2,
        mode: TransportMode,
    ) -> [Option<(Vec3, f32)>; 2] {
        if self.energy.is_some() {
            return [Lobes::Reflection, Lobes::Transmission].map(|lobes| {
                self.sample_lobes(wo, uc, u, mode, lobes)
                    .map(|s| (s.wi, s.weight[0]))
            });
        }
        let none = [None, None];
        if wo.z == 0.0 {
            return none;
        }
        let Some((h, uc)) = self.distribution.sample_visible(wo, uc.clamp(0.0, 1.0), u) else {
            return none;
        };
        let oh = wo.dot(h);
        if oh * wo.z <= 0.0 {
            return none;
        }
        let vf = self.distribution.visible_over_d(wo, h);
        if !(vf > 0.0) {
            return none;
        }
        let r = fresnel::dielectric(oh, self.eta);
        let k = oh.abs() / (wo.z.abs() * vf);
        let ok = |w: f32| (w.is_finite() && w > 0.0).then_some(w);
        // With one lobe allowed the sampler keeps `uc · p < p`: only `uc = 1` misses it.
        let reflected = (r > 0.0 && uc < 1.0)
            .then(|| reflect(wo, h).normalize())
            .filter(|wi| wi.z * wo.z > 0.0)
            .and_then(|wi| ok(r * self.distribution.g(wo, wi, h) * k).map(|w| (wi, w)));
        let refracted = (r < 1.0)
            .then(|| refract(wo, h, self.eta))
            .flatten()
            .filter(|wi| wi.z * wo.z < 0.0)
            .and_then(|wi| {
                let etap = if wo.z > 0.0 { self.eta } else { 1.0 / self.eta };
                let mut w = (1.0 - r) * self.distribution.g(wo, wi, h) * k;
                if mode == TransportMode::Radiance {
                    w /= etap * etap;
                }
                ok(w).map(|w| (wi, w))
            });
        [reflected, refracted]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::{Distribution, MicrofacetDistribution, spherical_direction};

    #[test]
    fn split_sampling_matches_the_one_lobe_samplers() {
        let mut rng = crate::sampler::Rng::new(13);
        for (m, eta) in [(0.01f32, 1.5f32), (5.0, 1.33), (30.0, 1.5), (60.0, 0.7)] {
            let g = RoughDielectric::new(MicrofacetDistribution::new(Distribution::Blinn, m), eta);
            for i in 0..3000 {
                let side = if i % 2 == 0 { 1.0 } else { -1.0 };
                let wo = spherical_direction(rng.uniform() * 1.57, 0.4) * Vec3::new(1.0, 1.0, side);
                let (uc, u) = (rng.uniform(), rng.uniform2());
                let mode = [TransportMode::Radiance, TransportMode::Importance][i % 2];
                let split = g.sample_split(wo, uc, u, mode);
                for (k, lobes) in [Lobes::Reflection, Lobes::Transmission]
                    .into_iter()
                    .enumerate()
                {
                    let one = g
                        .sample_lobes(wo, uc, u, mode, lobes)
                        .map(|s| (s.wi, s.weight[0]));
                    match (split[k], one) {
                        (Some((a, wa)), Some((b, wb))) => {
                            assert!((a - b).length() < 1e-6, "{m} {lobes:?}");
                            // Near the mirror the one-lobe sampler's F and G see the half vector
                            // recomputed from (wo, wi), a rounding away: 1e-3 there.
                            let tol: f32 = if m < 0.1 { 1e-3 } else { 1e-4 };
                            // Near grazing the same rounding of a small cosine is relatively
                            // larger (G is steep there).
                            let tol = tol.max(2e-6 / wo.z.abs().min(b.z.abs()));
                            assert!(
                                (wa - wb).abs() <= tol * wb.max(1e-3),
                                "{m} {lobes:?}: {wa} vs {wb}"
                            );
                        }
                        (None, None) => {}
                        // Rounding may decide a sample at the very edge differently.
                        (a, b) => {
                            let w = a.or(b).unwrap().1;
                            assert!(w < 1e-3, "{m} {lobes:?}: {a:?} vs {b:?}");
                        }
                    }
                }
            }
        }
    }
}
