//! Colour literals in recipes: `Rgb(r, g, b)` (linear Rec.709), `Srgb(r, g, b)` (sRGB-encoded,
//! 0 … 1), `Hex("#rrggbb")` (sRGB-encoded) and `Gray(v)` (linear).

use crate::color::Rgb;
use serde::{Deserialize, Serialize};

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
}

impl ColorDesc {
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
        }
    }
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
    }
}
