//! The spectral variant of [`super::spectral::Scatter`]: each model at a path's four hero
//! wavelengths ([`HeroSample`]; the rules per model in [`super::spectral`]'s docs and
//! docs/spectral.md).

use super::dispersion::Dispersion;
use super::layered::Model;
use super::spectral::Scatter;
use super::{
    Bsdf, BsdfSample, Bxdf, Lambert, Lobe, LobeKind, OrenNayar, RoughDielectric, SmoothDielectric,
    TorranceSparrow, TransportMode, flush_tiny, fresnel, refract, sample_cosine_hemisphere,
};
use crate::color::Rgb;
use crate::spectrum::measured::Measured;
use crate::spectrum::wavelengths::HeroWavelengths;
use crate::spectrum::{HeroSample, RgbSample, Spectral, basis};
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

impl Scatter<HeroSample> for Bsdf {
    fn eval_at(
        &self,
        wo: Vec3,
        wi: Vec3,
        mode: TransportMode,
        lambda: &HeroWavelengths,
    ) -> HeroSample {
        match self {
            Bsdf::Lambert(b) => lambert(b, None, wo, wi, lambda),
            Bsdf::OrenNayar(b) => oren_nayar(b, None, wo, wi, lambda),
            Bsdf::TorranceSparrow(b) => torrance_sparrow(b, wo, wi, lambda),
            Bsdf::Dielectric(b) => match b.dispersion {
                None => HeroSample::splat(b.value(wo, wi, mode)),
                Some(law) => rough_dispersive(b, law, wo, wi, mode, lambda),
            },
            Bsdf::SmoothDielectric(_) => HeroSample::ZERO,
            Bsdf::Layered(b) => match (bare_base(b), b.base_spectrum) {
                (Some(Bsdf::Lambert(l)), Some(m)) => lambert(l, Some(m), wo, wi, lambda),
                (Some(Bsdf::OrenNayar(o)), Some(m)) => oren_nayar(o, Some(m), wo, wi, lambda),
                (Some(base), _) => base.eval_at(wo, wi, mode, lambda),
                (None, _) => measured_base(
                    b,
                    wo,
                    wi,
                    mode,
                    upsample(b.eval_mode(wo, wi, mode), lambda),
                    lambda,
                ),
            },
        }
    }

    fn sample_at(
        &self,
        wo: Vec3,
        uc: f32,
        u: Vec2,
        mode: TransportMode,
        lambda: &HeroWavelengths,
    ) -> Option<BsdfSample<HeroSample>> {
        match self {
            Bsdf::SmoothDielectric(b) => match b.dispersion {
                None => grey(b.sample_mode(wo, uc, u, mode)?),
                Some(law) => smooth_dispersive(b, law, wo, uc, mode, lambda),
            },
            Bsdf::Dielectric(b) => match b.dispersion {
                None => grey(b.sample_mode(wo, uc, u, mode)?),
                Some(law) => {
                    let hero = at_eta(b, law.eta_at(lambda.lambda[0]));
                    let s = hero.sample_mode(wo, uc, u, mode)?;
                    let f = rough_dispersive(b, law, wo, s.wi, mode, lambda);
                    recolour(s, f)
                }
            },
            Bsdf::Layered(b) => match bare_base(b) {
                Some(base @ (Bsdf::Lambert(_) | Bsdf::OrenNayar(_)))
                    if b.base_spectrum.is_some() =>
                {
                    // A measured diffuse base: cosine-sampled as the RGB model does, valued per
                    // wavelength from its spectrum.
                    if wo.z <= 0.0 {
                        return None;
                    }
                    let wi = sample_cosine_hemisphere(u)?;
                    let f = self.eval_at(wo, wi, mode, lambda);
                    diffuse(wi, f, Bxdf::<RgbSample>::pdf(base, wo, wi))
                }
                Some(base) => base.sample_at(wo, uc, u, mode, lambda),
                None => {
                    let s = b.sample_mode(wo, uc, u, mode)?;
                    let f = measured_base(b, wo, s.wi, mode, upsample(s.f, lambda), lambda);
                    // `weight = f |cos θi| / pdf` (BsdfSample::from_eval), except for the
                    // Reference walk's unbiased weight.
                    let weight = if s.pdf_is_proportional {
                        upsample(s.weight, lambda)
                    } else {
                        f * (s.wi.z.abs() / s.pdf)
                    };
                    Some(BsdfSample {
                        f,
                        weight,
                        ..relabel(s)
                    })
                }
            },
            // The reflecting models sample a direction without regard to colour (as their RGB
            // `sample_mode` does, without evaluating RGB), then take the value at the wavelengths.
            Bsdf::Lambert(_) | Bsdf::OrenNayar(_) => {
                if wo.z <= 0.0 {
                    return None;
                }
                let wi = sample_cosine_hemisphere(u)?;
                let f = self.eval_at(wo, wi, mode, lambda);
                diffuse(wi, f, Bxdf::<RgbSample>::pdf(self, wo, wi))
            }
            Bsdf::TorranceSparrow(b) => {
                let wi = b.sample_wi(wo, uc, u)?;
                BsdfSample::from_eval(
                    wi,
                    torrance_sparrow(b, wo, wi, lambda),
                    b.pdf(wo, wi),
                    Lobe {
                        kind: LobeKind::Glossy,
                        layer: 0,
                    },
                )
            }
        }
    }

