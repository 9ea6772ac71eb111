//! Rough dielectric interface with reflection **and** transmission (Walter, Marschner, Li &
//! Torrance, "Microfacet models for refraction through rough surfaces", EGSR 2007, eqs. 16–21),
//! with the same micro-facet distribution and V-cavity `G` as [`super::TorranceSparrow`], so its
//! reflection lobe is exactly the Torrance–Sparrow dielectric lobe. Micro-normals are sampled from
//! the V-cavity's visible normals (see [`super::microfacet`]); `uc` first picks the cavity facet,
//! then (remapped) reflection versus transmission.
//!
//! Used by the Reference layer model's random walk, and later by translucent stones. Directions may
//! lie on either side; `eta` is the relative IOR of the side below the macro normal (`z < 0`) over
//! the side above. Transmission in [`TransportMode::Radiance`] carries the `1/η'²` radiance
//! scaling; [`TransportMode::Importance`] omits it, so `f_rad(wo, wi) = f_imp(wi, wo)`.

use super::interface_energy::InterfaceEnergy;
use super::memo::Memo;
use super::table::Table;
use super::{
    BsdfSample, Bxdf, Lobe, LobeFlags, LobeKind, MicrofacetDistribution, TransportMode, fresnel,
    reflect, refract,
};
use crate::sampler::hash_words;
use crate::spectrum::RgbSample;
use glam::{Vec2, Vec3};
use std::sync::Arc;

mod split;

/// Which lobes a call may sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lobes {
    /// Reflection and transmission, chosen by Fresnel.
    All,
    /// Reflection only (the weight then carries the Fresnel factor).
    Reflection,
    /// Transmission only (the weight then carries `1 − F`).
    Transmission,
}

/// Interfaces that differ only in where they are used share one lobe: a gem's materials often
/// repeat a coat (same distribution, roughness and IOR), and the tables take ~10 ms each.
type EnergyKey = (super::Distribution, super::Masking, u32, u32, u32);
static ENERGY: Memo<EnergyKey, Option<Arc<InterfaceEnergy>>> = Memo::new(4096);

/// A rough dielectric interface.
#[derive(Clone, Debug, PartialEq)]
pub struct RoughDielectric {
    /// Micro-facet distribution of the interface.
    pub distribution: MicrofacetDistribution,
    /// Relative IOR, below / above.
    pub eta: f32,
    /// Optional multiple-scattering lobe that returns the energy single scattering loses,
    /// reciprocally ([`InterfaceEnergy`]).
    pub energy: Option<Arc<InterfaceEnergy>>,
    /// The interface's dispersion, used by spectral paths (`None`: the same `eta` at every
    /// wavelength; `eta` is then its value at the d line).
    pub dispersion: Option<super::dispersion::Dispersion>,
}

impl RoughDielectric {
    /// An interface without compensation.
    pub fn new(distribution: MicrofacetDistribution, eta: f32) -> Self {
        RoughDielectric {
            distribution,
            eta,
            energy: None,
            dispersion: None,
        }
    }

    /// The same interface with its multiple-scattering lobe ([`InterfaceEnergy`]): measures the
    /// single-scattering reflection and transmission from each side (~10 ms) and builds the lobe
    /// that returns the missing flux reciprocally. A near-smooth interface loses nothing and gets
    /// no lobe.
    pub fn with_energy_tables(self) -> Self {
        self.with_energy_tables_at(32)
    }

    /// [`Self::with_energy_tables`] with `grid² · 4` stratified samples per table entry (32:
    /// 4096, ~0.2 % rms in the interface's albedo; 64: 16 384, for a stone's boundary, which
    /// light crosses and reflects from many times — tests/translucent/furnace.rs).
    pub fn with_energy_tables_at(mut self, grid: usize) -> Self {
        let d = self.distribution;
        let key = (
            d.kind(),
            d.masking(),
            d.alpha().to_bits(),
            self.eta.to_bits(),
            grid as u32,
        );
        self.energy = ENERGY.get_or_build(key, || self.build_energy(grid));
        self
    }

