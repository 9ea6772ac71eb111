//! A fluorescent colorant in a recipe (issue 20): the `fluorescence` of a `Lambert` base.
//!
//! ```ron
//! base: Lambert(
//!     albedo: Spectrum("spectra/dayglo-orange-substrate.csv"),
//!     fluorescence: (
//!         excitation: "spectra/dayglo-orange-excitation.csv", // fraction absorbed, 0 ..= 1
//!         emission: "spectra/dayglo-orange-emission.csv",     // shape, any scale
//!         quantum_yield: 0.8,                                  // 0 ..= 1
//!     ),
//! ),
//! ```
//!
//! `albedo` is then the substrate's reflectance *before* the colorant absorbs: the base reflects
//! elastically `albedo(λ) · (1 − a(λ))` and re-radiates what the colorant absorbs
//! ([`crate::spectrum::fluorescence`]), so a photon is either reflected, re-emitted (with the
//! yield, at a longer wavelength) or absorbed — never created.

use super::color::ColorDesc;
use super::spectrum::SpectrumDesc;
use crate::spectrum::cie::{LAMBDA_MAX, LAMBDA_MIN};
use crate::spectrum::fluorescence::Fluorescence;
use crate::spectrum::measured::{Measured, UNBOUNDED};
use crate::spectrum::rgb2spec;
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// The colorant of a fluorescent base.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluorescenceDesc {
    /// `a(λ)`: the fraction of incident photons the colorant absorbs, 0 ..= 1.
    pub excitation: SpectrumDesc,
    /// The shape of the emitted spectrum (any non-negative scale; normalised).
    pub emission: SpectrumDesc,
    /// Photons emitted per photon absorbed, 0 ..= 1.
    pub quantum_yield: f32,
}

/// What a fluorescent base compiles to.
pub(crate) struct CompiledFluorescence {
    /// The colorant.
    pub colorant: Arc<Fluorescence>,
    /// The elastic reflectance `albedo · (1 − a)` on the 1 nm grid.
    pub elastic: Measured,
}

impl FluorescenceDesc {
    /// The colorant and the base's elastic reflectance for the substrate `albedo`, or what is
    /// wrong (naming the field).
    pub(crate) fn compile(&self, albedo: &ColorDesc) -> Result<CompiledFluorescence, String> {
        let field = |name: &str, s: &SpectrumDesc, max: f32| {
            s.measured(max)
                .map_err(|e| format!("base.fluorescence.{name}: {e}"))
        };
        let excitation = field("excitation", &self.excitation, 1.0)?;
        // An emission spectrum is a shape (normalised below): any finite value ≥ 0.
        let emission = field("emission", &self.emission, UNBOUNDED)?;
        let colorant = Fluorescence::new(&excitation, &emission, self.quantum_yield)
            .map_err(|e| format!("base.fluorescence: {e}"))?;
        let substrate: Box<dyn Fn(f32) -> f32> = match albedo.measured(1.0) {
            Some(m) => {
                let m = m.map_err(|e| format!("base.albedo: {e}"))?;
                Box::new(move |l| m.at(l))
            }
            None => {
                let rgb = albedo.to_rgb().map_err(|e| format!("base.albedo: {e}"))?;
                if rgb.0.iter().any(|v| !(0.0..=1.0).contains(v)) {
                    return Err(format!(
                        "base.albedo = {:?} is out of range: allowed 0 ..= 1 per channel",
                        rgb.0
                    ));
                }
                let s = rgb2spec::reflectance(rgb.0);
                Box::new(move |l| s.eval(l))
            }
        };
        let points: Vec<(f32, f32)> = (0..=(LAMBDA_MAX - LAMBDA_MIN) as usize)
            .map(|i| {
                let l = LAMBDA_MIN + i as f32;
                (
                    l,
                    (substrate(l) * (1.0 - colorant.excitation(l))).clamp(0.0, 1.0),
                )
            })
            .collect();
        let elastic = Measured::from_points(&points, 1.0)
            .map_err(|e| format!("base.fluorescence (elastic reflectance): {e}"))?;
        Ok(CompiledFluorescence {
            colorant: Arc::new(colorant),
            elastic,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn desc(q: f32) -> FluorescenceDesc {
        FluorescenceDesc {
            excitation: SpectrumDesc::inline(vec![(400.0, 0.0), (500.0, 0.8), (600.0, 0.0)]),
            emission: SpectrumDesc::inline(vec![(520.0, 0.0), (590.0, 1.0), (680.0, 0.0)]),
            quantum_yield: q,
        }
    }

    #[test]
    fn the_colorant_takes_its_share_of_the_substrate() {
        let c = desc(0.9).compile(&ColorDesc::Gray(0.8)).unwrap();
        // a(450) = 0.4 on the excitation's linear flank (read per 1 nm cell, at 450.5 nm: 0.404):
        // 0.8 · 0.6 reflected elastically.
        assert!(
            (c.elastic.at(450.0) - 0.8 * 0.6).abs() < 5e-3,
            "{}",
            c.elastic.at(450.0)
        );
        assert!((c.elastic.at(700.0) - 0.8).abs() < 1e-4);
        assert!((c.colorant.quantum_yield() - 0.9).abs() < 1e-7);
        // Bad input names the field and the range.
        let e = desc(1.5).compile(&ColorDesc::Gray(0.8)).err().unwrap();
        assert!(e.contains("quantum_yield") && e.contains("0 ..= 1"), "{e}");
        let mut high = desc(0.5);
        high.excitation = SpectrumDesc::inline(vec![(400.0, 1.5), (600.0, 1.5)]);
        let e = high.compile(&ColorDesc::Gray(0.8)).err().unwrap();
        assert!(e.contains("base.fluorescence.excitation"), "{e}");
        let e = desc(0.5).compile(&ColorDesc::Gray(1.5)).err().unwrap();
        assert!(e.contains("base.albedo"), "{e}");
    }
}
