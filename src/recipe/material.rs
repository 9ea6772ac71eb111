//! Serde description of a layered material (a "stack"), separate from the runtime
//! [`crate::bsdf::LayeredBsdf`] it compiles into.
//!
//! ```ron
//! (
//!     coats: [(ior: 1.6, roughness: 12.0, thickness: 0.5)],
//!     base: Lambert(albedo: Srgb(0.37, 0.09, 0.11)), // optional: fluorescence: (…)
//!     // optional: model: Corrected | Course | Reference(samples: 4, max_depth: 256),
//!     //           fresnel: Exact | Schlick | Lazanyi | Table,
//!     //           distribution: Blinn | Beckmann | Ggx, masking: VCavity | Smith | SmithSeparable,
//!     //           outside_ior: 1.33, t_term: true/false, compensation: true/false,
//!     //           calibration: true/false
//! )
//! ```

use super::color::ColorDesc;
use crate::bsdf::{
    Base, Coat, ConductorIor, Distribution, FresnelMode, Masking, Metal, Model, ReferenceParams,
    StackDesc,
};
use crate::color::Rgb;
use serde::{Deserialize, Serialize};

/// One coat: a rough dielectric interface over a varnish layer.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CoatDesc {
    /// Absolute IOR of the varnish, 1.0001 ..= 10.
    pub ior: f32,
    /// RMS micro-facet slope angle in degrees, 0.01 ..< 90 (`α = tan m`), or exactly 0 for a
    /// perfectly smooth (specular, delta) top coat. Exclusive with
    /// `alpha`; one of them is required.
    #[serde(default)]
    pub roughness: Option<f32>,
    /// Roughness as `α` (the unit of pbrt-v4 and Mitsuba 3), 0.0002 ..= 10. Exclusive with
    /// `roughness`.
    #[serde(default)]
    pub alpha: Option<f32>,
    /// Layer thickness (course units, fig. 3.4 uses 0 … 15), ≥ 0. Default 0.
    #[serde(default)]
    pub thickness: f32,
    /// Absorption coefficient per unit thickness per channel (≥ 0); the course's `alpha` (the
    /// *inverse* of the colour the varnish shows). Exclusive with `tint`.
    #[serde(default)]
    pub absorption: Option<ColorDesc>,
    /// The colour white light keeps after one perpendicular pass through the layer (0 < c ≤ 1);
    /// converted to `absorption = −ln(tint)/thickness`. Needs `thickness > 0`.
    #[serde(default)]
    pub tint: Option<ColorDesc>,
}

/// A conductor's optical constants.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum MetalDesc {
    /// Gold (Johnson & Christy 1972).
    Gold,
    /// Silver (Johnson & Christy 1972).
    Silver,
    /// Copper (Johnson & Christy 1972).
    Copper,
    /// Aluminium (Rakić 1995).
    Aluminium,
    /// Brass, 70 % Cu / 30 % Zn (Querry 1985; docs/metals.md).
    Brass,
    /// A perfect mirror (reflectance 1).
    Perfect,
    /// Explicit complex IOR `n + i k` per channel.
    Complex {
        /// Real parts (r, g, b), > 0.
        n: (f32, f32, f32),
        /// Extinction coefficients (r, g, b), ≥ 0.
        k: (f32, f32, f32),
    },
}

/// The opaque base of a stack.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum BaseDesc {
    /// Lambertian with albedo 0 ..= 1.
    Lambert {
        /// Albedo (with `fluorescence`: the substrate's, before the colorant absorbs).
        albedo: ColorDesc,
        /// A fluorescent colorant in the base (issue 20; [`super::fluorescence`]).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        fluorescence: Option<super::fluorescence::FluorescenceDesc>,
    },
    /// Oren–Nayar with albedo and slope deviation σ in radians (0 ..= 1.5).
    OrenNayar {
        /// Albedo.
        albedo: ColorDesc,
        /// σ in radians.
        sigma: f32,
    },
    /// Rough conductor.
    Conductor {
        /// Optical constants.
        metal: MetalDesc,
        /// RMS slope angle in degrees, 0.01 ..< 90. Exclusive with `alpha`; one is required.
        #[serde(default)]
        roughness: Option<f32>,
        /// Roughness as `α`, 0.0002 ..= 10. Exclusive with `roughness`.
        #[serde(default)]
        alpha: Option<f32>,
    },
}

