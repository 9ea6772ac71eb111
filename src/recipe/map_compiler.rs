//! Compiles a recipe's surface map tree (and its named maps and fields) into the flat runtime
//! arrays of [`crate::texture::Map`], children before parents, collecting errors on the way.

use super::RecipeError;
use super::did_you_mean;
use super::gem::GemRecipe;
use super::surface::{BumpDesc, FieldDesc, MapDesc, SwitchDesc};
use crate::sampler::hash_words;
use crate::scene::{Effect, Effects};
use crate::texture::{
    Entry, FacetBump, FieldId, FieldNode, FieldTable, MapNode, NodeId, Octaves, Stop, Tilt,
    Voronoi, VoronoiNode,
};
use glam::Vec3;
use indexmap::IndexMap;
use std::collections::HashSet;

/// Deepest nesting of map nodes the compiler follows (through named maps too); the runtime tree
/// has its own, equal limit ([`crate::texture::map::MAX_DEPTH`]).
const MAX_NESTING: usize = crate::texture::map::MAX_DEPTH;

/// The leaf index `Body` compiles to until the material table is complete; then it becomes
/// [`crate::scene::Surface::body_index`].
pub(super) const BODY_LEAF: u32 = u32::MAX;

/// Unknown names reported with a did-you-mean hint, at most.
const MAX_HINTS: usize = 32;

/// Compilation state: the flat runtime arrays being filled, children before parents.
pub(crate) struct Compiler<'a> {
    pub(super) recipe: &'a GemRecipe,
    pub(super) nodes: Vec<MapNode>,
    pub(super) entries: Vec<Entry>,
    pub(super) stops: Vec<Stop>,
    pub(super) fields: FieldTable,
    /// Named maps: `None` while being compiled (to catch cycles), then their node.
    pub(super) named: IndexMap<String, Option<NodeId>>,
    /// Running count of seeded nodes, for default seeds.
    pub(super) counter: u64,
    /// Library index → surface material index, in first-use order after the recipe's own.
    pub(super) materials: IndexMap<usize, u32>,
    /// Keys of the errors already reported once (unknown names, cycles, too deep).
    pub(super) reported: HashSet<String>,
    pub(super) depth: usize,
    /// The tree path (or `maps."name"`) where each node was defined, by node index.
    pub(super) labels: Vec<String>,
    pub(super) effects: Effects,
    pub(super) errors: Vec<RecipeError>,
}

impl<'a> Compiler<'a> {
    pub(crate) fn new(recipe: &'a GemRecipe) -> Self {
        // The recipe's own materials keep their file order as indices 0, 1, …
        let own = recipe.content.materials.len();
        Compiler {
            recipe,
            nodes: vec![],
            entries: vec![],
            stops: vec![],
            fields: FieldTable::default(),
            named: IndexMap::new(),
            counter: 0,
            materials: (0..own).map(|i| (i, i as u32)).collect(),
            reported: HashSet::new(),
            depth: 0,
            labels: vec![],
            effects: Effects::default(),
            errors: vec![],
        }
    }

