//! The accuracy knobs on the command line (shared by `render`, `info` and `tradeoff`): `--model`,
//! `--fresnel`, `--effect NAME=on|off` and the aliases `--t-term`, `--absorption` and `--bump`.
//! [`KnobArgs::accuracy`] turns them, once, into the one knob type, an [`Accuracy`]; the loading
//! path ([`super::load`]) applies it to the compiled scene with [`crate::scene::Scene::set_accuracy`],
//! over the recipe's `render.accuracy` and every material's own choice
//! ([`crate::scene::accuracy`] says which stage resolves what).

use crate::bsdf::{Distribution, FresnelMode, Masking, Model};
use crate::scene::accuracy::{effect_named, parse_fresnel, parse_model, parse_switch};
use crate::scene::{Accuracy, Effect};
use clap::Args;

/// Accuracy knobs as written on the command line. Only [`KnobArgs::accuracy`] reads them.
///
/// `--t-term V`, `--absorption V` and `--bump V` are aliases: each makes the same entry as
/// `--effect t-term=V`, `--effect absorption=V` and `--effect facet-bump=V`. When an effect is
/// given both ways, the `--effect` form wins.
#[derive(Debug, Clone, Default, Args)]
pub struct KnobArgs {
    /// Evaluation model of every material: course, corrected or reference.
    #[arg(long, value_parser = model_arg)]
    model: Option<Model>,
    /// Fresnel evaluation of every material: exact, schlick, lazanyi or table.
    #[arg(long, value_parser = fresnel_arg)]
    fresnel: Option<FresnelMode>,
    /// Micro-facet distribution of every material: blinn, beckmann or ggx.
    #[arg(long, value_parser = |s: &str| s.parse::<Distribution>().map_err(|e| e.to_string()))]
    distribution: Option<Distribution>,
    /// Masking–shadowing of every material: v-cavity, smith or smith-separable.
    #[arg(long, value_parser = |s: &str| s.parse::<Masking>().map_err(|e| e.to_string()))]
    masking: Option<Masking>,
    /// Multiple-scattering compensation of every material: on or off.
    #[arg(long, value_parser = switch_arg)]
    compensation: Option<bool>,
    /// The Corrected model's albedo calibration of every material: on or off.
    #[arg(long, value_parser = switch_arg)]
    calibration: Option<bool>,
    /// The course's `t` term for every coated material: on or off (same as
    /// `--effect t-term=…`).
    #[arg(long, value_parser = |s: &str| alias_arg(Effect::TTerm, s))]
    t_term: Option<(Effect, bool)>,
    /// Coat absorption: on or off (same as `--effect absorption=…`).
    #[arg(long, value_parser = |s: &str| alias_arg(Effect::Absorption, s))]
    absorption: Option<(Effect, bool)>,
    /// Crystal-facet bump: on or off (same as `--effect facet-bump=…`).
    #[arg(long, value_parser = |s: &str| alias_arg(Effect::FacetBump, s))]
    bump: Option<(Effect, bool)>,
    /// Spectral transport (four wavelengths per path) for a scene that does not call for it, or
    /// RGB for one that does: `--spectral` alone is `on` (same as `--effect spectral=…`).
    #[arg(long, num_args = 0..=1, default_missing_value = "on",
          value_parser = |s: &str| alias_arg(Effect::Spectral, s))]
    spectral: Option<(Effect, bool)>,
    /// Polarised transport (each path carries its sensor's Stokes row; smooth dielectric
    /// boundaries act by Fresnel's Mueller matrices) for a scene without a polariser, or
    /// `off` to ignore the stage's polarisers: `--polarised` alone is `on` (same as
    /// `--effect polarisation=…`).
    #[arg(long, num_args = 0..=1, default_missing_value = "on",
          value_parser = |s: &str| alias_arg(Effect::Polarisation, s))]
    polarised: Option<(Effect, bool)>,
    /// Force any effect's code on or off, e.g. `--effect depth-of-field=off` (repeatable;
    /// `lapidary info` lists the effects).
    #[arg(long = "effect", value_parser = effect_arg)]
    effects: Vec<(Effect, bool)>,
}

impl KnobArgs {
    /// The knobs given, as the one knob type: the model and Fresnel mode, then the forced
    /// effects (the aliases first, then every `--effect` in order). An effect given twice with
    /// the same value is one entry; given `on` and `off` (`--effect spectral=on --spectral off`,
    /// `--bump on --effect facet-bump=off`, `--effect X=on --effect X=off`) it is refused, naming
    /// both flags: the command line never resolves a contradiction silently.
    pub fn accuracy(&self) -> Result<Accuracy, String> {
        let mut acc = Accuracy {
            model: self.model,
            fresnel: self.fresnel,
            distribution: self.distribution,
            masking: self.masking,
            compensation: self.compensation,
            calibration: self.calibration,
            effects: vec![],
        };
        let aliases = [
            ("t-term", self.t_term),
            ("absorption", self.absorption),
            ("bump", self.bump),
            ("spectral", self.spectral),
            ("polarised", self.polarised),
        ];
        let onoff = |on: bool| if on { "on" } else { "off" };
        let given = aliases
            .into_iter()
            .filter_map(|(flag, v)| v.map(|(e, on)| (format!("--{flag} {}", onoff(on)), e, on)))
            .chain(
                self.effects
                    .iter()
                    .map(|&(e, on)| (format!("--effect {}={}", e.name(), onoff(on)), e, on)),
            );
        let mut seen: Vec<(String, Effect, bool)> = vec![];
        for (flag, e, on) in given {
            if let Some((first, _, _)) = seen.iter().find(|(_, f, v)| *f == e && *v != on) {
                return Err(format!(
                    "`{flag}` contradicts `{first}`: the effect `{}` can be forced only one way",
                    e.name()
                ));
            }
            acc.force(e, on);
            seen.push((flag, e, on));
        }
        Ok(acc)
    }
}

