//! Compiles the recipe's translucent `body` (`body: (ior: …)`, [`super::body`]): its index and
//! dispersion law, boundary, medium, platelets ([`super::platelet_compiler`]) and crystal, with
//! the errors at their positions and the effects the body calls for when the surface shows it —
//! transmission, the medium, polarisation, spectral transport, the manifold walks.

use super::RecipeError;
use super::map_compiler::Compiler;
use crate::scene::{Body, Effect, Interior};

impl Compiler<'_> {
    /// The recipe's `body`, checked (errors recorded), and the effects it calls for when the
    /// surface shows it.
    pub(super) fn body(
        &mut self,
        shown: bool,
        body_index: u32,
        warnings: &mut Vec<RecipeError>,
    ) -> Option<Body> {
        let r = self.recipe;
        let desc = r.content.body.as_ref()?;
        let at = r.source.find(&["body", ":"]);
        let e = r.source.error(at, "");
        let place = format!("body ({}:{})", e.file, e.line);
        let alpha = match desc.alpha() {
            Ok(a) => a,
            Err(m) => {
                self.errors.push(r.source.error(at, m));
                return None;
            }
        };
        let dispersion = match desc.ior_law() {
            Ok(d) => d,
            Err(m) => {
                let at = r
                    .source
                    .find_from(at.unwrap_or(0), &["dispersion", ":"])
                    .or(at);
                self.errors.push(r.source.error(at, m));
                return None;
            }
        };
        let medium = match &desc.medium {
            None => None,
            Some(m) => match m.measured_coefficients() {
                Ok(c) => Some(Interior {
                    sigma_a: c.sigma_a,
                    sigma_s: c.sigma_s,
                    g: m.phase.g(),
                    sigma_a_measured: c.sigma_a_measured,
                    sigma_s_measured: c.sigma_s_measured,
                }),
                Err(msg) => {
                    let at = r.source.find_from(at.unwrap_or(0), &["medium", ":"]).or(at);
                    self.errors.push(r.source.error(at, format!("body.{msg}")));
                    return None;
                }
            },
        };
        let (platelets, platelet_materials) = self.platelets(desc, body_index, at.unwrap_or(0))?;
        let crystal = match desc
            .crystal
            .as_ref()
            .map(|c| c.compile(desc.ior, dispersion))
        {
            None => None,
            Some(Ok(c)) => Some(c),
            Some(Err((key, m))) => {
                let pos = r.source.find_from(at.unwrap_or(0), &[key, ":"]).or(at);
                self.errors.push(r.source.error(pos, m));
                return None;
            }
        };
        let body = Body {
            ior: desc.ior,
            dispersion,
            alpha,
            distribution: desc.distribution,
            masking: desc.masking,
            compensation: desc.compensation,
            medium,
            platelets,
            platelet_materials,
            crystal,
        };
        if body.crystal.is_some() && alpha > 0.0 {
            let at = r
                .source
                .find_from(at.unwrap_or(0), &["crystal", ":"])
                .or(at);
            self.errors.push(r.source.error(
                at,
                "body.crystal: a doubly refractive body needs a smooth boundary (remove \
                 `roughness`/`alpha`)",
            ));
            return None;
        }
        if shown {
            self.effects.turn_on(Effect::Transmission, place.clone());
            // Each effect is named by the body's key that calls for it, at that key's line.
            let place = |keys: &[&str], name: &str| {
                let e = r
                    .source
                    .error(r.source.find_from(at.unwrap_or(0), keys).or(at), "");
                format!("body.{name} ({}:{})", e.file, e.line)
            };
            if body.crystal.is_some() {
                let p = place(&["crystal", ":"], "crystal");
                self.effects.turn_on(Effect::Polarisation, p);
            }
            if body.crystal.is_some_and(|c| c.thin_nm.is_some()) {
                let p = place(&["thin_section", ":"], "crystal.thin_section");
                self.effects.turn_on(Effect::Spectral, p);
            }
            if body
                .crystal
                .is_some_and(|c| c.sigma_measured.iter().any(Option::is_some))
            {
                let p = place(&["pleochroism", ":"], "crystal.pleochroism");
                self.effects.turn_on(Effect::Spectral, p);
            }
            if let Some(key) = desc.crystal.as_ref().and_then(|c| c.own_dispersion()) {
                let p = place(&[key, ":"], &format!("crystal.{key}"));
                self.effects.turn_on(Effect::Spectral, p);
            }
            if body.dispersion.is_some() {
                let p = place(&["dispersion", ":"], "dispersion");
                self.effects.turn_on(Effect::Spectral, p);
            }
            for (key, given) in [
                (
                    "absorption_spectrum",
                    body.medium.is_some_and(|m| m.sigma_a_measured.is_some()),
                ),
                (
                    "scattering_spectrum",
                    body.medium.is_some_and(|m| m.sigma_s_measured.is_some()),
                ),
            ] {
                if given {
                    let p = place(&[key, ":"], &format!("medium.{key}"));
                    self.effects.turn_on(Effect::Spectral, p);
                }
            }
            if !body.platelets.is_empty() {
                let p = place(&["platelets", ":"], "platelets");
                self.effects.turn_on(Effect::Platelets, p);
                for (k, j, name, stack) in body.platelet_entries(body_index) {
                    let element = format!("body.platelets[{k}] entry {j} material \"{name}\"");
                    self.stack_effects(&element, name, stack);
                }
            }
            if body.has_medium() {
                let p = place(&["medium", ":"], "medium");
                self.effects.turn_on(Effect::Medium, p);
            }
        } else {
            warnings.push(r.source.error(
                at,
                "the recipe has a `body` but the surface never shows it (`Body`): the stone is \
                 opaque",
            ));
        }
        Some(body)
    }

    /// Turns on manifold next-event estimation (docs/platelets.md) where it can help: a body the surface
    /// shows, with a smooth boundary (the walk solves Snell's law at a specular interface), under
    /// at least one emitting area light (the walk connects to points on lights) — from inside
    /// (`manifold-nee`) where the body holds platelets or a scattering medium (vertices inside
    /// that scatter light), through the stone (`manifold-caustics`) where a floor receives its
    /// caustic. Not for a dispersive body: the walks solve Snell's law with one index, and a
    /// spectral path refracts each wavelength its own way (there light is found by BSDF sampling).
    /// Nor for a doubly refractive body, whose boundary splits light into two waves the walk
    /// does not follow; and in polarised transport, whose Stokes rows the walks' scalar chains
    /// do not carry, neither the caustics nor, under a polarised light, the walks from inside.
    pub(super) fn manifold_effect(&mut self, body: &Body, stage: &crate::scene::stage::Stage) {
        if body.dispersion.is_some() || body.crystal.is_some() {
            return;
        }
        let polarised = self.effects.called(Effect::Polarisation);
        let polarised_light = stage.lights.iter().any(|l| l.polariser.is_some());
        let r = self.recipe;
        let scatters_inside = !body.platelets.is_empty()
            || body.medium.is_some_and(|m| m.sigma_s.max_channel() > 0.0);
        let lit = stage.lights.iter().any(|l| l.radiance.max_channel() > 0.0);
        if self.effects.called(Effect::Transmission)
            && body.alpha == 0.0
            && scatters_inside
            && lit
            && !(polarised && polarised_light)
        {
            let at = r.source.find(&["body", ":"]);
            let e = r.source.error(at, "");
            self.effects.turn_on(
                Effect::ManifoldNee,
                format!(
                    "body ({}:{}): a smooth boundary around {}, under {} area light(s)",
                    e.file,
                    e.line,
                    if body.platelets.is_empty() {
                        "a scattering medium"
                    } else {
                        "platelets"
                    },
                    stage.lights.len()
                ),
            );
        }
        if self.effects.called(Effect::Transmission)
            && body.alpha == 0.0
            && lit
            && !polarised
            && let Some(g) = stage
                .ground
                .as_ref()
                .filter(|g| g.albedo.max_channel() > 0.0)
        {
            let at = r.source.find(&["body", ":"]);
            let e = r.source.error(at, "");
            self.effects.turn_on(
                Effect::ManifoldCaustics,
                format!(
                    "body ({}:{}): a smooth boundary over the stage's floor (y = {}), under {} area \
                     light(s)",
                    e.file,
                    e.line,
                    g.height,
                    stage.lights.len()
                ),
            );
        }
    }
}
