//! Serde description of a translucent stone's `body` (issue 17): the boundary (a smooth or rough
//! dielectric interface) and the interior medium. It compiles into [`crate::scene::Body`].
//!
//! ```ron
//! body: (
//!     ior: 1.52,                       // absolute IOR of the stone, 1.0001 ..= 4 (at the d line)
//!     dispersion: Abbe(58.0),          // optional: Abbe(V_d) | Cauchy(b: µm², c: µm⁴)
//!                                      //   | Sellmeier(b: (B1, B2, B3), c: (C1, C2, C3))
//!     roughness: 2.0,                  // optional: RMS slope angle, degrees (or `alpha`); default smooth
//!     distribution: Ggx,               // optional: Blinn | Beckmann | Ggx (default Ggx)
//!     masking: Smith,                  // optional: VCavity | Smith | SmithSeparable (default Smith)
//!     medium: (                        // optional: default clear (a vacuum inside)
//!         colour: Srgb(0.9, 0.6, 0.3), // what white light keeps after `distance` ...
//!         distance: 1.0,               // ... object units (or `absorption: (σr, σg, σb)`)
//!         scattering: (4.0, 4.0, 4.0), // σs per object unit (default 0)
//!         phase: HenyeyGreenstein(g: 0.3), // or Isotropic (default)
//!     ),
//! )
//! ```
//!
//! **Units.** Coefficients are per **object unit**: the units the stone's shape is given in (a
//! sphere's radius, a cabochon's semi-axes, a mesh's coordinates after its `scale`). The stage's
//! uniform `transform.scale` is applied at compile time, so a scaled stone keeps its look.

use super::color::ColorDesc;
pub use super::crystal::{CrystalDesc, PleochroismDesc, TrichroismDesc};
pub use super::dispersion::DispersionDesc;
use super::platelets::PlateletsDesc;
use super::ranged::refuse;
use super::spectrum::SpectrumDesc;
use crate::bsdf::dispersion::Ior;
use crate::bsdf::{Distribution, Masking};
use crate::color::Rgb;
use crate::medium::phase::G_LIMIT;
use crate::spectrum::measured::Measured;
use serde::{Deserialize, Deserializer, Serialize};

pub use super::spectrum::SIGMA_MAX;
/// IOR range of a body.
pub const BODY_IOR: (f32, f32) = (1.0001, 4.0);

ranged!(ior_range, "body.ior", 1.0001, 4.0);
ranged!(distance_range, "medium.distance", open 0.0, 1e4);
ranged!(g_range, "phase g", -0.99, 0.99);

/// A coefficient triple named `what`: finite, 0 ..= 1e4 per object unit.
fn sigma<'de, D: Deserializer<'de>>(d: D, what: &str) -> Result<(f32, f32, f32), D::Error> {
    let v = <(f32, f32, f32)>::deserialize(d)?;
    if [v.0, v.1, v.2]
        .iter()
        .all(|c| c.is_finite() && (0.0..=SIGMA_MAX).contains(c))
    {
        Ok(v)
    } else {
        // Stand-in: each coefficient at its nearest allowed value (NaN: 0).
        let f = |c: f32| if c > SIGMA_MAX { SIGMA_MAX } else { c.max(0.0) };
        refuse(
            format!(
                "medium.{what} = {v:?}: each coefficient must be 0 ..= {SIGMA_MAX} per object unit"
            ),
            (f(v.0), f(v.1), f(v.2)),
        )
    }
}

fn absorption<'de, D: Deserializer<'de>>(d: D) -> Result<Option<(f32, f32, f32)>, D::Error> {
    sigma(d, "absorption").map(Some)
}

fn scattering<'de, D: Deserializer<'de>>(d: D) -> Result<(f32, f32, f32), D::Error> {
    sigma(d, "scattering")
}

/// A transmittance colour: linear, each channel 0 <.. 1.
/// The least transmittance a measured body colour is read as (a zero would be infinite
/// absorption): `σa ≤ −ln(10⁻⁶)/distance ≈ 13.8/distance`.
pub const MIN_TRANSMITTANCE: f32 = 1e-6;

fn transmittance<'de, D: Deserializer<'de>>(d: D) -> Result<Option<ColorDesc>, D::Error> {
    let c = ColorDesc::deserialize(d)?;
    // The stand-in for a refused colour.
    let grey = || Some(ColorDesc::Gray(0.5));
    if let Some(m) = c.measured(1.0) {
        // A measured colour: its values within 0 ..= 1 (checked here), read per wavelength.
        return match m {
            Ok(_) => Ok(Some(c)),
            Err(e) => refuse(
                format!("medium.colour: {e}: the share of light left"),
                grey(),
            ),
        };
    }
    let rgb = match c.to_rgb() {
        Ok(rgb) => rgb,
        Err(e) => return refuse(e, grey()),
    };
    if rgb.0.iter().all(|&v| v > 0.0 && v <= 1.0) {
        Ok(Some(c))
    } else {
        refuse(
            format!(
                "medium.colour = {c:?} is linear {:?}: each channel must be 0 <.. 1 (the share of \
                 white light left after `distance`)",
                rgb.0
            ),
            grey(),
        )
    }
}