fn model_arg(s: &str) -> Result<Model, String> {
    parse_model(s).map_err(|e| e.0)
}

fn fresnel_arg(s: &str) -> Result<FresnelMode, String> {
    parse_fresnel(s).map_err(|e| e.0)
}

pub(crate) fn switch_arg(s: &str) -> Result<bool, String> {
    parse_switch("value", s).map_err(|e| e.0)
}

/// The value of an alias flag (`--bump off`) as the entry `--effect` makes.
fn alias_arg(effect: Effect, s: &str) -> Result<(Effect, bool), String> {
    Ok((effect, switch_arg(s)?))
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
        "medium-depth" | "medium_depth" => Some("medium-depth".into()),
        "medium-scattering" | "medium_scattering" => Some("medium-scattering".into()),
        "manifold-continuation" | "manifold_continuation" => Some("manifold-continuation".into()),
        "manifold-halvings" | "manifold_halvings" => Some("manifold-halvings".into()),
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

/// `acc` with polarised transport forced on when `stokes` (`--stokes` of `render` and
/// `preview`: the Stokes AOVs are measured by polarised transport); an error when the knobs turn
/// it off.
pub fn with_stokes(mut acc: Accuracy, stokes: bool) -> anyhow::Result<Accuracy> {
    use crate::scene::Effect;
    if stokes {
        if acc.forced(Effect::Polarisation) == Some(false) {
            anyhow::bail!(
                "--stokes contradicts --polarised off: the Stokes AOVs are measured by polarised \
                 transport"
            );
        }
        acc.force(Effect::Polarisation, true);
    }
    Ok(acc)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arguments_become_knobs() {
        let k = KnobArgs {
            model: Some(Model::Course),
            bump: Some(alias_arg(Effect::FacetBump, "off").unwrap()),
            effects: vec![effect_arg("depth-of-field=on").unwrap()],
            ..KnobArgs::default()
        };
        assert_eq!(
            k.accuracy().unwrap().to_string(),
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
    fn aliases_make_the_entries_of_effect() {
        use clap::Parser;
        #[derive(Parser)]
        struct Cli {
            #[command(flatten)]
            knobs: KnobArgs,
        }
        let parse = |args: &[&str]| {
            let argv = std::iter::once("lapidary").chain(args.iter().copied());
            Cli::try_parse_from(argv).unwrap().knobs.accuracy()
        };
        for (alias, effect) in [
            (["--bump", "off"], "facet-bump=off"),
            (["--t-term", "on"], "t-term=on"),
            (["--absorption", "off"], "absorption=off"),
        ] {
            assert_eq!(parse(&alias), parse(&["--effect", effect]), "{alias:?}");
        }
        // Both ways with one value: one entry.
        let both = parse(&["--effect", "facet-bump=off", "--bump", "off"]).unwrap();
        assert_eq!(both.forced(Effect::FacetBump), Some(false));
        assert_eq!(both.effects.len(), 1);
        let acc = parse(&["--model", "Reference", "--fresnel", "table"]).unwrap();
        assert_eq!(acc.to_string(), "model=reference,fresnel=table");
        assert!(Cli::try_parse_from(["lapidary", "--model", "fast"]).is_err());
        assert!(
            Cli::try_parse_from(["lapidary", "--model", "course", "--model", "course"]).is_err()
        );
    }

    #[test]
    fn contradictions_are_refused_naming_both_flags() {
        use clap::Parser;
        #[derive(Parser)]
        struct Cli {
            #[command(flatten)]
            knobs: KnobArgs,
        }
        let parse = |args: &[&str]| {
            let argv = std::iter::once("lapidary").chain(args.iter().copied());
            Cli::try_parse_from(argv).unwrap().knobs.accuracy()
        };
        for (args, first, second) in [
            (
                &["--effect", "spectral=on", "--spectral", "off"][..],
                "--spectral off",
                "--effect spectral=on",
            ),
            (
                &["--effect", "medium=on", "--effect", "medium=off"][..],
                "--effect medium=on",
                "--effect medium=off",
            ),
            (
                &["--bump", "on", "--effect", "facet-bump=off"][..],
                "--bump on",
                "--effect facet-bump=off",
            ),
            (
                &["--spectral", "--effect", "spectral=off"][..],
                "--spectral on",
                "spectral=off",
            ),
        ] {
            let e = parse(args).unwrap_err();
            assert!(e.contains(first) && e.contains(second), "{args:?}: {e}");
        }
        // The same value twice is not a contradiction.
        let same = parse(&["--effect", "medium=off", "--effect", "medium=off"]).unwrap();
        assert_eq!(same.effects.len(), 1);
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
