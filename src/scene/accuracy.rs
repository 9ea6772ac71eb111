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
//! [`Scene::set_accuracy`] is the only place an [`Accuracy`] is applied: it rewrites the material
//! descriptions, recounts the effects they call for and forces effects (the only caller of
//! [`super::Effects`]' forcing), before any BSDF table or world is built. It runs at these
//! stages, each crediting its source for `lapidary info`:
//!
//! 1. **compile** — `GemRecipe::compile` applies the recipe's `stage.render.accuracy`
//!    (credited `render.accuracy (file:line)`);
//! 2. **load** — `crate::cli::load` applies the command line's knobs, built once into an
//!    [`Accuracy`] by `crate::cli::knobs::KnobArgs` (credited `command line`), for every command
//!    that loads a recipe;
//! 3. **tradeoff** — each `--setting` is a [`Knobs`] applied to a copy of the loaded scene
//!    ([`Knobs::apply`]: its render-level part, then [`Scene::set_accuracy`]).
//!
//! A later stage overrides an earlier one knob by knob; `Scene::accuracy` holds the result, which
//! the render metadata (`lapidary.accuracy`) and the summaries print.
//!
//! Render-level knobs (spp, sampler, maximum depth) live in the render settings; [`Knobs`] bundles
//! them with an [`Accuracy`] for `tradeoff` settings written as `key=value,key=value`.

use super::{Effect, Scene};
use crate::bsdf::names::UnknownName;
use crate::bsdf::{Distribution, FresnelMode, Masking, Model, StackDesc};
use crate::sampler::SamplerKind;
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

/// Every knob key [`Knobs::set`] accepts (the effect names of [`Effect::name`] work too).
pub const KNOB_KEYS: [&str; 18] = [
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

/// An [`Accuracy`] plus the render-level knobs: one setting of a `tradeoff` study.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Knobs {
    /// Material-level knobs and forced effects.
    pub accuracy: Accuracy,
    /// Sampler (`None`: the recipe's).
    pub sampler: Option<SamplerKind>,
    /// Longest path in bounces (`None`: the recipe's).
    pub max_depth: Option<u32>,
    /// Most scattering events in a medium (`None`: the recipe's).
    pub medium_depth: Option<u32>,
    /// Whether media scatter (`None`: the recipe's).
    pub medium_scattering: Option<bool>,
    /// Whether failed manifold walks retry by the continuation (`None`: the recipe's).
    pub manifold_continuation: Option<bool>,
    /// Platelets explicit (`true`) or statistical (`None`: the recipe's).
    pub platelets_explicit: Option<bool>,
}

impl Knobs {
    /// Sets one knob (any key of [`KNOB_KEYS`]).
    pub fn set(&mut self, key: &str, value: &str) -> Result<(), KnobError> {
        match key {
            "sampler" => {
                self.sampler = Some(match value.to_ascii_lowercase().as_str() {
                    "sobol" => SamplerKind::Sobol,
                    "independent" => SamplerKind::Independent,
                    _ => {
                        return Err(KnobError(format!(
                            "sampler `{value}` is not one of: sobol, independent"
                        )));
                    }
                })
            }
            "max-depth" | "max_depth" => {
                let d: u32 = value
                    .parse()
                    .ok()
                    .filter(|d| (1..=1024).contains(d))
                    .ok_or_else(|| {
                        KnobError(format!(
                            "max-depth `{value}` is out of range: allowed 1 ..= 1024"
                        ))
                    })?;
                self.max_depth = Some(d);
            }
            "medium-depth" | "medium_depth" => {
                let max = crate::scene::stage::MAX_MEDIUM_DEPTH;
                let d: u32 = value.parse().ok().filter(|d| *d <= max).ok_or_else(|| {
                    KnobError(format!(
                        "medium-depth `{value}` is out of range: allowed 0 ..= {max}"
                    ))
                })?;
                self.medium_depth = Some(d);
            }
            "platelets"
                if matches!(
                    value.to_ascii_lowercase().as_str(),
                    "explicit" | "statistical"
                ) =>
            {
                self.platelets_explicit = Some(value.eq_ignore_ascii_case("explicit"));
            }
            "medium-scattering" | "medium_scattering" => {
                self.medium_scattering = Some(parse_switch("medium-scattering", value)?);
            }
            "manifold-continuation" | "manifold_continuation" => {
                self.manifold_continuation = Some(parse_switch("manifold-continuation", value)?);
            }
            _ => self.accuracy.set(key, value)?,
        }
        Ok(())
    }

    /// Applies the render-level knobs to `scene`'s settings and the rest with
    /// [`Scene::set_accuracy`].
    pub fn apply(&self, scene: &mut Scene, by: &str) -> Result<(), KnobError> {
        self.apply_render(scene);
        scene.set_accuracy(&self.accuracy, by)
    }

    /// Applies only the render-level knobs (sampler, depths, scattering, platelets) to `scene`.
    pub fn apply_render(&self, scene: &mut Scene) {
        if let Some(s) = self.sampler {
            scene.stage.render.sampler = s;
        }
        if let Some(d) = self.max_depth {
            scene.stage.render.max_depth = d;
        }
        if let Some(d) = self.medium_depth {
            scene.stage.render.medium_depth = d;
        }
        if let Some(s) = self.medium_scattering {
            scene.stage.render.medium_scattering = s;
        }
        if let Some(c) = self.manifold_continuation {
            scene.stage.render.manifold_continuation = c;
        }
        if let Some(e) = self.platelets_explicit {
            scene.stage.render.platelets_explicit = e;
        }
    }
}

