use crate::common::par_map;
use crate::support::{hit_key, rich_map};
use glam::Vec3;
use lapidary::sampler::Rng;
use lapidary::texture::{FieldId, FieldNode, Voronoi};

// ------------------------------------------------------------------------------------------------
// 7. No NaN
// ------------------------------------------------------------------------------------------------

/// Awkward points: 0 and signed zeros, integers, integer multiples of the map's cell sizes
/// (1/8 and 1/40) and of the fields' lattice spacings, ±1e6 and its neighbours, huge mixed signs,
/// and 20 000 random points with log-uniform magnitudes 1e-6 … 1e6 and random signs.
fn awkward_points() -> Vec<Vec3> {
    let mut pts = vec![
        Vec3::ZERO,
        Vec3::splat(-0.0),
        Vec3::new(-0.0, 0.0, -0.0),
        Vec3::new(0.0, -0.0, 0.5),
        Vec3::splat(1e6),
        Vec3::splat(-1e6),
        Vec3::new(1e6, -1e6, 0.0),
        Vec3::new(-1e6, 1e6, -0.0),
        Vec3::new(1e6, 0.5, -1e6),
        Vec3::splat(999_999.94),
        Vec3::splat(-999_999.94),
        Vec3::new(999_999.9, -1e6, 1e6),
        Vec3::splat(f32::MIN_POSITIVE),
        Vec3::splat(-f32::MIN_POSITIVE),
        Vec3::splat(1e-30),
    ];
    for x in -3..=3 {
        for y in -3..=3 {
            for z in -3..=3 {
                let c = Vec3::new(x as f32, y as f32, z as f32);
                pts.push(c);
                for scale in [0.125f32, 0.025, 1.0 / 3.0, 0.2, 0.5] {
                    pts.push(c * scale);
                }
            }
        }
    }
    // Large integer multiples of the cell sizes, up to 1e6 object units.
    for (k, scale) in [
        (1e3f32, 0.125f32),
        (4e4, 0.025),
        (8e6, 0.125),
        (4e7, 0.025),
        (3e6, 1.0 / 3.0),
        (2e6, 0.5),
    ] {
        pts.push(Vec3::new(k, -k, k) * scale);
        pts.push(Vec3::new(k - 1.0, 1.0 - k, 0.0) * scale);
    }
    let mut rng = Rng::new(0x77);
    for _ in 0..20_000 {
        let mut p = Vec3::ZERO;
        for i in 0..3 {
            let mag = 10f32.powf(12.0 * rng.uniform() - 6.0);
            p[i] = if rng.uniform() < 0.5 { -mag } else { mag };
        }
        pts.push(p);
    }
    pts
}

/// At every awkward point and for `u ∈ {0, −0, 2⁻¹²⁶, ½, 1 − 2⁻²⁴, 1, NaN, ∞, −1}`: the material
/// is one of the map's, the facet is present, finite, unit and above the surface. Deterministic.
#[test]
fn lookups_stay_finite_at_awkward_points_and_u() {
    let map = rich_map(0x70);
    let us = [
        0.0f32,
        -0.0,
        f32::MIN_POSITIVE,
        0.5,
        1.0 - f32::EPSILON / 2.0,
        1.0,
        f32::NAN,
        f32::INFINITY,
        -1.0,
    ];
    let pts = awkward_points();
    let checked: Vec<usize> = par_map(&pts.chunks(512).collect::<Vec<_>>(), |chunk| {
        for &p in chunk.iter() {
            for u in us {
                let hit = map.lookup(p, u);
                assert!(hit.material <= 3, "{p:?} u={u}: {hit:?}");
                let f = hit.facet.expect("a facet");
                assert!(
                    f.is_finite() && (f.length() - 1.0).abs() < 1e-5 && f.z > 0.0,
                    "{p:?} u={u}: {hit:?}"
                );
                assert!(!hit.trail.ids().is_empty() && hit.trail.ids().len() <= 2);
            }
        }
        chunk.len()
    });
    assert_eq!(checked.iter().sum::<usize>(), pts.len());
    // u = 1 and NaN fall back to ½ — the same answers.
    for &p in pts.iter().take(500) {
        let half = hit_key(&map.lookup(p, 0.5));
        assert_eq!(hit_key(&map.lookup(p, 1.0)), half, "{p:?}");
        assert_eq!(hit_key(&map.lookup(p, f32::NAN)), half, "{p:?}");
    }
}

/// `Voronoi::sample` and `nearest` (jitter 0, ½, 1; positions in cell units at the map scales
/// 1, 8, 40, 1000 cells per unit) and every field node of [`rich_map`] (constant, fBm,
/// turbulence, marble, sums, a product, clamped and unclamped remaps) are finite at every awkward
/// point, with `F1 ≤ F2`, `edge ≥ 0` and `nearest` agreeing with `sample`. Deterministic.
#[test]
fn voronoi_and_fields_stay_finite_at_awkward_points() {
    let map = rich_map(0x71);
    let fields = &map.fields;
    let kinds: Vec<&'static str> = fields
        .nodes()
        .iter()
        .map(|n| match n {
            FieldNode::Constant(_) => "constant",
            FieldNode::Fbm { .. } => "fbm",
            FieldNode::Turbulence { .. } => "turbulence",
            FieldNode::Marble { .. } => "marble",
            FieldNode::Sum { .. } => "sum",
            FieldNode::Product { .. } => "product",
            FieldNode::Remap { .. } => "remap",
        })
        .collect();
    for kind in [
        "constant",
        "fbm",
        "turbulence",
        "marble",
        "sum",
        "product",
        "remap",
    ] {
        assert!(kinds.contains(&kind), "{kind} is not covered");
    }
    let pts = awkward_points();
    let bases = [
        Voronoi::new(1, 0.0),
        Voronoi::new(2, 0.5),
        Voronoi::new(3, 1.0),
    ];
    let chunks: Vec<&[Vec3]> = pts.chunks(512).collect();
    par_map(&chunks, |chunk| {
        for &p in chunk.iter() {
            for id in 0..fields.len() as FieldId {
                let v = fields.eval(id, p);
                assert!(
                    v.is_finite(),
                    "field {id} ({}) at {p:?}: {v}",
                    kinds[id as usize]
                );
            }
            for inv_scale in [1.0f32, 8.0, 40.0, 1000.0] {
                let q = p * inv_scale;
                for v in &bases {
                    let s = v.sample(q);
                    assert!(
                        s.f1.is_finite()
                            && s.f2.is_finite()
                            && s.edge.is_finite()
                            && s.feature.is_finite(),
                        "{q:?}: {s:?}"
                    );
                    assert!(s.f1 <= s.f2 && s.edge >= 0.0, "{q:?}: {s:?}");
                    let n = v.nearest(q);
                    assert_eq!((n.f1, n.cell, n.id), (s.f1, s.cell, s.id), "{q:?}");
                }
            }
        }
    });
}
