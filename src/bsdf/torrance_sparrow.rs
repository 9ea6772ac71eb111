//! Torrance–Sparrow micro-facet reflection (course eq. 2.1, §3.3.1):
//! `f = F(wi·h) D(h) G / (4 |cos θo| |cos θi|)` with the V-cavity `G`, for dielectric and conductor
//! interfaces alike (the [`Fresnel`] decides which). Sampling draws a visible normal of the V-cavity
//! model ([`MicrofacetDistribution::sample_visible`]) and reflects `wo`:
//! `pdf = G1(wo, h) D(h) / (4 cos θo)`, weight `F G / G1 ≤ F`.
//!
//! Optionally the lobe carries a multiple-scattering energy compensation (Turquin, "Practical
//! multiple scattering compensation for microfacet models", 2019, eq. 15):
//! `f = f_ss · (1 + F0 (1 − E_ss(μo)) / E_ss(μo))`, with `E_ss` the single-scattering albedo at
//! `F = 1` (a 64-entry table built once). It returns the energy that the V-cavity model's masking
//! discards and that further bounces on the micro-surface would reflect; a perfect conductor then has
//! albedo 1 at every angle. It depends on `wo` only, so it is not reciprocal.

use super::memo::Memo;
use super::table::Table;
use super::{Bsdf, Lobe, LobeFlags, LobeKind, TransportMode, flush_tiny};
use super::{BsdfSample, Bxdf, Fresnel, MicrofacetDistribution, reflect};
use crate::sampler::hash_words;
use crate::spectrum::RgbSample;
use glam::{Vec2, Vec3};
use std::sync::Arc;

/// Single-scattering albedo tables at `F = 1`, shared by every lobe with the same distribution.
type ESsKey = (super::Distribution, super::Masking, u32);
static E_SS: Memo<ESsKey, Arc<Table>> = Memo::new(4096);

/// Multiple-scattering compensation data (module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Compensation {
    /// Single-scattering albedo at `F = 1`, over `cos θo`.
    pub e_ss: Arc<Table>,
    /// Reflectance at normal incidence.
    pub f0: RgbSample,
}

/// A measured metal seen from a host medium, for spectral paths: the facet's Fresnel factor at
/// wavelength `λ` is the conductor's with the relative index `(n + i k)(λ) / host`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpectralMetal {
    /// The metal ([`super::Metal::nk_at`]).
    pub metal: super::Metal,
    /// Index of the medium above the metal (1: air; a body's or varnish's index).
    pub host: f32,
}

/// A micro-facet reflection lobe over the upper hemisphere.
#[derive(Clone, Debug, PartialEq)]
pub struct TorranceSparrow {
    /// Micro-facet normal distribution.
    pub distribution: MicrofacetDistribution,
    /// Reflectance of one facet.
    pub fresnel: Fresnel,
    /// Optional multiple-scattering compensation.
    pub compensation: Option<Compensation>,
    /// The measured metal behind `fresnel`, when there is one (spectral paths use its tables).
    pub metal: Option<SpectralMetal>,
}

impl TorranceSparrow {
    /// A plain single-scattering lobe.
    pub fn new(distribution: MicrofacetDistribution, fresnel: Fresnel) -> Self {
        TorranceSparrow {
            distribution,
            fresnel,
            compensation: None,
            metal: None,
        }
    }

    /// The same lobe with multiple-scattering compensation (builds its table, ~2 ms, once per
    /// distribution: the table does not depend on the Fresnel factor).
    pub fn with_compensation(mut self) -> Self {
        let d = self.distribution;
        let key = (d.kind(), d.masking(), d.alpha().to_bits());
        let e_ss = E_SS.get_or_build(key, || {
            let plain = TorranceSparrow::new(d, Fresnel::Perfect);
            Arc::new(crate::bsdf::store::table("e_ss", &(d, 32), || {
                Table::by_sampling(32, hash_words(&[0xc0_4e05]), |wo, uc, u| {
                    plain.sample_weight(wo, uc, u)
                })
            }))
        });
        self.compensation = Some(Compensation {
            e_ss,
            f0: self.fresnel.eval(1.0),
        });
        self
    }

    /// The compensation factor for viewing direction `wo` (1 without compensation).
    #[inline]
    pub fn compensation_factor(&self, wo: Vec3) -> RgbSample {
        match &self.compensation {
            None => RgbSample::ONE,
            Some(c) => {
                let e = c.e_ss.at(wo.z)[0].clamp(1e-3, 1.0);
                RgbSample::ONE + c.f0 * ((1.0 - e) / e)
            }
        }
    }

