//! Why a map lookup chose its material: the same walk as [`Map::lookup`], recording every node it
//! passes (the pixel inspector of `lapidary preview`). It allocates and is never on the render
//! path; a test proves it agrees with the lookup.

use super::map::{CellTrail, Map, MapHit, MapNode, NodeId, choose_stop};
use glam::Vec3;

/// What one node of the walk decided.
#[derive(Clone, Debug, PartialEq)]
pub enum MapDecision {
    /// A Voronoi map: the point's cell, whether it is filled and which entry it picked.
    Voronoi {
        /// The cell's 64-bit id.
        cell: u64,
        /// Whether the cell is filled (always, for `fill = 1`).
        filled: bool,
        /// The map's `fill`.
        fill: f32,
        /// The entry the filled cell picked (0-based), `None` when not filled.
        entry: Option<u32>,
        /// Number of entries.
        entries: u32,
        /// Whether the map's filled cells carry a facet bump.
        bump: bool,
    },
    /// An overlay: whether its upper map covered the point.
    Overlay {
        /// `true`: the upper (`over`) map is shown; `false`: it was transparent, the lower shows.
        over: bool,
    },
    /// A switch: the field's value and the stop it took.
    Switch {
        /// The field's value at the point.
        value: f32,
        /// The stop taken (0-based).
        stop: u32,
        /// Number of stops.
        stops: u32,
        /// Whether the value lies in a stochastic blend band (the stop was then drawn).
        in_band: bool,
    },
    /// A material leaf.
    Material {
        /// Index in the scene's material table.
        index: u32,
    },
}

/// One node of the walk.
#[derive(Clone, Debug, PartialEq)]
pub struct MapStep {
    /// The node.
    pub node: NodeId,
    /// Its path from the root as the walk reached it (`surface.over.entries[2]`).
    pub path: String,
    /// Nesting level (the root is 0).
    pub level: u32,
    /// What it decided.
    pub decision: MapDecision,
}

/// A lookup with its reasons.
#[derive(Clone, Debug, PartialEq)]
pub struct MapExplanation {
    /// The nodes walked, in order (an overlay's upper map before its lower one).
    pub steps: Vec<MapStep>,
    /// The lookup's result, equal to [`Map::lookup`]'s for the same point and `u`.
    pub hit: MapHit,
}

impl Map {
    /// [`Map::lookup`] at object-space point `p` with switch number `u`, recording each node's
    /// decision.
    pub fn explain(&self, p: Vec3, u: f32) -> MapExplanation {
        let mut walk = Walk {
            map: self,
            p,
            u: if (0.0..1.0).contains(&u) { u } else { 0.5 },
            trail: CellTrail::EMPTY,
            steps: vec![],
        };
        let (material, facet) = walk.visit(self.root, "surface", 0).unwrap_or((0, None));
        MapExplanation {
            steps: walk.steps,
            hit: MapHit {
                material,
                facet,
                trail: walk.trail,
            },
        }
    }
}

struct Walk<'a> {
    map: &'a Map,
    p: Vec3,
    u: f32,
    trail: CellTrail,
    steps: Vec<MapStep>,
}

