//! The description of a layer stack (what a recipe's material compiles to): its coats, base and
//! model, with the ranges every parameter must lie in ([`validate`]).

use crate::bsdf::{Distribution, FresnelMode, Masking, Metal};
use crate::color::Rgb;
use serde::{Deserialize, Serialize};

/// One coat of a stack: a rough dielectric interface and the varnish below it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coat {
    /// Absolute IOR of the varnish (the medium above the top coat is [`StackDesc::outside_ior`]).
    pub ior: f32,
    /// RMS micro-facet slope angle of the interface, degrees (0.01 ≤ m < 90), or exactly 0 for a
    /// perfectly smooth interface (a Dirac reflection and refraction; the top coat only).
    pub roughness: f32,
    /// Absorption coefficient per unit thickness, per channel (≥ 0).
    pub absorption: Rgb,
    /// Layer thickness in the course's arbitrary units (≥ 0).
    pub thickness: f32,
}

/// A conductor's complex IOR, absolute.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ConductorIor {
    /// `n + i k` per channel.
    Complex {
        /// Real part.
        n: Rgb,
        /// Extinction coefficient.
        k: Rgb,
    },
    /// Reflectance 1 at every angle (a perfect mirror; for furnace tests).
    Perfect,
    /// A measured metal: RGB paths use its preset `n + i k` ([`Metal::nk`]), spectral paths its
    /// tables at each wavelength ([`Metal::nk_at`]).
    Measured(Metal),
}

impl ConductorIor {
    /// `(n, k)` per RGB channel, `None` for the perfect mirror.
    pub fn rgb(&self) -> Option<(Rgb, Rgb)> {
        match *self {
            ConductorIor::Complex { n, k } => Some((n, k)),
            ConductorIor::Measured(m) => Some(m.nk()),
            ConductorIor::Perfect => None,
        }
    }
}

/// The opaque base of a stack.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Base {
    /// Lambertian, albedo per channel.
    Lambert {
        /// Albedo (0 … 1).
        albedo: Rgb,
    },
    /// Oren–Nayar.
    OrenNayar {
        /// Albedo (0 … 1).
        albedo: Rgb,
        /// Slope standard deviation, radians.
        sigma: f32,
    },
    /// A rough conductor (Torrance–Sparrow).
    Conductor {
        /// Complex IOR, absolute (relative IORs against the varnish are formed at build time).
        ior: ConductorIor,
        /// RMS slope angle, degrees.
        roughness: f32,
    },
}

/// Parameters of the Reference random walk.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ReferenceParams {
    /// Independent walks averaged by one `eval` (≥ 1).
    pub samples: u32,
    /// Maximum number of bounces at the base per walk. Russian roulette ends ordinary walks after a
    /// few bounces; the limit matters for near-mirror bases under a coat, where light trapped by
    /// total internal reflection keeps its weight (32 lost 6% at θo 80° for m 0.5°; 256 loses
    /// none measurable).
    pub max_depth: u32,
}

impl Default for ReferenceParams {
    fn default() -> Self {
        ReferenceParams {
            samples: 4,
            max_depth: 256,
        }
    }
}

/// Which evaluation model a stack uses (docs/design.md §5.2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Model {
    /// Course eqs. 3.1–3.3 as published.
    Course,
    /// Energy-consistent local model (default).
    #[default]
    Corrected,
    /// Stochastic random walk.
    Reference(ReferenceParams),
}

/// Everything that defines a stack at runtime, before its tables are built.
#[derive(Clone, Debug, PartialEq)]
pub struct StackDesc {
    /// Coats, top first (may be empty: then the stack is its base).
    pub coats: Vec<Coat>,
    /// The opaque base.
    pub base: Base,
    /// Evaluation model.
    pub model: Model,
    /// Fresnel evaluation for the Torrance–Sparrow lobes.
    pub fresnel: FresnelMode,
    /// Micro-facet distribution for all interfaces.
    pub distribution: Distribution,
    /// Masking–shadowing for all interfaces.
    pub masking: Masking,
    /// Absolute IOR of the medium the surface is seen from (1: air; 1.33 a coat under water),
    /// 1 ..= 3; the top coat must be denser.
    pub outside_ior: f32,
    /// The course's internal-reflection term `t` (eq. 3.3); `None` = the model's default (on for
    /// Course, off for Corrected; the Reference has no such term).
    pub t_term: Option<bool>,
    /// Multiple-scattering energy compensation (Turquin 2019) of a conductor base (Corrected and
    /// Reference) and of the coats' interfaces (Reference). The Course model never uses it.
    pub compensation: bool,
    /// The Corrected model's albedo calibration to the adding solution ([`super::calibrate`]); on by
    /// default, off to measure what it buys (`tradeoff` knob `calibration`).
    pub calibration: bool,
    /// A measured albedo spectrum of a Lambert or Oren–Nayar base (the `albedo` above is its RGB
    /// projection). Spectral renders read it per wavelength: a stack without coats directly, one
    /// under coats that do not absorb through its albedo ladder ([`super::ladder`]); otherwise a coated
    /// stack's spectral value is its RGB value as a spectrum ([`crate::bsdf::spectral`]).
    pub base_spectrum: Option<&'static crate::spectrum::measured::Measured>,
    /// A fluorescent colorant in a Lambert base (docs/fluorescence.md, [`super::fluorescent`]): the base's albedo
    /// (and `base_spectrum`) are then its elastic reflectance; the colorant adds the fluorescent
    /// lobe. Coats above it must not absorb.
    pub fluorescence: Option<std::sync::Arc<crate::spectrum::fluorescence::Fluorescence>>,
}

