//! The one loading path of every command that reads a gem recipe (`render`, `info`, `map`,
//! `regress`, `tradeoff`): read the recipe, register the files it reads as inputs of the
//! command's [`OutputPlan`], compile it, apply the command line's accuracy knobs (one
//! [`Accuracy`], see [`crate::scene::accuracy`]), and later build the [`World`].
//!
//! Errors read as they always have: a recipe's own errors carry their `file:line:col`, and a knob
//! or world that fails is prefixed with the recipe's path as given (`gems/x.ron: …`).
//! `lapidary check` reads recipes its own way, collecting every error instead of stopping at the
//! first.

use crate::image::outputs::OutputPlan;
use crate::recipe::GemRecipe;
use crate::recipe::stage::{EnvironmentDesc, ShapeDesc};
use crate::render::world::Setup;
use crate::render::{World, WorldError};
use crate::scene::{Accuracy, Scene};
use anyhow::{Result, anyhow};
use std::path::{Path, PathBuf};

/// A gem recipe read and compiled, with the command line's knobs applied.
#[derive(Debug)]
pub struct Loaded {
    /// The recipe's path as given on the command line (the prefix of error messages).
    pub path: PathBuf,
    /// The recipe as read (its library and text, for `lapidary info`).
    pub recipe: GemRecipe,
    /// The compiled scene, the recipe's `render.accuracy` and then `knobs` applied.
    pub scene: Scene,
}

/// Reads and compiles the recipe at `path` and applies `knobs` to the compiled scene (credited to
/// the command line). With a `plan`, the files the recipe reads besides itself (included
/// libraries, the mesh, the environment map) are registered as its inputs, so that none of them
/// can be an output; the recipe itself is the caller's to register, in its own order.
pub fn load_scene(path: &Path, knobs: &Accuracy, plan: Option<&mut OutputPlan>) -> Result<Loaded> {
    let recipe = GemRecipe::load(path).map_err(|e| anyhow!("{e}"))?;
    if let Some(plan) = plan {
        for (input, role) in recipe_inputs(&recipe) {
            plan.input(&input, role)?;
        }
    }
    let mut scene = recipe.compile().map_err(|e| anyhow!("{e}"))?;
    scene
        .set_accuracy(knobs, "command line")
        .map_err(|e| anyhow!("{}: {e}", path.display()))?;
    Ok(Loaded {
        path: path.to_path_buf(),
        recipe,
        scene,
    })
}

impl Loaded {
    /// The world of the loaded scene (see [`build_world`]).
    pub fn world(&self, setup: &Setup) -> Result<World, WorldFailed> {
        build_world(&self.path, &self.scene, setup)
    }
}

/// A world that could not be built, named by its recipe's path: `gems/x.ron: stone shape: …`.
#[derive(Debug, thiserror::Error)]
#[error("{path}: {error}")]
pub struct WorldFailed {
    /// The recipe's path, as given.
    pub path: String,
    /// What went wrong.
    pub error: WorldError,
}

impl WorldFailed {
    /// Whether the build gave up on its deadline or cancel flag ([`WorldError::Stopped`]).
    pub fn stopped(&self) -> bool {
        matches!(self.error, WorldError::Stopped)
    }
}

/// Builds the world of `scene` (the recipe at `path`, or a variant of it such as a `tradeoff`
/// setting) with `setup`'s deadline, cancel flag and progress.
pub fn build_world(path: &Path, scene: &Scene, setup: &Setup) -> Result<World, WorldFailed> {
    World::build(scene, setup).map_err(|error| WorldFailed {
        path: path.display().to_string(),
        error,
    })
}

/// The files a loaded recipe reads besides itself: included libraries, the mesh, the
/// environment map.
pub(crate) fn recipe_inputs(recipe: &GemRecipe) -> Vec<(PathBuf, &'static str)> {
    let mut inputs: Vec<(PathBuf, &'static str)> = recipe
        .library
        .sources()
        .iter()
        .skip(1)
        .map(|s| (PathBuf::from(&s.file), "the included library"))
        .collect();
    let base = recipe.base_dir();
    if let Some(stage) = &recipe.content.stage {
        match &stage.shape {
            Some(ShapeDesc::Mesh { file, .. }) => inputs.push((base.join(file), "the mesh")),
            Some(ShapeDesc::Design { file, .. }) => {
                inputs.push((base.join(file), "the GemCad design"))
            }
            _ => {}
        }
        if let Some(EnvironmentDesc::Map { file, .. }) = &stage.environment {
            inputs.push((base.join(file), "the environment map"));
        }
    }
    inputs
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Effect;

    fn scratch(name: &str, text: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("lapidary-load-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path
    }

    const GEM: &str = r#"(materials: {"a": (base: Lambert(albedo: Gray(0.5)))},
        surface: Voronoi(scale: 0.1, entries: [(1.0, Material("a"))], bump: Cone(half_angle: 20.0)))"#;

    #[test]
    fn loads_compiles_and_applies_the_knobs_once() {
        let path = scratch("gem.ron", GEM);
        let plain = load_scene(&path, &Accuracy::default(), None).unwrap();
        assert!(plain.scene.accuracy.is_default());
        assert!(plain.scene.effects.on(Effect::FacetBump));
        let mut knobs = Accuracy::default();
        knobs.force(Effect::FacetBump, false);
        let off = load_scene(&path, &knobs, None).unwrap();
        assert_eq!(off.scene.accuracy, knobs);
        assert_eq!(
            off.scene.effects.forced_by(Effect::FacetBump),
            Some("command line")
        );
        assert!(off.world(&Setup::default()).is_ok());
    }

    #[test]
    fn errors_name_the_recipe() {
        let path = scratch("bad.ron", "(materials: {}, surface: Material(\"x\"))");
        let e = load_scene(&path, &Accuracy::default(), None).unwrap_err();
        assert!(e.to_string().contains(":1:26: unknown material"), "{e}");
        let path = scratch("gem2.ron", GEM);
        // Every effect is simulated since issue 20: forcing one is accepted and credited to
        // the command line (a refused knob would be prefixed with the recipe's path).
        let mut knobs = Accuracy::default();
        knobs.force(Effect::Fluorescence, true);
        let loaded = load_scene(&path, &knobs, None).unwrap();
        assert_eq!(
            loaded.scene.effects.forced_by(Effect::Fluorescence),
            Some("command line")
        );
    }
}