    fn pdf_at(&self, wo: Vec3, wi: Vec3, lambda: &HeroWavelengths) -> f32 {
        match self {
            Bsdf::Dielectric(b) => match b.dispersion {
                None => b.pdf(wo, wi),
                Some(law) => at_eta(b, law.eta_at(lambda.lambda[0])).pdf(wo, wi),
            },
            Bsdf::Layered(b) => match bare_base(b) {
                Some(base) => Scatter::<HeroSample>::pdf_at(base, wo, wi, lambda),
                None => b.pdf(wo, wi),
            },
            _ => Bxdf::<RgbSample>::pdf(self, wo, wi),
        }
    }

    fn interface_eta(&self, channel: usize, lambda: &HeroWavelengths) -> Option<f32> {
        match self {
            Bsdf::SmoothDielectric(b) => eta_at(b.eta, b.dispersion, channel, lambda),
            _ => None,
        }
    }
    fn conductor_ior(&self, channel: usize, lambda: &HeroWavelengths) -> Option<(f32, f32)> {
        match self {
            _ if !(lambda.pdf[channel] > 0.0) => None,
            // A measured metal's `n + i k` at the wavelength, relative to its host, as
            // `facet_fresnel` evaluates it; an RGB `n, k` has none per wavelength.
            Bsdf::TorranceSparrow(b) => b.metal.map(|m| {
                let (n, k) = m.metal.nk_at(lambda.lambda[channel]);
                (n / m.host, k / m.host)
            }),
            Bsdf::Layered(l) if l.levels.is_empty() => {
                <Bsdf as Scatter<HeroSample>>::conductor_ior(&l.base, channel, lambda)
            }
            _ => None,
        }
    }
    fn rough_interface_eta(&self, channel: usize, lambda: &HeroWavelengths) -> Option<f32> {
        match self {
            // The wavelength's own index, as `rough_dispersive` evaluates the interface.
            Bsdf::Dielectric(b) => eta_at(b.eta, b.dispersion, channel, lambda),
            _ => None,
        }
    }
}

/// A dielectric interface's relative index `eta` at channel `channel`'s wavelength (its `law`'s
/// value there, if dispersive); `None` for a channel the path no longer carries.
fn eta_at(
    eta: f32,
    law: Option<Dispersion>,
    channel: usize,
    lambda: &HeroWavelengths,
) -> Option<f32> {
    (lambda.pdf[channel] > 0.0).then(|| law.map_or(eta, |l| l.eta_at(lambda.lambda[channel])))
}

