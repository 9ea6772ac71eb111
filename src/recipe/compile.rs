//! Compiles a parsed [`GemRecipe`] into a runtime [`Scene`]: the material table, the flat map
//! tree, the resolved stage and the effects set. Errors are collected, not returned at the first:
//! an unknown name is reported and compilation goes on with a stand-in, so one run of
//! `lapidary check` lists every problem it can find. The map tree itself is compiled in
//! [`super::map_compiler`].

use super::RecipeError;
use super::gem::GemRecipe;
use super::map_compiler::{BODY_LEAF, Compiler};
use super::source::Source;
use crate::bsdf::StackDesc;
use crate::sampler::hash_words;
use crate::scene::{Accuracy, Effect, Scene, Surface, accuracy};
use crate::texture::{Map, MapNode};
use std::collections::HashSet;
use std::path::Path;

/// Everything `lapidary check` learns about a file: every error found, warnings, and the compiled
/// scene when there were no errors.
#[derive(Debug, Default)]
pub struct Report {
    /// Errors, in the order found.
    pub errors: Vec<RecipeError>,
    /// Things that are allowed but probably unintended (unused materials).
    pub warnings: Vec<RecipeError>,
    /// The compiled scene (when `errors` is empty).
    pub scene: Option<Scene>,
}

impl GemRecipe {
    /// Checks a file completely: syntax, includes, every material, the whole tree, the stage;
    /// reports every error it can find. The parser goes on past a value it refuses (a number out
    /// of range: recorded with its position, a stand-in read in its place; see
    /// [`super::source::recover`]), so the checks after parsing run too; it stops at a syntax
    /// error, an unknown field or a value of the wrong kind, and then only its errors are
    /// reported.
    pub fn check(path: &Path) -> Report {
        match Source::read(path) {
            Ok(source) => Self::check_source(source, Some(path)),
            Err(e) => Report {
                errors: vec![e],
                ..Report::default()
            },
        }
    }

    /// [`GemRecipe::check`] over text already in memory.
    pub fn check_source(source: Source, path: Option<&Path>) -> Report {
        let (recipe, mut errors) = Self::read(source, path);
        let Some(recipe) = recipe else {
            return Report {
                errors,
                ..Report::default()
            };
        };
        let mut warnings = vec![];
        let scene = recipe.compile_into(&mut errors, &mut warnings);
        Report {
            scene: if errors.is_empty() { scene } else { None },
            errors,
            warnings,
        }
    }

    /// Compiles materials, map tree, stage and effects into a runtime scene; the first error.
    pub fn compile(&self) -> Result<Scene, RecipeError> {
        let mut errors = vec![];
        let scene = self.compile_into(&mut errors, &mut vec![]);
        match errors.into_iter().next() {
            Some(e) => Err(e),
            None => Ok(scene.expect("no errors means a scene")),
        }
    }

    fn compile_into(
        &self,
        errors: &mut Vec<RecipeError>,
        warnings: &mut Vec<RecipeError>,
    ) -> Option<Scene> {
        let scene = Compiler::new(self).run(errors, warnings);
        if let Some(scene) = &scene {
            for name in scene.surface.unused() {
                warnings.push(self.source.error(
                    self.source.key(name),
                    format!("material \"{name}\" is defined but the surface never uses it"),
                ));
            }
        }
        scene
    }
}

