//! Transported light: the quantity a path multiplies, one value per carried wavelength.
//!
//! Stored colour ([`crate::color::Rgb`]: recipes, textures, images) and transported light are
//! different types. Transport code — BSDF values, path throughput, emitted radiance — is generic over
//! a [`Spectral`] type together with its [`Spectral::Wavelengths`], modelled on pbrt-v4's
//! `SampledSpectrum` / `SampledWavelengths` (Pharr, Jakob & Humphreys, *Physically Based Rendering*,
//! 4th ed., §4.5):
//!
//! - [`RgbSample`] with [`RgbWavelengths`] — the RGB variant: three linear Rec.709 channels and no
//!   wavelengths at all (a zero-sized type). Its arithmetic is exactly the renderer's arithmetic
//!   before the split, so RGB renders are bit-identical to it.
//! - [`HeroSample`] with [`wavelengths::HeroWavelengths`] — the spectral variant (issue 19): four
//!   wavelengths drawn per camera path (Wilkie et al., "Hero Wavelength Spectral Sampling", EGSR
//!   2014), its value a radiance at each ([`hero`]).
//!
//! Building blocks of the spectral variant: [`cie`] (CIE 1931 colour-matching functions, D65, the
//! sRGB matrices) and [`rgb2spec`] (RGB colours as smooth spectra, Jakob & Hanika 2019).
//!
//! **Why monomorphised generics.** The variant is a type parameter (`trace::<RgbSample>`), resolved
//! at compile time, as Mitsuba 3 compiles one renderer per variant. A scene that needs no spectral
//! effect runs code in which the spectral type does not occur: no branch on a runtime "mode", no
//! wider registers, no conversion per vertex. A `dyn` spectrum or an enum of variants would put a
//! dispatch or a widest-case layout on every multiply of the hot path. The cost is compile time and
//! code size for each variant, paid only by the variants the binary instantiates.

pub mod basis;
pub mod cie;
pub mod fluorescence;
pub mod hero;
pub mod line;
pub mod measured;
pub mod prefilter;
pub mod rgb;
pub mod rgb2spec;
pub mod wavelengths;

pub use hero::HeroSample;
pub use rgb::{CHANNELS, RgbSample};

use crate::color::Rgb;
use std::fmt::Debug;
use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Sub};

/// The wavelengths of the RGB variant: none (the three channels are Rec.709 primaries).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RgbWavelengths;

