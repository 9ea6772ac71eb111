//! Scattering at a path's wavelengths: the interface the integrator calls ([`Scatter`]), for
//! the RGB variant (the [`Bxdf`] models as they are) and the spectral one ([`HeroSample`]).
//!
//! Each model at four wavelengths `λ_i` (issue 19; docs/spectral.md):
//!
//! - **Lambert, Oren–Nayar** — the albedo as a smooth reflectance spectrum (Jakob & Hanika 2019,
//!   [`Spectral::from_reflectance`]), the model applied at each wavelength (Oren–Nayar's
//!   interreflection term is quadratic in the albedo, so this is not the RGB value upsampled).
//! - **Torrance–Sparrow** — the geometry is colourless; the facet's Fresnel factor of a measured
//!   metal is the exact conductor formula with the tabulated `(n + i k)(λ) / host`
//!   ([`super::Metal::nk_at`]); any other Fresnel factor is the RGB one as a reflectance spectrum
//!   (not `n` and `k` upsampled separately, which gives wrong colours: mitsuba3 #208). The
//!   multiple-scattering compensation (Turquin 2019) uses the same `F0(λ)`.
//! - **Dielectric interfaces** — colourless, unless dispersive ([`super::dispersion`]): a smooth
//!   interface reflects all four wavelengths (each with its own Fresnel factor, weighted against
//!   the hero's choice probability) and refracts only the hero (the path terminates its secondary
//!   wavelengths, pbrt-v4 §4.5.4); a rough interface samples with the hero's index and keeps all
//!   four, each weighted by its own `f(λ_i)` over the hero's density.
//! - **Layer stacks** — a stack without coats is its base (so bare metal flakes and platelets are
//!   spectral metals); a coated stack is evaluated by its RGB model and its value taken as an
//!   spectrum by the linear map of [`crate::spectrum::basis`] (Smits' construction over
//!   Jakob–Hanika basis spectra): the stack's tables (energy, calibration, multiple-reflection
//!   lobe) are built per RGB channel, so the spectrum of a coated stack is a spectrum of its RGB
//!   value, not the stack of its parameters' spectra (docs/spectral.md states what this costs in
//!   colour) — except that a measured diffuse base under clear coats is read per wavelength
//!   through the stack's albedo ladder (`hero::measured_base`).
//!
//! The spectral variant's implementation is `bsdf::hero`.

use super::layered::lobes::WeightsMemo;
use super::{Bsdf, BsdfSample, Bxdf, TransportMode};
use crate::spectrum::{RgbSample, RgbWavelengths, Spectral};
use glam::{Vec2, Vec3};