/// The value at the wavelengths of a coated stack whose diffuse base has a measured reflectance.
/// - With an albedo ladder (coats that do not absorb, [`super::layered::ladder`]): the stack
///   with a grey base of the measured albedo `ρ(λ)` at each wavelength, to the ladder's
///   interpolation.
/// - A fluorescent base's elastic reflection: the stack's upsampled RGB value `f` with its
///   single-scatter base term `D(wo, wi) · ρ` ([`super::LayeredBsdf::fluorescent_value`]: the
///   Corrected model's body for a Lambert base of albedo `ρ` under clear coats) moved from the
///   upsampled RGB albedo to `ρ(λ)` — the dye absorbs most of a laser's green: its elastic
///   `ρ(532 nm)` is 0.09 where the upsampled projection gives several times more; the
///   multiple-reflection lobe and the albedo calibration keep their RGB values.
///
/// Any other stack: `f` unchanged (the spectrum of its RGB value).
#[inline]
fn measured_base(
    b: &super::LayeredBsdf,
    wo: Vec3,
    wi: Vec3,
    mode: TransportMode,
    f: HeroSample,
    lambda: &HeroWavelengths,
) -> HeroSample {
    let Some(m) = b.base_spectrum else {
        return f;
    };
    if let Some(ladder) = &b.ladder {
        return HeroSample(ladder.eval(wo, wi, mode, lambda.lambda.map(|l| m.at(l))));
    }
    let (Some(_), Bsdf::Lambert(base)) = (b.fluorescence(), &b.base) else {
        return f;
    };
    let d = b.fluorescent_value(wo, wi);
    if !(d > 0.0) {
        return f;
    }
    let rgb = upsample(base.albedo, lambda);
    HeroSample(std::array::from_fn(|i| {
        (f.0[i] + d * (m.at(lambda.lambda[i]) - rgb.0[i])).max(0.0)
    }))
}

/// The base a coat-less stack evaluates to (the course's plain base for the Course model, the
/// compensated one otherwise); `None` for a coated stack or the Reference walk.
#[inline]
fn bare_base(b: &super::LayeredBsdf) -> Option<&Bsdf> {
    if b.coats() > 0 {
        return None;
    }
    match b.model() {
        Model::Course => Some(&b.base_plain),
        Model::Corrected => Some(&b.base),
        Model::Reference(_) => None,
    }
}

/// A value the RGB model computed, as a spectrum at the wavelengths (the linear map of
/// [`crate::spectrum::basis`]: a grey stays flat).
#[inline]
fn upsample(v: RgbSample, lambda: &HeroWavelengths) -> HeroSample {
    HeroSample(basis::upsample(v.0, &lambda.lambda))
}

/// An RGB sample's record in the spectral type, with zero values (filled in by the caller).
#[inline]
fn relabel(s: BsdfSample) -> BsdfSample<HeroSample> {
    BsdfSample {
        wi: s.wi,
        f: HeroSample::ZERO,
        pdf: s.pdf,
        weight: HeroSample::ZERO,
        lobe: s.lobe,
        flags: s.flags,
        eta: s.eta,
        pdf_is_proportional: s.pdf_is_proportional,
        terminate_secondary: false,
    }
}

/// A colourless sample (every channel equal) at every wavelength.
#[inline]
fn grey(s: BsdfSample) -> Option<BsdfSample<HeroSample>> {
    Some(BsdfSample {
        f: HeroSample::splat(s.f.0[0]),
        weight: HeroSample::splat(s.weight.0[0]),
        ..relabel(s)
    })
}

/// A diffuse sample with the spectral value `f`.
#[inline]
fn diffuse(wi: Vec3, f: HeroSample, pdf: f32) -> Option<BsdfSample<HeroSample>> {
    BsdfSample::from_eval(
        wi,
        f,
        pdf,
        Lobe {
            kind: LobeKind::Diffuse,
            layer: 0,
        },
    )
}

