//! The spectral variant of transported light (issue 19): a value at each of the four wavelengths
//! a path carries ([`HeroWavelengths`]), hero-wavelength spectral sampling (Wilkie, Nawaz, Droske,
//! Weidlich & Hanika, "Hero Wavelength Spectral Sampling", EGSR 2014).
//!
//! **Stored colour to transported light.** A recipe's RGB reflectance becomes the sigmoid-
//! polynomial spectrum of Jakob & Hanika 2019 ([`super::rgb2spec::reflectance`]: ≤ 1 at every
//! wavelength, a grey exactly flat); an unbounded quantity (an absorption coefficient, a part of
//! a complex index) `scale · s(λ)` ([`super::rgb2spec::unbounded`]); emitted radiance the
//! illuminant form `scale · s(λ) · D65(λ)` ([`super::rgb2spec::illuminant`]), so that a grey light
//! is D65-shaped and renders white.
//!
//! **To the film.** A path's estimate `L(λ_i)` at its wavelengths becomes CIE 1931 XYZ by
//! `(1/4) Σ_i L(λ_i) (x̄, ȳ, z̄)(λ_i) / p(λ_i)`, divided by `∫ȳ` (so that a constant spectrum 1
//! has `Y = 1`, as [`super::cie::spectrum_to_xyz`]), then linear Rec.709 through
//! [`super::cie::xyz_to_linear_srgb`] — both linear, so computed in one step with the
//! colour-matching functions already in linear Rec.709 ([`super::cie::rgb_bar_table`]);
//! wavelengths whose density is 0 (terminated secondaries) add nothing, and the hero's density,
//! divided by 4 at termination, makes it stand for the four.

use super::wavelengths::{HeroWavelengths, N};
use super::{Spectral, cie, rgb2spec};
use crate::color::Rgb;
use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Sub};

/// Transported light in the spectral variant: one value per carried wavelength (radiance,
/// throughput, reflectance … at `lambda[i]` of the path's [`HeroWavelengths`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HeroSample(pub [f32; N]);

impl HeroSample {
    /// Combines two values wavelength by wavelength.
    #[inline]
    fn zip(self, o: Self, f: impl Fn(f32, f32) -> f32) -> Self {
        HeroSample(std::array::from_fn(|i| f(self.0[i], o.0[i])))
    }

    /// The spectrum `f` (a function of the wavelength in nm) at the wavelengths.
    #[inline]
    pub fn at(lambda: &HeroWavelengths, f: impl Fn(f32) -> f32) -> Self {
        HeroSample(lambda.lambda.map(f))
    }
}

impl Add for HeroSample {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        self.zip(o, |a, b| a + b)
    }
}

impl AddAssign for HeroSample {
    #[inline]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}

impl Sub for HeroSample {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        self.zip(o, |a, b| a - b)
    }
}

impl Mul for HeroSample {
    type Output = Self;
    #[inline]
    fn mul(self, o: Self) -> Self {
        self.zip(o, |a, b| a * b)
    }
}

impl MulAssign for HeroSample {
    #[inline]
    fn mul_assign(&mut self, o: Self) {
        *self = *self * o;
    }
}

impl Mul<f32> for HeroSample {
    type Output = Self;
    #[inline]
    fn mul(self, s: f32) -> Self {
        HeroSample(self.0.map(|a| a * s))
    }
}

impl MulAssign<f32> for HeroSample {
    #[inline]
    fn mul_assign(&mut self, s: f32) {
        *self = *self * s;
    }
}

impl Div<f32> for HeroSample {
    type Output = Self;
    #[inline]
    fn div(self, s: f32) -> Self {
        HeroSample(self.0.map(|a| a / s))
    }
}

/// Which conversion a memo entry holds.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Reflectance = 1,
    Unbounded = 2,
    Illuminant = 3,
}

/// A memo entry's key: the conversion, the colour's bits and the four wavelengths' bits.
type Key = [u32; 8];

/// log2 of the per-thread memo's entries.
const MEMO_BITS: u32 = 4;

