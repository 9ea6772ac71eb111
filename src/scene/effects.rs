//! The effects set: which optional parts of the simulation a compiled scene needs, and which
//! recipe element turned each one on (docs/design.md §7). The renderer tests a bit per effect and skips the
//! work of every effect that is off; `lapidary info` prints the reasons.

use std::fmt;

/// An optional part of the simulation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Effect {
    /// Absorption in a coat (a varnish with `thickness > 0` and a non-zero absorption or tint).
    Absorption,
    /// The course's internal-reflection `t` term (eq. 3.3) in a layered evaluation.
    TTerm,
    /// Crystal-facet bump: tilted facet normals on Voronoi cells.
    FacetBump,
    /// A sparse map over another (`Overlay`): the glitter map.
    GlitterOverlay,
    /// A `Switch` with a stochastic `blend` band.
    StochasticSwitch,
    /// Light transmitted into a translucent body (refraction in and out, total internal reflection).
    Transmission,
    /// Spectral transport: four wavelengths per path (hero-wavelength sampling), measured spectra,
    /// spectral metals, dispersion (issue 19).
    Spectral,
    /// Fluorescence, course §5.2.2 (issue 20): a used material whose Lambert base fluoresces.
    Fluorescence,
    /// Spectral prefiltering (issue 20; Ward & Eydelberg-Vileshin 2002): an RGB render of a scene
    /// whose lights have a line or a measured spectrum reduces its reflectances and fluorescent
    /// colorants under that light instead of D65 ([`crate::spectrum::prefilter`]).
    LightPrefilter,
    /// Thin-lens depth of field (a camera `aperture > 0`).
    DepthOfField,
    /// Importance sampling of an environment map.
    EnvironmentImportance,
    /// Absorption and scattering in a body's interior (a non-vacuum medium).
    Medium,
    /// Metal platelets suspended in a body (volumetric aventurescence).
    Platelets,
    /// Manifold next-event estimation: light sampled through a smooth boundary from platelets and
    /// medium points inside the stone (Hanika et al. 2015).
    ManifoldNee,
    /// Manifold next-event estimation from the floor through the stone (two refractions): the
    /// caustic a small light throws through a smooth body (Hanika et al. 2015).
    ManifoldCaustics,
    /// Polarised transport ([`crate::polarisation::transport`]): each path carries its sensor's
    /// Stokes row; smooth dielectric boundaries act by Fresnel's Mueller matrices.
    Polarisation,
}

impl Effect {
    /// Every effect, in a fixed order.
    pub const ALL: [Effect; 16] = [
        Effect::Absorption,
        Effect::TTerm,
        Effect::FacetBump,
        Effect::GlitterOverlay,
        Effect::StochasticSwitch,
        Effect::Transmission,
        Effect::Medium,
        Effect::Platelets,
        Effect::ManifoldNee,
        Effect::ManifoldCaustics,
        Effect::Spectral,
        Effect::Fluorescence,
        Effect::LightPrefilter,
        Effect::DepthOfField,
        Effect::EnvironmentImportance,
        Effect::Polarisation,
    ];

    /// Short name, as printed and as used by `--effect` toggles.
    pub fn name(self) -> &'static str {
        match self {
            Effect::Absorption => "absorption",
            Effect::TTerm => "t-term",
            Effect::FacetBump => "facet-bump",
            Effect::GlitterOverlay => "glitter-overlay",
            Effect::StochasticSwitch => "stochastic-switch",
            Effect::Transmission => "transmission",
            Effect::Medium => "medium",
            Effect::Platelets => "platelets",
            Effect::ManifoldNee => "manifold-nee",
            Effect::ManifoldCaustics => "manifold-caustics",
            Effect::Spectral => "spectral",
            Effect::Fluorescence => "fluorescence",
            Effect::DepthOfField => "depth-of-field",
            Effect::EnvironmentImportance => "environment-importance",
            Effect::LightPrefilter => "light-prefilter",
            Effect::Polarisation => "polarisation",
        }
    }

    /// What turns the effect on.
    pub fn trigger(self) -> &'static str {
        match self {
            Effect::Absorption => {
                "a used material with a coat of thickness > 0 and absorption/tint"
            }
            Effect::TTerm => {
                "a used coated material evaluated with the t term (Course model, or t_term: true)"
            }
            Effect::FacetBump => "a Voronoi map with `bump`",
            Effect::GlitterOverlay => "an Overlay node",
            Effect::StochasticSwitch => "a Switch with blend > 0",
            Effect::Transmission => "a recipe `body` that the surface map shows (`Body`)",
            Effect::Medium => "a `body` whose `medium` absorbs or scatters",
            Effect::Platelets => "a `body` with `platelets`",
            Effect::ManifoldNee => {
                "a smooth `body` boundary around platelets or a scattering medium, under an area light"
            }
            Effect::ManifoldCaustics => {
                "a smooth `body` boundary on a stage with a floor, under an area light"
            }
            Effect::Spectral => {
                "a dispersive `body` IOR (Cauchy, Sellmeier or Abbe number), a measured medium or \
                 light spectrum, or `--spectral`"
            }
            Effect::Fluorescence => "a used material whose Lambert base has `fluorescence`",
            Effect::DepthOfField => "a perspective camera with aperture > 0",
            Effect::EnvironmentImportance => "an environment Map (EXR)",
            Effect::Polarisation => {
                "a light with a `polariser`, a stage `analyser` (the `Polariscope` and \
                 `Dichroscope` presets), a doubly refractive `body.crystal`, `--stokes`, or \
                 `--polarised`"
            }
            Effect::LightPrefilter => {
                "an RGB render (`--spectral off`) of a stage whose lights have a `line` or a \
                 measured `spectrum`"
            }
        }
    }

    fn bit(self) -> u32 {
        1 << self as u8
    }
}

