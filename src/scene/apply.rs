//! Applying accuracy knobs to a compiled scene ([`Scene::set_accuracy`]): the material
//! descriptions are rewritten — the surface's layered materials and the faces of the body's
//! platelets alike — and the effects they call for are recounted, each credited to the element
//! that calls for it (`material "gold" coats[0]`, `body.platelets[0] entry 1 material "copper"
//! coats[0]`) for `lapidary info`.

use super::accuracy::{Accuracy, KnobError};
use super::{Effect, Effects, Scene};
use crate::bsdf::{Model, StackDesc};

/// Which effects a material calls for: the first absorbing coat, and whether the `t` term applies.
pub(crate) fn stack_calls(stack: &StackDesc) -> (Option<usize>, bool) {
    let absorbing = stack
        .coats
        .iter()
        .position(|c| c.thickness > 0.0 && c.absorption.max_channel() > 0.0);
    let t_term = !stack.coats.is_empty()
        && stack.t_term.unwrap_or(matches!(stack.model, Model::Course))
        && !matches!(stack.model, Model::Reference(_));
    (absorbing, t_term)
}

/// Records the effects `stack` calls for after knobs from `by` rewrote it, credited to `element`
/// (e.g. `material "gold"`).
fn record_calls(effects: &mut Effects, element: &str, stack: &StackDesc, by: &str) {
    let (absorbing, t_term) = stack_calls(stack);
    if let Some(i) = absorbing {
        effects.turn_on(Effect::Absorption, format!("{element} coats[{i}]"));
    }
    if t_term {
        effects.turn_on(
            Effect::TTerm,
            format!("{element} ({:#} model, knobs from {by})", stack.model),
        );
    }
}

impl Scene {
    /// Applies accuracy knobs: rewrites the model, Fresnel mode and the other knobs of every
    /// material (the surface's and the platelet faces'), recounts which materials call for
    /// absorption and the `t` term, and forces the chosen effects. `by` names where the knobs
    /// came from (`command line`, `render.accuracy`), for `lapidary info`.
    ///
    /// Every effect can be forced either way since issue 20 (the last slot for later work,
    /// fluorescence, is simulated), so this does not fail today; the `Result` stays for knobs a
    /// scene may refuse.
    pub fn set_accuracy(&mut self, acc: &Accuracy, by: &str) -> Result<(), KnobError> {
        if acc.is_default() {
            return Ok(());
        }
        for stack in &mut self.surface.stacks {
            acc.apply_to(stack);
        }
        if let Some(body) = &mut self.surface.body {
            for (_, stack) in &mut body.platelet_materials {
                acc.apply_to(stack);
            }
            if let Some(c) = acc.compensation {
                body.compensation = c;
            }
        }
        self.effects.clear(Effect::Absorption);
        self.effects.clear(Effect::TTerm);
        for (k, stack) in self.surface.stacks.iter().enumerate() {
            if self.surface.used[k] {
                let element = format!("material \"{}\"", self.surface.names[k]);
                record_calls(&mut self.effects, &element, stack, by);
            }
        }
        // Platelet faces are used when the body is shown and holds platelets.
        if self.effects.called(Effect::Platelets)
            && let Some(body) = &self.surface.body
        {
            for (k, j, name, stack) in body.platelet_entries(self.surface.body_index()) {
                let element = format!("body.platelets[{k}] entry {j} material \"{name}\"");
                record_calls(&mut self.effects, &element, stack, by);
            }
        }
        for &(e, on) in &acc.effects {
            self.effects.force(e, on, by);
            self.accuracy.force(e, on);
        }
        // A light's spectrum calls for spectral transport; rendered in RGB instead, it calls for
        // the prefilter that reduces the materials under it.
        self.effects.clear(Effect::LightPrefilter);
        if !self.effects.on(Effect::Spectral) {
            for (i, l) in self.stage.lights.iter().enumerate() {
                let field = match (&l.line, &l.spectrum) {
                    (Some(_), _) => "line",
                    (None, Some(_)) => "spectrum",
                    (None, None) => continue,
                };
                self.effects.turn_on(
                    Effect::LightPrefilter,
                    format!("stage.lights[{i}].{field} (RGB render: knobs from {by})"),
                );
            }
        }
        // Polarised transport (forced on here) has no manifold walks where their scalar chains
        // would miss the Stokes row (the recipe compiler's rule, `manifold_effect`).
        if self.effects.on(Effect::Polarisation) {
            self.effects.clear(Effect::ManifoldCaustics);
            if self.stage.lights.iter().any(|l| l.polariser.is_some()) {
                self.effects.clear(Effect::ManifoldNee);
            }
        }
        self.accuracy.model = acc.model.or(self.accuracy.model);
        self.accuracy.fresnel = acc.fresnel.or(self.accuracy.fresnel);
        Ok(())
    }
}
