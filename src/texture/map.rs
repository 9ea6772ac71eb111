//! The runtime map tree: which layered material, which facet, at an object-space point.
//!
//! Nodes live in one flat array and refer to each other by index, children before parents (so a
//! tree cannot have cycles); entries, stops and fields live in their own flat arrays. A lookup walks
//! indices on the stack: no allocation, no strings, no hashing of names.
//!
//! Semantics (docs/design.md §6, course §5.2.1, fig. 5.2):
//! - `Material(m)`: material index `m` everywhere.
//! - `Voronoi`: the point's cell (nearest feature point at `p / scale`) is *filled* with probability
//!   `fill` and, if filled, picks entry `k` with probability `weightₖ / Σ weight` — both decided by
//!   independent hashes of the cell id, so they are constant over a cell and reproducible. An
//!   unfilled cell is *transparent*. The picked entry (a material or a whole sub-map) is looked up at
//!   the same point. With a facet bump, every filled cell carries one tilted normal.
//! - `Overlay { under, over }`: `over` where it is opaque, `under` where `over` is transparent (the
//!   glitter map over the surface map).
//! - `Switch { field, stops, blend }`: with thresholds `t₀ < t₁ < …`, the field value `v` selects the
//!   last stop with `tₖ ≤ v` (the first stop below `t₀`). Within `blend / 2` of a threshold `tₖ`
//!   the choice between stops `k − 1` and `k` is random per lookup, `P(k)` rising linearly from 0 to
//!   1 across the band, decided by the lookup's random number `u` (then rescaled to stay uniform for
//!   deeper switches). A whole material is chosen, never a mix of BRDFs.
//!
//! A filled cell's facet normal is that of the deepest Voronoi with a bump on the path to the chosen
//! material.

use super::bump::FacetBump;
use super::field::{FieldId, FieldTable};
use super::voronoi::Voronoi;
use crate::sampler::{mix64, to_unit_f32};
use glam::Vec3;

/// What a map lookup is given besides the point: the switch number `u ∈ [0, 1)` (stochastic
/// blends) and, optionally, a field's value at the point already evaluated (`known`: the lane loop
/// evaluates the map's leading field for all its lanes at once, [`Map::leading_field`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapQuery {
    /// The switch number.
    pub u: f32,
    /// A field and its value at the point.
    pub known: Option<(FieldId, f32)>,
}

impl From<f32> for MapQuery {
    /// A query with switch number `u` and nothing known.
    fn from(u: f32) -> Self {
        MapQuery { u, known: None }
    }
}

/// Index of a node in its [`Map`].
pub type NodeId = u32;

/// Most Voronoi cells one lookup may visit; deeper trees are rejected by [`Map::new`].
pub const MAX_TRAIL: usize = 16;

/// Deepest nesting of nodes (a chain of maps inside maps) a lookup may walk; deeper trees are
/// rejected by [`Map::new`], so a lookup's recursion stays shallow.
pub const MAX_DEPTH: usize = 64;

/// One node of the tree.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MapNode {
    /// A leaf: the index of a material in the scene's material table.
    Material(u32),
    /// A Voronoi surface or glitter map.
    Voronoi(VoronoiNode),
    /// `over` where opaque, else `under`.
    Overlay {
        /// Shown where `over` is transparent.
        under: NodeId,
        /// Shown where it is opaque.
        over: NodeId,
    },
    /// A field chooses between stops.
    Switch {
        /// The field compared with the thresholds.
        field: FieldId,
        /// First stop in [`Map::stops`].
        first: u32,
        /// Number of stops (≥ 1).
        count: u32,
        /// Width of the stochastic band around each threshold (field units, ≥ 0).
        blend: f32,
    },
}

/// A Voronoi map node.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VoronoiNode {
    /// The cellular basis (seed, jitter).
    pub basis: Voronoi,
    /// `1 / scale`, scale being the mean cell spacing in object units.
    pub inv_scale: f32,
    /// First entry in [`Map::entries`].
    pub first: u32,
    /// Number of entries (≥ 1).
    pub count: u32,
    /// Fraction of cells that are filled (0 … 1); the rest are transparent.
    pub fill: f32,
    /// Facet bump of the filled cells, if any.
    pub bump: Option<FacetBump>,
}

/// A weighted Voronoi entry; `cumulative` is the normalised running sum of weights (last = 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Entry {
    /// Normalised cumulative weight up to and including this entry.
    pub cumulative: f32,
    /// The entry's sub-tree.
    pub node: NodeId,
}

