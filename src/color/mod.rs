//! Colour: the radiometric quantity every BSDF returns and every path carries.
//!
//! [`Spectrum`] is linear Rec.709 RGB today. It is the only type the BSDFs, the layer stack and (later)
//! the integrator use for colour, so spectral rendering (course §5.2.2, fluorescence) can change the
//! channel count and meaning here without touching the material interface.

use serde::{Deserialize, Serialize};
use std::ops::{Add, AddAssign, Div, Index, Mul, MulAssign, Sub};

/// Number of colour channels carried by [`Spectrum`].
pub const CHANNELS: usize = 3;

/// A linear Rec.709 RGB triple (radiance, reflectance, absorption coefficient …, per channel).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Spectrum(pub [f32; CHANNELS]);

impl Spectrum {
    /// All channels zero.
    pub const ZERO: Spectrum = Spectrum([0.0; CHANNELS]);
    /// All channels one.
    pub const ONE: Spectrum = Spectrum([1.0; CHANNELS]);

    /// A colour with the three given linear channels.
    pub const fn rgb(r: f32, g: f32, b: f32) -> Self {
        Spectrum([r, g, b])
    }
    /// The same value in every channel.
    pub const fn splat(v: f32) -> Self {
        Spectrum([v; CHANNELS])
    }
    /// Applies `f` to every channel.
    #[inline]
    pub fn map(self, f: impl Fn(f32) -> f32) -> Self {
        Spectrum(self.0.map(f))
    }
    /// Combines two colours channel by channel.
    #[inline]
    pub fn zip(self, o: Self, f: impl Fn(f32, f32) -> f32) -> Self {
        Spectrum([
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
    /// Converts an sRGB-encoded colour (IEC 61966-2-1 transfer curve) to linear Rec.709.
    pub fn from_srgb(r: f32, g: f32, b: f32) -> Self {
        fn lin(c: f32) -> f32 {
            if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            }
        }
        Spectrum([lin(r), lin(g), lin(b)])
    }
}

impl Index<usize> for Spectrum {
    type Output = f32;
    fn index(&self, i: usize) -> &f32 {
        &self.0[i]
    }
}
impl Add for Spectrum {
    type Output = Spectrum;
    #[inline]
    fn add(self, o: Spectrum) -> Spectrum {
        self.zip(o, |a, b| a + b)
    }
}
impl AddAssign for Spectrum {
    #[inline]
    fn add_assign(&mut self, o: Spectrum) {
        *self = *self + o;
    }
}
impl Sub for Spectrum {
    type Output = Spectrum;
    #[inline]
    fn sub(self, o: Spectrum) -> Spectrum {
        self.zip(o, |a, b| a - b)
    }
}
impl Mul for Spectrum {
    type Output = Spectrum;
    #[inline]
    fn mul(self, o: Spectrum) -> Spectrum {
        self.zip(o, |a, b| a * b)
    }
}
impl MulAssign for Spectrum {
    #[inline]
    fn mul_assign(&mut self, o: Spectrum) {
        *self = *self * o;
    }
}
impl Mul<f32> for Spectrum {
    type Output = Spectrum;
    #[inline]
    fn mul(self, s: f32) -> Spectrum {
        self.map(|a| a * s)
    }
}
impl MulAssign<f32> for Spectrum {
    #[inline]
    fn mul_assign(&mut self, s: f32) {
        *self = *self * s;
    }
}
impl Mul<Spectrum> for f32 {
    type Output = Spectrum;
    #[inline]
    fn mul(self, s: Spectrum) -> Spectrum {
        s * self
    }
}
impl Div<f32> for Spectrum {
    type Output = Spectrum;
    #[inline]
    fn div(self, s: f32) -> Spectrum {
        self.map(|a| a / s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_numbers() {
        let c = Spectrum::from_srgb(0.0, 1.0, 0.5);
        assert_eq!(c[0], 0.0);
        assert!((c[1] - 1.0).abs() < 1e-6);
        assert!((c[2] - 0.21404).abs() < 1e-4);
    }

    #[test]
    fn arithmetic_is_per_channel() {
        let a = Spectrum::rgb(1.0, 2.0, 3.0);
        let b = Spectrum::rgb(2.0, 0.5, -1.0);
        assert_eq!(a * b, Spectrum::rgb(2.0, 1.0, -3.0));
        assert_eq!((a + b)[2], 2.0);
        assert!(!(a * b).is_valid());
        assert!((Spectrum::ONE.luminance() - 1.0).abs() < 1e-6);
    }
}