impl StackDesc {
    /// A stack with the default model, exact Fresnel and Blinn distribution.
    pub fn new(coats: Vec<Coat>, base: Base) -> Self {
        StackDesc {
            coats,
            base,
            model: Model::default(),
            fresnel: FresnelMode::Exact,
            distribution: Distribution::Blinn,
            masking: Masking::VCavity,
            outside_ior: 1.0,
            t_term: None,
            compensation: true,
            calibration: true,
            base_spectrum: None,
            fluorescence: None,
        }
    }
    /// The same stack under another model.
    pub fn with_model(mut self, model: Model) -> Self {
        self.model = model;
        self
    }
}

/// Why a stack description cannot be built.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum StackError {
    /// A parameter is outside its allowed range.
    #[error("{what} = {value} is out of range: allowed {range}")]
    OutOfRange {
        /// Which parameter.
        what: String,
        /// The offending value.
        value: f32,
        /// The allowed range, in words.
        range: &'static str,
    },
}

/// Checks every parameter of `desc` against its allowed range.
pub fn validate(desc: &StackDesc) -> Result<(), StackError> {
    let bad = |what: String, value: f32, range: &'static str| {
        Err(StackError::OutOfRange { what, value, range })
    };
    if !(desc.outside_ior >= 1.0 && desc.outside_ior <= 3.0) {
        return bad("outside_ior".into(), desc.outside_ior, "1 ..= 3");
    }
    if let Some(c) = desc.coats.first()
        && !(c.ior >= 1.0001 * desc.outside_ior)
    {
        return bad(
            "coats[0].ior".into(),
            c.ior,
            "above 1.0001 × outside_ior (the top coat must be denser than the outside medium)",
        );
    }
    for (i, c) in desc.coats.iter().enumerate() {
        if !(c.ior >= 1.0001 && c.ior <= 10.0) {
            return bad(format!("coats[{i}].ior"), c.ior, "1.0001 ..= 10");
        }
        if c.roughness == 0.0 && i > 0 {
            return bad(
                format!("coats[{i}].roughness"),
                c.roughness,
                "0.01 ..< 90 degrees below the top coat (a perfectly smooth coat, roughness 0, \
                 must be coats[0])",
            );
        }
        if !(c.roughness == 0.0 || (c.roughness >= 0.01 && c.roughness < 90.0)) {
            return bad(
                format!("coats[{i}].roughness"),
                c.roughness,
                "0 (smooth) or 0.01 ..< 90 degrees",
            );
        }
        if !(c.thickness >= 0.0 && c.thickness.is_finite()) {
            return bad(
                format!("coats[{i}].thickness"),
                c.thickness,
                "any finite value ≥ 0",
            );
        }
        for ch in 0..3 {
            let a = c.absorption[ch];
            if !(a >= 0.0 && a.is_finite()) {
                return bad(
                    format!("coats[{i}].absorption[{ch}]"),
                    a,
                    "any finite value ≥ 0",
                );
            }
        }
    }
    let check_albedo = |albedo: Rgb| {
        for ch in 0..3 {
            if !(0.0..=1.0).contains(&albedo[ch]) {
                return bad(format!("base.albedo[{ch}]"), albedo[ch], "0 ..= 1");
            }
        }
        Ok(())
    };
    match desc.base {
        Base::Lambert { albedo } => check_albedo(albedo)?,
        Base::OrenNayar { albedo, sigma } => {
            check_albedo(albedo)?;
            if !(0.0..=1.5).contains(&sigma) {
                return bad("base.sigma".into(), sigma, "0 ..= 1.5 radians");
            }
        }
        Base::Conductor { ior, roughness } => {
            if !(0.01..90.0).contains(&roughness) {
                return bad("base.roughness".into(), roughness, "0.01 ..< 90 degrees");
            }
            if let Some((n, k)) = ior.rgb() {
                for ch in 0..3 {
                    if !(n[ch] > 0.0 && n[ch] <= 20.0) {
                        return bad(format!("base.n[{ch}]"), n[ch], "0 <.. 20");
                    }
                    if !(k[ch] >= 0.0 && k[ch] <= 20.0) {
                        return bad(format!("base.k[{ch}]"), k[ch], "0 ..= 20");
                    }
                }
            }
        }
    }
    if let Model::Reference(p) = desc.model
        && (p.samples == 0 || p.max_depth == 0)
    {
        return bad("model.Reference.samples/max_depth".into(), 0.0, ">= 1");
    }
    if desc.fluorescence.is_some() {
        if !matches!(desc.base, Base::Lambert { .. }) {
            return bad(
                "base.fluorescence".into(),
                1.0,
                "only on a Lambert base (the course's fluorescent Lambertian base)",
            );
        }
        if let Some(i) = desc
            .coats
            .iter()
            .position(|c| c.thickness > 0.0 && c.absorption.max_channel() > 0.0)
        {
            return bad(
                format!("coats[{i}].absorption over a fluorescent base"),
                desc.coats[i].absorption.max_channel(),
                "0 (a varnish over a fluorescent base must be clear: the lobe's coats are \
                 achromatic)",
            );
        }
    }
    Ok(())
}