fn opt_distance<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f32>, D::Error> {
    distance_range(d).map(Some)
}

fn opt_angle<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f32>, D::Error> {
    let v = f32::deserialize(d)?;
    if v == 0.0 || (0.01..90.0).contains(&v) {
        Ok(Some(v))
    } else {
        refuse(
            format!(
                "body.roughness = {v} is out of range: allowed 0 (smooth) or 0.01 ..< 90 degrees"
            ),
            Some(0.0),
        )
    }
}

fn opt_alpha<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f32>, D::Error> {
    let v = f32::deserialize(d)?;
    let (lo, hi) = super::material::ALPHA_RANGE;
    if v == 0.0 || (lo..=hi).contains(&v) {
        Ok(Some(v))
    } else {
        refuse(
            format!("body.alpha = {v} is out of range: allowed 0 (smooth) or {lo} ..= {hi}"),
            Some(0.0),
        )
    }
}

fn default_distribution() -> Distribution {
    Distribution::Ggx
}
fn default_compensation() -> bool {
    true
}

fn default_masking() -> Masking {
    Masking::Smith
}

/// A translucent stone's body: boundary and interior.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyDesc {
    /// Absolute IOR of the stone, 1.0001 ..= 4.
    #[serde(deserialize_with = "ior_range")]
    pub ior: f32,
    /// Boundary roughness as the RMS slope angle in degrees, 0 (smooth, the default) or
    /// 0.01 ..< 90. Exclusive with `alpha`.
    #[serde(default, deserialize_with = "opt_angle")]
    pub roughness: Option<f32>,
    /// Boundary roughness as `α`, 0 (smooth) or 0.0002 ..= 10. Exclusive with `roughness`.
    #[serde(default, deserialize_with = "opt_alpha")]
    pub alpha: Option<f32>,
    /// Micro-facet distribution of a rough boundary (default GGX, as pbrt-v4 and Mitsuba 3).
    #[serde(default = "default_distribution")]
    pub distribution: Distribution,
    /// Masking of a rough boundary (default Smith, Walter et al. 2007).
    #[serde(default = "default_masking")]
    pub masking: Masking,
    /// Whether a rough boundary returns the energy single scattering loses (the reciprocal
    /// multiple-scattering lobe of `bsdf::interface_energy`; default `true`, so a clear body in
    /// a white furnace is exactly 1). `false` is the plain Walter et al. (2007) interface, as
    /// Mitsuba 3's `roughdielectric`, pbrt-v4's and Cycles' are: it loses energy at every rough
    /// event (a furnace reads below 1), and is there to match them.
    #[serde(default = "default_compensation")]
    pub compensation: bool,
    /// How the IOR changes with the wavelength; `None`: it does not. A dispersive body turns
    /// spectral transport on (its RGB render uses `ior`, the index at the d line).
    #[serde(default)]
    pub dispersion: Option<DispersionDesc>,
    /// The interior; `None` is clear (nothing absorbs or scatters).
    #[serde(default)]
    pub medium: Option<MediumDesc>,
    /// Metal platelets suspended in the body (at most 8 populations; issue 18).
    #[serde(default, deserialize_with = "super::platelets::population_list")]
    pub platelets: Vec<PlateletsDesc>,
    /// A doubly refractive crystal: `ior` is then its ordinary index `n_o` (ω) and this gives the
    /// rest. Needs a smooth boundary; turns polarised transport on.
    #[serde(default)]
    pub crystal: Option<CrystalDesc>,
}

