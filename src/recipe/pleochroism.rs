//! Serde description of a crystal's `pleochroism` (part of [`super::crystal`]): the colour —
//! RGB or a measured transmittance spectrum — white light keeps after a distance when it travels
//! as each of the crystal's principal waves, compiled into absorption coefficients (and their
//! spectra, which spectral transport reads per wavelength).

use super::color::ColorDesc;
use crate::color::Rgb;
use crate::spectrum::measured::Measured;
use serde::{Deserialize, Deserializer, Serialize};

ranged!(pleochroism_distance, "pleochroism.distance", open 0.0, 1e4);

/// An absorption coefficient per object unit and, given as a spectrum, its spectrum.
pub type Sigma = (Rgb, Option<&'static Measured>);

/// What white light keeps of each channel after `distance` as an absorption coefficient per
/// object unit, `−ln(colour)/distance`; for a colour given as a spectrum `T(λ)`, the spectrum
/// `−ln T(λ)/distance` that spectral transport reads per wavelength, and for RGB transport its
/// projection (as a body's `absorption_spectrum`); or what is wrong with `name`.
fn sigma(c: &ColorDesc, name: &str, distance: f32) -> Result<Sigma, String> {
    let at = |e: String| format!("pleochroism.{name}: {e}");
    if let ColorDesc::Spectrum(s) = c {
        // The points' range first (with their positions), then each point's coefficient: the
        // spectrum is linear in σ between the points, as a body's `absorption_spectrum` is.
        c.measured(1.0).transpose().map_err(at)?;
        let points: Vec<(f32, f32)> = s
            .points
            .iter()
            .map(|&(l, v)| (l, -v.ln() / distance))
            .collect();
        if points.iter().any(|p| !(p.1 <= super::spectrum::SIGMA_MAX)) {
            return Err(at(format!(
                "each value must keep at least exp(−{} × distance) (0 keeps none at any \
                 distance): allowed 0 <..= 1",
                super::spectrum::SIGMA_MAX
            )));
        }
        let m = Measured::from_points(&points, super::spectrum::SIGMA_MAX)
            .map_err(at)?
            .intern();
        return Ok((m.to_rgb(), Some(m)));
    }
    let rgb = c.to_rgb().map_err(at)?;
    if rgb.0.iter().all(|v| *v > 0.0 && *v <= 1.0) {
        Ok((rgb.map(|v| -v.ln() / distance), None))
    } else {
        Err(format!(
            "pleochroism.{name} = {:?}: each channel must be in 0 <..= 1 (the share of white \
             light kept after `distance`)",
            rgb.0
        ))
    }
}

/// A dichroic crystal's absorption per wave, on top of the body's `medium`: the colour white
/// light keeps after `distance` when it travels as the ordinary wave (ω) and as the
/// extraordinary wave across the axis (ε, its field along the axis); an extraordinary wave at
/// angle θ to the axis absorbs `σ_ω cos² θ + σ_ε sin² θ`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PleochroismDesc {
    /// Colour of the ordinary wave after `distance` (each channel 0 <..= 1).
    pub ordinary: ColorDesc,
    /// Colour of the extraordinary wave (across the axis) after `distance`.
    pub extraordinary: ColorDesc,
    /// Object units, 0 <.. 1e4.
    #[serde(deserialize_with = "pleochroism_distance")]
    pub distance: f32,
}

impl PleochroismDesc {
    /// The absorption coefficients per object unit `[σ_ω, σ_ε]` (and their spectra where
    /// given as spectra), or what is wrong.
    pub fn coefficients(&self) -> Result<[Sigma; 2], String> {
        Ok([
            sigma(&self.ordinary, "ordinary", self.distance)?,
            sigma(&self.extraordinary, "extraordinary", self.distance)?,
        ])
    }
}

/// A trichroic crystal's absorption, on top of the body's `medium`: the colour white light keeps
/// after `distance` when it vibrates along X (`alpha`), Y (`beta`) and Z (`gamma`) — what a
/// dichroscope shows looking along the other two axes. A wave whose unit displacement is `D̂`
/// absorbs `Σ (D̂·aᵢ)² σᵢ` (the absorbing crystal's quadratic form, Born & Wolf, *Principles of
/// Optics*, §15.6).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrichroismDesc {
    /// Colour of light vibrating along X after `distance` (each channel 0 <..= 1).
    pub alpha: ColorDesc,
    /// Along Y.
    pub beta: ColorDesc,
    /// Along Z.
    pub gamma: ColorDesc,
    /// Object units, 0 <.. 1e4.
    #[serde(deserialize_with = "pleochroism_distance")]
    pub distance: f32,
}

impl TrichroismDesc {
    /// The absorption coefficients per object unit `[σ_α, σ_β, σ_γ]` (and their spectra where
    /// given as spectra), or what is wrong.
    pub fn coefficients(&self) -> Result<[Sigma; 3], String> {
        Ok([
            sigma(&self.alpha, "alpha", self.distance)?,
            sigma(&self.beta, "beta", self.distance)?,
            sigma(&self.gamma, "gamma", self.distance)?,
        ])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trichroic_colours_become_coefficients() {
        let t = TrichroismDesc {
            alpha: ColorDesc::Rgb(0.5, 0.5, 0.5),
            beta: ColorDesc::Rgb(1.0, 1.0, 1.0),
            gamma: ColorDesc::Rgb(0.25, 0.5, 1.0),
            distance: 2.0,
        };
        let [a, b, g] = t.coefficients().unwrap().map(|s| {
            assert!(s.1.is_none(), "an RGB colour has no spectrum");
            s.0
        });
        assert!((a.0[0] - 0.5f32.ln().abs() / 2.0).abs() < 1e-6);
        assert_eq!(b.0, [0.0; 3]);
        assert!((g.0[0] - 4.0f32.ln() / 2.0).abs() < 1e-6 && g.0[2] == 0.0);
        // A spectrum: its coefficient per wavelength, and that of its colour for RGB.
        let spectrum = |points: Vec<(f32, f32)>| {
            ColorDesc::Spectrum(crate::recipe::spectrum::SpectrumDesc::inline(points))
        };
        let measured = TrichroismDesc {
            gamma: spectrum(vec![(360.0, 0.9), (550.0, 0.9), (560.0, 0.1), (830.0, 0.1)]),
            ..t.clone()
        };
        let (rgb, m) = measured.coefficients().unwrap()[2];
        let m = m.expect("a spectrum");
        assert!((m.at(450.0) - 0.9f32.ln().abs() / 2.0).abs() < 1e-6);
        assert!((m.at(700.0) - 0.1f32.ln().abs() / 2.0).abs() < 1e-6);
        assert!(rgb.0[0] > rgb.0[2], "reddish light is kept less: {rgb:?}");
        let zero = TrichroismDesc {
            gamma: spectrum(vec![(360.0, 0.5), (600.0, 0.0), (830.0, 0.5)]),
            ..t.clone()
        };
        assert!(zero.coefficients().unwrap_err().contains("0 <..= 1"));
        let above = TrichroismDesc {
            gamma: spectrum(vec![(360.0, 0.5), (830.0, 1.5)]),
            ..t.clone()
        };
        assert!(above.coefficients().unwrap_err().contains("1.5"));
        let bad = TrichroismDesc {
            gamma: ColorDesc::Rgb(0.0, 0.5, 1.0),
            ..t
        };
        assert!(
            bad.coefficients()
                .unwrap_err()
                .contains("pleochroism.gamma")
        );
    }
}