    /// The sampled direction: `wo` reflected about a visible micro-normal (module docs); `None`
    /// below the horizon. Shared by the RGB and spectral samplers.
    #[inline]
    pub(crate) fn sample_wi(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<Vec3> {
        if wo.z <= 0.0 {
            return None;
        }
        let (h, _) = self.distribution.sample_visible(wo, uc, u)?;
        if wo.dot(h) <= 0.0 {
            return None;
        }
        let wi = reflect(wo, h).normalize();
        (wi.z > 0.0).then_some(wi)
    }

    /// The weight `f |cos θi| / pdf` of `sample(wo, uc, u)` (0 where it fails) in closed form,
    /// `F G ⟨wo·h⟩ / (cos θo · pdf_visible/D)` — `F G / G1` with the V-cavity —, without
    /// evaluating `D`: the same estimator for the albedo tables at a fraction of the cost (it
    /// differs from the sample's weight only by rounding).
    #[inline]
    pub fn sample_weight(&self, wo: Vec3, uc: f32, u: Vec2) -> RgbSample {
        if wo.z <= 0.0 {
            return RgbSample::ZERO;
        }
        let Some((h, _)) = self.distribution.sample_visible(wo, uc, u) else {
            return RgbSample::ZERO;
        };
        let oh = wo.dot(h);
        if oh <= 0.0 {
            return RgbSample::ZERO;
        }
        let wi = reflect(wo, h).normalize();
        if wi.z <= 0.0 {
            return RgbSample::ZERO;
        }
        let vf = self.distribution.visible_over_d(wo, h);
        if !(vf > 0.0) {
            return RgbSample::ZERO;
        }
        let g = self.distribution.g(wo, wi, h);
        let w = self.fresnel.eval(wi.dot(h).max(0.0)) * (g * oh / (wo.z * vf));
        let w = if self.compensation.is_some() {
            w * self.compensation_factor(wo)
        } else {
            w
        };
        if w.is_valid() { w } else { RgbSample::ZERO }
    }

    /// `(eval(wo, wi), pdf(wo, wi))` with the half vector and `D` computed once; bit for bit the
    /// two calls' results.
    #[inline]
    pub fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (RgbSample, f32) {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return (RgbSample::ZERO, 0.0);
        }
        let Some(h) = Self::half(wo, wi) else {
            return (RgbSample::ZERO, 0.0);
        };
        let oh = wo.dot(h);
        if oh <= 0.0 {
            return (RgbSample::ZERO, 0.0);
        }
        let d = self.distribution.d(h);
        let pdf = self.distribution.pdf_visible_with_d(wo, h, d) / (4.0 * oh);
        // As `eval`: a back-facing facet (rounding near grazing mirror pairs) scatters nothing.
        if wi.dot(h) <= 0.0 || d == 0.0 {
            return (RgbSample::ZERO, pdf);
        }
        let g = self.distribution.g(wo, wi, h);
        let f = self.fresnel.eval(wi.dot(h).max(0.0));
        let v = f * (d * g / (4.0 * wo.z * wi.z));
        let f = flush_tiny(if self.compensation.is_some() {
            v * self.compensation_factor(wo)
        } else {
            v
        });
        (f, pdf)
    }

    /// The half vector of two upper-hemisphere directions, `None` when undefined (`wo = −wi`).
    #[inline]
    pub(crate) fn half(wo: Vec3, wi: Vec3) -> Option<Vec3> {
        let h = wo + wi;
        let l2 = h.length_squared();
        (l2 > 1e-30 && h.z > 0.0).then(|| h / l2.sqrt())
    }
}

impl Bxdf for TorranceSparrow {
    #[inline]
    fn flags(&self) -> LobeFlags {
        LobeFlags::REFLECTION | LobeFlags::GLOSSY
    }
    #[inline]
    fn eval_mode(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> RgbSample {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return RgbSample::ZERO;
        }
        let Some(h) = Self::half(wo, wi) else {
            return RgbSample::ZERO;
        };
        // Near grazing mirror pairs, rounding can tilt h past a direction: a back-facing facet
        // scatters nothing (and `pdf` is 0 there too).
        if wo.dot(h) <= 0.0 || wi.dot(h) <= 0.0 {
            return RgbSample::ZERO;
        }
        let d = self.distribution.d(h);
        if d == 0.0 {
            return RgbSample::ZERO;
        }
        let g = self.distribution.g(wo, wi, h);
        let f = self.fresnel.eval(wi.dot(h).max(0.0));
        let v = f * (d * g / (4.0 * wo.z * wi.z));
        flush_tiny(if self.compensation.is_some() {
            v * self.compensation_factor(wo)
        } else {
            v
        })
    }

    #[inline]
    fn sample_mode(&self, wo: Vec3, uc: f32, u: Vec2, _mode: TransportMode) -> Option<BsdfSample> {
        let wi = self.sample_wi(wo, uc, u)?;
        let (f, pdf) = self.eval_pdf(wo, wi);
        BsdfSample::from_eval(
            wi,
            f,
            pdf,
            Lobe {
                kind: LobeKind::Glossy,
                layer: 0,
            },
        )
    }

    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let Some(h) = Self::half(wo, wi) else {
            return 0.0;
        };
        let oh = wo.dot(h);
        if oh <= 0.0 {
            return 0.0;
        }
        self.distribution.pdf_visible(wo, h) / (4.0 * oh)
    }
}

