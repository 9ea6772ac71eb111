//! The RGB variant of transported light: three linear Rec.709 channels, exactly the arithmetic the
//! renderer has always used (docs/design.md §12).

use super::Spectral;
use crate::color::Rgb;
use std::ops::{Add, AddAssign, Div, Index, Mul, MulAssign, Sub};

/// Number of colour channels carried by [`RgbSample`].
pub const CHANNELS: usize = 3;

/// Transported light in the RGB variant: a linear Rec.709 triple (radiance, throughput,
/// reflectance, absorption coefficient …, per channel). Not serialisable: what a recipe stores is a
/// [`Rgb`] colour, converted once where a material or light is built.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RgbSample(pub [f32; CHANNELS]);

impl RgbSample {
    /// All channels zero.
    pub const ZERO: RgbSample = RgbSample([0.0; CHANNELS]);
    /// All channels one.
    pub const ONE: RgbSample = RgbSample([1.0; CHANNELS]);

    /// A colour with the three given linear channels.
    pub const fn rgb(r: f32, g: f32, b: f32) -> Self {
        RgbSample([r, g, b])
    }
    /// The same value in every channel.
    pub const fn splat(v: f32) -> Self {
        RgbSample([v; CHANNELS])
    }
    /// Applies `f` to every channel.
    #[inline]
    pub fn map(self, f: impl Fn(f32) -> f32) -> Self {
        RgbSample(self.0.map(f))
    }
    /// Combines two colours channel by channel.
    #[inline]
    pub fn zip(self, o: Self, f: impl Fn(f32, f32) -> f32) -> Self {
        RgbSample([
            f(self.0[0], o.0[0]),
            f(self.0[1], o.0[1]),
            f(self.0[2], o.0[2]),
        ])
    }
    /// Largest channel.
    #[inline]
    pub fn max_channel(self) -> f32 {
        self.0[0].max(self.0[1]).max(self.0[2])
    }
    /// Smallest channel.
    #[inline]
    pub fn min_channel(self) -> f32 {
        self.0[0].min(self.0[1]).min(self.0[2])
    }
    /// Mean of the channels.
    #[inline]
    pub fn average(self) -> f32 {
        (self.0[0] + self.0[1] + self.0[2]) / 3.0
    }
    /// Rec.709 relative luminance Y (ITU-R BT.709 primaries, D65).
    #[inline]
    pub fn luminance(self) -> f32 {
        0.2126 * self.0[0] + 0.7152 * self.0[1] + 0.0722 * self.0[2]
    }
    /// True when every channel is exactly zero.
    #[inline]
    pub fn is_black(self) -> bool {
        self.0.iter().all(|&c| c == 0.0)
    }
    /// True when every channel is finite.
    #[inline]
    pub fn is_finite(self) -> bool {
        self.0.iter().all(|c| c.is_finite())
    }
    /// True when every channel is finite and `>= 0`.
    #[inline]
    pub fn is_valid(self) -> bool {
        self.0.iter().all(|&c| c.is_finite() && c >= 0.0)
    }
    /// `exp` per channel.
    #[inline]
    pub fn exp(self) -> Self {
        self.map(f32::exp)
    }
}