    /// Measures the single-scattering tables and builds the lobe (uncached).
    fn build_energy(&self, grid: usize) -> Option<Arc<InterfaceEnergy>> {
        let plain = RoughDielectric::new(self.distribution, self.eta);
        // Reflection and transmission sampled separately with the same numbers: their split is
        // then free of the binomial noise of choosing between them.
        let table = |sign: f32| {
            // 4096 samples per entry: ~0.2 % rms in E at any angle (1024 gave up to 1.7 % at
            // grazing for m 45°), and the lobe returns exactly 1 − E.
            Table::by_sampling(
                grid,
                hash_words(&[0xd1e1, sign.to_bits() as u64]),
                |wo, uc, u| {
                    let wo = Vec3::new(wo.x, wo.y, sign * wo.z);
                    let [r, t] = plain
                        .sample_split(wo, uc, u, TransportMode::Importance)
                        .map(|s| s.map_or(0.0, |(_, w)| w));
                    RgbSample([r, t, 0.0])
                },
            )
        };
        let key = (self.distribution, self.eta, grid);
        let [above, below] =
            crate::bsdf::store::tables("interface energy", &key, || [table(1.0), table(-1.0)]);
        InterfaceEnergy::new(above, below, self.eta).map(Arc::new)
    }

    /// Probability that a sample from `wo` with `lobes` allowed is drawn from the
    /// multiple-scattering lobe: its share of the flux those lobes carry.
    #[inline]
    fn p_multiple(&self, wo: Vec3, lobes: Lobes) -> f32 {
        let Some(e) = &self.energy else {
            return 0.0;
        };
        let (r, t) = e.single(wo);
        let (mr, mt) = e.split(wo);
        let (ms, ss) = match lobes {
            Lobes::All => (mr + mt, r + t),
            Lobes::Reflection => (mr, r),
            Lobes::Transmission => (mt, t),
        };
        if ms + ss > 0.0 { ms / (ms + ss) } else { 0.0 }
    }

    /// The generalised half vector (Walter eq. 16), facing `+z`; `None` when undefined or when a
    /// direction is back-facing to it.
    #[inline]
    fn half(&self, wo: Vec3, wi: Vec3) -> Option<(Vec3, bool, f32)> {
        let (co, ci) = (wo.z, wi.z);
        if co == 0.0 || ci == 0.0 {
            return None;
        }
        let reflect = co * ci > 0.0;
        let etap = if reflect {
            1.0
        } else if co > 0.0 {
            self.eta
        } else {
            1.0 / self.eta
        };
        let mut h = wi * etap + wo;
        let l2 = h.length_squared();
        if !(l2 > 1e-30) {
            return None;
        }
        h /= l2.sqrt();
        if h.z < 0.0 {
            h = -h;
        }
        if h.dot(wi) * ci <= 0.0 || h.dot(wo) * co <= 0.0 {
            return None;
        }
        Some((h, reflect, etap))
    }

