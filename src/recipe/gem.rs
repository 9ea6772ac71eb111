//! A gem recipe (`gems/*.ron`): the `materials` library, optional named `maps`, and the `surface`
//! map tree; and its compilation into the runtime [`Surface`].
//!
//! ```ron
//! (
//!     seed: 0,                                  // optional: re-rolls every default seed
//!     materials: { "name": (coats: [...], base: ...), ... },
//!     maps: { "tiles": Voronoi(...), ... },     // optional: sub-maps used as Map("tiles")
//!     surface: Overlay(under: ..., over: ...),  // the tree (see `surface.rs`)
//! )
//! ```
//!
//! Compiling a recipe and looking up its surface:
//!
//! ```
//! use lapidary::recipe::GemRecipe;
//! let recipe = GemRecipe::parse("inline.ron", r#"(
//!     materials: {
//!         "body": (coats: [(ior: 1.58, roughness: 0.5)], base: Lambert(albedo: Gray(0.6))),
//!         "flake": (base: Conductor(metal: Copper, roughness: 3.0)),
//!     },
//!     surface: Overlay(
//!         under: Material("body"),
//!         over: Voronoi(scale: 0.05, fill: 0.1, entries: [(1.0, Material("flake"))],
//!                       bump: Beckmann(rms: 10.0)),
//!     ),
//! )"#)?;
//! let surface = recipe.compile()?;
//! let hit = surface.map.lookup(glam::Vec3::new(0.1, 0.2, 0.3), 0.5);
//! let name = &surface.names[hit.material as usize];
//! // Flakes carry a tilted facet normal; the body does not.
//! assert_eq!(hit.facet.is_some(), name == "flake");
//! # Ok::<(), lapidary::recipe::RecipeError>(())
//! ```
//!
//! The recipe issue after the maps extends this with the stage, includes, the translucent body and
//! the effects set; the fields here keep their meaning.

use super::surface::{BumpDesc, FieldDesc, MapDesc, SwitchDesc};
use super::{MaterialDesc, MaterialFile, MaterialLibrary, RecipeError, did_you_mean, ron_options};
use crate::sampler::hash_words;
use crate::scene::Surface;
use crate::texture::{
    Entry, FacetBump, FieldId, FieldNode, FieldTable, Map, MapNode, NodeId, Octaves, Stop, Tilt,
    Voronoi, VoronoiNode,
};
use glam::Vec3;
use indexmap::IndexMap;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// What a gem recipe file holds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GemDesc {
    /// Recipe seed (default 0): every default Voronoi and noise seed derives from it.
    #[serde(default)]
    pub seed: u64,
    /// Layered materials by name, in file order (their index is the material id).
    pub materials: IndexMap<String, MaterialDesc>,
    /// Named sub-maps, usable as `Map("name")` anywhere in the tree.
    #[serde(default)]
    pub maps: IndexMap<String, MapDesc>,
    /// The surface map tree.
    pub surface: MapDesc,
}

/// A parsed gem recipe with its source text (for error positions).
#[derive(Clone, Debug)]
pub struct GemRecipe {
    file: String,
    source: String,
    /// The parsed content.
    pub content: GemDesc,
}

impl GemRecipe {
    /// Reads and parses a recipe file (materials are validated, the tree is not yet compiled).
    pub fn load(path: &Path) -> Result<Self, RecipeError> {
        let (file, source) = super::read_source(path)?;
        Self::parse(&file, &source)
    }

    /// Parses recipe text; `file` is used in messages.
    pub fn parse(file: &str, source: &str) -> Result<Self, RecipeError> {
        let content: GemDesc = ron_options().from_str(source).map_err(|e| RecipeError {
            file: file.to_string(),
            line: e.span.start.line,
            col: e.span.start.col,
            message: e.code.to_string(),
        })?;
        let recipe = GemRecipe {
            file: file.to_string(),
            source: source.to_string(),
            content,
        };
        recipe.library()?;
        Ok(recipe)
    }

    /// The file name used in messages.
    pub fn file(&self) -> &str {
        &self.file
    }

    /// The recipe's materials as a library (validated, with positions for errors).
    pub fn library(&self) -> Result<MaterialLibrary, RecipeError> {
        let lib = MaterialLibrary::from_parts(
            &self.file,
            &self.source,
            MaterialFile {
                materials: self.content.materials.clone(),
            },
        );
        for name in lib.names() {
            lib.stack(name)?;
        }
        Ok(lib)
    }