    fn push(&mut self, node: MapNode) -> NodeId {
        if self.nodes.len() >= super::ranged::MAX_MAP_NODES {
            if self.reported.insert("too many nodes".into()) {
                let at = self.recipe.source.find(&["surface", ":"]);
                let max = super::ranged::MAX_MAP_NODES;
                self.errors.push(self.recipe.source.error(
                    at,
                    format!("surface: the map tree has more than {max} nodes; at most {max}"),
                ));
            }
            return 0;
        }
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

    /// Reports an unknown name once, at its first use in the file (the message is only made,
    /// and the use only looked for, the first time).
    fn unknown(&mut self, kind: &str, name: &str, message: impl FnOnce(&Self) -> String) {
        let key = format!("{kind}({name})");
        if !self.reported.contains(&key) {
            let at = self.recipe.source.call(kind, name);
            let message = message(self);
            self.report_once(key, at, message);
        }
    }

    /// Whether an unknown name still gets a did-you-mean: for the first [`MAX_HINTS`] errors only
    /// (each hint compares the name with every known one).
    fn hints(&self) -> bool {
        self.reported.len() < MAX_HINTS
    }

    /// Pushes an error unless one with the same `key` was already reported.
    fn report_once(&mut self, key: String, at: Option<usize>, message: String) {
        if self.reported.insert(key) {
            self.errors.push(self.recipe.source.error(at, message));
        }
    }

    /// Compiles `desc`, found at tree path `at` (e.g. `surface.over`), into a node.
    pub(super) fn node(&mut self, desc: &MapDesc, at: &str) -> NodeId {
        if self.depth >= MAX_NESTING {
            let message = format!(
                "{at}: maps nest more than {MAX_NESTING} levels deep, too deep to evaluate"
            );
            if self.reported.insert("too deep".into()) {
                // At the definition of the innermost named map on the path, else at `surface`.
                let src = &self.recipe.source;
                let pos = at
                    .rsplit("maps.\"")
                    .next()
                    .filter(|_| at.contains("maps.\""))
                    .and_then(|rest| rest.split('"').next())
                    .and_then(|name| src.key(name))
                    .or_else(|| src.find(&["surface", ":"]));
                self.errors.push(src.error(pos, message));
            }
            return self.push(MapNode::Material(0));
        }
        self.depth += 1;
        let id = self.node_inner(desc, at);
        self.depth -= 1;
        // A named map keeps the label of its definition (set by the inner call); a stand-in for
        // an error is labelled where it stands.
        self.labels.resize(self.nodes.len(), String::new());
        if let Some(l) = self.labels.get_mut(id as usize)
            && l.is_empty()
        {
            *l = at.to_string();
        }
        id
    }

    fn node_inner(&mut self, desc: &MapDesc, at: &str) -> NodeId {
        let r = self.recipe;
        match desc {
            MapDesc::Body => {
                if r.content.body.is_none() {
                    let at = r.source.find(&["Body"]);
                    self.report_once(
                        "no body".into(),
                        at,
                        "`Body` shows the recipe's translucent body, but the recipe has no \
                         `body: (ior: …)`"
                            .into(),
                    );
                    return self.push(MapNode::Material(0));
                }
                self.push(MapNode::Material(BODY_LEAF))
            }
            MapDesc::Material(name) => {
                let Some(lib_index) = r.library.index_of(name) else {
                    self.unknown("Material", name, |c| {
                        r.library.unknown_hinted(name, c.hints())
                    });
                    return self.push(MapNode::Material(0));
                };
                let next = self.materials.len() as u32;
                let m = *self.materials.entry(lib_index).or_insert(next);
                self.push(MapNode::Material(m))
            }
            MapDesc::Map(name) => {
                match self.named.get(name) {
                    Some(Some(id)) => return *id,
                    Some(None) => {
                        // Point at the use inside the map's own definition (or inside a map it
                        // uses), which closes the cycle.
                        let src = &r.source;
                        let quoted = format!("{name:?}");
                        let at = src
                            .key(name)
                            .and_then(|k| src.find_from(k + 1, &["Map", "(", &quoted]))
                            .or_else(|| src.find(&["Map", "(", &quoted]));
                        self.report_once(
                            format!("cycle({name})"),
                            at,
                            format!("map \"{name}\" contains itself (a cycle through `maps`)"),
                        );
                        return self.push(MapNode::Material(0));
                    }
                    None => {}
                }
                let Some(sub) = r.content.maps.get(name) else {
                    self.unknown("Map", name, |c| {
                        let maps = &r.content.maps;
                        let hint = c
                            .hints()
                            .then(|| did_you_mean(name, maps.keys().map(String::as_str)))
                            .flatten()
                            .map(|s| format!(" (did you mean \"{s}\"?)"))
                            .unwrap_or_default();
                        let mut known: Vec<&str> =
                            maps.keys().map(String::as_str).take(24).collect();
                        if maps.len() > known.len() {
                            known.push("…");
                        }
                        format!(
                            "unknown map \"{name}\"{hint}; `maps` defines: {}",
                            if known.is_empty() {
                                "nothing".to_string()
                            } else {
                                known.join(", ")
                            }
                        )
                    });
                    return self.push(MapNode::Material(0));
                };
                self.named.insert(name.clone(), None);
                let id = self.node(sub, &format!("maps.{name:?}"));
                self.named.insert(name.clone(), Some(id));
                id
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
                let children: Vec<(f32, NodeId)> = entries
                    .iter()
                    .enumerate()
                    .map(|(k, (w, d))| (w.0, self.node(d, &format!("{at}.entries[{k}]"))))
                    .collect();
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
                if let Some(b) = bump.filter(|b| match b.tilt {
                    Tilt::Cone { half_angle } => half_angle > 0.0,
                    Tilt::Beckmann { rms } => rms > 0.0,
                }) {
                    self.effects
                        .turn_on(Effect::FacetBump, format!("{at}.bump = {:?}", b.tilt));
                }
                self.push(MapNode::Voronoi(VoronoiNode {
                    basis: Voronoi::new(seed, *jitter),
                    inv_scale: 1.0 / scale,
                    first,
                    count: children.len() as u32,
                    fill: *fill,
                    bump,
                }))
            }
            MapDesc::Overlay { under, over } => {
                let under = self.node(under, &format!("{at}.under"));
                let over = self.node(over, &format!("{at}.over"));
                self.effects
                    .turn_on(Effect::GlitterOverlay, format!("{at} (Overlay)"));
                self.push(MapNode::Overlay { under, over })
            }
            MapDesc::Switch(SwitchDesc(s)) => {
                let field = self.field(&s.by);
                let children: Vec<(f32, NodeId)> = s
                    .stops
                    .iter()
                    .enumerate()
                    .map(|(k, (t, d))| (*t, self.node(d, &format!("{at}.stops[{k}]"))))
                    .collect();
                let first = self.stops.len() as u32;
                self.stops.extend(
                    children
                        .iter()
                        .map(|&(threshold, node)| Stop { threshold, node }),
                );
                if s.blend > 0.0 && children.len() > 1 {
                    self.effects.turn_on(
                        Effect::StochasticSwitch,
                        format!("{at} (Switch, blend {})", s.blend),
                    );
                }
                self.push(MapNode::Switch {
                    field,
                    first,
                    count: children.len() as u32,
                    blend: s.blend,
                })
            }
        }
    }

    /// Compiles a field description into [`Compiler::fields`] (children first); default seeds
    /// continue the running count.
    pub(super) fn field(&mut self, desc: &FieldDesc) -> FieldId {
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
                let ids: Vec<FieldId> = list.iter().map(|f| self.field(f)).collect();
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
                input: self.field(field),
                from: [from.0, from.1],
                to: [to.0, to.1],
                clamp: *clamp,
            },
        };
        match self.fields.add(node) {
            Ok(id) => id,
            Err(e) => {
                // Unreachable for parsed input (children are added first); keep it an error.
                let r = self.recipe;
                self.errors
                    .push(r.source.error(None, format!("internal: {e}")));
                0
            }
        }
    }
}
