//! Runtime scene data compiled from a recipe: flat arrays indexed by integers, no names or maps on
//! the hot path. Today: the gem's [`Surface`] (materials and map tree); the stage, lights and the
//! effects set join it with the recipe and renderer issues.

use crate::bsdf::StackDesc;
use crate::texture::Map;

/// A gem's compiled surface.
#[derive(Clone, Debug)]
pub struct Surface {
    /// Material names, by material index (recipe order).
    pub names: Vec<String>,
    /// Layered stacks, by material index (tables are built by the renderer).
    pub stacks: Vec<StackDesc>,
    /// The map tree; its leaves are indices into `names`/`stacks`.
    pub map: Map,
    /// Whether the tree uses each material.
    pub used: Vec<bool>,
}

impl Surface {
    /// Names of materials the tree never uses.
    pub fn unused(&self) -> impl Iterator<Item = &str> {
        self.names
            .iter()
            .zip(&self.used)
            .filter(|(_, u)| !**u)
            .map(|(n, _)| n.as_str())
    }
}