/// Smallest and largest `alpha` a recipe may give.
pub const ALPHA_RANGE: (f32, f32) = (0.0002, 10.0);

/// The RMS slope angle in degrees of a roughness given as `roughness` (degrees) or `alpha`
/// (`m = atan α`); `what` names the element in the error.
fn slope_angle(roughness: Option<f32>, alpha: Option<f32>, what: &str) -> Result<f32, String> {
    match (roughness, alpha) {
        (Some(m), None) => Ok(m),
        (None, Some(a)) => {
            if a == 0.0 {
                // A perfectly smooth interface, like `roughness: 0`.
                return Ok(0.0);
            }
            if !(ALPHA_RANGE.0..=ALPHA_RANGE.1).contains(&a) {
                return Err(format!(
                    "{what}.alpha = {a} is out of range: allowed 0 (smooth) or {} ..= {}",
                    ALPHA_RANGE.0, ALPHA_RANGE.1
                ));
            }
            Ok((f64::from(a).atan().to_degrees()) as f32)
        }
        (Some(_), Some(_)) => Err(format!(
            "{what}: give either `roughness` (degrees) or `alpha`, not both"
        )),
        (None, None) => Err(format!(
            "{what}: needs a roughness: `roughness` (RMS slope angle, degrees) or `alpha`"
        )),
    }
}

fn coat_list<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Vec<CoatDesc>, D::Error> {
    super::ranged::bounded_list(d, "coats", super::ranged::MAX_COATS, false)
}
fn samples_range<'de, D: serde::Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    let max = super::ranged::MAX_REFERENCE_SAMPLES;
    super::ranged::whole(d, "samples", 1, max).map(|v| v as u32)
}
fn walk_depth_range<'de, D: serde::Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    let max = super::ranged::MAX_REFERENCE_DEPTH;
    super::ranged::whole(d, "max_depth", 1, max).map(|v| v as u32)
}

fn default_samples() -> u32 {
    ReferenceParams::default().samples
}
fn default_depth() -> u32 {
    ReferenceParams::default().max_depth
}

/// Evaluation model as written in a recipe.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum ModelDesc {
    /// Course eqs. 3.1–3.3 as published.
    Course,
    /// Energy-consistent local model (default).
    #[default]
    Corrected,
    /// Stochastic random walk.
    Reference {
        /// Walks per evaluation, 1 ..= 256 (default 4).
        #[serde(default = "default_samples", deserialize_with = "samples_range")]
        samples: u32,
        /// Maximum bounces per walk, 1 ..= 4096 (default 256).
        #[serde(default = "default_depth", deserialize_with = "walk_depth_range")]
        max_depth: u32,
    },
}

impl ModelDesc {
    /// The runtime model.
    pub fn to_model(&self) -> Model {
        match *self {
            ModelDesc::Course => Model::Course,
            ModelDesc::Corrected => Model::Corrected,
            ModelDesc::Reference { samples, max_depth } => {
                Model::Reference(ReferenceParams { samples, max_depth })
            }
        }
    }
}

fn air() -> f32 {
    1.0
}

fn yes() -> bool {
    true
}

/// A layered material.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialDesc {
    /// Coats, top first (may be empty; at most 16).
    #[serde(default, deserialize_with = "coat_list")]
    pub coats: Vec<CoatDesc>,
    /// The opaque base.
    pub base: BaseDesc,
    /// Evaluation model (default Corrected).
    #[serde(default)]
    pub model: ModelDesc,
    /// Fresnel evaluation (default Exact).
    #[serde(default)]
    pub fresnel: FresnelMode,
    /// Micro-facet distribution (default Blinn).
    #[serde(default)]
    pub distribution: Distribution,
    /// Masking–shadowing (default the course's V-cavity).
    #[serde(default)]
    pub masking: Masking,
    /// Absolute IOR of the medium outside the surface (default 1, air; e.g. 1.33 under water),
    /// 1 ..= 3.
    #[serde(default = "air")]
    pub outside_ior: f32,
    /// The course's `t` term; default: on for Course, off otherwise.
    #[serde(default)]
    pub t_term: Option<bool>,
    /// Multiple-scattering compensation (default true).
    #[serde(default = "yes")]
    pub compensation: bool,
    /// The Corrected model's albedo calibration (default true).
    #[serde(default = "yes")]
    pub calibration: bool,
}