impl fmt::Display for Effect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The effects a scene needs, each with the first recipe element that turned it on and how many
/// elements call for it; and the effects whose code is forced on or off (an accuracy knob, or a
/// check that code for an effect the scene does not call for changes nothing).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Effects {
    bits: u32,
    reasons: Vec<(Effect, String, usize)>,
    /// Forced effects: the forced state and who forced it (e.g. `--bump off`).
    forced: Vec<(Effect, bool, String)>,
}

impl Effects {
    /// Records that `element` (e.g. `material "glitter_1" coats[0]`) calls for `effect`.
    pub fn turn_on(&mut self, effect: Effect, element: impl Into<String>) {
        self.bits |= effect.bit();
        match self.reasons.iter_mut().find(|(e, _, _)| *e == effect) {
            Some((_, _, n)) => *n += 1,
            None => self.reasons.push((effect, element.into(), 1)),
        }
    }

    /// Whether `effect`'s code runs: its forced state if forced, else whether the scene calls for
    /// it.
    #[inline]
    pub fn on(&self, effect: Effect) -> bool {
        match self.forced(effect) {
            Some(on) => on,
            None => self.called(effect),
        }
    }

    /// Whether something in the scene calls for `effect` (forcing aside).
    #[inline]
    pub fn called(&self, effect: Effect) -> bool {
        self.bits & effect.bit() != 0
    }

    /// Forces `effect`'s code on or off; `by` names who did (a flag or a recipe field). Only
    /// [`super::Scene::set_accuracy`] calls it: knobs reach a scene as an [`super::Accuracy`].
    pub(super) fn force(&mut self, effect: Effect, on: bool, by: impl Into<String>) {
        self.forced.retain(|(e, _, _)| *e != effect);
        self.forced.push((effect, on, by.into()));
    }

    /// The forced state of `effect`, if it is forced.
    pub fn forced(&self, effect: Effect) -> Option<bool> {
        self.forced
            .iter()
            .find(|(e, _, _)| *e == effect)
            .map(|(_, on, _)| *on)
    }

    /// Who forced `effect`, if anyone.
    pub fn forced_by(&self, effect: Effect) -> Option<&str> {
        self.forced
            .iter()
            .find(|(e, _, _)| *e == effect)
            .map(|(_, _, by)| by.as_str())
    }

    /// Forgets that anything calls for `effect` (used when a knob rewrites the materials and
    /// their effects are recounted).
    pub(crate) fn clear(&mut self, effect: Effect) {
        self.bits &= !effect.bit();
        self.reasons.retain(|(e, _, _)| *e != effect);
    }

    /// The first element that turned `effect` on and the number of elements that call for it.
    pub fn reason(&self, effect: Effect) -> Option<(&str, usize)> {
        self.reasons
            .iter()
            .find(|(e, _, _)| *e == effect)
            .map(|(_, s, n)| (s.as_str(), *n))
    }

    /// The effects whose code runs ([`on`](Self::on)), in [`Effect::ALL`] order.
    pub fn iter(&self) -> impl Iterator<Item = Effect> + '_ {
        Effect::ALL.into_iter().filter(|e| self.on(*e))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bits_and_reasons() {
        let mut fx = Effects::default();
        assert!(Effect::ALL.iter().all(|e| !fx.on(*e)));
        fx.turn_on(Effect::FacetBump, "surface.over.bump");
        fx.turn_on(Effect::FacetBump, "maps.\"x\".bump");
        fx.turn_on(Effect::Absorption, "material \"a\" coats[0]");
        assert!(fx.on(Effect::FacetBump) && fx.on(Effect::Absorption) && !fx.on(Effect::TTerm));
        assert_eq!(fx.reason(Effect::FacetBump), Some(("surface.over.bump", 2)));
        assert_eq!(
            fx.iter().collect::<Vec<_>>(),
            [Effect::Absorption, Effect::FacetBump]
        );
        let names: std::collections::HashSet<_> = Effect::ALL.iter().map(|e| e.name()).collect();
        assert_eq!(names.len(), Effect::ALL.len());
    }
}