impl From<TorranceSparrow> for Bsdf {
    fn from(t: TorranceSparrow) -> Bsdf {
        Bsdf::TorranceSparrow(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::{Distribution, FresnelMode, spherical_direction};

    #[test]
    fn mirror_pair_is_symmetric_and_finite() {
        let ts = TorranceSparrow::new(
            MicrofacetDistribution::new(Distribution::Blinn, 5.0),
            Fresnel::dielectric(1.5, FresnelMode::Exact),
        );
        let wo = spherical_direction(0.4, 0.0);
        let wi = spherical_direction(0.4, std::f32::consts::PI);
        let f = ts.eval(wo, wi);
        assert!(f.is_valid() && f[0] > 0.0);
        assert_eq!(ts.eval(wo, wi), ts.eval(wi, wo));
        assert_eq!(ts.eval(wo, -wo), RgbSample::ZERO);
        let g = spherical_direction(1.570_796_2, 0.0);
        assert!(ts.eval(g, g).is_valid());
    }

    #[test]
    fn sample_agrees_with_eval() {
        let ts = TorranceSparrow::new(
            MicrofacetDistribution::new(Distribution::Beckmann, 12.0),
            Fresnel::Perfect,
        );
        let wo = spherical_direction(0.9, 0.3);
        let s = ts.sample(wo, 0.5, Vec2::new(0.3, 0.8)).unwrap();
        let f = ts.eval(wo, s.wi);
        assert!((s.f[0] - f[0]).abs() <= 1e-6 * f[0]);
        assert!((s.pdf - ts.pdf(wo, s.wi)).abs() <= 1e-6 * s.pdf);
    }

    #[test]
    fn eval_pdf_is_eval_and_pdf_bit_for_bit() {
        let mut rng = crate::sampler::Rng::new(7);
        for (m, fresnel) in [
            (0.01f32, Fresnel::dielectric(1.5, FresnelMode::Exact)),
            (
                12.0,
                Fresnel::conductor(
                    RgbSample::splat(0.2),
                    RgbSample::splat(3.0),
                    FresnelMode::Exact,
                ),
            ),
            (60.0, Fresnel::Perfect),
        ] {
            let ts =
                TorranceSparrow::new(MicrofacetDistribution::new(Distribution::Blinn, m), fresnel)
                    .with_compensation();
            for _ in 0..2000 {
                let wo = spherical_direction(rng.uniform() * 1.6, rng.uniform() * 6.3);
                let wi = spherical_direction(rng.uniform() * 1.6, rng.uniform() * 6.3);
                let (f, p) = ts.eval_pdf(wo, wi);
                assert_eq!(f, ts.eval(wo, wi));
                assert_eq!(p.to_bits(), ts.pdf(wo, wi).to_bits());
            }
        }
    }

    #[test]
    fn closed_form_weight_is_the_sample_weight() {
        let mut rng = crate::sampler::Rng::new(5);
        for m in [0.01f32, 3.0, 30.0, 70.0] {
            for kind in [Distribution::Blinn, Distribution::Ggx] {
                let ts = TorranceSparrow::new(
                    MicrofacetDistribution::new(kind, m),
                    Fresnel::dielectric(1.5, FresnelMode::Exact),
                );
                for _ in 0..2000 {
                    let wo = spherical_direction(rng.uniform() * 1.57, 0.4);
                    let (uc, u) = (rng.uniform(), rng.uniform2());
                    let w = ts.sample_weight(wo, uc, u)[0];
                    let sample = ts.sample(wo, uc, u);
                    let s = sample.map_or(0.0, |s| s.weight[0]);
                    let wi_z = sample.map_or(1.0, |s| s.wi.z);
                    // Near the mirror (e ≈ 6.6e7) the sample's F and G see the half vector recomputed
                    // from (wo, wi), a rounding away from the sampled one: 1e-3 there.
                    let tol: f32 = if m < 0.1 { 1e-3 } else { 1e-4 };
                    // Near grazing the same rounding of a small cosine is relatively larger
                    // (G is steep there).
                    let tol = tol.max(2e-6 / wo.z.min(wi_z));
                    assert!(
                        (w - s).abs() <= tol * s.max(1e-3),
                        "{kind:?} {m}: {w} vs {s}"
                    );
                }
            }
        }
    }

    #[test]
    fn compensation_makes_a_perfect_mirror_lossless() {
        use crate::bsdf::measure::{albedo_by_sampling, direction_deg};
        let plain = TorranceSparrow::new(
            MicrofacetDistribution::new(Distribution::Blinn, 30.0),
            Fresnel::Perfect,
        );
        let comp = plain.clone().with_compensation();
        for th in [0.0, 45.0, 80.0] {
            let wo = direction_deg(th, 0.0);
            let a = albedo_by_sampling(&plain, wo, 50_000, 3).mean[0];
            let b = albedo_by_sampling(&comp, wo, 50_000, 3).mean[0];
            assert!(
                a < 0.995,
                "single scattering loses energy at m=30°, θ={th}: {a}"
            );
            assert!((b - 1.0).abs() < 0.01, "compensated albedo at θ={th}: {b}");
        }
    }
}