impl Compiler<'_> {
    /// Compiles everything, appending errors to `errors`; the scene when none were found.
    pub(super) fn run(
        mut self,
        errors: &mut Vec<RecipeError>,
        warnings: &mut Vec<RecipeError>,
    ) -> Option<Scene> {
        let r = self.recipe;
        let own = r.content.materials.len();
        let root = self.node(&r.content.surface, "surface");
        // Named maps the tree never reaches are still checked (in one scratch compiler, so the
        // scene's tables and default seeds are those of the tree alone; each map is compiled
        // once however many unused maps use it), and reported unused.
        let mut scratch: Option<Compiler> = None;
        for (name, sub) in &r.content.maps {
            if self.named.contains_key(name) {
                continue;
            }
            let scratch = scratch.get_or_insert_with(|| {
                let mut c = Compiler::new(r);
                c.named = self.named.clone();
                c.reported = self.reported.clone();
                c
            });
            if !scratch.named.contains_key(name) {
                scratch.named.insert(name.clone(), None);
                let id = scratch.node(sub, &format!("maps.{name:?}"));
                scratch.named.insert(name.clone(), Some(id));
            }
            warnings.push(r.source.error(
                r.source.key(name),
                format!("map \"{name}\" is defined but the surface never uses it"),
            ));
        }
        if let Some(scratch) = scratch {
            let seen: HashSet<String> = self.errors.iter().map(|e| e.to_string()).collect();
            self.errors.extend(
                scratch
                    .errors
                    .into_iter()
                    .filter(|e| !seen.contains(&e.to_string())),
            );
        }
        let mut used = vec![false; self.materials.len()];
        let mut map_labels = std::mem::take(&mut self.labels);
        let (mut nodes, entries, stops, fields) = (
            std::mem::take(&mut self.nodes),
            std::mem::take(&mut self.entries),
            std::mem::take(&mut self.stops),
            std::mem::take(&mut self.fields),
        );
        // `Body` leaves point one past the material table.
        let body_index = self.materials.len() as u32;
        let mut body_shown = false;
        for n in &mut nodes {
            if *n == MapNode::Material(BODY_LEAF) {
                *n = MapNode::Material(body_index);
                body_shown = true;
            }
        }
        let body = self.body(body_shown, body_index, warnings);
        for n in &nodes {
            // Stand-ins for unknown names point at material 0, which need not exist.
            if let MapNode::Material(m) = n
                && let Some(u) = used.get_mut(*m as usize)
            {
                *u = true;
            }
        }
        map_labels.resize(nodes.len(), String::new());
        let map = match Map::new(nodes, entries, stops, fields, root) {
            Ok(map) => Some(map),
            Err(e) => {
                if self.errors.is_empty() {
                    let at = r.source.find(&["surface", ":"]);
                    self.errors
                        .push(r.source.error(at, format!("surface: {e}")));
                }
                None
            }
        };
        let mut names = Vec::with_capacity(self.materials.len());
        let mut stacks = Vec::with_capacity(self.materials.len());
        let table: Vec<(usize, u32)> = self.materials.iter().map(|(a, b)| (*a, *b)).collect();
        for (lib_index, surface_index) in table {
            let name = r
                .library
                .name_at(lib_index)
                .expect("indices come from the library")
                .to_string();
            debug_assert_eq!(surface_index as usize, names.len());
            // Errors in materials were reported when the library was read.
            if let Ok(stack) = r.library.stack(&name) {
                if used[surface_index as usize] {
                    self.stack_effects(&format!("material \"{name}\""), &name, &stack);
                }
                stacks.push(stack);
            }
            names.push(name);
        }
        let stage = super::resolve::stage(r, &mut self.effects, &mut self.errors);
        if let (Some(b), Some(st)) = (&body, &stage) {
            self.manifold_effect(b, st);
        }
        if let (Some(b), Some(s)) = (&body, &stage)
            && body_shown
        {
            self.check_platelet_span(b, s);
        }
        let accuracy = self.accuracy();
        let hash = recipe_hash(r);
        let ok = self.errors.is_empty() && stacks.len() == names.len();
        errors.append(&mut self.errors);
        let (map, stage) = (map?, stage?);
        let mut scene = ok.then(|| Scene {
            surface: Surface {
                names,
                stacks,
                map,
                map_labels,
                used: used
                    .iter()
                    .enumerate()
                    .map(|(i, u)| *u || i >= own)
                    .collect(),
                body,
            },
            stage,
            effects: self.effects,
            accuracy: Accuracy::default(),
            hash,
        })?;
        if let Some((accuracy, by)) = accuracy
            && let Err(e) = scene.set_accuracy(&accuracy, &by)
        {
            let at = r.source.find(&["accuracy", ":"]);
            errors.push(r.source.error(at, format!("stage.render.accuracy: {e}")));
            return None;
        }
        Some(scene)
    }

    /// The recipe's `stage.render.accuracy`, checked, and where it is written; errors are
    /// recorded.
    fn accuracy(&mut self) -> Option<(Accuracy, String)> {
        let r = self.recipe;
        let desc = r.content.stage.as_ref()?.render.accuracy.as_ref()?;
        let at = r.source.find(&["accuracy", ":"]);
        let mut acc = Accuracy {
            model: desc.model.as_ref().map(|m| m.to_model()),
            fresnel: desc.fresnel,
            distribution: desc.distribution,
            masking: desc.masking,
            compensation: desc.compensation,
            calibration: desc.calibration,
            effects: vec![],
        };
        for (key, value) in [
            ("t-term", desc.t_term),
            ("absorption", desc.absorption),
            ("bump", desc.bump),
        ] {
            if let Some(on) = value
                && let Some(e) = accuracy::effect_named(key)
            {
                acc.force(e, on);
            }
        }
        for (name, &on) in &desc.effects {
            match accuracy::effect_named(name) {
                Some(e) => acc.force(e, on),
                None => {
                    let names: Vec<&str> = Effect::ALL.iter().map(|e| e.name()).collect();
                    let pos = r.source.key(name).or(at);
                    self.errors.push(r.source.error(
                        pos,
                        format!(
                            "stage.render.accuracy.effects: unknown effect \"{name}\": allowed {}",
                            names.join(", ")
                        ),
                    ));
                }
            }
        }
        let e = r.source.error(at, "");
        Some((acc, format!("render.accuracy ({}:{})", e.file, e.line)))
    }

    /// Effects a used material `name` calls for, credited to `element` (`material "gold"`, or a
    /// platelet entry).
    pub(super) fn stack_effects(&mut self, element: &str, name: &str, stack: &StackDesc) {
        let file = self
            .recipe
            .library
            .position_of(name)
            .unwrap_or_else(|| "?".into());
        let (absorbing, t_term) = crate::scene::stack_calls(stack);
        if let Some(i) = absorbing {
            self.effects
                .turn_on(Effect::Absorption, format!("{element} coats[{i}] ({file})"));
        }
        if t_term {
            self.effects.turn_on(
                Effect::TTerm,
                format!("{element} ({file}, {:?} model)", stack.model),
            );
        }
        // A measured albedo is read per wavelength only by a coat-less base; under coats both
        // modes use its RGB projection (the stack's tables are per RGB channel), so it does not
        // call for spectral transport there.
        if stack.base_spectrum.is_some() && stack.coats.is_empty() {
            self.effects.turn_on(
                Effect::Spectral,
                format!("{element} base.albedo spectrum ({file})"),
            );
        }
        // A fluorescent base moves light between wavelengths: exactly in spectral transport
        // (which it calls for), by the reduced 3 × 3 matrix when `spectral=off`.
        if stack.fluorescence.is_some() {
            let element = format!("{element} base.fluorescence ({file})");
            self.effects.turn_on(Effect::Fluorescence, element.clone());
            self.effects.turn_on(Effect::Spectral, element);
        }
    }
}

/// A 64-bit hash of the recipe's text and of every file it includes (for render metadata): the
/// same files give the same hash.
fn recipe_hash(r: &GemRecipe) -> u64 {
    let mut words = vec![];
    for source in r.library.sources() {
        let bytes = source.text.as_bytes();
        words.extend(bytes.chunks(8).map(|c| {
            let mut b = [0u8; 8];
            b[..c.len()].copy_from_slice(c);
            u64::from_le_bytes(b)
        }));
        words.push(bytes.len() as u64);
    }
    hash_words(&words)
}
