//! The gem's compiled surface: its material table and map tree.

use super::Body;
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
    /// Where each map node is defined in the recipe, by node index: its tree path
    /// (`surface.under.entries[1]`) or, for a named map, `maps."name"` (the pixel inspector's
    /// names; not used by lookups).
    pub map_labels: Vec<String>,
    /// Whether the tree uses each material.
    pub used: Vec<bool>,
    /// The translucent body, if the recipe gives one. Map leaves whose index is
    /// [`Surface::body_index`] (one past the last stack) show the bare boundary (`Body`).
    pub body: Option<Body>,
}

impl Surface {
    /// The material index of `Body` leaves: one past the last layered material.
    pub fn body_index(&self) -> u32 {
        self.stacks.len() as u32
    }

    /// Every name a map leaf can carry, by index: the materials, then `"Body"` when the recipe
    /// has a body.
    pub fn leaf_names(&self) -> Vec<String> {
        let mut v = self.names.clone();
        if let Some(b) = &self.body {
            v.push("Body".into());
            v.extend(
                b.platelet_materials
                    .iter()
                    .map(|(n, _)| format!("platelet:{n}")),
            );
        }
        v
    }

    /// The name of material index `i` (`"Body"` for the body's index, the material's own name
    /// for a platelet face).
    pub fn name(&self, i: u32) -> &str {
        let n = self.names.len();
        match (i as usize).checked_sub(n + 1) {
            None => self.names.get(i as usize).map_or("Body", String::as_str),
            Some(k) => self
                .body
                .as_ref()
                .and_then(|b| b.platelet_materials.get(k))
                .map_or("?", |(name, _)| name.as_str()),
        }
    }

    /// Names of materials neither the tree nor a platelet population uses.
    pub fn unused(&self) -> impl Iterator<Item = &str> {
        let plates: Vec<&str> = self
            .body
            .iter()
            .flat_map(|b| b.platelet_materials.iter().map(|(n, _)| n.as_str()))
            .collect();
        self.names
            .iter()
            .zip(&self.used)
            .filter(move |(n, u)| !**u && !plates.contains(&n.as_str()))
            .map(|(n, _)| n.as_str())
    }
}