/// An RGB sample's direction and density with the spectral value `f` at it.
#[inline]
fn recolour(s: BsdfSample, f: HeroSample) -> Option<BsdfSample<HeroSample>> {
    let weight = f * (s.wi.z.abs() / s.pdf);
    (f.is_valid() && weight.is_valid()).then(|| BsdfSample {
        f,
        weight,
        ..relabel(s)
    })
}

/// A diffuse albedo at the wavelengths: the measured spectrum where the recipe gave one (read
/// exactly per wavelength), else the RGB albedo as a smooth reflectance spectrum.
#[inline]
fn albedo_at(rgb: RgbSample, measured: Option<&Measured>, lambda: &HeroWavelengths) -> HeroSample {
    match measured {
        Some(m) => HeroSample(lambda.lambda.map(|l| m.at(l))),
        None => HeroSample::from_reflectance(Rgb::from(rgb), lambda),
    }
}

fn lambert(
    b: &Lambert,
    measured: Option<&Measured>,
    wo: Vec3,
    wi: Vec3,
    lambda: &HeroWavelengths,
) -> HeroSample {
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return HeroSample::ZERO;
    }
    albedo_at(b.albedo, measured, lambda) * FRAC_1_PI
}

fn oren_nayar(
    b: &OrenNayar,
    measured: Option<&Measured>,
    wo: Vec3,
    wi: Vec3,
    lambda: &HeroWavelengths,
) -> HeroSample {
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return HeroSample::ZERO;
    }
    let (direct, inter) = b.factors(wo, wi);
    let f = albedo_at(b.albedo, measured, lambda)
        .map(|r| (r * FRAC_1_PI * (direct + r * inter)).max(0.0));
    if f.is_valid() { f } else { HeroSample::ZERO }
}

/// An RGB Fresnel factor as a reflectance spectrum (a grey stays flat).
#[inline]
fn reflectance(f: RgbSample, lambda: &HeroWavelengths) -> HeroSample {
    if f.0[0] == f.0[1] && f.0[1] == f.0[2] {
        HeroSample::splat(f.0[0])
    } else {
        HeroSample::from_reflectance(Rgb::from(f), lambda)
    }
}

/// The facet reflectance of a Torrance–Sparrow lobe at `cos_i`, and its value at normal
/// incidence when `with_f0` (for the compensation), at the wavelengths.
#[inline]
fn facet_fresnel(
    b: &TorranceSparrow,
    cos_i: f32,
    with_f0: bool,
    lambda: &HeroWavelengths,
) -> (HeroSample, HeroSample) {
    match b.metal {
        Some(m) => {
            let (mut f, mut f0) = (HeroSample::ZERO, HeroSample::ZERO);
            for i in 0..4 {
                let (n, k) = m.metal.nk_at(lambda.lambda[i]);
                let (n, k) = (n / m.host, k / m.host);
                f.0[i] = fresnel::conductor(cos_i, n, k);
                if with_f0 {
                    // Normal incidence in closed form: ((n − 1)² + k²) / ((n + 1)² + k²).
                    f0.0[i] = ((n - 1.0) * (n - 1.0) + k * k) / ((n + 1.0) * (n + 1.0) + k * k);
                }
            }
            (f, f0)
        }
        None => {
            let f = reflectance(b.fresnel.eval(cos_i), lambda);
            let f0 = if with_f0 {
                reflectance(b.fresnel.eval(1.0), lambda)
            } else {
                HeroSample::ZERO
            };
            (f, f0)
        }
    }
}