impl std::str::FromStr for Knobs {
    type Err = KnobError;

    /// `key=value,key=value` (an empty string or `baseline` sets nothing).
    fn from_str(s: &str) -> Result<Knobs, KnobError> {
        let mut k = Knobs::default();
        for part in s.split(',').map(str::trim).filter(|p| !p.is_empty()) {
            if part == "baseline" {
                continue;
            }
            let (key, value) = part.split_once('=').ok_or_else(|| {
                KnobError(format!(
                    "`{part}` is not `key=value` (keys: {})",
                    KNOB_KEYS.join(", ")
                ))
            })?;
            k.set(key.trim(), value.trim())?;
        }
        Ok(k)
    }
}

impl fmt::Display for Knobs {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut parts = vec![];
        let acc = self.accuracy.to_string();
        if !acc.is_empty() {
            parts.push(acc);
        }
        if let Some(s) = self.sampler {
            parts.push(format!("sampler={}", s.name()));
        }
        if let Some(d) = self.max_depth {
            parts.push(format!("max-depth={d}"));
        }
        if let Some(d) = self.medium_depth {
            parts.push(format!("medium-depth={d}"));
        }
        if let Some(s) = self.medium_scattering {
            parts.push(format!(
                "medium-scattering={}",
                if s { "on" } else { "off" }
            ));
        }
        if let Some(c) = self.manifold_continuation {
            parts.push(format!(
                "manifold-continuation={}",
                if c { "on" } else { "off" }
            ));
        }
        if let Some(e) = self.platelets_explicit {
            parts.push(format!(
                "platelets={}",
                if e { "explicit" } else { "statistical" }
            ));
        }
        if parts.is_empty() {
            f.write_str("baseline")
        } else {
            f.write_str(&parts.join(","))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_prints_settings() {
        let k: Knobs =
            "model=course, fresnel=table,bump=off,t-term=on,sampler=independent,max-depth=4"
                .parse()
                .unwrap();
        assert_eq!(k.accuracy.model, Some(Model::Course));
        assert_eq!(k.accuracy.fresnel, Some(FresnelMode::Table));
        assert_eq!(k.accuracy.forced(Effect::FacetBump), Some(false));
        assert_eq!(k.accuracy.forced(Effect::TTerm), Some(true));
        assert_eq!(k.sampler, Some(SamplerKind::Independent));
        assert_eq!(k.max_depth, Some(4));
        let again: Knobs = k.to_string().parse().unwrap();
        assert_eq!(again, k);
        assert_eq!("baseline".parse::<Knobs>().unwrap().to_string(), "baseline");
    }

    #[test]
    fn bad_knobs_name_what_is_allowed() {
        let e = "model=fast".parse::<Knobs>().unwrap_err().0;
        assert!(e.contains("course, corrected, reference"), "{e}");
        let e = "bump=maybe".parse::<Knobs>().unwrap_err().0;
        assert!(e.contains("on, off"), "{e}");
        let e = "max-depth=0".parse::<Knobs>().unwrap_err().0;
        assert!(e.contains("1 ..= 1024"), "{e}");
        let e = "colour=red".parse::<Knobs>().unwrap_err().0;
        assert!(e.contains("unknown knob") && e.contains("fresnel"), "{e}");
        let e = "bump".parse::<Knobs>().unwrap_err().0;
        assert!(e.contains("key=value"), "{e}");
    }

    #[test]
    fn apply_rewrites_materials() {
        use crate::bsdf::{Base, Coat};
        use crate::color::Rgb;
        use crate::scene::stack_calls;
        let coat = Coat {
            ior: 1.5,
            roughness: 10.0,
            absorption: Rgb::splat(0.5),
            thickness: 1.0,
        };
        let mut s = StackDesc::new(
            vec![coat],
            Base::Lambert {
                albedo: Rgb::splat(0.5),
            },
        );
        assert_eq!(stack_calls(&s), (Some(0), false));
        let k: Knobs = "model=course,absorption=off,fresnel=schlick"
            .parse()
            .unwrap();
        k.accuracy.apply_to(&mut s);
        assert_eq!((s.model, s.fresnel), (Model::Course, FresnelMode::Schlick));
        assert_eq!(s.coats[0].absorption, Rgb::ZERO);
        assert_eq!(stack_calls(&s), (None, true));
        let k: Knobs = "t-term=off".parse().unwrap();
        k.accuracy.apply_to(&mut s);
        assert_eq!(stack_calls(&s), (None, false));
    }

    #[test]
    fn microfacet_knobs_rewrite_materials_and_print_back() {
        use crate::bsdf::{Base, ConductorIor, Distribution, Masking};
        let mut s = StackDesc::new(
            vec![],
            Base::Conductor {
                ior: ConductorIor::Perfect,
                roughness: 10.0,
            },
        );
        let k: Knobs = "distribution=ggx,masking=smith-separable,compensation=off,calibration=off"
            .parse()
            .unwrap();
        k.accuracy.apply_to(&mut s);
        assert_eq!(s.distribution, Distribution::Ggx);
        assert_eq!(s.masking, Masking::SmithSeparable);
        assert!(!s.compensation);
        assert!(!s.calibration);
        assert_eq!(
            k.accuracy.to_string(),
            "distribution=ggx,masking=smith-separable,compensation=off,calibration=off"
        );
        let e = "masking=torrance".parse::<Knobs>().unwrap_err().0;
        assert!(e.contains("v-cavity, smith, smith-separable"), "{e}");
        let e = "distribution=phong".parse::<Knobs>().unwrap_err().0;
        assert!(e.contains("blinn, beckmann, ggx"), "{e}");
    }
}