/// A homogeneous interior. Give the absorption either as coefficients or as a colour after a
/// distance.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MediumDesc {
    /// Absorption coefficient `σa` per object unit per channel, 0 ..= 1e4.
    #[serde(default, deserialize_with = "absorption")]
    pub absorption: Option<(f32, f32, f32)>,
    /// The colour (linear share, each channel 0 <.. 1) that white light keeps after travelling
    /// `distance` through the body without scattering: `σa = −ln(colour)/distance`.
    #[serde(default, deserialize_with = "transmittance")]
    pub colour: Option<ColorDesc>,
    /// The distance of `colour`, object units, 0 <.. 1e4.
    #[serde(default, deserialize_with = "opt_distance")]
    pub distance: Option<f32>,
    /// Scattering coefficient `σs` per object unit per channel, 0 ..= 1e4 (default 0).
    #[serde(default, deserialize_with = "scattering")]
    pub scattering: (f32, f32, f32),
    /// The phase function (default isotropic).
    #[serde(default)]
    pub phase: PhaseDesc,
    /// A measured absorption spectrum: `(wavelength nm, σa per object unit)` points, wavelengths
    /// increasing in 200 ..= 2000, values 0 ..= 1e4, 2 ..= 4096 points, inline or a CSV file
    /// (`"file.csv"` or `(file: "file.csv", scale: s)`, [`super::spectrum`]). Not with
    /// `absorption` or `colour`. Turns spectral transport on; RGB renders use its projection.
    #[serde(default)]
    pub absorption_spectrum: Option<SpectrumDesc>,
    /// A measured scattering spectrum, as `absorption_spectrum` (σs). Not with `scattering`.
    #[serde(default)]
    pub scattering_spectrum: Option<SpectrumDesc>,
}

/// A phase function.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum PhaseDesc {
    /// The same in every direction.
    #[default]
    Isotropic,
    /// Henyey–Greenstein with mean cosine `g`, −0.99 ..= 0.99 (> 0 forward).
    HenyeyGreenstein {
        /// Asymmetry.
        #[serde(deserialize_with = "g_range")]
        g: f32,
    },
}

impl PhaseDesc {
    /// The asymmetry `g` (0 for isotropic).
    pub fn g(self) -> f32 {
        match self {
            PhaseDesc::Isotropic => 0.0,
            PhaseDesc::HenyeyGreenstein { g } => g.clamp(-G_LIMIT, G_LIMIT),
        }
    }
}

impl BodyDesc {
    /// The body's index as a function of the wavelength (`None`: not dispersive), or what is
    /// wrong with the law ([`DispersionDesc::law`]).
    pub fn ior_law(&self) -> Result<Option<Ior>, String> {
        self.dispersion
            .map(|d| d.law(self.ior, BODY_IOR.1))
            .transpose()
    }

    /// The boundary's `α` (0: smooth), or what is wrong.
    pub fn alpha(&self) -> Result<f32, String> {
        match (self.roughness, self.alpha) {
            (Some(_), Some(_)) => {
                Err("body: give either `roughness` (degrees) or `alpha`, not both".into())
            }
            (Some(m), None) => Ok(m.to_radians().tan()),
            (None, Some(a)) => Ok(a),
            (None, None) => Ok(0.0),
        }
    }
}

/// A medium's coefficients per object unit as compiled: RGB values and, where the recipe gave
/// them, the measured spectra they are the projections of.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coefficients {
    /// `σa` (RGB).
    pub sigma_a: Rgb,
    /// `σs` (RGB).
    pub sigma_s: Rgb,
    /// Measured `σa(λ)`.
    pub sigma_a_measured: Option<Measured>,
    /// Measured `σs(λ)`.
    pub sigma_s_measured: Option<Measured>,
}

impl MediumDesc {
    /// The coefficients per object unit, with the measured spectra where given, or what is
    /// wrong.
    pub fn measured_coefficients(&self) -> Result<Coefficients, String> {
        let spectrum = |what: &str, pts: &Option<SpectrumDesc>| {
            pts.as_ref()
                .map(|p| {
                    p.measured(SIGMA_MAX)
                        .map_err(|e| format!("medium.{what}: {e}"))
                })
                .transpose()
        };
        let mut a = spectrum("absorption_spectrum", &self.absorption_spectrum)?;
        if let Some(m) = self.colour_spectrum()? {
            a = Some(m);
        }
        let s = spectrum("scattering_spectrum", &self.scattering_spectrum)?;
        if self.absorption_spectrum.is_some()
            && (self.absorption.is_some() || self.colour.is_some())
        {
            return Err(
                "medium: give the absorption as one of `absorption`, `colour` and `distance`, or \
                 `absorption_spectrum`"
                    .into(),
            );
        }
        if s.is_some() && self.scattering != (0.0, 0.0, 0.0) {
            return Err(
                "medium: give either `scattering` or `scattering_spectrum`, not both".into(),
            );
        }
        let (mut sigma_a, mut sigma_s) = self.coefficients()?;
        if let Some(m) = a {
            sigma_a = m.to_rgb();
        }
        if let Some(m) = s {
            sigma_s = m.to_rgb();
        }
        Ok(Coefficients {
            sigma_a,
            sigma_s,
            sigma_a_measured: a,
            sigma_s_measured: s,
        })
    }