/// A switch stop.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stop {
    /// Field value from which this stop applies.
    pub threshold: f32,
    /// The stop's sub-tree.
    pub node: NodeId,
}

/// The cells one lookup visited, outermost first.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CellTrail {
    ids: [u64; MAX_TRAIL],
    len: u8,
    /// Bit `k` set: cell `k` belongs to a sparse (`fill < 1`) map and was filled.
    sparse: u16,
}

impl CellTrail {
    pub(super) const EMPTY: CellTrail = CellTrail {
        ids: [0; MAX_TRAIL],
        len: 0,
        sparse: 0,
    };

    /// The visited cell ids.
    pub fn ids(&self) -> &[u64] {
        &self.ids[..usize::from(self.len)]
    }

    /// The innermost filled cell of a sparse (glitter) map, if the lookup landed in one.
    pub fn glitter_cell(&self) -> Option<u64> {
        (0..usize::from(self.len))
            .rev()
            .find(|&k| self.sparse & (1 << k) != 0)
            .map(|k| self.ids[k])
    }

    /// One 64-bit value identifying the whole trail (for an id AOV).
    pub fn hash(&self) -> u64 {
        self.ids()
            .iter()
            .fold(0x243f_6a88_85a3_08d3, |h, &id| mix64(h ^ id))
    }

    pub(super) fn push(&mut self, id: u64, sparse: bool) {
        let k = usize::from(self.len);
        if k < MAX_TRAIL {
            self.ids[k] = id;
            self.sparse |= u16::from(sparse) << k;
            self.len += 1;
        }
    }
}

/// The result of a lookup.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapHit {
    /// Index of the material in the scene's material table.
    pub material: u32,
    /// Facet normal in tangent space (`z` = unbumped normal) where a bump applies.
    pub facet: Option<Vec3>,
    /// The cells visited.
    pub trail: CellTrail,
}

/// Why a set of nodes is not a valid map.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MapError {
    /// A node refers to itself, a later node or a missing one.
    #[error("node {0} refers to a node that is not defined before it")]
    BadReference(NodeId),
    /// The root can be transparent somewhere.
    #[error(
        "the surface can be transparent: a Voronoi with fill < 1 needs an Overlay over an opaque map"
    )]
    Transparent,
    /// Too many nested Voronoi maps on one path.
    #[error("a lookup could visit {0} Voronoi maps; at most {MAX_TRAIL} are allowed")]
    TooDeep(usize),
    /// Nodes nested too deeply to evaluate.
    #[error("maps nest {0} levels deep; at most {MAX_DEPTH} can be evaluated")]
    TooDeeplyNested(usize),
}

#[derive(Clone, Copy, Debug)]
struct NodeFacts {
    transparent: bool,
    trail: usize,
    depth: usize,
}

/// A compiled map tree.
#[derive(Clone, Debug, PartialEq)]
pub struct Map {
    /// All nodes, children before parents.
    pub nodes: Vec<MapNode>,
    /// Voronoi entries.
    pub entries: Vec<Entry>,
    /// Switch stops (thresholds ascending within a switch).
    pub stops: Vec<Stop>,
    /// Fields the switches read.
    pub fields: FieldTable,
    /// The root node.
    pub root: NodeId,
}

const FILL_SALT: u64 = 0x94d0_49bb_1331_11eb;
const PICK_SALT: u64 = 0xbf58_476d_1ce4_e5b9;

impl VoronoiNode {
    /// Whether the cell with id `id` is filled.
    #[inline]
    pub fn filled(&self, id: u64) -> bool {
        self.fill >= 1.0 || to_unit_f32(mix64(id ^ FILL_SALT)) < self.fill
    }

    /// The entry (0-based, relative to `first`) a filled cell with id `id` picks.
    #[inline]
    pub fn pick(&self, id: u64, entries: &[Entry]) -> usize {
        let x = to_unit_f32(mix64(id ^ PICK_SALT));
        let list = &entries[self.first as usize..(self.first + self.count) as usize];
        list.iter()
            .position(|e| x < e.cumulative)
            .unwrap_or(list.len() - 1)
    }
}

