//! Runtime scene data compiled from a recipe (docs/design.md §7): flat arrays indexed by integers, no
//! names or hash maps on the hot path, kept apart from the serde description in [`crate::recipe`].
//!
//! A [`Scene`] is the gem's [`Surface`] (material table and map tree), the resolved [`Stage`]
//! (shape, placement, ground, environment, lights, camera, render settings) and the [`Effects`] set:
//! which optional parts of the simulation the scene calls for, and why.

pub mod accuracy;
mod apply;
pub mod knobs;
pub(crate) use apply::stack_calls;
pub mod body;
pub mod effects;
mod presets;
pub mod stage;
pub mod surface;
pub mod view;

pub use accuracy::{Accuracy, KnobError};
pub use body::{Body, Interior};
pub use effects::{Effect, Effects};
pub use knobs::Knobs;
pub use stage::Stage;
pub use surface::Surface;

/// A compiled recipe, ready to render.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Materials and map tree.
    pub surface: Surface,
    /// Shape, lights, camera, render settings.
    pub stage: Stage,
    /// The effects the scene calls for, and those forced on or off.
    pub effects: Effects,
    /// The accuracy knobs applied so far (recipe, then command line).
    pub accuracy: Accuracy,
    /// Hash of the recipe's text and included files (for render metadata).
    pub hash: u64,
}