    /// The absorption spectrum of a measured `colour` after `distance`: `σa(λ) =
    /// −ln(colour(λ))/distance` per wavelength (a colour value below [`MIN_TRANSMITTANCE`] counts
    /// as that: at most `13.8/distance`); `None` when the colour is not a spectrum.
    fn colour_spectrum(&self) -> Result<Option<Measured>, String> {
        let (Some(c), Some(d)) = (&self.colour, self.distance) else {
            return Ok(None);
        };
        let Some(m) = c.measured(1.0) else {
            return Ok(None);
        };
        let m = m.map_err(|e| format!("medium.colour: {e}"))?;
        Ok(Some(m.map(|t| {
            (-t.max(MIN_TRANSMITTANCE).ln() / d).clamp(0.0, SIGMA_MAX)
        })))
    }

    /// `σa` and `σs` per object unit (RGB, measured spectra as their projections), or what is
    /// wrong.
    pub fn coefficients(&self) -> Result<(Rgb, Rgb), String> {
        let sigma_a = match (&self.absorption, &self.colour, self.distance) {
            (Some(a), None, None) => Rgb::new(a.0, a.1, a.2),
            (None, Some(c), Some(d)) => match self.colour_spectrum()? {
                Some(m) => m.to_rgb(),
                None => {
                    let c = c.to_rgb()?;
                    Rgb(c.0.map(|v| (-v.ln() / d).max(0.0)))
                }
            },
            (None, None, None) => Rgb::ZERO,
            (Some(_), Some(_), _) | (Some(_), _, Some(_)) => {
                return Err(
                    "medium: give the absorption either as `absorption` or as `colour` and \
                     `distance`, not both"
                        .into(),
                );
            }
            (None, Some(_), None) => {
                return Err("medium: `colour` needs `distance` (object units, 0 <.. 1e4)".into());
            }
            (None, None, Some(_)) => {
                return Err("medium: `distance` needs `colour`".into());
            }
        };
        if sigma_a.0.iter().any(|&v| !(v <= SIGMA_MAX)) {
            return Err(format!(
                "medium: the colour gives absorption {:?} per object unit, above {SIGMA_MAX}",
                sigma_a.0
            ));
        }
        let s = self.scattering;
        Ok((sigma_a, Rgb::new(s.0, s.1, s.2)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<BodyDesc, String> {
        crate::recipe::ron_options()
            .from_str(text)
            .map_err(|e| e.to_string())
    }

    #[test]
    fn colour_form_converts_to_coefficients() {
        let b = parse("(ior: 1.5, medium: (colour: Rgb(0.5, 1.0, 0.25), distance: 2.0))").unwrap();
        let (a, s) = b.medium.as_ref().unwrap().coefficients().unwrap();
        assert!((a.0[0] - std::f32::consts::LN_2 / 2.0).abs() < 1e-6);
        assert_eq!(a.0[1], 0.0);
        assert!((a.0[2] - 2.0 * std::f32::consts::LN_2 / 2.0).abs() < 1e-6);
        assert_eq!(s, Rgb::ZERO);
        assert_eq!(b.alpha().unwrap(), 0.0);
    }

    #[test]
    fn bad_values_are_refused_with_the_range() {
        for (text, needle) in [
            ("(ior: 0.9)", "1.0001 ..= 4"),
            ("(ior: 1.5, roughness: 95.0)", "0.01 ..< 90"),
            ("(ior: 1.5, alpha: 20.0)", "0.0002 ..= 10"),
            (
                "(ior: 1.5, medium: (absorption: (1.0, -1.0, 0.0)))",
                "0 ..= 10000",
            ),
            (
                "(ior: 1.5, medium: (colour: Gray(0.0), distance: 1.0))",
                "0 <.. 1",
            ),
            (
                "(ior: 1.5, medium: (colour: Gray(0.5), distance: 0.0))",
                "0 <.. 10000",
            ),
            (
                "(ior: 1.5, medium: (phase: HenyeyGreenstein(g: 1.0)))",
                "-0.99 ..= 0.99",
            ),
        ] {
            let e = parse(text).unwrap_err();
            assert!(e.contains(needle), "{text}: {e}");
        }
        let both = parse("(ior: 1.5, roughness: 2.0, alpha: 0.1)").unwrap();
        assert!(both.alpha().is_err());
        let half = parse("(ior: 1.5, medium: (colour: Gray(0.5)))").unwrap();
        assert!(half.medium.unwrap().coefficients().is_err());
        let two = parse(
            "(ior: 1.5, medium: (absorption: (1.0, 1.0, 1.0), colour: Gray(0.5), distance: 1.0))",
        )
        .unwrap();
        assert!(two.medium.unwrap().coefficients().is_err());
    }
}
