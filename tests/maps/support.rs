use glam::Vec3;
use lapidary::texture::{
    Entry, FacetBump, FieldNode, FieldTable, Map, MapHit, MapNode, Octaves, Stop, Tilt, Voronoi,
    VoronoiNode,
};

// ------------------------------------------------------------------------------------------------
// Maps used by several tests
// ------------------------------------------------------------------------------------------------

/// Weights 1 : 2 : 3 : 4 as normalised cumulative weights.
pub(crate) const CUMULATIVE: [f32; 4] = [0.1, 0.3, 0.6, 1.0];
/// Materials of the four weighted entries, and of the background under a sparse map.
pub(crate) const ENTRY_MATERIALS: [u32; 4] = [10, 11, 12, 13];
pub(crate) const BACKGROUND: u32 = 99;
/// Index of the weighted Voronoi node in [`weighted_map`].
pub(crate) const WEIGHTED_NODE: usize = 7;

pub(crate) fn vnode(
    seed: u64,
    inv_scale: f32,
    (first, count): (u32, u32),
    fill: f32,
) -> VoronoiNode {
    VoronoiNode {
        basis: Voronoi::new(seed, 1.0),
        inv_scale,
        first,
        count,
        fill,
        bump: None,
    }
}

/// A Voronoi with entries weighted 1 : 2 : 3 : 4 (materials 10 … 13) and fill `fill`; for
/// `fill < 1` over the background material 99. Its entries start at index 2, after a decoy list
/// that a second (unreachable) Voronoi uses, so `first` is exercised.
pub(crate) fn weighted_map(seed: u64, fill: f32, inv_scale: f32) -> Map {
    let mut nodes: Vec<MapNode> = ENTRY_MATERIALS
        .iter()
        .map(|&m| MapNode::Material(m))
        .collect();
    nodes.push(MapNode::Material(BACKGROUND)); // 4
    nodes.push(MapNode::Material(98)); // 5: decoy
    let mut entries = vec![
        Entry {
            cumulative: 0.5,
            node: 5,
        },
        Entry {
            cumulative: 1.0,
            node: 4,
        },
    ];
    entries.extend(CUMULATIVE.iter().enumerate().map(|(k, &c)| Entry {
        cumulative: c,
        node: k as u32,
    }));
    nodes.push(MapNode::Voronoi(vnode(
        seed ^ 0xdec0,
        inv_scale,
        (0, 2),
        1.0,
    ))); // 6: decoy
    nodes.push(MapNode::Voronoi(vnode(seed, inv_scale, (2, 4), fill))); // 7
    let root = if fill < 1.0 {
        nodes.push(MapNode::Overlay { under: 4, over: 7 });
        8
    } else {
        7
    };
    Map::new(nodes, entries, vec![], FieldTable::default(), root).expect("a valid map")
}

pub(crate) fn voronoi_node(map: &Map, index: usize) -> VoronoiNode {
    match map.nodes[index] {
        MapNode::Voronoi(v) => v,
        ref other => panic!("node {index} is {other:?}"),
    }
}

pub(crate) fn octaves(seed: u32) -> Octaves {
    Octaves {
        octaves: 5,
        gain: 0.5,
        lacunarity: 2.0,
        seed,
    }
}

/// Materials 0 … 3 in a map that uses every node and field kind: a sparse glitter Voronoi
/// (Beckmann facets, material 3) over a dense surface Voronoi (cone facets) whose entries are two
/// switches with blend bands (over a remapped sum/product of fBm, turbulence, marble and a
/// constant, and over an unclamped remap of fBm) and a plain material.
pub(crate) fn rich_map(seed: u64) -> Map {
    let mut f = FieldTable::default();
    let c = f.add(FieldNode::Constant(0.3)).unwrap();
    let fbm = f
        .add(FieldNode::Fbm {
            inv_scale: 3.0,
            octaves: octaves(1),
        })
        .unwrap();
    let turb = f
        .add(FieldNode::Turbulence {
            inv_scale: 5.0,
            octaves: octaves(7),
        })
        .unwrap();
    let marble = f
        .add(FieldNode::Marble {
            inv_scale: 2.0,
            axis: Vec3::new(1.0, 2.0, 0.5).normalize(),
            turbulence: 1.5,
            octaves: octaves(9),
        })
        .unwrap();
    let (first, count) = f.add_args(&[fbm, turb, marble, c]);
    let sum = f.add(FieldNode::Sum { first, count }).unwrap();
    let (first, count) = f.add_args(&[turb, marble]);
    let prod = f.add(FieldNode::Product { first, count }).unwrap();
    let (first, count) = f.add_args(&[sum, prod]);
    let total = f.add(FieldNode::Sum { first, count }).unwrap();
    let remap = f
        .add(FieldNode::Remap {
            input: total,
            from: [-0.5, 2.5],
            to: [0.0, 1.0],
            clamp: true,
        })
        .unwrap();
    let free = f
        .add(FieldNode::Remap {
            input: fbm,
            from: [-1.0, 1.0],
            to: [0.0, 1.0],
            clamp: false,
        })
        .unwrap();
    let stop = |threshold: f32, node: u32| Stop { threshold, node };
    let stops = vec![
        stop(0.0, 0),
        stop(0.4, 1),
        stop(0.7, 2),
        stop(0.0, 1),
        stop(0.5, 0),
    ];
    let entry = |cumulative: f32, node: u32| Entry { cumulative, node };
    let entries = vec![entry(0.6, 4), entry(0.85, 5), entry(1.0, 2), entry(1.0, 3)];
    let nodes = vec![
        MapNode::Material(0),
        MapNode::Material(1),
        MapNode::Material(2),
        MapNode::Material(3),
        MapNode::Switch {
            field: remap,
            first: 0,
            count: 3,
            blend: 0.15,
        },
        MapNode::Switch {
            field: free,
            first: 3,
            count: 2,
            blend: 0.3,
        },
        MapNode::Voronoi(VoronoiNode {
            bump: Some(FacetBump {
                tilt: Tilt::Cone { half_angle: 12.0 },
            }),
            ..vnode(seed, 8.0, (0, 3), 1.0)
        }),
        MapNode::Voronoi(VoronoiNode {
            bump: Some(FacetBump {
                tilt: Tilt::Beckmann { rms: 20.0 },
            }),
            ..vnode(seed.wrapping_add(1), 40.0, (3, 1), 0.15)
        }),
        MapNode::Overlay { under: 6, over: 7 },
    ];
    Map::new(nodes, entries, stops, f, 8).expect("a valid map")
}

/// Everything of a hit, with the facet as bits (so `-0.0` and NaN payloads count).
pub(crate) type HitKey = (u32, Option<[u32; 3]>, Vec<u64>, u64, Option<u64>);

pub(crate) fn hit_key(h: &MapHit) -> HitKey {
    (
        h.material,
        h.facet
            .map(|f| [f.x.to_bits(), f.y.to_bits(), f.z.to_bits()]),
        h.trail.ids().to_vec(),
        h.trail.hash(),
        h.trail.glitter_cell(),
    )
}