thread_local! {
    /// Recent conversions at recent wavelengths, direct-mapped: a path meets the same light, sky,
    /// medium and albedo colours at every vertex at its one set of wavelengths, and each
    /// conversion is a table lookup and four sigmoid evaluations. The key holds every input bit,
    /// so a hit returns exactly what the conversion would (an all-zero key is never made: the
    /// kind is at least 1).
    static MEMO: std::cell::RefCell<[(Key, HeroSample); 1 << MEMO_BITS]> =
        const { std::cell::RefCell::new([([0; 8], HeroSample([0.0; N])); 1 << MEMO_BITS]) };
}

/// The value of a grey colour (equal, finite, non-negative channels; clamped as
/// [`rgb2spec::unbounded`] clamps), whose spectrum is flat: the conversions return it without
/// the table or the memo, exactly the flat spectrum (`Sigmoid::flat` would round through the
/// sigmoid's inverse).
#[inline]
fn grey(c: Rgb) -> Option<f32> {
    let [r, g, b] = c.0;
    // Non-short-circuit `&`: the compares, one branch.
    ((r == g) & (g == b) & (0.0..f32::INFINITY).contains(&r)).then(|| r.min(f32::MAX / 4.0))
}

/// `compute()` through the memo.
#[inline]
fn memo(
    kind: Kind,
    c: Rgb,
    lambda: &HeroWavelengths,
    compute: impl FnOnce() -> HeroSample,
) -> HeroSample {
    let l = lambda.lambda.map(f32::to_bits);
    let rgb = c.0.map(f32::to_bits);
    let key: Key = [kind as u32, rgb[0], rgb[1], rgb[2], l[0], l[1], l[2], l[3]];
    // The slot from the colour and the hero wavelength (the others follow from it for sampled
    // wavelengths); the comparison below checks every word.
    let h = (key[0] ^ key[1].wrapping_mul(0x9e37_79b9))
        .wrapping_add(key[2].wrapping_mul(0x85eb_ca6b))
        .wrapping_add(key[3].wrapping_mul(0xc2b2_ae35))
        .wrapping_add(key[4].wrapping_mul(0x27d4_eb2f));
    let slot = (h >> (32 - MEMO_BITS)) as usize;
    if let Some(v) = MEMO.with(|m| {
        let (k, v) = m.borrow()[slot];
        (k == key).then_some(v)
    }) {
        return v;
    }
    let v = compute();
    MEMO.with(|m| m.borrow_mut()[slot] = (key, v));
    v
}

/// A colour that is not grey at the wavelengths, through the memo: the conversions' slow path,
/// kept out of line so that the grey fast paths inline into the integrator.
#[inline(never)]
fn coloured(kind: Kind, c: Rgb, lambda: &HeroWavelengths) -> HeroSample {
    memo(kind, c, lambda, || match kind {
        Kind::Reflectance => {
            let s = rgb2spec::reflectance(c.0);
            HeroSample::at(lambda, |l| s.eval(l))
        }
        Kind::Unbounded => {
            let (scale, s) = rgb2spec::unbounded(c.0);
            HeroSample::at(lambda, |l| scale * s.eval(l))
        }
        Kind::Illuminant => {
            let (scale, s) = rgb2spec::illuminant(c.0);
            HeroSample(std::array::from_fn(|i| {
                scale * s.eval(lambda.lambda[i]) * lambda.illuminant[i]
            }))
        }
    })
}

impl Spectral for HeroSample {
    type Wavelengths = HeroWavelengths;
    const WAVELENGTH_DIMENSIONS: u32 = 1;
    const ZERO: Self = HeroSample([0.0; N]);
    const ONE: Self = HeroSample([1.0; N]);
    const CHANNELS: usize = N;

    #[inline]
    fn wavelength_nm(lambda: &HeroWavelengths, i: usize) -> Option<f32> {
        lambda.lambda.get(i).copied()
    }

    #[inline]
    fn from_channels(f: impl Fn(usize) -> f32) -> Self {
        HeroSample(std::array::from_fn(f))
    }
    #[inline]
    fn splat(v: f32) -> Self {
        HeroSample([v; N])
    }