/// A value of transported light (or throughput, or a reflectance at the carried wavelengths).
///
/// Channel `i` belongs to wavelength `i` of the [`Spectral::Wavelengths`] the path carries; all
/// arithmetic is per channel.
pub trait Spectral:
    Copy
    + Debug
    + Default
    + PartialEq
    + Send
    + Sync
    + 'static
    + Add<Output = Self>
    + AddAssign
    + Sub<Output = Self>
    + Mul<Output = Self>
    + MulAssign
    + Mul<f32, Output = Self>
    + MulAssign<f32>
    + Div<f32, Output = Self>
{
    /// The wavelengths a value is carried at (drawn once per camera path).
    type Wavelengths: Copy + Debug + Default + Send + Sync;
    /// Sampler dimensions [`Spectral::sample_wavelengths`] reads (0: the variant carries no
    /// wavelengths and the integrator does not draw the wavelength slot at all).
    const WAVELENGTH_DIMENSIONS: u32;
    /// All channels zero.
    const ZERO: Self;
    /// All channels one.
    const ONE: Self;
    /// Number of channels (carried wavelengths; 3 for RGB).
    const CHANNELS: usize;
    /// The same value in every channel.
    fn splat(v: f32) -> Self;
    /// Channel `i` is `f(i)` (`i < CHANNELS`).
    fn from_channels(f: impl Fn(usize) -> f32) -> Self;
    /// The wavelengths of a camera path from the sampler's wavelength slot `u ∈ [0, 1)`
    /// ([`crate::sampler`] layout).
    fn sample_wavelengths(u: f32) -> Self::Wavelengths;
    /// Channel `i`'s wavelength in nm, for a variant that carries wavelengths (`None` for RGB).
    fn wavelength_nm(_lambda: &Self::Wavelengths, _i: usize) -> Option<f32> {
        None
    }
    /// A stored reflectance (0 … 1 per channel) at the wavelengths.
    fn from_reflectance(c: Rgb, lambda: &Self::Wavelengths) -> Self;
    /// A stored unbounded quantity (radiance, absorption coefficient, complex IOR part) at the
    /// wavelengths.
    fn from_unbounded(c: Rgb, lambda: &Self::Wavelengths) -> Self;
    /// A stored emitted radiance (a light's or the sky's colour) at the wavelengths: for a
    /// spectral variant the illuminant form, so that a grey light is D65-shaped and renders
    /// white; the same as [`Spectral::from_unbounded`] by default (and in the RGB variant).
    #[inline]
    fn from_illuminant(c: Rgb, lambda: &Self::Wavelengths) -> Self {
        Self::from_unbounded(c, lambda)
    }
    /// A measured coefficient spectrum (a medium's absorption or scattering) at the wavelengths;
    /// `rgb` is its projection ([`measured::Measured::to_rgb`]), which is what the RGB variant
    /// (this default) uses.
    #[inline]
    fn from_measured(m: &measured::Measured, rgb: Rgb, lambda: &Self::Wavelengths) -> Self {
        let _ = m;
        Self::from_unbounded(rgb, lambda)
    }
    /// An emitted radiance given as a function of wavelength (nm), `rgb` its colour: the
    /// spectral variant evaluates `f` at its wavelengths, the RGB variant (this default) uses
    /// `rgb`.
    #[inline]
    fn from_emission_fn(f: impl Fn(f32) -> f32, rgb: Rgb, lambda: &Self::Wavelengths) -> Self {
        let _ = f;
        Self::from_unbounded(rgb, lambda)
    }
    /// The film colour of a path's radiance estimate carried at `lambda` (for a spectral variant
    /// this divides by the wavelengths' density and projects onto the colour matching functions).
    fn to_rgb(self, lambda: &Self::Wavelengths) -> Rgb;
    /// Channel `i` (`i < CHANNELS`).
    fn channel(self, i: usize) -> f32;
    /// `f` applied to every channel.
    fn map(self, f: impl Fn(f32) -> f32) -> Self;
    /// Largest channel (Russian roulette, lobe choice).
    fn max_channel(self) -> f32;
    /// Mean of the channels.
    fn average(self) -> f32;
    /// True when every channel is exactly zero.
    fn is_black(self) -> bool;
    /// True when every channel is finite and `>= 0`.
    fn is_valid(self) -> bool;
    /// Makes the path carry only its hero wavelength from here on: called by a wavelength-dependent
    /// refraction (dispersion), after which the other wavelengths' directions would differ. The
    /// RGB variant has no wavelengths and ignores it.
    #[inline]
    fn terminate_secondary(_lambda: &mut Self::Wavelengths) {}
    /// Re-radiation at a fluorescent base (issue 20; [`fluorescence`]): `self` is a path's
    /// throughput toward the camera at `lambda`; afterwards it is the throughput of the light that
    /// fed it, and `lambda` the wavelengths that light is carried at. The spectral variant draws,
    /// per channel, an excitation wavelength `λi ≤ λo` with `u` (stratified over the channels)
    /// and multiplies by `K(λi → λo) / p(λi)`; a channel nothing excites carries 0. The RGB
    /// variant has no wavelengths: it returns the colorant's reduced 3 × 3 re-radiation matrix
    /// `M` (rows outgoing, columns incident channels), which the path applies to everything it
    /// gathers from there ([`Spectral::remix`]); the spectral variant returns `None`.
    ///
    /// # Arguments
    /// * `lines` – the scene's narrow emission lines, which the excitation sampling also draws
    ///   from ([`fluorescence::Fluorescence::sample_excitation_mixed`]).
    /// * `u` – `(component choice, wavelength)`, each in `[0, 1)`.
    fn fluoresce(
        &mut self,
        lambda: &mut Self::Wavelengths,
        colorant: &fluorescence::Fluorescence,
        lines: &[line::Line],
        u: glam::Vec2,
    ) -> Option<[[f32; 3]; 3]>;
    /// `m · self` for an RGB value (channel mixing after a re-radiation); the spectral variant,
    /// which never gets a matrix, returns `self`.
    fn remix(self, m: &[[f32; 3]; 3]) -> Self;
    /// The wavelengths of a camera path from the sampler's 2-D wavelength slot when the scene has
    /// narrow emission `lines` ([`wavelengths::HeroWavelengths::sample_with_lines`]); without
    /// lines, and in the RGB variant, [`Spectral::sample_wavelengths`]`(u.x)`.
    #[inline]
    fn sample_wavelengths_with(u: glam::Vec2, lines: &[line::Line]) -> Self::Wavelengths {
        let _ = lines;
        Self::sample_wavelengths(u.x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Stored → transported → stored is the identity in the RGB variant, bit for bit.
    #[test]
    fn rgb_variant_round_trips_exactly() {
        let lambda = RgbSample::sample_wavelengths(0.37);
        for c in [
            Rgb::new(0.1, 0.7, 3.5),
            Rgb::ZERO,
            Rgb::new(1e-30, 65504.0, 0.5),
        ] {
            assert_eq!(RgbSample::from_reflectance(c, &lambda).to_rgb(&lambda), c);
            assert_eq!(RgbSample::from_unbounded(c, &lambda).to_rgb(&lambda), c);
        }
        assert_eq!(std::mem::size_of::<RgbWavelengths>(), 0);
    }
}
