use crate::common::par_map;
use crate::support::{CUMULATIVE, HitKey, hit_key, octaves, rich_map, weighted_map};
use crate::{alpha_i, binomial_p, block_ids, normal_p, pearson, pick_probabilities, random_point};
use glam::Vec3;
use lapidary::sampler::{Rng, mix64, to_unit_f32};
use lapidary::texture::{FieldId, FieldNode, FieldTable, Voronoi};
use rayon::prelude::*;

// ------------------------------------------------------------------------------------------------
// 5. Determinism across threads
// ------------------------------------------------------------------------------------------------

/// The 200 × 200 grid of points (plane z = 0.37, `[−1.5, 1.5]²`) with one random `u` each.
fn grid_points() -> Vec<(Vec3, f32)> {
    let n = 200;
    (0..n * n)
        .map(|i| {
            let (x, y) = ((i % n) as f32, (i / n) as f32);
            let p = Vec3::new(
                -1.5 + 3.0 * x / (n - 1) as f32,
                -1.5 + 3.0 * y / (n - 1) as f32,
                0.37,
            );
            (p, to_unit_f32(mix64(i as u64 ^ 0x5eed)))
        })
        .collect()
}

/// The same 40 000 lookups sequentially, with rayon's global pool, with a 3-thread rayon pool and
/// with scoped threads (`par_map` over rows) agree bit for bit (material, facet bits, trail ids,
/// trail hash, glitter cell); so do two freshly built identical maps. Not vacuous: all four
/// materials, facets and stochastic switch bands (`u` matters somewhere) occur.
#[test]
fn lookups_are_deterministic_across_threads_and_builds() {
    let map = rich_map(0x55);
    let points = grid_points();
    let sequential: Vec<HitKey> = points
        .iter()
        .map(|&(p, u)| hit_key(&map.lookup(p, u)))
        .collect();
    let global: Vec<HitKey> = points
        .par_iter()
        .map(|&(p, u)| hit_key(&map.lookup(p, u)))
        .collect();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(3)
        .build()
        .expect("a thread pool");
    let pooled: Vec<HitKey> = pool.install(|| {
        points
            .par_iter()
            .with_min_len(7)
            .map(|&(p, u)| hit_key(&map.lookup(p, u)))
            .collect()
    });
    let rows: Vec<&[(Vec3, f32)]> = points.chunks(200).collect();
    let scoped: Vec<HitKey> = par_map(&rows, |row| {
        row.iter()
            .map(|&(p, u)| hit_key(&map.lookup(p, u)))
            .collect::<Vec<_>>()
    })
    .into_iter()
    .flatten()
    .collect();
    let again = rich_map(0x55);
    assert_eq!(map, again);
    let rebuilt: Vec<HitKey> = points
        .par_iter()
        .map(|&(p, u)| hit_key(&again.lookup(p, u)))
        .collect();
    for (name, other) in [
        ("rayon", &global),
        ("3-thread pool", &pooled),
        ("scoped threads", &scoped),
        ("rebuilt map", &rebuilt),
    ] {
        let diff = sequential
            .iter()
            .zip(other.iter())
            .position(|(a, b)| a != b);
        assert_eq!(diff, None, "{name} differs at point {diff:?}");
        assert_eq!(other.len(), sequential.len());
    }
    let mut materials = [0usize; 4];
    for k in &sequential {
        materials[k.0 as usize] += 1;
        assert!(k.1.is_some(), "every path ends under a bumped Voronoi");
    }
    assert!(materials.iter().all(|&c| c > 100), "{materials:?}");
    let u_matters = points
        .iter()
        .filter(|&&(p, _)| map.lookup(p, 0.01).material != map.lookup(p, 0.99).material)
        .count();
    assert!(u_matters > 100, "blend bands in use: {u_matters}");
    // A different seed is a different map.
    let other = rich_map(0x56);
    let same = points
        .iter()
        .filter(|&&(p, u)| hit_key(&other.lookup(p, u)) == hit_key(&map.lookup(p, u)))
        .count();
    assert!(same < points.len() / 100, "{same}");
}

// ------------------------------------------------------------------------------------------------
// 6. Different seeds decorrelate
// ------------------------------------------------------------------------------------------------

