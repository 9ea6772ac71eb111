//! The gem's compiled surface: its material table and map tree.

use crate::bsdf::StackDesc;
use crate::texture::Map;

/// A gem's compiled surface.
#[derive(Clone, Debug, PartialEq)]
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
