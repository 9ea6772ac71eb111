//! The accuracy knobs on the command line (shared by `render` and `tradeoff`): `--model`,
//! `--fresnel`, `--t-term`, `--absorption`, `--bump` and `--effect NAME=on|off`. They override the
//! recipe's `render.accuracy` and every material's own choice ([`crate::scene::accuracy`]).

use crate::bsdf::{FresnelMode, Model};
use crate::scene::accuracy::{effect_named, parse_fresnel, parse_model, parse_switch};
use crate::scene::{Accuracy, Effect, KnobError, Scene};
use clap::Args;

/// Accuracy knobs.
#[derive(Debug, Clone, Default, Args)]
pub struct KnobArgs {
    /// Evaluation model of every material: course, corrected or reference.
    #[arg(long, value_parser = model_arg)]
    pub model: Option<Model>,
    /// Fresnel evaluation of every material: exact, schlick, lazanyi or table.
    #[arg(long, value_parser = fresnel_arg)]
    pub fresnel: Option<FresnelMode>,
    /// The course's `t` term for every coated material: on or off.
    #[arg(long, value_parser = switch_arg)]
    pub t_term: Option<bool>,
    /// Coat absorption: on or off.
    #[arg(long, value_parser = switch_arg)]
    pub absorption: Option<bool>,
    /// Crystal-facet bump: on or off.
    #[arg(long, value_parser = switch_arg)]
    pub bump: Option<bool>,
    /// Force any effect's code on or off, e.g. `--effect depth-of-field=off` (repeatable;
    /// `lapidary info` lists the effects).
    #[arg(long = "effect", value_parser = effect_arg)]
    pub effects: Vec<(Effect, bool)>,
}

impl KnobArgs {
    /// The knobs given, as an [`Accuracy`].
    pub fn accuracy(&self) -> Accuracy {
        let mut acc = Accuracy {
            model: self.model,
            fresnel: self.fresnel,
            effects: vec![],
        };
        for (e, on) in [
            (Effect::TTerm, self.t_term),
            (Effect::Absorption, self.absorption),
            (Effect::FacetBump, self.bump),
        ] {
            if let Some(on) = on {
                acc.force(e, on);
            }
        }
        for &(e, on) in &self.effects {
            acc.force(e, on);
        }
        acc
    }

    /// Applies the knobs to `scene` (credited to the command line).
    pub fn apply(&self, scene: &mut Scene) -> Result<(), KnobError> {
        scene.set_accuracy(&self.accuracy(), "command line")
    }
}

fn model_arg(s: &str) -> Result<Model, String> {
    parse_model(s).map_err(|e| e.0)
}

fn fresnel_arg(s: &str) -> Result<FresnelMode, String> {
    parse_fresnel(s).map_err(|e| e.0)
}

fn switch_arg(s: &str) -> Result<bool, String> {
    parse_switch("value", s).map_err(|e| e.0)
}

fn effect_arg(s: &str) -> Result<(Effect, bool), String> {
    let names = || {
        Effect::ALL
            .iter()
            .map(|e| e.name())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let (name, value) = s
        .split_once('=')
        .ok_or_else(|| format!("`{s}` is not NAME=on|off (effects: {})", names()))?;
    let e = effect_named(name.trim())
        .ok_or_else(|| format!("unknown effect `{name}`: allowed {}", names()))?;
    Ok((e, switch_arg(value.trim())?))
}

/// Which knob a setting's key names: `model`, `fresnel`, `sampler`, `max-depth` (also written
/// `max_depth`) or an effect (under any of its names); `None` for an unknown key, which the
/// setting's parser reports.
fn knob_of(key: &str) -> Option<String> {
    match key {
        "model" | "fresnel" | "sampler" => Some(key.into()),
        "max-depth" | "max_depth" => Some("max-depth".into()),
        _ => effect_named(key).map(|e| e.name().to_string()),
    }
}

/// Checks the form of a `tradeoff --setting` before anything renders: not empty (the recipe as
/// written is `baseline`), no empty item between commas, and no knob named twice (such as
/// `model=course,model=reference`, or `bump=off,facet-bump=on`, two names of one knob). The
/// values are checked by the setting's parser.
pub fn check_setting(setting: &str) -> Result<(), String> {
    if setting.trim().is_empty() {
        return Err(
            "an empty setting; write `baseline` for the recipe as written, or \
                    key=value,… (e.g. model=course,fresnel=table)"
                .into(),
        );
    }
    let mut seen: Vec<(String, &str)> = vec![];
    for part in setting.split(',').map(str::trim) {
        if part.is_empty() {
            return Err("an empty item between commas; write key=value,key=value".into());
        }
        let key = part.split_once('=').map_or(part, |(k, _)| k).trim();
        let Some(knob) = knob_of(key) else { continue };
        if let Some((_, first)) = seen.iter().find(|(k, _)| *k == knob) {
            return Err(format!(
                "names the knob `{knob}` twice (`{first}` and `{part}`); give each knob once, \
                 or use two --setting options to compare the values"
            ));
        }
        seen.push((knob, part));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arguments_become_knobs() {
        let k = KnobArgs {
            model: Some(Model::Course),
            bump: Some(false),
            effects: vec![effect_arg("depth-of-field=on").unwrap()],
            ..KnobArgs::default()
        };
        assert_eq!(
            k.accuracy().to_string(),
            "model=course,bump=off,depth-of-field=on"
        );
        assert!(effect_arg("sparkle=on").unwrap_err().contains("facet-bump"));
        assert!(
            effect_arg("absorption")
                .unwrap_err()
                .contains("NAME=on|off")
        );
        assert!(switch_arg("maybe").unwrap_err().contains("on, off"));
    }

    #[test]
    fn settings_are_checked_for_form() {
        for ok in [
            "baseline",
            "model=course",
            "model=course, fresnel=table",
            "max-depth=4",
        ] {
            assert_eq!(check_setting(ok), Ok(()), "{ok}");
        }
        assert!(check_setting("").unwrap_err().contains("empty setting"));
        assert!(check_setting("  ").unwrap_err().contains("empty setting"));
        assert!(
            check_setting("model=course,")
                .unwrap_err()
                .contains("empty item")
        );
        let e = check_setting("model=course,model=reference").unwrap_err();
        assert!(
            e.contains("`model` twice") && e.contains("model=reference"),
            "{e}"
        );
        let e = check_setting("max_depth=2,max-depth=4").unwrap_err();
        assert!(e.contains("`max-depth` twice"), "{e}");
        let e = check_setting("bump=off,facet-bump=on").unwrap_err();
        assert!(e.contains("twice"), "{e}");
    }
}