    /// `f(wo, wi)` in sr⁻¹ (cosine excluded) for directions on either side: single scattering plus
    /// the multiple-scattering lobe when the interface has one.
    pub fn value(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> f32 {
        let ss = self.value_single(wo, wi, mode);
        match &self.energy {
            None => ss,
            Some(e) => {
                let v = ss + e.value(wo, wi, mode);
                if v.is_finite() && v >= super::F_FLUSH {
                    v
                } else {
                    0.0
                }
            }
        }
    }

    /// The single-scattering part of [`Self::value`] (Walter et al. 2007, eqs. 20–21).
    fn value_single(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> f32 {
        let Some((h, is_reflect, etap)) = self.half(wo, wi) else {
            return 0.0;
        };
        let d = self.distribution.d(h);
        let f = self.fresnel_at(wo, wi, h, is_reflect);
        self.value_single_at(wo, wi, mode, (h, is_reflect, etap), d, f)
    }

    /// The Fresnel factor of the pair `(wo, wi)` at micro-normal `h`. F is the same seen from
    /// both sides of a refraction, but from the dense side near the critical angle `1 − F` is
    /// ill-conditioned in the f32 cosine (up to a rounding turning a transmission into total
    /// internal reflection): it is evaluated at the direction on the rarer side, so that
    /// f(wo, wi) and f(wi, wo) agree (tests/dielectric.rs, reciprocity).
    #[inline]
    fn fresnel_at(&self, wo: Vec3, wi: Vec3, h: Vec3, is_reflect: bool) -> f32 {
        let rarer_is_wo = is_reflect || (wo.z > 0.0) == (self.eta >= 1.0);
        fresnel::dielectric(if rarer_is_wo { wo } else { wi }.dot(h), self.eta)
    }

    /// [`Self::value_single`] from the half vector, `D(h)` and the Fresnel factor.
    #[inline]
    fn value_single_at(
        &self,
        wo: Vec3,
        wi: Vec3,
        mode: TransportMode,
        (h, is_reflect, etap): (Vec3, bool, f32),
        d: f32,
        f: f32,
    ) -> f32 {
        if d == 0.0 {
            return 0.0;
        }
        let g = self.distribution.g(wo, wi, h);
        let v = if is_reflect {
            f * d * g / (4.0 * (wo.z * wi.z).abs())
        } else {
            let denom = (wi.dot(h) + wo.dot(h) / etap).powi(2) * wi.z * wo.z;
            let mut ft = (1.0 - f) * d * g * (wi.dot(h) * wo.dot(h) / denom).abs();
            if mode == TransportMode::Radiance {
                ft /= etap * etap;
            }
            ft
        };
        if v.is_finite() && v >= super::F_FLUSH {
            v
        } else {
            0.0
        }
    }

    /// `(value(wo, wi, mode), pdf_lobes(wo, wi, lobes))` with the half vector, `D` and the
    /// Fresnel factor computed once; bit for bit the two calls' results.
    pub fn value_pdf(&self, wo: Vec3, wi: Vec3, mode: TransportMode, lobes: Lobes) -> (f32, f32) {
        let (ss, ss_pdf) = match self.half(wo, wi) {
            None => (0.0, 0.0),
            Some(hv) => {
                let (h, is_reflect, _) = hv;
                let d = self.distribution.d(h);
                let f = self.fresnel_at(wo, wi, h, is_reflect);
                (
                    self.value_single_at(wo, wi, mode, hv, d, f),
                    self.pdf_single_at(wo, wi, lobes, hv, f, || {
                        self.distribution.pdf_visible_with_d(wo, h, d)
                    }),
                )
            }
        };
        match &self.energy {
            None => (ss, ss_pdf),
            Some(e) => {
                let v = ss + e.value(wo, wi, mode);
                let v = if v.is_finite() && v >= super::F_FLUSH {
                    v
                } else {
                    0.0
                };
                (v, self.mix_pdf(e, wo, wi, lobes, ss_pdf))
            }
        }
    }

    /// The mixture density of the multiple-scattering lobe and single scattering (density
    /// `ss` of `wi`).
    #[inline]
    fn mix_pdf(&self, e: &InterfaceEnergy, wo: Vec3, wi: Vec3, lobes: Lobes, ss: f32) -> f32 {
        let pm = self.p_multiple(wo, lobes);
        let (rf, tr) = (lobes != Lobes::Transmission, lobes != Lobes::Reflection);
        let allowed = if wo.z * wi.z > 0.0 { rf } else { tr };
        let ms = if allowed { e.pdf(wo, wi, rf, tr) } else { 0.0 };
        let p = pm * ms + (1.0 - pm) * ss;
        if p.is_finite() { p.max(0.0) } else { 0.0 }
    }

    /// Density of sampling `wi` from `wo` with the given lobes allowed.
    pub fn pdf_lobes(&self, wo: Vec3, wi: Vec3, lobes: Lobes) -> f32 {
        let ss = self.pdf_single(wo, wi, lobes);
        match &self.energy {
            None => ss,
            Some(e) => self.mix_pdf(e, wo, wi, lobes, ss),
        }
    }

    /// Density of the single-scattering sampler alone.
    fn pdf_single(&self, wo: Vec3, wi: Vec3, lobes: Lobes) -> f32 {
        let Some((h, is_reflect, etap)) = self.half(wo, wi) else {
            return 0.0;
        };
        let r = self.fresnel_at(wo, wi, h, is_reflect);
        self.pdf_single_at(wo, wi, lobes, (h, is_reflect, etap), r, || {
            self.distribution.pdf_visible(wo, h)
        })
    }

    /// [`Self::pdf_single`] from the half vector, the Fresnel factor and the micro-normal
    /// density (asked for only when the lobes allowed can produce the pair).
    #[inline]
    fn pdf_single_at(
        &self,
        wo: Vec3,
        wi: Vec3,
        lobes: Lobes,
        (h, is_reflect, etap): (Vec3, bool, f32),
        r: f32,
        pdf_h: impl FnOnce() -> f32,
    ) -> f32 {
        // The lobe probability with the Fresnel factor `value` uses (the rarer side's cosine for
        // a transmission pair): the sampler's own `F(wo·h)` differs from it only where `1 − F` is
        // rounding noise near the critical angle, and this keeps pdf > 0 wherever f > 0.
        let (pr, pt) = match lobes {
            Lobes::All => (r, 1.0 - r),
            Lobes::Reflection => (r, 0.0),
            Lobes::Transmission => (0.0, 1.0 - r),
        };
        if pr + pt <= 0.0 {
            return 0.0;
        }
        let pdf_h = pdf_h();
        let p = if is_reflect {
            pdf_h / (4.0 * wo.dot(h).abs()) * pr / (pr + pt)
        } else {
            let denom = (wi.dot(h) + wo.dot(h) / etap).powi(2);
            pdf_h * wi.dot(h).abs() / denom * pt / (pr + pt)
        };
        if p.is_finite() { p.max(0.0) } else { 0.0 }
    }

    /// Samples `wi` from `wo` (either side) choosing reflection or transmission by Fresnel.
    ///
    /// # Arguments
    /// * `uc` – picks reflection vs transmission.
    /// * `u` – picks the micro-normal.
    pub fn sample_lobes(
        &self,
        wo: Vec3,
        uc: f32,
        u: Vec2,
        mode: TransportMode,
        lobes: Lobes,
    ) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let mut uc = uc.clamp(0.0, 1.0);
        if let Some(e) = &self.energy {
            let pm = self.p_multiple(wo, lobes);
            if uc < pm {
                let (rf, tr) = (lobes != Lobes::Transmission, lobes != Lobes::Reflection);
                let wi = e.sample(wo, (uc / pm).min(1.0), u, rf, tr)?;
                return self.finish_sample(wo, wi, mode, lobes);
            }
            uc = ((uc - pm) / (1.0 - pm)).clamp(0.0, 1.0);
        }
        let (h, uc) = self.distribution.sample_visible(wo, uc, u)?;
        let oh = wo.dot(h);
        if oh * wo.z <= 0.0 {
            return None;
        }
        let r = fresnel::dielectric(oh, self.eta);
        let (pr, pt) = match lobes {
            Lobes::All => (r, 1.0 - r),
            Lobes::Reflection => (r, 0.0),
            Lobes::Transmission => (0.0, 1.0 - r),
        };
        if pr + pt <= 0.0 {
            return None;
        }
        let wi = if uc * (pr + pt) < pr {
            let wi = reflect(wo, h).normalize();
            if wi.z * wo.z <= 0.0 {
                return None;
            }
            wi
        } else {
            let wi = refract(wo, h, self.eta)?;
            if wi.z * wo.z >= 0.0 {
                return None;
            }
            wi
        };
        self.finish_sample(wo, wi, mode, lobes)
    }

    /// The sample record for a direction drawn by [`Self::sample_lobes`]: `f` and `pdf` of the
    /// whole mixture.
    fn finish_sample(
        &self,
        wo: Vec3,
        wi: Vec3,
        mode: TransportMode,
        lobes: Lobes,
    ) -> Option<BsdfSample> {
        let (f, pdf) = self.value_pdf(wo, wi, mode, lobes);
        let (kind, eta) = if wi.z * wo.z > 0.0 {
            (LobeKind::Glossy, 1.0)
        } else if wo.z > 0.0 {
            (LobeKind::Transmission, self.eta)
        } else {
            (LobeKind::Transmission, 1.0 / self.eta)
        };
        BsdfSample::from_eval(wi, RgbSample::splat(f), pdf, Lobe { kind, layer: 0 })
            .map(|s| s.with_eta(eta))
    }
}

/// The interface as a full BSDF: both lobes, chosen by Fresnel, directions on either side.
impl Bxdf for RoughDielectric {
    #[inline]
    fn flags(&self) -> LobeFlags {
        LobeFlags::REFLECTION | LobeFlags::TRANSMISSION | LobeFlags::GLOSSY
    }
    #[inline]
    fn eval_mode(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> RgbSample {
        RgbSample::splat(self.value(wo, wi, mode))
    }
    #[inline]
    fn sample_mode(&self, wo: Vec3, uc: f32, u: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        self.sample_lobes(wo, uc, u, mode, Lobes::All)
    }
    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.pdf_lobes(wo, wi, Lobes::All)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::{Distribution, spherical_direction};

    fn glass(m: f32) -> RoughDielectric {
        RoughDielectric::new(MicrofacetDistribution::new(Distribution::Blinn, m), 1.5)
    }

    #[test]
    fn value_pdf_is_value_and_pdf_bit_for_bit() {
        let mut rng = crate::sampler::Rng::new(11);
        for (m, energy) in [(0.01f32, false), (8.0, true), (40.0, false), (70.0, true)] {
            let mut g = glass(m);
            if energy {
                g = g.with_energy_tables_at(8);
            }
            let modes = [TransportMode::Radiance, TransportMode::Importance];
            let lobes = [Lobes::All, Lobes::Reflection, Lobes::Transmission];
            for i in 0..3000 {
                let side = |r: f32| if r < 0.5 { 1.0 } else { -1.0 };
                let wo = spherical_direction(rng.uniform() * 1.6, rng.uniform() * 6.3)
                    * Vec3::new(1.0, 1.0, side(rng.uniform()));
                let wi = spherical_direction(rng.uniform() * 1.6, rng.uniform() * 6.3)
                    * Vec3::new(1.0, 1.0, side(rng.uniform()));
                let (mode, l) = (modes[i % 2], lobes[i % 3]);
                let (v, p) = g.value_pdf(wo, wi, mode, l);
                assert_eq!(v.to_bits(), g.value(wo, wi, mode).to_bits());
                assert_eq!(p.to_bits(), g.pdf_lobes(wo, wi, l).to_bits());
            }
        }
    }

    #[test]
    fn adjoint_symmetry() {
        let g = glass(15.0);
        let wo = spherical_direction(0.4, 0.0);
        let wi = -spherical_direction(0.3, 2.9);
        let a = g.value(wo, wi, TransportMode::Radiance);
        let b = g.value(wi, wo, TransportMode::Importance);
        assert!(a > 0.0 && (a - b).abs() < 1e-4 * a, "{a} {b}");
        // Generalised reciprocity (Veach 1997, eq. 5.14): f(wo,wi)/η_o² = f(wi,wo)/η_i² in radiance
        // mode; here wo is outside (η 1) and wi inside (η 1.5).
        let c = g.value(wi, wo, TransportMode::Radiance);
        assert!((a * 1.5f32.powi(2) - c).abs() < 1e-4 * c, "{a} {c}");
    }

    #[test]
    fn energy_is_conserved_in_the_mean() {
        // Mean weight of all-lobe sampling is the directional albedo + transmittance ≤ 1 (importance
        // mode has no η² factors), close to 1 for a moderate roughness away from grazing.
        // The mean sample weight of `g` from `wo` over 200 000 all-lobe samples.
        let mean_weight = |g: &RoughDielectric, wo: Vec3, seed: u64| {
            let mut rng = crate::sampler::Rng::new(seed);
            let n = 200_000;
            let mut sum = 0.0f64;
            for _ in 0..n {
                let (uc, u) = (rng.uniform(), rng.uniform2());
                if let Some(s) = g.sample_lobes(wo, uc, u, TransportMode::Importance, Lobes::All) {
                    sum += f64::from(s.weight[0]);
                }
            }
            sum / n as f64
        };
        let g = glass(10.0);
        for side in [1.0f32, -1.0] {
            let wo = spherical_direction(0.5, 0.0) * Vec3::new(1.0, 1.0, side);
            let mean = mean_weight(&g, wo, 3);
            assert!(mean > 0.95 && mean < 1.005, "side {side}: {mean}");
            // With the multiple-scattering lobe every direction keeps all its flux.
            let full_mean = mean_weight(&g.clone().with_energy_tables(), wo, 4);
            assert!((full_mean - 1.0).abs() < 0.01, "side {side}: {full_mean}");
        }
    }
}