fn torrance_sparrow(
    b: &TorranceSparrow,
    wo: Vec3,
    wi: Vec3,
    lambda: &HeroWavelengths,
) -> HeroSample {
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return HeroSample::ZERO;
    }
    let Some(h) = TorranceSparrow::half(wo, wi) else {
        return HeroSample::ZERO;
    };
    if wo.dot(h) <= 0.0 || wi.dot(h) <= 0.0 {
        return HeroSample::ZERO;
    }
    let d = b.distribution.d(h);
    if d == 0.0 {
        return HeroSample::ZERO;
    }
    let g = b.distribution.g(wo, wi, h);
    let (f, f0) = facet_fresnel(b, wi.dot(h).max(0.0), b.compensation.is_some(), lambda);
    let v = f * (d * g / (4.0 * wo.z * wi.z));
    flush_tiny(match &b.compensation {
        None => v,
        Some(c) => {
            let e = c.e_ss.at(wo.z)[0].clamp(1e-3, 1.0);
            v * (HeroSample::ONE + f0 * ((1.0 - e) / e))
        }
    })
}

/// The rough interface with relative index `eta` (its multiple-scattering lobe, built for the
/// d line's index, kept: the lobe changes little over a dispersion of a few hundredths).
#[inline]
fn at_eta(b: &RoughDielectric, eta: f32) -> RoughDielectric {
    RoughDielectric {
        eta,
        dispersion: None,
        ..b.clone()
    }
}

fn rough_dispersive(
    b: &RoughDielectric,
    law: Dispersion,
    wo: Vec3,
    wi: Vec3,
    mode: TransportMode,
    lambda: &HeroWavelengths,
) -> HeroSample {
    let mut d = at_eta(b, 1.0);
    HeroSample(std::array::from_fn(|i| {
        if lambda.pdf[i] == 0.0 {
            return 0.0;
        }
        d.eta = law.eta_at(lambda.lambda[i]);
        d.value(wo, wi, mode)
    }))
}

/// A smooth dispersive interface: the hero's Fresnel factor picks reflection or refraction;
/// a reflection keeps the four wavelengths (weights `F(λ_i)/F(λ_0)`), a refraction only the hero.
fn smooth_dispersive(
    b: &SmoothDielectric,
    law: Dispersion,
    wo: Vec3,
    uc: f32,
    mode: TransportMode,
    lambda: &HeroWavelengths,
) -> Option<BsdfSample<HeroSample>> {
    if wo.z == 0.0 || !wo.is_finite() {
        return None;
    }
    let eta: [f32; 4] = lambda.lambda.map(|l| law.eta_at(l));
    let r0 = fresnel::dielectric(wo.z, eta[0]);
    let t0 = 1.0 - r0;
    let alive = |i: usize| lambda.pdf[i] > 0.0;
    let (wi, value, prob, kind, etap, terminate) = if uc < r0 || t0 <= 0.0 {
        let wi = Vec3::new(-wo.x, -wo.y, wo.z);
        let value = HeroSample(std::array::from_fn(|i| {
            if alive(i) {
                fresnel::dielectric(wo.z, eta[i])
            } else {
                0.0
            }
        }));
        (wi, value, r0, LobeKind::SpecularReflection, 1.0, false)
    } else {
        let wi = refract(wo, Vec3::Z, eta[0])?;
        if wi.z * wo.z >= 0.0 {
            return None;
        }
        let etap = if wo.z > 0.0 { eta[0] } else { 1.0 / eta[0] };
        let ft = match mode {
            TransportMode::Radiance => t0 / (etap * etap),
            TransportMode::Importance => t0,
        };
        let mut value = HeroSample::ZERO;
        value.0[0] = ft;
        (wi, value, t0, LobeKind::SpecularTransmission, etap, true)
    };
    let cos = wi.z.abs();
    if !(cos > 0.0 && prob > 0.0) {
        return None;
    }
    let mut s = BsdfSample::from_eval(wi, value / cos, prob, Lobe { kind, layer: 0 })?;
    s.eta = etap;
    s.terminate_secondary = terminate && b.dispersion.is_some();
    Some(s)
}