/// A scattering model evaluated at the wavelengths a path carries: what the integrator calls.
/// The RGB variant ignores the (zero-sized) wavelengths and is the [`Bxdf`] model itself, bit for
/// bit; the spectral variant is this module's.
pub trait Scatter<S: Spectral> {
    /// `f(wo, wi)` at the path's wavelengths, sr⁻¹, cosine excluded ([`Bxdf::eval_mode`]).
    fn eval_at(&self, wo: Vec3, wi: Vec3, mode: TransportMode, lambda: &S::Wavelengths) -> S;
    /// Samples `wi` ([`Bxdf::sample_mode`]); a sample with
    /// [`BsdfSample::terminate_secondary`] asks the path to keep only its hero wavelength.
    fn sample_at(
        &self,
        wo: Vec3,
        uc: f32,
        u: Vec2,
        mode: TransportMode,
        lambda: &S::Wavelengths,
    ) -> Option<BsdfSample<S>>;
    /// Density of `wi` from `wo` ([`Bxdf::pdf`]), for the hero wavelength's sampling.
    fn pdf_at(&self, wo: Vec3, wi: Vec3, lambda: &S::Wavelengths) -> f32;
    /// `(eval_at(wo, wi, mode, lambda), pdf_at(wo, wi, lambda))` bit for bit
    /// ([`Bxdf::eval_pdf_mode`]: a model computes what the two share once).
    #[inline]
    fn eval_pdf_at(
        &self,
        wo: Vec3,
        wi: Vec3,
        mode: TransportMode,
        lambda: &S::Wavelengths,
    ) -> (S, f32) {
        (
            self.eval_at(wo, wi, mode, lambda),
            self.pdf_at(wo, wi, lambda),
        )
    }
    /// [`Scatter::eval_pdf_at`] for a path vertex that keeps `memo` between this call and
    /// [`Scatter::sample_memo`] for the same `wo` (a layer stack's lobe weights); bit for bit.
    #[inline]
    fn eval_pdf_memo(
        &self,
        wo: Vec3,
        wi: Vec3,
        mode: TransportMode,
        lambda: &S::Wavelengths,
        _memo: &WeightsMemo,
    ) -> (S, f32) {
        self.eval_pdf_at(wo, wi, mode, lambda)
    }
    /// [`Scatter::sample_at`] with the vertex's `memo` ([`Scatter::eval_pdf_memo`]); bit for
    /// bit.
    #[inline]
    fn sample_memo(
        &self,
        wo: Vec3,
        uc: f32,
        u: Vec2,
        mode: TransportMode,
        lambda: &S::Wavelengths,
        _memo: &WeightsMemo,
    ) -> Option<BsdfSample<S>> {
        self.sample_at(wo, uc, u, mode, lambda)
    }
    /// For a smooth dielectric interface, its relative IOR (below over above) at the wavelength
    /// of `channel`; `None` for every other model and for a channel the path no longer carries
    /// (what polarised transport turns into Fresnel's Mueller matrices,
    /// [`crate::polarisation::transport`]).
    fn interface_eta(&self, channel: usize, lambda: &S::Wavelengths) -> Option<f32>;

    /// The relative complex IOR `(n, k)` at the wavelength of `channel` of a bare conductor — a
    /// Torrance–Sparrow conductor lobe, or a stack without coats over one — whose Fresnel form
    /// keeps it ([`super::Fresnel::complex_ior`]; spectral paths: a measured metal's tables);
    /// `None` for any other model. Polarised transport reflects off it by Fresnel's Mueller
    /// matrix instead of depolarising. By default none (a transport without conductor indices
    /// per channel leaves conductors depolarising).
    fn conductor_ior(&self, _channel: usize, _lambda: &S::Wavelengths) -> Option<(f32, f32)> {
        None
    }

    /// For a bare rough dielectric interface (Walter et al. 2007), its relative IOR (below over
    /// above) at the wavelength of `channel`; `None` for any other model and for a channel the
    /// path no longer carries. Polarised transport refracts and reflects at each micro-facet by
    /// Fresnel's Mueller matrix instead of depolarising. By default none.
    fn rough_interface_eta(&self, _channel: usize, _lambda: &S::Wavelengths) -> Option<f32> {
        None
    }
}