impl Map {
    /// Checks references (children before parents), that the root is opaque everywhere and that
    /// no lookup visits more than [`MAX_TRAIL`] cells.
    pub fn new(
        nodes: Vec<MapNode>,
        entries: Vec<Entry>,
        stops: Vec<Stop>,
        fields: FieldTable,
        root: NodeId,
    ) -> Result<Map, MapError> {
        for (i, node) in nodes.iter().enumerate() {
            let earlier = |n: NodeId| (n as usize) < i;
            let ok = match *node {
                MapNode::Material(_) => true,
                MapNode::Voronoi(v) => {
                    v.count > 0
                        && entries
                            .get(v.first as usize..(v.first + v.count) as usize)
                            .is_some_and(|es| es.iter().all(|e| earlier(e.node)))
                }
                MapNode::Overlay { under, over } => earlier(under) && earlier(over),
                MapNode::Switch {
                    field,
                    first,
                    count,
                    ..
                } => {
                    (field as usize) < fields.len()
                        && count > 0
                        && stops
                            .get(first as usize..(first + count) as usize)
                            .is_some_and(|ss| ss.iter().all(|s| earlier(s.node)))
                }
            };
            if !ok {
                return Err(MapError::BadReference(i as NodeId));
            }
        }
        if root as usize >= nodes.len() {
            return Err(MapError::BadReference(root));
        }
        let map = Map {
            nodes,
            entries,
            stops,
            fields,
            root,
        };
        let facts = map.analyse(root)[root as usize];
        if facts.depth > MAX_DEPTH {
            return Err(MapError::TooDeeplyNested(facts.depth));
        }
        if facts.transparent {
            return Err(MapError::Transparent);
        }
        if facts.trail > MAX_TRAIL {
            return Err(MapError::TooDeep(facts.trail));
        }
        Ok(map)
    }

    /// The children of `node`.
    fn children(&self, node: NodeId) -> impl Iterator<Item = NodeId> + '_ {
        let (entries, stops, pair): (&[Entry], &[Stop], [Option<NodeId>; 2]) =
            match self.nodes[node as usize] {
                MapNode::Material(_) => (&[], &[], [None, None]),
                MapNode::Voronoi(v) => (
                    &self.entries[v.first as usize..(v.first + v.count) as usize],
                    &[],
                    [None, None],
                ),
                MapNode::Overlay { under, over } => (&[], &[], [Some(over), Some(under)]),
                MapNode::Switch { first, count, .. } => (
                    &[],
                    &self.stops[first as usize..(first + count) as usize],
                    [None, None],
                ),
            };
        entries
            .iter()
            .map(|e| e.node)
            .chain(stops.iter().map(|s| s.node))
            .chain(pair.into_iter().flatten())
    }

    /// Per node, in one pass over the children-before-parents array (linear even when named maps
    /// make the tree a DAG): whether it can be transparent, the most Voronoi cells a lookup below
    /// it visits, and the longest chain of nodes below it (itself included).
    fn analyse(&self, upto: NodeId) -> Vec<NodeFacts> {
        let mut facts: Vec<NodeFacts> = Vec::with_capacity(upto as usize + 1);
        for i in 0..=upto {
            let kids: Vec<NodeFacts> = self.children(i).map(|c| facts[c as usize]).collect();
            let depth = 1 + kids.iter().map(|k| k.depth).max().unwrap_or(0);
            let any_transparent = kids.iter().any(|k| k.transparent);
            let f = match self.nodes[i as usize] {
                MapNode::Material(_) => NodeFacts {
                    transparent: false,
                    trail: 0,
                    depth,
                },
                MapNode::Voronoi(v) => NodeFacts {
                    transparent: v.fill < 1.0 || any_transparent,
                    trail: 1 + kids.iter().map(|k| k.trail).max().unwrap_or(0),
                    depth,
                },
                // Children order: over, under.
                MapNode::Overlay { .. } => NodeFacts {
                    transparent: kids[1].transparent,
                    trail: kids[0].trail.saturating_add(kids[1].trail),
                    depth,
                },
                MapNode::Switch { .. } => NodeFacts {
                    transparent: any_transparent,
                    trail: kids.iter().map(|k| k.trail).max().unwrap_or(0),
                    depth,
                },
            };
            facts.push(f);
        }
        facts
    }

    /// Whether some point can come out transparent below `node`.
    pub fn may_be_transparent(&self, node: NodeId) -> bool {
        self.analyse(node)[node as usize].transparent
    }

    /// The most Voronoi cells a lookup below `node` can visit.
    pub fn max_trail(&self, node: NodeId) -> usize {
        self.analyse(node)[node as usize].trail
    }

    /// The longest chain of nested nodes below `node`, itself included.
    pub fn depth(&self, node: NodeId) -> usize {
        self.analyse(node)[node as usize].depth
    }

    /// The material, facet and visited cells at object-space point `p`; `u ∈ [0,1)` decides the
    /// stochastic switch bands. Allocation-free.
    pub fn lookup(&self, p: Vec3, u: f32) -> MapHit {
        self.lookup_knowing(p, MapQuery::from(u))
    }

    /// The field of the switch that decides most lookups: the first switch reached from the root
    /// through overlays' lower maps (a lookup evaluates it unless an upper map covers the point).
    /// The lane loop evaluates it for all its lanes at once ([`Map::lookup_knowing`]).
    pub fn leading_field(&self) -> Option<FieldId> {
        let mut node = self.root;
        for _ in 0..self.nodes.len() {
            match self.nodes[node as usize] {
                MapNode::Overlay { under, .. } => node = under,
                MapNode::Switch { field, .. } => return Some(field),
                _ => return None,
            }
        }
        None
    }

    /// [`Map::lookup`] with a [`MapQuery`]: its `known` field value at `p` is read by every switch
    /// on that field instead of evaluating it (a field's value depends only on the point).
    pub fn lookup_knowing(&self, p: Vec3, query: MapQuery) -> MapHit {
        let MapQuery { u, known } = query;
        let mut trail = CellTrail::EMPTY;
        let mut u = if (0.0..1.0).contains(&u) { u } else { 0.5 };
        let (material, facet) = self
            .visit(self.root, p, known, &mut u, &mut trail)
            .unwrap_or((0, None)); // unreachable: `new` proves the root opaque
        MapHit {
            material,
            facet,
            trail,
        }
    }

    fn visit(
        &self,
        node: NodeId,
        p: Vec3,
        known: Option<(FieldId, f32)>,
        u: &mut f32,
        trail: &mut CellTrail,
    ) -> Option<(u32, Option<Vec3>)> {
        match self.nodes[node as usize] {
            MapNode::Material(m) => Some((m, None)),
            MapNode::Voronoi(v) => {
                let cell = v.basis.nearest(p * v.inv_scale);
                let filled = v.filled(cell.id);
                trail.push(cell.id, filled && v.fill < 1.0);
                if !filled {
                    return None;
                }
                let k = v.pick(cell.id, &self.entries);
                let child = self.entries[v.first as usize + k].node;
                let (m, facet) = self.visit(child, p, known, u, trail)?;
                Some((m, facet.or_else(|| v.bump.map(|b| b.normal(cell.id)))))
            }
            MapNode::Overlay { under, over } => self
                .visit(over, p, known, u, trail)
                .or_else(|| self.visit(under, p, known, u, trail)),
            MapNode::Switch {
                field,
                first,
                count,
                blend,
            } => {
                let stops = &self.stops[first as usize..(first + count) as usize];
                let v = match known {
                    Some((f, v)) if f == field => v,
                    _ => self.fields.eval(field, p),
                };
                let k = choose_stop(stops, v, blend, u);
                self.visit(stops[k].node, p, known, u, trail)
            }
        }
    }
}