impl MaterialDesc {
    /// Converts to the runtime description, naming the offending field on error.
    pub fn to_stack(&self) -> Result<StackDesc, String> {
        let mut coats = Vec::with_capacity(self.coats.len());
        for (i, c) in self.coats.iter().enumerate() {
            let absorption = match (&c.absorption, &c.tint) {
                (Some(_), Some(_)) => {
                    return Err(format!(
                        "coats[{i}]: give either `absorption` or `tint`, not both"
                    ));
                }
                (Some(a), None) => a
                    .to_rgb()
                    .map_err(|e| format!("coats[{i}].absorption: {e}"))?,
                (None, Some(t)) => {
                    if let Some(m) = t.measured(1.0) {
                        m.map_err(|e| format!("coats[{i}].tint: {e}"))?;
                    }
                    let t = t.to_rgb().map_err(|e| format!("coats[{i}].tint: {e}"))?;
                    if !(c.thickness > 0.0) {
                        return Err(format!(
                            "coats[{i}].tint needs thickness > 0 (got {})",
                            c.thickness
                        ));
                    }
                    if t.0.iter().any(|&v| !(v > 0.0 && v <= 1.0)) {
                        return Err(format!(
                            "coats[{i}].tint = {:?} is out of range: allowed 0 <.. 1 per channel",
                            t.0
                        ));
                    }
                    t.map(|v| -v.ln() / c.thickness)
                }
                (None, None) => Rgb::ZERO,
            };
            coats.push(Coat {
                ior: c.ior,
                roughness: slope_angle(c.roughness, c.alpha, &format!("coats[{i}]"))?,
                absorption,
                thickness: c.thickness,
            });
        }
        let mut base_spectrum = None;
        let mut albedo_of = |albedo: &ColorDesc| match albedo.measured(1.0) {
            // A measured albedo: values within 0 ..= 1 at every wavelength; its RGB projection
            // (which a saturated spectrum can push past 1 in one channel) kept within 0 ..= 1.
            Some(m) => {
                let m = m.map_err(|e| format!("base.albedo: {e}"))?;
                base_spectrum = Some(m.intern());
                Ok(m.to_rgb().map(|v| v.min(1.0)))
            }
            None => albedo.to_rgb().map_err(|e| format!("base.albedo: {e}")),
        };
        let mut fluorescence = None;
        let base = match &self.base {
            BaseDesc::Lambert {
                albedo,
                fluorescence: Some(f),
            } => {
                let c = f.compile(albedo)?;
                let rgb = c.elastic.to_rgb().map(|v| v.min(1.0));
                base_spectrum = Some(c.elastic.intern());
                fluorescence = Some(c.colorant);
                Base::Lambert { albedo: rgb }
            }
            BaseDesc::Lambert {
                albedo,
                fluorescence: None,
            } => Base::Lambert {
                albedo: albedo_of(albedo)?,
            },
            BaseDesc::OrenNayar { albedo, sigma } => Base::OrenNayar {
                albedo: albedo_of(albedo)?,
                sigma: *sigma,
            },
            BaseDesc::Conductor {
                metal,
                roughness,
                alpha,
            } => {
                let preset = ConductorIor::Measured;
                let ior = match metal {
                    MetalDesc::Gold => preset(Metal::Gold),
                    MetalDesc::Silver => preset(Metal::Silver),
                    MetalDesc::Copper => preset(Metal::Copper),
                    MetalDesc::Aluminium => preset(Metal::Aluminium),
                    MetalDesc::Brass => preset(Metal::Brass),
                    MetalDesc::Perfect => ConductorIor::Perfect,
                    MetalDesc::Complex { n, k } => ConductorIor::Complex {
                        n: Rgb::new(n.0, n.1, n.2),
                        k: Rgb::new(k.0, k.1, k.2),
                    },
                };
                Base::Conductor {
                    ior,
                    roughness: slope_angle(*roughness, *alpha, "base")?,
                }
            }
        };
        Ok(StackDesc {
            coats,
            base,
            model: self.model.to_model(),
            fresnel: self.fresnel,
            distribution: self.distribution,
            masking: self.masking,
            outside_ior: self.outside_ior,
            t_term: self.t_term,
            compensation: self.compensation,
            calibration: self.calibration,
            base_spectrum,
            fluorescence,
        })
    }
}
