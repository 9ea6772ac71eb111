//! Stored colour: what a recipe, a texture, an environment map, a film pixel and an AOV hold.
//!
//! [`Rgb`] is a linear Rec.709 triple (ITU-R BT.709 primaries, D65 white). It is a *description*:
//! it is never multiplied along a path. Transported light is a different type,
//! [`crate::spectrum::Spectral`], whose RGB variant ([`crate::spectrum::RgbSample`]) is converted
//! from an [`Rgb`] once, where a material or a light is built, and back to an [`Rgb`] once, where a
//! path's radiance reaches the film (docs/design.md §12). Measured spectra (issue 19) become a
//! second kind of stored colour here; the transport code does not change.

use serde::{Deserialize, Serialize};

/// A linear Rec.709 colour as stored in a recipe, a texture or an image.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Rgb(pub [f32; 3]);

impl Rgb {
    /// Black.
    pub const ZERO: Rgb = Rgb([0.0; 3]);
    /// White (1 in every channel).
    pub const ONE: Rgb = Rgb([1.0; 3]);

    /// A colour with the three given linear channels.
    pub const fn new(r: f32, g: f32, b: f32) -> Self {
        Rgb([r, g, b])
    }
    /// The same value in every channel.
    pub const fn splat(v: f32) -> Self {
        Rgb([v; 3])
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
        Rgb([lin(r), lin(g), lin(b)])
    }
    /// Rec.709 relative luminance Y.
    #[inline]
    pub fn luminance(self) -> f32 {
        0.2126 * self.0[0] + 0.7152 * self.0[1] + 0.0722 * self.0[2]
    }
    /// Applies `f` to every channel.
    #[inline]
    pub fn map(self, f: impl Fn(f32) -> f32) -> Self {
        Rgb(self.0.map(f))
    }
    /// Combines two colours channel by channel.
    #[inline]
    pub fn zip(self, o: Self, f: impl Fn(f32, f32) -> f32) -> Self {
        Rgb([
            f(self.0[0], o.0[0]),
            f(self.0[1], o.0[1]),
            f(self.0[2], o.0[2]),
        ])
    }
    /// True when every channel is finite and `>= 0`.
    #[inline]
    pub fn is_valid(self) -> bool {
        self.0.iter().all(|&c| c.is_finite() && c >= 0.0)
    }
    /// True when every channel is exactly zero.
    #[inline]
    pub fn is_black(self) -> bool {
        self.0.iter().all(|&c| c == 0.0)
    }
    /// Largest channel.
    #[inline]
    pub fn max_channel(self) -> f32 {
        self.0[0].max(self.0[1]).max(self.0[2])
    }
}

impl std::ops::Index<usize> for Rgb {
    type Output = f32;
    fn index(&self, i: usize) -> &f32 {
        &self.0[i]
    }
}

// A stored colour may be blended and scaled (interpolating texels, an intensity knob); products of
// two colours are transport and happen on [`crate::spectrum::Spectral`] values.
impl std::ops::Add for Rgb {
    type Output = Rgb;
    #[inline]
    fn add(self, o: Rgb) -> Rgb {
        self.zip(o, |a, b| a + b)
    }
}
impl std::ops::Mul<f32> for Rgb {
    type Output = Rgb;
    #[inline]
    fn mul(self, s: f32) -> Rgb {
        self.map(|a| a * s)
    }
}
impl std::ops::Div<f32> for Rgb {
    type Output = Rgb;
    #[inline]
    fn div(self, s: f32) -> Rgb {
        self.map(|a| a / s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_numbers() {
        let c = Rgb::from_srgb(0.0, 1.0, 0.5);
        assert_eq!(c[0], 0.0);
        assert!((c[1] - 1.0).abs() < 1e-6);
        assert!((c[2] - 0.21404).abs() < 1e-4);
        assert!((Rgb::ONE.luminance() - 1.0).abs() < 1e-6);
    }
}