/// The stop a switch takes for field value `v` (module docs); consumes and rescales `u` inside a
/// blend band so it stays uniform on `[0, 1)` for later decisions.
pub fn choose_stop(stops: &[Stop], v: f32, blend: f32, u: &mut f32) -> usize {
    let v = if v.is_nan() { stops[0].threshold } else { v };
    let k = stops.iter().rposition(|s| s.threshold <= v).unwrap_or(0);
    let half = 0.5 * blend;
    if blend <= 0.0 {
        return k;
    }
    // Band around tₖ (between k − 1 and k), or around tₖ₊₁ (between k and k + 1).
    let band = if k >= 1 && v < stops[k].threshold + half {
        Some((k - 1, (v - (stops[k].threshold - half)) / blend))
    } else if k + 1 < stops.len() && v >= stops[k + 1].threshold - half {
        Some((k, (v - (stops[k + 1].threshold - half)) / blend))
    } else {
        None
    };
    match band {
        Some((lower, p_upper)) => {
            let p_upper = p_upper.clamp(0.0, 1.0);
            let p_lower = 1.0 - p_upper;
            if *u < p_lower {
                *u = (*u / p_lower).min(1.0 - f32::EPSILON / 2.0);
                lower
            } else {
                *u = ((*u - p_lower) / p_upper).clamp(0.0, 1.0 - f32::EPSILON / 2.0);
                lower + 1
            }
        }
        None => k,
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::texture::bump::Tilt;

    /// A Voronoi node (cell spacing 0.1, jitter 1) whose filled cells carry a 10° cone bump.
    pub(crate) fn voronoi(first: u32, count: u32, fill: f32, seed: u64) -> MapNode {
        MapNode::Voronoi(VoronoiNode {
            basis: Voronoi::new(seed, 1.0),
            inv_scale: 10.0,
            first,
            count,
            fill,
            bump: Some(FacetBump {
                tilt: Tilt::Cone { half_angle: 10.0 },
            }),
        })
    }

    /// Materials 0, 1, 2; a sparse glitter Voronoi (fill ¼) over a dense two-entry one.
    fn glitter_over_surface() -> Map {
        let nodes = vec![
            MapNode::Material(0),
            MapNode::Material(1),
            MapNode::Material(2),
            voronoi(0, 2, 1.0, 1),
            voronoi(2, 1, 0.25, 2),
            MapNode::Overlay { under: 3, over: 4 },
        ];
        let entries = vec![
            Entry {
                cumulative: 0.5,
                node: 0,
            },
            Entry {
                cumulative: 1.0,
                node: 1,
            },
            Entry {
                cumulative: 1.0,
                node: 2,
            },
        ];
        Map::new(nodes, entries, vec![], FieldTable::default(), 5).unwrap()
    }

    #[test]
    fn overlay_shows_glitter_in_filled_cells_only() {
        let map = glitter_over_surface();
        let mut counts = [0usize; 3];
        for i in 0..4000 {
            let p = Vec3::new(i as f32 * 0.0137, (i % 97) as f32 * 0.031, 0.2);
            let hit = map.lookup(p, 0.5);
            counts[hit.material as usize] += 1;
            // The glitter cell is the only sparse one; the surface cell has its own facet.
            assert_eq!(hit.material == 2, hit.trail.glitter_cell().is_some());
            assert!(hit.facet.is_some());
            let n = if hit.material == 2 { 1 } else { 2 };
            assert_eq!(hit.trail.ids().len(), n);
        }
        assert!(counts.iter().all(|&c| c > 400), "{counts:?}");
        assert_eq!(map.max_trail(map.root), 2);
    }

    #[test]
    fn construction_rejects_bad_trees() {
        // A transparent root.
        let nodes = vec![MapNode::Material(0), voronoi(0, 1, 0.5, 1)];
        let entries = vec![Entry {
            cumulative: 1.0,
            node: 0,
        }];
        let e = Map::new(
            nodes.clone(),
            entries.clone(),
            vec![],
            FieldTable::default(),
            1,
        );
        assert_eq!(e.unwrap_err(), MapError::Transparent);
        // A forward reference (would allow cycles).
        let nodes = vec![MapNode::Overlay { under: 1, over: 1 }, MapNode::Material(0)];
        let e = Map::new(nodes, vec![], vec![], FieldTable::default(), 0);
        assert_eq!(e.unwrap_err(), MapError::BadReference(0));
        // Seventeen nested Voronoi maps.
        let mut nodes = vec![MapNode::Material(0)];
        let mut entries = vec![];
        for i in 0..17u32 {
            entries.push(Entry {
                cumulative: 1.0,
                node: i,
            });
            nodes.push(voronoi(i, 1, 1.0, u64::from(i)));
        }
        let e = Map::new(nodes, entries, vec![], FieldTable::default(), 17);
        assert_eq!(e.unwrap_err(), MapError::TooDeep(17));
    }

    #[test]
    fn switch_bands_are_linear_and_keep_u_uniform() {
        let stops = [
            Stop {
                threshold: 0.0,
                node: 0,
            },
            Stop {
                threshold: 0.5,
                node: 1,
            },
        ];
        let pick = |v: f32, u: f32| {
            let mut u = u;
            (choose_stop(&stops, v, 0.2, &mut u), u)
        };
        assert_eq!(pick(0.3, 0.99).0, 0);
        assert_eq!(pick(0.7, 0.01).0, 1);
        assert_eq!(pick(-5.0, 0.5).0, 0);
        assert_eq!(pick(f32::NAN, 0.5).0, 0);
        // In the band: P(upper) = (v − 0.4)/0.2; the rescaled u stays in [0, 1).
        let n = 10_000;
        for v in [0.42f32, 0.5, 0.58] {
            let mut upper = 0;
            for i in 0..n {
                let (k, u2) = pick(v, (i as f32 + 0.5) / n as f32);
                assert!((0.0..1.0).contains(&u2));
                upper += k;
            }
            let want = (v - 0.4) / 0.2;
            assert!(
                (upper as f32 / n as f32 - want).abs() < 1e-3,
                "{v}: {upper}"
            );
        }
    }
}