    /// Compiles materials and map tree into the runtime surface.
    pub fn compile(&self) -> Result<Surface, RecipeError> {
        let lib = self.library()?;
        let names: Vec<String> = lib.names().map(str::to_string).collect();
        let stacks = names
            .iter()
            .map(|n| lib.stack(n))
            .collect::<Result<Vec<_>, _>>()?;
        let mut c = Compiler {
            recipe: self,
            nodes: vec![],
            entries: vec![],
            stops: vec![],
            fields: FieldTable::default(),
            named: IndexMap::new(),
            counter: 0,
            used: vec![false; names.len()],
        };
        let root = c.node(&self.content.surface)?;
        let used = c.used.clone();
        let map = Map::new(c.nodes, c.entries, c.stops, c.fields, root).map_err(|e| {
            let (line, col) = self.find(&["surface"]);
            self.error(line, col, format!("surface: {e}"))
        })?;
        Ok(Surface {
            names,
            stacks,
            map,
            used,
        })
    }

    fn error(&self, line: usize, col: usize, message: String) -> RecipeError {
        RecipeError {
            file: self.file.clone(),
            line,
            col,
            message,
        }
    }

    /// Position of the first occurrence of the token sequence `parts` (each separated by optional
    /// whitespace), e.g. `["Material", "(", "\"x\""]`; `(0, 0)` if absent.
    fn find(&self, parts: &[&str]) -> (usize, usize) {
        let src = &self.source;
        let mut start = 0;
        while let Some(off) = src[start..].find(parts[0]) {
            let at = start + off;
            let mut pos = at + parts[0].len();
            let ok = parts[1..].iter().all(|p| {
                let rest = &src[pos..];
                let trimmed = rest.trim_start();
                pos += rest.len() - trimmed.len();
                if trimmed.starts_with(p) {
                    pos += p.len();
                    true
                } else {
                    false
                }
            });
            if ok {
                return super::line_col(src, at);
            }
            start = at + parts[0].len();
        }
        (0, 0)
    }
}

/// Compilation state: the flat runtime arrays being filled, children before parents.
struct Compiler<'a> {
    recipe: &'a GemRecipe,
    nodes: Vec<MapNode>,
    entries: Vec<Entry>,
    stops: Vec<Stop>,
    fields: FieldTable,
    /// Named maps: `None` while being compiled (to catch cycles), then their node.
    named: IndexMap<String, Option<NodeId>>,
    /// Running count of seeded nodes, for default seeds.
    counter: u64,
    used: Vec<bool>,
}