impl Spectral for RgbSample {
    #[inline]
    fn fluoresce(
        &mut self,
        _lambda: &mut super::RgbWavelengths,
        colorant: &super::fluorescence::Fluorescence,
        _lines: &[super::line::Line],
        _u: glam::Vec2,
    ) -> Option<[[f32; 3]; 3]> {
        Some(*colorant.rgb_matrix())
    }
    #[inline]
    fn remix(self, m: &[[f32; 3]; 3]) -> Self {
        let v = self.0;
        RgbSample(std::array::from_fn(|r| {
            m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2]
        }))
    }
    type Wavelengths = super::RgbWavelengths;
    const WAVELENGTH_DIMENSIONS: u32 = 0;
    const ZERO: Self = RgbSample::ZERO;
    const ONE: Self = RgbSample::ONE;
    const CHANNELS: usize = CHANNELS;
    #[inline]
    fn channel(self, i: usize) -> f32 {
        self.0[i]
    }
    #[inline]
    fn map(self, f: impl Fn(f32) -> f32) -> Self {
        RgbSample::map(self, f)
    }
    #[inline]
    fn from_channels(f: impl Fn(usize) -> f32) -> Self {
        RgbSample(std::array::from_fn(f))
    }
    #[inline]
    fn splat(v: f32) -> Self {
        RgbSample::splat(v)
    }
    #[inline]
    fn sample_wavelengths(_u: f32) -> Self::Wavelengths {
        super::RgbWavelengths
    }
    #[inline]
    fn from_reflectance(c: Rgb, _lambda: &Self::Wavelengths) -> Self {
        RgbSample(c.0)
    }
    #[inline]
    fn from_unbounded(c: Rgb, _lambda: &Self::Wavelengths) -> Self {
        RgbSample(c.0)
    }
    #[inline]
    fn to_rgb(self, _lambda: &Self::Wavelengths) -> Rgb {
        Rgb(self.0)
    }
    #[inline]
    fn max_channel(self) -> f32 {
        RgbSample::max_channel(self)
    }
    #[inline]
    fn average(self) -> f32 {
        RgbSample::average(self)
    }
    #[inline]
    fn is_black(self) -> bool {
        RgbSample::is_black(self)
    }
    #[inline]
    fn is_valid(self) -> bool {
        RgbSample::is_valid(self)
    }
}

/// The RGB variant's conversion from a stored colour: the same three numbers.
impl From<Rgb> for RgbSample {
    #[inline]
    fn from(c: Rgb) -> Self {
        RgbSample(c.0)
    }
}

/// The film colour of an RGB-variant value: the same three numbers.
impl From<RgbSample> for Rgb {
    #[inline]
    fn from(c: RgbSample) -> Self {
        Rgb(c.0)
    }
}

impl Index<usize> for RgbSample {
    type Output = f32;
    fn index(&self, i: usize) -> &f32 {
        &self.0[i]
    }
}
impl Add for RgbSample {
    type Output = RgbSample;
    #[inline]
    fn add(self, o: RgbSample) -> RgbSample {
        self.zip(o, |a, b| a + b)
    }
}
impl AddAssign for RgbSample {
    #[inline]
    fn add_assign(&mut self, o: RgbSample) {
        *self = *self + o;
    }
}
impl Sub for RgbSample {
    type Output = RgbSample;
    #[inline]
    fn sub(self, o: RgbSample) -> RgbSample {
        self.zip(o, |a, b| a - b)
    }
}
impl Mul for RgbSample {
    type Output = RgbSample;
    #[inline]
    fn mul(self, o: RgbSample) -> RgbSample {
        self.zip(o, |a, b| a * b)
    }
}
impl MulAssign for RgbSample {
    #[inline]
    fn mul_assign(&mut self, o: RgbSample) {
        *self = *self * o;
    }
}
impl Mul<f32> for RgbSample {
    type Output = RgbSample;
    #[inline]
    fn mul(self, s: f32) -> RgbSample {
        self.map(|a| a * s)
    }
}
impl MulAssign<f32> for RgbSample {
    #[inline]
    fn mul_assign(&mut self, s: f32) {
        *self = *self * s;
    }
}
impl Mul<RgbSample> for f32 {
    type Output = RgbSample;
    #[inline]
    fn mul(self, s: RgbSample) -> RgbSample {
        s * self
    }
}
impl Div<f32> for RgbSample {
    type Output = RgbSample;
    #[inline]
    fn div(self, s: f32) -> RgbSample {
        self.map(|a| a / s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arithmetic_is_per_channel() {
        let a = RgbSample::rgb(1.0, 2.0, 3.0);
        let b = RgbSample::rgb(2.0, 0.5, -1.0);
        assert_eq!(a * b, RgbSample::rgb(2.0, 1.0, -3.0));
        assert_eq!((a + b)[2], 2.0);
        assert!(!(a * b).is_valid());
        assert!((RgbSample::ONE.luminance() - 1.0).abs() < 1e-6);
    }
}
