//! [`Knobs`]: an [`Accuracy`] plus the render-level knobs (sampler, depths, the medium's
//! scattering, the manifold walks' effort, the platelets' form), one setting of a
//! `tradeoff` study written `key=value,key=value` (docs/accuracy.md). The material-level part is
//! [`super::accuracy`]'s.

use super::Scene;
use super::accuracy::{Accuracy, KNOB_KEYS, KnobError, parse_switch};
use crate::sampler::SamplerKind;
use std::fmt;

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
    /// Most halvings of a manifold walk's Newton step (`None`: the recipe's).
    pub manifold_halvings: Option<u32>,
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
            "manifold-halvings" | "manifold_halvings" => {
                let max = crate::scene::stage::MAX_MANIFOLD_HALVINGS;
                let h: u32 = value.parse().ok().filter(|h| *h <= max).ok_or_else(|| {
                    KnobError(format!(
                        "manifold-halvings `{value}` is out of range: allowed 0 ..= {max}"
                    ))
                })?;
                self.manifold_halvings = Some(h);
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
        if let Some(h) = self.manifold_halvings {
            scene.stage.render.manifold_halvings = h;
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
        if let Some(h) = self.manifold_halvings {
            parts.push(format!("manifold-halvings={h}"));
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
    use crate::bsdf::{FresnelMode, Model, StackDesc};
    use crate::scene::Effect;

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
        let e = "manifold-halvings=9".parse::<Knobs>().unwrap_err().0;
        assert!(e.contains("0 ..= 8"), "{e}");
        let k: Knobs = "manifold-halvings=0".parse().unwrap();
        assert_eq!(k.manifold_halvings, Some(0));
        assert_eq!(k.to_string(), "manifold-halvings=0");
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