    #[inline]
    fn sample_wavelengths(u: f32) -> HeroWavelengths {
        HeroWavelengths::sample(u)
    }

    #[inline]
    fn from_reflectance(c: Rgb, lambda: &HeroWavelengths) -> Self {
        // A grey is exactly flat (the studio's floor, grey albedos): no lookup, no memo.
        match grey(c) {
            Some(v) => HeroSample::splat(v.min(1.0)),
            None => coloured(Kind::Reflectance, c, lambda),
        }
    }

    #[inline]
    fn from_unbounded(c: Rgb, lambda: &HeroWavelengths) -> Self {
        match grey(c) {
            Some(v) => HeroSample::splat(v),
            None => coloured(Kind::Unbounded, c, lambda),
        }
    }

    #[inline]
    fn from_illuminant(c: Rgb, lambda: &HeroWavelengths) -> Self {
        // A grey light or sky is D65 scaled (the studio's lights and sky gradient).
        match grey(c) {
            Some(v) => HeroSample(lambda.illuminant.map(|d| v * d)),
            None => coloured(Kind::Illuminant, c, lambda),
        }
    }

    fn from_measured(m: &super::measured::Measured, _rgb: Rgb, lambda: &HeroWavelengths) -> Self {
        HeroSample::at(lambda, |l| m.at(l))
    }

    #[inline]
    fn sample_wavelengths_with(u: glam::Vec2, lines: &[super::line::Line]) -> HeroWavelengths {
        HeroWavelengths::sample_with_lines(u.x, u.y, lines)
    }

    #[inline]
    fn from_emission_fn(f: impl Fn(f32) -> f32, _rgb: Rgb, lambda: &HeroWavelengths) -> Self {
        HeroSample::at(lambda, f)
    }

    fn to_rgb(self, lambda: &HeroWavelengths) -> Rgb {
        // `(1/4) Σ L(λ_i)/p(λ_i) · rgb_bar(λ_i)` with the colour-matching functions already in
        // linear sRGB per unit `∫ȳ` (module docs), linear between their 1 nm values.
        let bar = cie::rgb_bar_table();
        let mut rgb = [0.0f32; 3];
        for i in 0..N {
            let p = lambda.pdf[i];
            if p > 0.0 {
                let w = self.0[i] / p;
                let x = lambda.lambda[i] - cie::LAMBDA_MIN;
                let j = super::wavelengths::index(x, cie::CMF_SAMPLES - 2);
                let f = (x - j as f32).clamp(0.0, 1.0);
                let (a, b) = (bar[j], bar[j + 1]);
                for c in 0..3 {
                    rgb[c] += w * (a[c] + f * (b[c] - a[c]));
                }
            }
        }
        let n = N as f32;
        Rgb::new(rgb[0] / n, rgb[1] / n, rgb[2] / n)
    }

    #[inline]
    fn channel(self, i: usize) -> f32 {
        self.0[i]
    }

    #[inline]
    fn map(self, f: impl Fn(f32) -> f32) -> Self {
        HeroSample(self.0.map(f))
    }

    #[inline]
    fn max_channel(self) -> f32 {
        self.0.iter().copied().fold(f32::NEG_INFINITY, f32::max)
    }

    #[inline]
    fn average(self) -> f32 {
        self.0.iter().sum::<f32>() / N as f32
    }

    #[inline]
    fn is_black(self) -> bool {
        self.0.iter().all(|&c| c == 0.0)
    }

    #[inline]
    fn is_valid(self) -> bool {
        // "Every channel finite and ≥ 0", branch-free (it runs at every vertex): the smallest
        // channel is ≥ 0 (`f32::min` skips NaN, and −0 passes as `−0 ≥ 0` does), and the sum in
        // `f64` — which four `f32` cannot overflow — is finite exactly when every channel is.
        let [a, b, c, d] = self.0;
        let sum = f64::from(a) + f64::from(b) + f64::from(c) + f64::from(d);
        (a.min(b).min(c.min(d)) >= 0.0) & (sum < f64::INFINITY)
    }

