//! Accuracy knobs (docs/design.md §9): every approximation and optional effect of a render, settable from
//! the command line (`lapidary render --model course --bump off …`), from a recipe
//! (`render: (accuracy: (…))`) and by `lapidary tradeoff --setting …`.
//!
//! A knob either rewrites what the scene asks for (the evaluation model and Fresnel mode of every
//! material) or **forces an effect's code** on or off ([`super::Effects::forced`]):
//!
//! | knob | forced off | forced on |
//! |---|---|---|
//! | `t-term` | every coated material without the course's `t` term | every coated Course/Corrected material with it |
//! | `absorption` | coats are clear (`α = 0`) | the absorption code runs for clear coats too (factor exactly 1) |
//! | `bump` (`facet-bump`) | facet normals are ignored | facet frames are used wherever a map gives one |
//! | `glitter-overlay` | an `Overlay` shows only its `under` map | (no code to force) |
//! | `stochastic-switch` | switches are hard (`blend` ignored) | (no code to force) |
//! | `depth-of-field` | a pinhole camera | the thin-lens path is taken (at aperture 0 it gives the pinhole ray) |
//! | `environment-importance` | an environment map is sampled uniformly | (no code to force) |
//!
//! # One type, resolved into the compiled scene
//!
//! [`Accuracy`] is the one representation of the knobs, wherever they are written: a model, a
//! Fresnel mode and a list of forced effects. The spellings that name one effect twice are
//! aliases that make the same entry: `bump` is `facet-bump` ([`effect_named`]), and on the command
//! line `--bump V`, `--t-term V` and `--absorption V` are `--effect facet-bump=V`,
//! `--effect t-term=V` and `--effect absorption=V`. Model and Fresnel names are
//! [`crate::bsdf::names`].
//!
//! [`Scene::set_accuracy`](super::Scene::set_accuracy) is the only place an [`Accuracy`] is
//! applied: it rewrites the material descriptions, recounts the effects they call for and forces
//! effects (the only caller of [`super::Effects`]' forcing), before any BSDF table or world is
//! built. It runs at these stages, each crediting its source for `lapidary info`:
//!
//! 1. **compile** — `GemRecipe::compile` applies the recipe's `stage.render.accuracy`
//!    (credited `render.accuracy (file:line)`);
//! 2. **load** — `crate::cli::load` applies the command line's knobs, built once into an
//!    [`Accuracy`] by `crate::cli::knobs::KnobArgs` (credited `command line`), for every command
//!    that loads a recipe;
//! 3. **tradeoff** — each `--setting` is a [`Knobs`](super::Knobs) applied to a copy of the
//!    loaded scene ([`Knobs::apply`](super::Knobs::apply): its render-level part, then
//!    [`Scene::set_accuracy`](super::Scene::set_accuracy)).
//!
//! A later stage overrides an earlier one knob by knob; `Scene::accuracy` holds the result, which
//! the render metadata (`lapidary.accuracy`) and the summaries print.
//!
//! Render-level knobs (spp, sampler, maximum depth) live in the render settings;
//! [`Knobs`](super::Knobs) bundles them with an [`Accuracy`] for `tradeoff` settings written as
//! `key=value,key=value`.

use super::Effect;
use crate::bsdf::names::UnknownName;
use crate::bsdf::{Distribution, FresnelMode, Masking, Model, StackDesc};
use std::fmt;

/// Material-level knobs and forced effects. The default changes nothing.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Accuracy {
    /// Evaluation model for every material (`None`: each material's own).
    pub model: Option<Model>,
    /// Fresnel evaluation for every material (`None`: each material's own).
    pub fresnel: Option<FresnelMode>,
    /// Micro-facet distribution for every material (`None`: each material's own).
    pub distribution: Option<Distribution>,
    /// Masking–shadowing for every material (`None`: each material's own).
    pub masking: Option<Masking>,
    /// Multiple-scattering energy compensation (Turquin 2019) of every material's conductor base
    /// (and the Reference walk's interfaces), and of a translucent body's rough boundary, on or
    /// off (`None`: each material's and the body's own; it adds ~2 % to gold at mid angles
    /// against an uncompensated peer, docs/parity.md).
    pub compensation: Option<bool>,
    /// The Corrected model's albedo calibration to the adding solution on or off (`None`: each
    /// material's own; docs/materials.md measures what it buys).
    pub calibration: Option<bool>,
    /// Effects forced on (`true`) or off, in the order they were set.
    pub effects: Vec<(Effect, bool)>,
}

/// An accuracy knob that cannot be set.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct KnobError(pub String);

impl Accuracy {
    /// Forces `effect` on or off (replacing an earlier setting of it).
    pub fn force(&mut self, effect: Effect, on: bool) {
        self.effects.retain(|(e, _)| *e != effect);
        self.effects.push((effect, on));
    }

    /// The forced state of `effect`, if set.
    pub fn forced(&self, effect: Effect) -> Option<bool> {
        self.effects
            .iter()
            .find(|(e, _)| *e == effect)
            .map(|(_, on)| *on)
    }

    /// Whether no knob is set.
    pub fn is_default(&self) -> bool {
        *self == Accuracy::default()
    }