/// Voronoi maps with seeds 1 and 2 (weights 1 : 2 : 3 : 4, one cell per object unit) agree on the
/// material at 100 000 uniform points of a 10 000³ box (all in distinct cells with probability
/// 0.995) as often as independent picks do, `Σ pₖ² ≈ 0.30`: exact two-sided binomial test at
/// `α_i`. Negative control: seed 1 against itself at points moved by 0.1 cell agrees far more
/// often and is rejected at `α_i`. No cell id is shared between the seeds.
#[test]
fn voronoi_seeds_decorrelate() {
    let n = 100_000u64;
    let (a, b) = (weighted_map(1, 1.0, 1.0), weighted_map(2, 1.0, 1.0));
    let chance: f64 = pick_probabilities(&CUMULATIVE).iter().map(|p| p * p).sum();
    let mut rng = Rng::new(0x66);
    let (mut agree, mut agree_shifted) = (0u64, 0u64);
    for _ in 0..n {
        let p = random_point(&mut rng, -5000.0, 5000.0);
        let (ha, hb) = (a.lookup(p, 0.5), b.lookup(p, 0.5));
        assert_ne!(ha.trail.ids(), hb.trail.ids());
        agree += u64::from(ha.material == hb.material);
        let shifted = a.lookup(p + Vec3::new(0.1, 0.0, 0.0), 0.5);
        agree_shifted += u64::from(shifted.material == ha.material);
    }
    let p = binomial_p(agree, n, chance);
    let p_control = binomial_p(agree_shifted, n, chance);
    println!(
        "voronoi seeds 1, 2: {agree} of {n} agree (chance {chance:.4}), p {p:.3e}; \
         control (0.1-cell shift): {agree_shifted} agree, p {p_control:.3e}"
    );
    assert!(
        p >= alpha_i(),
        "seeds 1 and 2 agree {agree} of {n}: p = {p:e}"
    );
    assert!(p_control < alpha_i(), "the control was not detected");
    let (va, vb) = (Voronoi::new(1, 1.0), Voronoi::new(2, 1.0));
    let ids: std::collections::HashSet<u64> = block_ids(&va, 50_000).into_iter().collect();
    assert!(block_ids(&vb, 50_000).iter().all(|id| !ids.contains(id)));
}

/// fBm fields with seeds 1 and 2, and 3 and 1000 (same scale and octaves), sampled at 100 000
/// uniform points of a 2000³ box (points ≈ 40 lattice units apart, so the samples are
/// independent): `√n · r` is standard normal when the fields are independent; two-sided test at
/// `α_i` each. Negative control: fBm seed 1 against itself moved by 0.25 lattice units is
/// correlated and is rejected at `α_i`.
///
/// Also turbulence with seeds 1 and 2 (|noise| of every seed vanishes on the integer lattice, so
/// without the per-octave lattice offsets of `Octaves` these correlated at r ≈ 0.05), and fBm with
/// seed 1 at scale 1 against seed 2 at scale ½ (with octave seeds `seed + k` these shared four of
/// five octaves, r ≈ 0.5).
#[test]
fn perlin_seeds_decorrelate() {
    let n = 100_000;
    let mut t = FieldTable::default();
    let mut fbm = |seed| {
        t.add(FieldNode::Fbm {
            inv_scale: 1.0,
            octaves: octaves(seed),
        })
        .unwrap()
    };
    let mut ids: Vec<FieldId> = vec![fbm(1), fbm(2), fbm(3), fbm(1000)];
    for seed in [1, 2] {
        ids.push(
            t.add(FieldNode::Turbulence {
                inv_scale: 1.0,
                octaves: octaves(seed),
            })
            .unwrap(),
        );
    }
    ids.push(
        t.add(FieldNode::Fbm {
            inv_scale: 2.0,
            octaves: octaves(2),
        })
        .unwrap(),
    );
    let mut rng = Rng::new(0x67);
    let points: Vec<Vec3> = (0..n)
        .map(|_| random_point(&mut rng, -1000.0, 1000.0))
        .collect();
    let values = |id: FieldId, shift: Vec3| -> Vec<f64> {
        points
            .iter()
            .map(|&p| f64::from(t.eval(id, p + shift)))
            .collect()
    };
    let v: Vec<Vec<f64>> = ids.iter().map(|&id| values(id, Vec3::ZERO)).collect();
    let shifted = values(ids[0], Vec3::new(0.25, 0.0, 0.0));
    let sqrt_n = (n as f64).sqrt();
    for (label, x, y, independent) in [
        ("fbm seeds 1, 2", &v[0], &v[1], true),
        ("fbm seeds 3, 1000", &v[2], &v[3], true),
        ("turbulence seeds 1, 2", &v[4], &v[5], true),
        ("fbm seed 1 scale 1, seed 2 scale 1/2", &v[0], &v[6], true),
        ("control: fbm seed 1, 0.25 shift", &v[0], &shifted, false),
    ] {
        let r = pearson(x, y);
        let p = normal_p(r * sqrt_n);
        println!("{label:<36} r {r:+.5} (se {:.5}) p {p:.3e}", 1.0 / sqrt_n);
        assert!(x.iter().chain(y).all(|v| v.is_finite()));
        if independent {
            assert!(p >= alpha_i(), "{label}: r = {r}, p = {p:e}");
        } else {
            assert!(p < alpha_i(), "{label}: correlation not detected, r = {r}");
        }
    }
}
