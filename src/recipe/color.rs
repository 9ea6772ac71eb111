//! Colour literals in recipes: `Rgb(r, g, b)` (linear Rec.709), `Srgb(r, g, b)` (sRGB-encoded,
//! 0 … 1), `Hex("#rrggbb")` (sRGB-encoded), `Gray(v)` (linear) and `Spectrum(…)`, a measured
//! reflectance or transmittance spectrum ([`super::spectrum`]; issue 19).

use super::spectrum::SpectrumDesc;
use crate::color::Rgb;
use crate::spectrum::measured::Measured;
use serde::{Deserialize, Serialize};

/// Largest value a colour's spectrum may have (a reflectance or transmittance is further limited
/// to 1 where the recipe uses it).
pub const SPECTRUM_MAX: f32 = 1e4;

/// A colour as written in a recipe.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum ColorDesc {
    /// Linear Rec.709 RGB.
    Rgb(f32, f32, f32),
    /// sRGB-encoded RGB, each channel 0 … 1.
    Srgb(f32, f32, f32),
    /// sRGB-encoded hexadecimal `#rrggbb`.
    Hex(String),
    /// The same linear value in every channel.
    Gray(f32),
    /// A spectrum: `(nm, value)` points or a CSV file ([`SpectrumDesc`]). RGB renders use its
    /// D65-weighted linear sRGB projection ([`Measured::to_rgb`]); spectral renders read it per
    /// wavelength where the model allows (a coat-less diffuse base, a body's colour), else they
    /// use the projection.
    Spectrum(SpectrumDesc),
}

impl ColorDesc {
    /// The spectrum on the 10 nm grid when the colour is a `Spectrum` (values checked within
    /// `0 ..= max`), else `None`.
    pub fn measured(&self, max: f32) -> Option<Result<Measured, String>> {
        match self {
            ColorDesc::Spectrum(s) => Some(grid(s, max)),
            _ => None,
        }
    }

    /// The linear colour, or a message saying what is wrong with the literal.
    pub fn to_rgb(&self) -> Result<Rgb, String> {
        let check = |v: [f32; 3]| {
            if v.iter().all(|c| c.is_finite()) {
                Ok(())
            } else {
                Err("colour channels must be finite numbers".to_string())
            }
        };
        match self {
            ColorDesc::Rgb(r, g, b) => {
                check([*r, *g, *b])?;
                Ok(Rgb::new(*r, *g, *b))
            }
            ColorDesc::Gray(v) => {
                check([*v; 3])?;
                Ok(Rgb::splat(*v))
            }
            ColorDesc::Srgb(r, g, b) => {
                check([*r, *g, *b])?;
                if [*r, *g, *b].iter().any(|c| !(0.0..=1.0).contains(c)) {
                    return Err(format!("Srgb({r}, {g}, {b}): channels must be in 0 ..= 1"));
                }
                Ok(Rgb::from_srgb(*r, *g, *b))
            }
            ColorDesc::Hex(s) => {
                let h = s.strip_prefix('#').unwrap_or(s);
                if h.len() != 6 || !h.chars().all(|c| c.is_ascii_hexdigit()) {
                    return Err(format!(
                        "Hex(\"{s}\"): expected \"#rrggbb\" with six hexadecimal digits"
                    ));
                }
                let byte =
                    |i: usize| u8::from_str_radix(&h[i..i + 2], 16).map(|v| f32::from(v) / 255.0);
                match (byte(0), byte(2), byte(4)) {
                    (Ok(r), Ok(g), Ok(b)) => Ok(Rgb::from_srgb(r, g, b)),
                    _ => Err(format!("Hex(\"{s}\"): not a hexadecimal colour")),
                }
            }
            ColorDesc::Spectrum(s) => grid(s, SPECTRUM_MAX).map(|m| m.to_rgb()),
        }
    }
}

/// `s` on the 10 nm grid, its values checked within `0 ..= max`; errors name the CSV file and
/// line of the offending point ([`SpectrumDesc::measured`]), or the inline point.
fn grid(s: &SpectrumDesc, max: f32) -> Result<Measured, String> {
    s.measured(max).map_err(|e| match &s.csv {
        Some(_) => e,
        None => format!("Spectrum: {e}"),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn literals_convert() {
        assert_eq!(ColorDesc::Gray(0.5).to_rgb().unwrap(), Rgb::splat(0.5));
        let h = ColorDesc::Hex("#ff0080".into()).to_rgb().unwrap();
        assert!((h[0] - 1.0).abs() < 1e-6 && h[1] == 0.0 && (h[2] - 0.2158).abs() < 1e-3);
        assert!(ColorDesc::Hex("#ff00".into()).to_rgb().is_err());
        assert!(ColorDesc::Srgb(1.2, 0.0, 0.0).to_rgb().is_err());
        assert!(ColorDesc::Rgb(f32::NAN, 0.0, 0.0).to_rgb().is_err());
        // A flat spectrum is its grey; a bad one says what is wrong.
        let flat = ColorDesc::Spectrum(SpectrumDesc::inline(vec![(360.0, 0.4), (830.0, 0.4)]));
        let g = flat.to_rgb().unwrap();
        assert!(g.0.iter().all(|&c| (c - 0.4).abs() < 1e-6), "{g:?}");
        let bad = ColorDesc::Spectrum(SpectrumDesc::inline(vec![(500.0, 0.4), (400.0, 0.4)]));
        assert!(bad.to_rgb().unwrap_err().contains("does not increase"));
        assert!(flat.measured(0.3).unwrap().is_err());
    }
}