    /// Sets the knob `key` (`model`, `fresnel`, `t-term`, `absorption`, `bump`, or an effect name)
    /// from its written `value`; the error names the allowed values.
    pub fn set(&mut self, key: &str, value: &str) -> Result<(), KnobError> {
        match key {
            "model" => self.model = Some(parse_model(value)?),
            "fresnel" => self.fresnel = Some(parse_fresnel(value)?),
            "distribution" => {
                self.distribution = Some(
                    value
                        .parse()
                        .map_err(|e: UnknownName| KnobError(e.to_string()))?,
                )
            }
            "compensation" => self.compensation = Some(parse_switch(key, value)?),
            "calibration" => self.calibration = Some(parse_switch(key, value)?),
            "masking" => {
                self.masking = Some(
                    value
                        .parse()
                        .map_err(|e: UnknownName| KnobError(e.to_string()))?,
                )
            }
            _ => {
                let effect = effect_named(key).ok_or_else(|| {
                    KnobError(format!(
                        "unknown knob `{key}`: allowed {}",
                        KNOB_KEYS.join(", ")
                    ))
                })?;
                self.force(effect, parse_switch(key, value)?);
            }
        }
        Ok(())
    }

    /// Applies the knobs to one material description.
    pub fn apply_to(&self, stack: &mut StackDesc) {
        if let Some(m) = self.model {
            stack.model = m;
        }
        if let Some(f) = self.fresnel {
            stack.fresnel = f;
        }
        if let Some(d) = self.distribution {
            stack.distribution = d;
        }
        if let Some(m) = self.masking {
            stack.masking = m;
        }
        if let Some(c) = self.compensation {
            stack.compensation = c;
        }
        if let Some(c) = self.calibration {
            stack.calibration = c;
        }
        if let Some(t) = self.forced(Effect::TTerm) {
            stack.t_term = Some(t);
        }
        if self.forced(Effect::Absorption) == Some(false) {
            for c in &mut stack.coats {
                c.absorption = crate::color::Rgb::ZERO;
            }
        }
    }
}

/// Every knob key [`Knobs::set`](super::Knobs::set) accepts (the effect names of [`Effect::name`]
/// work too).
pub const KNOB_KEYS: [&str; 19] = [
    "model",
    "fresnel",
    "distribution",
    "masking",
    "compensation",
    "calibration",
    "t-term",
    "absorption",
    "bump",
    "glitter-overlay",
    "stochastic-switch",
    "depth-of-field",
    "environment-importance",
    "sampler",
    "max-depth",
    "medium-depth",
    "medium-scattering",
    "manifold-continuation",
    "manifold-halvings",
];

/// The effect a knob key names (`bump` is short for `facet-bump`).
pub fn effect_named(key: &str) -> Option<Effect> {
    match key {
        "bump" => Some(Effect::FacetBump),
        "t_term" => Some(Effect::TTerm),
        _ => Effect::ALL.into_iter().find(|e| e.name() == key),
    }
}

/// `course`, `corrected` or `reference` (4 walks per evaluation, depth 256), in any letter case
/// ([`Model`]'s `FromStr`).
pub fn parse_model(value: &str) -> Result<Model, KnobError> {
    value
        .parse()
        .map_err(|e: crate::bsdf::names::UnknownName| KnobError(e.to_string()))
}

/// `exact`, `schlick`, `lazanyi` or `table`, in any letter case ([`FresnelMode`]'s `FromStr`).
pub fn parse_fresnel(value: &str) -> Result<FresnelMode, KnobError> {
    value
        .parse()
        .map_err(|e: crate::bsdf::names::UnknownName| KnobError(e.to_string()))
}

/// `on`/`off` (also `true`/`false`, `yes`/`no`) for knob `key`.
pub fn parse_switch(key: &str, value: &str) -> Result<bool, KnobError> {
    match value.to_ascii_lowercase().as_str() {
        "on" | "true" | "yes" => Ok(true),
        "off" | "false" | "no" => Ok(false),
        _ => Err(KnobError(format!("{key} `{value}` is not one of: on, off"))),
    }
}

impl fmt::Display for Accuracy {
    /// `key=value` pairs joined by commas, in the form [`Accuracy::set`] reads.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut parts = vec![];
        if let Some(m) = self.model {
            parts.push(format!("model={m}"));
        }
        if let Some(fr) = self.fresnel {
            parts.push(format!("fresnel={fr}"));
        }
        if let Some(d) = self.distribution {
            parts.push(format!("distribution={d}"));
        }
        if let Some(m) = self.masking {
            parts.push(format!("masking={m}"));
        }
        if let Some(c) = self.compensation {
            parts.push(format!("compensation={}", if c { "on" } else { "off" }));
        }
        if let Some(c) = self.calibration {
            parts.push(format!("calibration={}", if c { "on" } else { "off" }));
        }
        for (e, on) in &self.effects {
            let name = if *e == Effect::FacetBump {
                "bump"
            } else {
                e.name()
            };
            parts.push(format!("{name}={}", if *on { "on" } else { "off" }));
        }
        f.write_str(&parts.join(","))
    }
}
