//! Test maps shared by the texture tests.

use super::map::tests::voronoi;
use super::map::{Entry, Map, MapNode, Stop};
use super::{FieldNode, FieldTable};

/// Materials 0–3: a sparse glitter Voronoi (material 2) over a dense one (0 or 1), both under a
/// switch on `field` with a band of width `blend` around `threshold` whose upper stop is
/// material 3.
pub(crate) fn glitter_under_switch(field: FieldNode, threshold: f32, blend: f32) -> Map {
    let nodes = vec![
        MapNode::Material(0),
        MapNode::Material(1),
        MapNode::Material(2),
        voronoi(0, 2, 1.0, 1),
        voronoi(2, 1, 0.25, 2),
        MapNode::Overlay { under: 3, over: 4 },
        MapNode::Material(3),
        MapNode::Switch {
            field: 0,
            first: 0,
            count: 2,
            blend,
        },
    ];
    let entry = |cumulative, node| Entry { cumulative, node };
    let entries = vec![entry(0.5, 0), entry(1.0, 1), entry(1.0, 2)];
    let mut fields = FieldTable::default();
    assert_eq!(fields.add(field).unwrap(), 0);
    let stops = vec![
        Stop {
            threshold: f32::NEG_INFINITY,
            node: 5,
        },
        Stop { threshold, node: 6 },
    ];
    Map::new(nodes, entries, stops, fields, 7).unwrap()
}