impl Scatter<RgbSample> for Bsdf {
    #[inline]
    fn eval_at(&self, wo: Vec3, wi: Vec3, mode: TransportMode, _: &RgbWavelengths) -> RgbSample {
        self.eval_mode(wo, wi, mode)
    }
    #[inline]
    fn sample_at(
        &self,
        wo: Vec3,
        uc: f32,
        u: Vec2,
        mode: TransportMode,
        _: &RgbWavelengths,
    ) -> Option<BsdfSample> {
        self.sample_mode(wo, uc, u, mode)
    }
    #[inline]
    fn pdf_at(&self, wo: Vec3, wi: Vec3, _: &RgbWavelengths) -> f32 {
        Bxdf::<RgbSample>::pdf(self, wo, wi)
    }
    #[inline]
    fn eval_pdf_at(
        &self,
        wo: Vec3,
        wi: Vec3,
        mode: TransportMode,
        _: &RgbWavelengths,
    ) -> (RgbSample, f32) {
        self.eval_pdf_mode(wo, wi, mode)
    }
    #[inline]
    fn eval_pdf_memo(
        &self,
        wo: Vec3,
        wi: Vec3,
        mode: TransportMode,
        _: &RgbWavelengths,
        memo: &WeightsMemo,
    ) -> (RgbSample, f32) {
        match self {
            Bsdf::Layered(b) => b.eval_pdf_memo(wo, wi, mode, memo),
            _ => self.eval_pdf_mode(wo, wi, mode),
        }
    }
    #[inline]
    fn sample_memo(
        &self,
        wo: Vec3,
        uc: f32,
        u: Vec2,
        mode: TransportMode,
        _: &RgbWavelengths,
        memo: &WeightsMemo,
    ) -> Option<BsdfSample> {
        match self {
            Bsdf::Layered(b) => b.sample_memo(wo, uc, u, mode, memo),
            _ => self.sample_mode(wo, uc, u, mode),
        }
    }
    #[inline]
    fn interface_eta(&self, _channel: usize, _: &RgbWavelengths) -> Option<f32> {
        match self {
            Bsdf::SmoothDielectric(b) => Some(b.eta),
            _ => None,
        }
    }
    fn conductor_ior(&self, channel: usize, _: &RgbWavelengths) -> Option<(f32, f32)> {
        match self {
            Bsdf::TorranceSparrow(b) => b.fresnel.complex_ior(channel),
            Bsdf::Layered(l) if l.levels.is_empty() => {
                <Bsdf as Scatter<RgbSample>>::conductor_ior(&l.base, channel, &RgbWavelengths)
            }
            _ => None,
        }
    }
    fn rough_interface_eta(&self, _channel: usize, _: &RgbWavelengths) -> Option<f32> {
        match self {
            Bsdf::Dielectric(b) => Some(b.eta),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::dispersion::{Dispersion, Ior};
    use crate::bsdf::{Lambert, SmoothDielectric, fresnel, spherical_direction};
    use crate::spectrum::HeroSample;
    use crate::spectrum::wavelengths::HeroWavelengths;

    fn lambda(u: f32) -> HeroWavelengths {
        HeroWavelengths::sample(u)
    }

    /// Greys and colourless models give the RGB value at every wavelength.
    #[test]
    fn colourless_models_match_rgb() {
        let wo = spherical_direction(0.4, 0.2);
        let wi = spherical_direction(0.9, 2.5);
        let l = lambda(0.3);
        let grey = Bsdf::Lambert(Lambert {
            albedo: RgbSample::splat(0.5),
        });
        let v: HeroSample = grey.eval_at(wo, wi, TransportMode::Radiance, &l);
        let rgb = grey.eval(wo, wi).0[0];
        assert!(v.0.iter().all(|&x| (x - rgb).abs() < 1e-6), "{v:?} {rgb}");
    }

    /// A dispersive smooth interface refracts the hero by Snell's law with `n(λ_0)` and ends the
    /// secondaries; a reflection keeps them.
    #[test]
    fn smooth_dispersion_refracts_the_hero() {
        let law = Dispersion {
            inside: Ior::from_abbe(1.7, 20.0).unwrap(),
            outside: 1.0,
        };
        let b = Bsdf::SmoothDielectric(SmoothDielectric::new(1.7).with_dispersion(law));
        let wo = spherical_direction(0.7, 0.0);
        for u in [0.05f32, 0.3, 0.6, 0.95] {
            let l = lambda(u);
            let t: BsdfSample<HeroSample> = b
                .sample_at(wo, 0.999, Vec2::ZERO, TransportMode::Radiance, &l)
                .unwrap();
            assert!(t.terminate_secondary && t.flags.is_transmission());
            let n = law.eta_at(l.lambda[0]);
            let (s_o, s_i) = (wo.truncate().length(), t.wi.truncate().length());
            assert!((s_o - n * s_i).abs() < 1e-5, "Snell at {} nm", l.lambda[0]);
            assert!(t.weight.0[1..].iter().all(|&w| w == 0.0));
            let r: BsdfSample<HeroSample> = b
                .sample_at(wo, 0.0, Vec2::ZERO, TransportMode::Radiance, &l)
                .unwrap();
            assert!(!r.terminate_secondary);
            // Each wavelength's own Fresnel factor over the hero's choice probability.
            let f0 = fresnel::dielectric(wo.z, n);
            for i in 0..4 {
                let want = fresnel::dielectric(wo.z, law.eta_at(l.lambda[i])) / f0;
                assert!((r.weight.0[i] - want).abs() < 1e-5 * want, "{i}");
            }
        }
    }
}