impl Walk<'_> {
    fn record(&mut self, node: NodeId, path: &str, level: u32, decision: MapDecision) -> usize {
        self.steps.push(MapStep {
            node,
            path: path.to_string(),
            level,
            decision,
        });
        self.steps.len() - 1
    }

    fn visit(&mut self, node: NodeId, path: &str, level: u32) -> Option<(u32, Option<Vec3>)> {
        let map = self.map;
        // `Map::new` bounds the nesting, so this recursion is as shallow as the lookup's.
        match map.nodes[node as usize] {
            MapNode::Material(index) => {
                self.record(node, path, level, MapDecision::Material { index });
                Some((index, None))
            }
            MapNode::Voronoi(v) => {
                let cell = v.basis.nearest(self.p * v.inv_scale);
                let filled = v.filled(cell.id);
                self.trail.push(cell.id, filled && v.fill < 1.0);
                let entry = filled.then(|| v.pick(cell.id, &map.entries) as u32);
                let decision = MapDecision::Voronoi {
                    cell: cell.id,
                    filled,
                    fill: v.fill,
                    entry,
                    entries: v.count,
                    bump: v.bump.is_some(),
                };
                self.record(node, path, level, decision);
                let k = entry?;
                let child = map.entries[(v.first + k) as usize].node;
                let (m, facet) = self.visit(child, &format!("{path}.entries[{k}]"), level + 1)?;
                Some((m, facet.or_else(|| v.bump.map(|b| b.normal(cell.id)))))
            }
            MapNode::Overlay { under, over } => {
                let at = self.record(node, path, level, MapDecision::Overlay { over: true });
                if let Some(hit) = self.visit(over, &format!("{path}.over"), level + 1) {
                    return Some(hit);
                }
                self.steps[at].decision = MapDecision::Overlay { over: false };
                self.visit(under, &format!("{path}.under"), level + 1)
            }
            MapNode::Switch {
                field,
                first,
                count,
                blend,
            } => {
                let stops = &map.stops[first as usize..(first + count) as usize];
                let value = map.fields.eval(field, self.p);
                let half = 0.5 * blend;
                let in_band = blend > 0.0
                    && stops[1..]
                        .iter()
                        .any(|s| value >= s.threshold - half && value < s.threshold + half);
                let k = choose_stop(stops, value, blend, &mut self.u);
                let decision = MapDecision::Switch {
                    value,
                    stop: k as u32,
                    stops: count,
                    in_band,
                };
                self.record(node, path, level, decision);
                self.visit(stops[k].node, &format!("{path}.stops[{k}]"), level + 1)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::{FieldNode, Octaves};

    /// Materials 0–3: a sparse glitter Voronoi (material 2) over a dense one (0 or 1), under a
    /// switch on a Perlin field with a blend band whose upper stop is material 3.
    fn fixture() -> Map {
        let field = FieldNode::Fbm {
            inv_scale: 3.0,
            octaves: Octaves {
                octaves: 3,
                gain: 0.5,
                lacunarity: 2.0,
                seed: 7,
            },
        };
        crate::texture::fixtures::glitter_under_switch(field, 0.0, 0.2)
    }

    #[test]
    fn explanation_agrees_with_the_lookup() {
        let map = fixture();
        let mut seen = [0usize; 4];
        let (mut bands, mut uncovered) = (0, 0);
        for i in 0..5000u32 {
            let p = Vec3::new(
                (i % 71) as f32 * 0.029,
                (i / 71) as f32 * 0.017,
                (i % 13) as f32 * 0.05,
            );
            let u = ((i as f32) * 0.618_034).fract();
            let e = map.explain(p, u);
            assert_eq!(e.hit, map.lookup(p, u), "point {p}, u {u}");
            seen[e.hit.material as usize] += 1;
            // The walk ends at the leaf it reports.
            let last = e.steps.last().unwrap();
            assert_eq!(
                last.decision,
                MapDecision::Material {
                    index: e.hit.material
                }
            );
            assert_eq!(e.steps[0].path, "surface");
            match e.steps[0].decision {
                MapDecision::Switch { in_band, stop, .. } => {
                    bands += usize::from(in_band);
                    let want = if stop == 0 {
                        "surface.stops[0]"
                    } else {
                        "surface.stops[1]"
                    };
                    assert_eq!(e.steps[1].path, want);
                }
                ref d => panic!("root decided {d:?}"),
            }
            // Under the overlay: glitter covered the point exactly when material 2 shows.
            if let Some(o) = e
                .steps
                .iter()
                .find(|s| matches!(s.decision, MapDecision::Overlay { .. }))
            {
                let covered = o.decision == MapDecision::Overlay { over: true };
                assert_eq!(covered, e.hit.material == 2);
                uncovered += usize::from(!covered);
            }
        }
        assert!(seen.iter().all(|&n| n > 100), "{seen:?}");
        assert!(bands > 50 && uncovered > 500, "{bands} {uncovered}");
    }
}