    #[inline]
    fn terminate_secondary(lambda: &mut HeroWavelengths) {
        lambda.terminate_secondary();
    }

    fn fluoresce(
        &mut self,
        lambda: &mut HeroWavelengths,
        colorant: &super::fluorescence::Fluorescence,
        lines: &[super::line::Line],
        u: glam::Vec2,
    ) -> Option<[[f32; 3]; 3]> {
        for i in 0..N {
            let mut ui = u.y + i as f32 / N as f32;
            if ui >= 1.0 {
                ui -= 1.0;
            }
            match colorant.sample_excitation_mixed(lambda.lambda[i], lines, u.x, ui) {
                Some(s) if self.0[i] != 0.0 => {
                    self.0[i] *= s.weight;
                    lambda.set(i, s.lambda);
                }
                _ => self.0[i] = 0.0,
            }
        }
        None
    }

    #[inline]
    fn remix(self, _m: &[[f32; 3]; 3]) -> Self {
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arithmetic_is_per_wavelength() {
        let a = HeroSample([1.0, 2.0, 3.0, 4.0]);
        let b = HeroSample([0.5, 0.25, 2.0, 0.0]);
        assert_eq!((a * b).0, [0.5, 0.5, 6.0, 0.0]);
        assert_eq!((a + b).0, [1.5, 2.25, 5.0, 4.0]);
        assert_eq!((a - b).0, [0.5, 1.75, 1.0, 4.0]);
        assert_eq!((a * 2.0).0, [2.0, 4.0, 6.0, 8.0]);
        assert_eq!((a / 2.0).0, [0.5, 1.0, 1.5, 2.0]);
        assert_eq!(a.max_channel(), 4.0);
        assert_eq!(a.average(), 2.5);
        assert!(!HeroSample([1.0, -0.0, 0.0, f32::NAN]).is_valid());
        assert!(HeroSample::ZERO.is_black());
    }

    /// The branch-free `is_valid` is "every channel finite and ≥ 0", on every combination of
    /// the awkward values (8⁴ samples), and `grey` accepts exactly the finite non-negative greys.
    #[test]
    fn validity_is_finite_and_non_negative() {
        let odd = [
            0.0,
            -0.0,
            1.5,
            -1e-30,
            f32::MAX,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ];
        for i in 0..odd.len().pow(4) {
            let v: [f32; 4] =
                std::array::from_fn(|k| odd[(i / odd.len().pow(k as u32)) % odd.len()]);
            let want = v.iter().all(|&c| c.is_finite() && c >= 0.0);
            assert_eq!(HeroSample(v).is_valid(), want, "{v:?}");
        }
        for &c in &odd {
            let want = c.is_finite() && c >= 0.0;
            assert_eq!(grey(Rgb::splat(c)).is_some(), want, "{c}");
        }
        assert_eq!(grey(Rgb::new(0.5, 0.5, 0.25)), None);
    }

    #[test]
    fn a_grey_reflectance_is_flat_at_every_wavelength() {
        let lambda = HeroWavelengths::sample(0.41);
        let v = HeroSample::from_reflectance(Rgb::new(0.3, 0.3, 0.3), &lambda);
        for c in v.0 {
            assert!((c - 0.3).abs() < 1e-6, "{v:?}");
        }
        let white = HeroSample::from_reflectance(Rgb::new(1.0, 1.0, 1.0), &lambda);
        assert_eq!(white, HeroSample::ONE);
    }

    #[test]
    fn terminated_wavelengths_add_nothing() {
        let mut lambda = HeroWavelengths::sample(0.2);
        let full = HeroSample([1.0, 1.0, 1.0, 1.0]);
        lambda.terminate_secondary();
        // Only the hero counts, four times over.
        let only_hero = HeroSample([1.0, 0.0, 0.0, 0.0]).to_rgb(&lambda);
        assert_eq!(full.to_rgb(&lambda), only_hero);
    }
}