impl Compiler<'_> {
    fn push(&mut self, node: MapNode) -> NodeId {
        self.nodes.push(node);
        (self.nodes.len() - 1) as NodeId
    }

    /// The seed of the next seeded node: the explicit one, or one derived from its position.
    fn seed(&mut self, explicit: Option<u64>) -> u64 {
        self.counter += 1;
        match explicit {
            Some(s) => hash_words(&[self.recipe.content.seed, 0x5eed, s]),
            None => hash_words(&[self.recipe.content.seed, 0xdef, self.counter]),
        }
    }

    fn node(&mut self, desc: &MapDesc) -> Result<NodeId, RecipeError> {
        let r = self.recipe;
        match desc {
            MapDesc::Material(name) => match r.content.materials.get_index_of(name) {
                Some(i) => {
                    self.used[i] = true;
                    Ok(self.push(MapNode::Material(i as u32)))
                }
                None => {
                    let (line, col) = r.find(&["Material", "(", &format!("\"{name}\"")]);
                    let hint = did_you_mean(name, r.content.materials.keys().map(String::as_str))
                        .map(|s| format!(" (did you mean \"{s}\"?)"))
                        .unwrap_or_default();
                    Err(r.error(
                        line,
                        col,
                        format!(
                            "unknown material \"{name}\"{hint}; `materials` defines: {}",
                            r.content
                                .materials
                                .keys()
                                .cloned()
                                .collect::<Vec<_>>()
                                .join(", ")
                        ),
                    ))
                }
            },
            MapDesc::Map(name) => {
                let (line, col) = r.find(&["Map", "(", &format!("\"{name}\"")]);
                match self.named.get(name) {
                    Some(Some(id)) => return Ok(*id),
                    Some(None) => {
                        return Err(r.error(
                            line,
                            col,
                            format!("map \"{name}\" contains itself (a cycle through `maps`)"),
                        ));
                    }
                    None => {}
                }
                let Some(sub) = r.content.maps.get(name) else {
                    let hint = did_you_mean(name, r.content.maps.keys().map(String::as_str))
                        .map(|s| format!(" (did you mean \"{s}\"?)"))
                        .unwrap_or_default();
                    return Err(r.error(line, col, format!("unknown map \"{name}\"{hint}")));
                };
                self.named.insert(name.clone(), None);
                let id = self.node(sub)?;
                self.named.insert(name.clone(), Some(id));
                Ok(id)
            }
            MapDesc::Voronoi {
                scale,
                jitter,
                seed,
                entries,
                fill,
                bump,
            } => {
                let seed = self.seed(*seed);
                let children = entries
                    .iter()
                    .map(|(w, d)| Ok((w.0, self.node(d)?)))
                    .collect::<Result<Vec<_>, RecipeError>>()?;
                let total: f64 = children.iter().map(|(w, _)| f64::from(*w)).sum();
                let first = self.entries.len() as u32;
                let mut run = 0.0f64;
                for (k, (w, node)) in children.iter().enumerate() {
                    run += f64::from(*w);
                    let cumulative = if k + 1 == children.len() {
                        1.0
                    } else {
                        (run / total) as f32
                    };
                    self.entries.push(Entry {
                        cumulative,
                        node: *node,
                    });
                }
                let bump = bump.as_ref().map(|b| FacetBump {
                    tilt: match *b {
                        BumpDesc::Cone { half_angle } => Tilt::Cone { half_angle },
                        BumpDesc::Beckmann { rms } => Tilt::Beckmann { rms },
                    },
                });
                Ok(self.push(MapNode::Voronoi(VoronoiNode {
                    basis: Voronoi::new(seed, *jitter),
                    inv_scale: 1.0 / scale,
                    first,
                    count: children.len() as u32,
                    fill: *fill,
                    bump,
                })))
            }
            MapDesc::Overlay { under, over } => {
                let under = self.node(under)?;
                let over = self.node(over)?;
                Ok(self.push(MapNode::Overlay { under, over }))
            }
            MapDesc::Switch(SwitchDesc(s)) => {
                let field = self.field(&s.by)?;
                let children = s
                    .stops
                    .iter()
                    .map(|(t, d)| Ok((*t, self.node(d)?)))
                    .collect::<Result<Vec<_>, RecipeError>>()?;
                let first = self.stops.len() as u32;
                self.stops.extend(
                    children
                        .iter()
                        .map(|&(threshold, node)| Stop { threshold, node }),
                );
                Ok(self.push(MapNode::Switch {
                    field,
                    first,
                    count: children.len() as u32,
                    blend: s.blend,
                }))
            }
        }
    }

    fn field(&mut self, desc: &FieldDesc) -> Result<FieldId, RecipeError> {
        let octaves = |this: &mut Self, n: u32, gain: f32, lacunarity: f32, seed: Option<u64>| {
            let s = this.seed(seed);
            Octaves {
                octaves: n,
                gain,
                lacunarity,
                seed: (s ^ (s >> 32)) as u32,
            }
        };
        let node = match desc {
            FieldDesc::Constant(c) => FieldNode::Constant(*c),
            FieldDesc::Perlin {
                scale,
                octaves: n,
                gain,
                lacunarity,
                seed,
            } => FieldNode::Fbm {
                inv_scale: 1.0 / scale,
                octaves: octaves(self, *n, *gain, *lacunarity, *seed),
            },
            FieldDesc::Turbulence {
                scale,
                octaves: n,
                gain,
                lacunarity,
                seed,
            } => FieldNode::Turbulence {
                inv_scale: 1.0 / scale,
                octaves: octaves(self, *n, *gain, *lacunarity, *seed),
            },
            FieldDesc::Marble {
                scale,
                axis,
                turbulence,
                octaves: n,
                gain,
                lacunarity,
                seed,
            } => FieldNode::Marble {
                inv_scale: 1.0 / scale,
                axis: Vec3::new(axis.0, axis.1, axis.2).normalize(),
                turbulence: *turbulence,
                octaves: octaves(self, *n, *gain, *lacunarity, *seed),
            },
            FieldDesc::Sum(list) | FieldDesc::Product(list) => {
                let ids = list
                    .iter()
                    .map(|f| self.field(f))
                    .collect::<Result<Vec<_>, _>>()?;
                let (first, count) = self.fields.add_args(&ids);
                if matches!(desc, FieldDesc::Sum(_)) {
                    FieldNode::Sum { first, count }
                } else {
                    FieldNode::Product { first, count }
                }
            }
            FieldDesc::Remap {
                field,
                from,
                to,
                clamp,
            } => FieldNode::Remap {
                input: self.field(field)?,
                from: [from.0, from.1],
                to: [to.0, to.1],
                clamp: *clamp,
            },
        };
        self.fields
            .add(node)
            .map_err(|e| self.recipe.error(0, 0, format!("internal: {e}")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gem(name: &str) -> GemRecipe {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("gems")
            .join(name);
        GemRecipe::load(&path).unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn shipped_gems_compile_and_use_every_material() {
        for (name, materials, depth) in [("lepidolite.ron", 20, 3), ("sunstone.ron", 5, 1)] {
            let s = gem(name).compile().unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(s.names.len(), materials, "{name}");
            assert_eq!(
                s.unused().count(),
                0,
                "{name}: {:?}",
                s.unused().collect::<Vec<_>>()
            );
            assert_eq!(s.map.max_trail(s.map.root), depth, "{name}");
            let hit = s.map.lookup(Vec3::new(0.1, 0.2, 0.3), 0.5);
            assert!((hit.material as usize) < materials);
        }
    }

    fn err(src: &str) -> RecipeError {
        let e = GemRecipe::parse("g.ron", src).and_then(|g| g.compile());
        e.expect_err("must fail")
    }

    const MATS: &str = r#"materials: { "a": (base: Lambert(albedo: Gray(0.5))), "b": (base: Lambert(albedo: Gray(0.2))) },"#;

    #[test]
    fn errors_point_at_the_problem() {
        let e = err(&format!(
            "({MATS}\n surface: Voronoi(scale: 0.1,\n   fill: 1.5, entries: [(1.0, Material(\"a\"))]))"
        ));
        assert_eq!((e.line, e.col), (3, 10), "{e}");
        assert!(
            e.message.contains("fill = 1.5") && e.message.contains("0 ..= 1"),
            "{e}"
        );

        let e = err(&format!(
            "({MATS}\n surface: Voronoi(scale: 0.1, entries: [(1.0, Material(\"b\")),\n (2.0, Material(\"aa\"))]))"
        ));
        assert_eq!((e.line, e.col), (3, 8), "{e}");
        assert!(
            e.message.contains("unknown material \"aa\"")
                && e.message.contains("did you mean \"a\""),
            "{e}"
        );

        let e = err(&format!(
            "({MATS}\n surface: Voronoi(scale: 0.1, fill: 0.5, entries: [(1.0, Material(\"a\"))]))"
        ));
        assert!(e.message.contains("transparent") && e.line == 2, "{e}");

        let e = err(&format!(
            "({MATS}\n surface: Voronoi(scale: 0.1, entries: [(-1.0, Material(\"a\"))]))"
        ));
        assert!(e.message.contains("weight = -1") && e.line == 2, "{e}");

        let e = err(&format!(
            "({MATS}\n surface: Switch(by: Constant(0.0), stops: [(0.5, Material(\"a\")), (0.2, Material(\"b\"))]))"
        ));
        assert!(e.message.contains("strictly ascending"), "{e}");

        let e = err(&format!(
            "({MATS}\n surface: Switch(by: Constant(0.0), stops: [(0.0, Material(\"a\")), (0.2, Material(\"b\"))], blend: 0.5))"
        ));
        assert!(
            e.message.contains("blend = 0.5") && e.message.contains("0 ..= 0.2"),
            "{e}"
        );

        let e = err(&format!(
            "({MATS}\n maps: {{ \"x\": Voronoi(scale: 1.0, entries: [(1.0, Map(\"x\"))]) }},\n surface: Map(\"x\"))"
        ));
        assert!(e.message.contains("contains itself"), "{e}");

        let e = err(&format!("({MATS}\n surface: Voronoy(scale: 1.0))"));
        assert!(e.line == 2 && e.message.contains("Voronoy"), "{e}");

        let e = err(&format!(
            "({MATS}\n surface: Switch(by: Marble(scale: 1.0, octaves: 40), stops: [(0.0, Material(\"a\"))]))"
        ));
        assert!(
            e.line == 2 && e.message.contains("octaves = 40") && e.message.contains("1 ..= 16"),
            "{e}"
        );
    }

    #[test]
    fn seeds_derive_from_the_recipe_seed() {
        let src = |seed: u64| {
            format!(
                "(seed: {seed}, {MATS}\n surface: Voronoi(scale: 0.1, entries: [(1.0, Material(\"a\")), (1.0, Material(\"b\"))]))"
            )
        };
        let a = GemRecipe::parse("g", &src(0)).unwrap().compile().unwrap();
        let b = GemRecipe::parse("g", &src(1)).unwrap().compile().unwrap();
        let a2 = GemRecipe::parse("g", &src(0)).unwrap().compile().unwrap();
        let mut differ = 0;
        for i in 0..200 {
            let p = Vec3::new(i as f32 * 0.137, 0.3, -0.2);
            let (ha, hb) = (a.map.lookup(p, 0.5), b.map.lookup(p, 0.5));
            assert_eq!(ha, a2.map.lookup(p, 0.5));
            differ += usize::from(ha.material != hb.material);
        }
        assert!(differ > 50, "{differ}");
    }
}
