//! Claim 2, order independence: the platelets are a pure function of `(seed, cell)`, so what a
//! ray finds does not depend on the order cells are generated or walked in, nor on the thread
//! that renders it.

use super::{build, differences, gem, render_on};
use glam::{DVec3, Vec3};
use lapidary::platelet::grid::intersect;
use lapidary::platelet::{Orientation, Platelet, PlateletId, Population};
use lapidary::render::Strategy;
use lapidary::sampler::Rng;
use std::collections::HashMap;

/// Populations of the order tests: small uniform discs (2 per cell), touching discs (16 per cell,
/// all of radius 0.1 in cells of 0.22), and discs all perpendicular to x (spread 0).
fn populations() -> Vec<Population> {
    vec![
        Population::new(
            3000.0,
            (0.01, 0.03),
            Orientation::Uniform,
            vec![(0.5, 1), (1.0, 2)],
            41,
        )
        .unwrap(),
        Population::new(1500.0, (0.1, 0.1), Orientation::Uniform, vec![(1.0, 3)], 42).unwrap(),
        Population::new(
            400.0,
            (0.03, 0.08),
            Orientation::Aligned {
                axis: Vec3::X,
                spread: 0.0,
            },
            vec![(1.0, 4)],
            43,
        )
        .unwrap(),
    ]
}

/// A cell's platelets are the same whatever was generated before: 3 populations × 10³ cells,
/// generated x-fastest, then z-fastest backwards, then in a random order interleaving the
/// populations (each from a clone), and with `each_in_cell` stopping early at a random index
/// (the platelets seen are a prefix of the cell's list).
#[test]
fn cells_hold_the_same_platelets_in_any_order() {
    let pops = populations();
    let mut cells: Vec<[i32; 3]> = vec![];
    for x in -5..5 {
        for y in -5..5 {
            for z in -5..5 {
                cells.push([x, y, z]);
            }
        }
    }
    let mut buf = vec![];
    let mut reference: HashMap<(usize, [i32; 3]), Vec<Platelet>> = HashMap::new();
    for (k, p) in pops.iter().enumerate() {
        for &c in &cells {
            p.cell_platelets(c, &mut buf);
            reference.insert((k, c), buf.clone());
        }
    }
    let total: usize = reference.values().map(Vec::len).sum();
    assert!(total > 10_000, "{total} platelets");
    // Backwards, z fastest.
    let mut backwards = cells.clone();
    backwards.sort_by_key(|c| [c[0], c[1], c[2]]);
    backwards.reverse();
    for (k, p) in pops.iter().enumerate() {
        for &c in &backwards {
            p.cell_platelets(c, &mut buf);
            assert_eq!(
                buf,
                reference[&(k, c)],
                "population {k} cell {c:?} backwards"
            );
        }
    }
    // Random order, populations interleaved, from clones.
    let clones = pops.clone();
    let mut rng = Rng::new(0x0d3e);
    let mut jobs: Vec<(usize, [i32; 3])> = (0..pops.len())
        .flat_map(|k| cells.iter().map(move |&c| (k, c)))
        .collect();
    for i in (1..jobs.len()).rev() {
        let j = ((rng.uniform() * (i + 1) as f32) as usize).min(i);
        jobs.swap(i, j);
    }
    for &(k, c) in &jobs {
        clones[k].cell_platelets(c, &mut buf);
        assert_eq!(
            buf,
            reference[&(k, c)],
            "population {k} cell {c:?} shuffled"
        );
        // Stopping early sees a prefix.
        let stop = (rng.uniform() * 4.0) as u32;
        let mut seen = vec![];
        clones[k].each_in_cell(c, |i, p| {
            assert_eq!(i as usize, seen.len());
            seen.push(p);
            i == stop
        });
        assert_eq!(
            seen[..],
            reference[&(k, c)][..seen.len()],
            "population {k} cell {c:?} prefix"
        );
        assert_eq!(seen.len(), reference[&(k, c)].len().min(stop as usize + 1));
    }
}

/// Every disc crossing `o + t d`, `0 < t < len`, in order, by repeated nearest hits (each from the
/// last hit, skipping the platelet it is on).
fn walk_all(pops: &[Population], o: Vec3, d: Vec3, len: f32) -> Vec<(PlateletId, f32)> {
    let mut out = vec![];
    let (mut t, mut skip) = (0.0, None);
    while let Some(h) = intersect(pops, o, d, t, len, skip) {
        assert!(h.t > t && h.t < len, "hit at {} outside ({t}, {len})", h.t);
        out.push((h.id, h.t));
        assert!(out.len() < 10_000, "the walk does not end");
        t = h.t;
        skip = Some(h.id);
    }
    out
}

/// Every disc crossing the segment by brute force in f64 over the cells of its bounding box, and
/// whether each is ambiguous for an f32 walk (hit within 1e-4 of its rim, of an end, or at a
/// grazing angle).
fn brute_all(pops: &[Population], o: Vec3, d: Vec3, len: f32) -> Vec<(PlateletId, f64, bool)> {
    let (o64, d64, len64) = (o.as_dvec3(), d.as_dvec3(), f64::from(len));
    let mut out = vec![];
    let mut buf = vec![];
    for (k, pop) in pops.iter().enumerate() {
        let (a, b) = (o, o + d * len);
        let lo = (a.min(b) / pop.cell).floor() - 1.0;
        let hi = (a.max(b) / pop.cell).floor() + 1.0;
        for x in lo.x as i32..=hi.x as i32 {
            for y in lo.y as i32..=hi.y as i32 {
                for z in lo.z as i32..=hi.z as i32 {
                    pop.cell_platelets([x, y, z], &mut buf);
                    for (i, p) in buf.iter().enumerate() {
                        let (c, n, r) = (
                            p.center.as_dvec3(),
                            p.normal.as_dvec3(),
                            f64::from(p.radius),
                        );
                        let dn = d64.dot(n);
                        if dn == 0.0 {
                            continue;
                        }
                        let t = (c - o64).dot(n) / dn;
                        let q = (o64 + d64 * t - c).length();
                        let near_rim = (q - r).abs() < 1e-4 * r.max(1e-3);
                        let near_end = t.abs() < 1e-4 || (t - len64).abs() < 1e-4;
                        let grazing = dn.abs() < 1e-4 * d64.length();
                        if (q <= r || near_rim) && t > -1e-4 && t < len64 + 1e-4 {
                            let id = PlateletId {
                                population: k as u32,
                                cell: [x, y, z],
                                index: i as u32,
                            };
                            out.push((id, t, near_rim || near_end || grazing));
                        }
                    }
                }
            }
        }
    }
    out
}

/// A segment walked forward and backward crosses the same discs at matching distances, and
/// they are the discs an f64 brute force finds (up to hits within 1e-4 of a rim or an end). The
/// three populations together (nearest over populations), 600 segments: 400 random (length up
/// to 2, ≈ 9 cells of the touching population), 100 along the axes (the aligned discs face-on or
/// edge-on), 100 starting on cell corners and faces (`o` a multiple of a cell).
#[test]
fn forward_and_backward_walks_cross_the_same_discs() {
    let pops = populations();
    let mut rng = Rng::new(0xbac4);
    let mut segments: Vec<(Vec3, Vec3, f32)> = vec![];
    let unit = |rng: &mut Rng| {
        let z = 1.0 - 2.0 * rng.uniform();
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = std::f32::consts::TAU * rng.uniform();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    };
    for _ in 0..400 {
        let o = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - 1.0;
        segments.push((o, unit(&mut rng), 0.1 + 1.9 * rng.uniform()));
    }
    let axes = [
        Vec3::X,
        Vec3::NEG_X,
        Vec3::Y,
        Vec3::NEG_Y,
        Vec3::Z,
        Vec3::NEG_Z,
    ];
    for i in 0..100 {
        let o = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - 1.0;
        segments.push((o, axes[i % 6], 1.5));
    }
    for i in 0..100 {
        let cell = pops[i % 3].cell;
        let k = Vec3::new(
            (rng.uniform() * 8.0).floor(),
            (rng.uniform() * 8.0).floor(),
            (rng.uniform() * 8.0).floor(),
        ) - 4.0;
        let mut o = k * cell;
        if i % 2 == 1 {
            o.y += 0.37 * cell; // on an x and a z face only
        }
        segments.push((o, unit(&mut rng), 1.2));
    }
    let (mut hits, mut ambiguous) = (0usize, 0usize);
    for (s, &(o, d, len)) in segments.iter().enumerate() {
        let fwd = walk_all(&pops, o, d, len);
        let back = walk_all(&pops, o + d * len, -d, len);
        let brute = brute_all(&pops, o, d, len);
        hits += fwd.len();
        let what = || format!("segment {s}: o {o} d {d} len {len}");
        // Ordered, and each id once.
        assert!(fwd.windows(2).all(|w| w[0].1 <= w[1].1), "{}", what());
        let mut ids: Vec<PlateletId> = fwd.iter().map(|h| h.0).collect();
        ids.sort_by_key(|i| (i.population, i.cell, i.index));
        ids.dedup();
        assert_eq!(ids.len(), fwd.len(), "{}: a disc hit twice", what());
        let fwd_map: HashMap<PlateletId, f32> = fwd.iter().copied().collect();
        let back_map: HashMap<PlateletId, f32> = back.iter().copied().collect();
        for (id, t, amb) in &brute {
            let in_f = fwd_map.get(id);
            let in_b = back_map.get(id);
            match (in_f, in_b) {
                (Some(tf), Some(tb)) => {
                    assert!(
                        (f64::from(*tf) - t).abs() < 1e-4,
                        "{}: {id:?} at {tf} forward, {t} in f64",
                        what()
                    );
                    assert!(
                        (f64::from(len - *tb) - t).abs() < 1e-4,
                        "{}: {id:?} at {tb} backward, {t} in f64",
                        what()
                    );
                }
                _ if *amb => ambiguous += 1,
                _ => panic!(
                    "{}: {id:?} at t {t} (f64): forward {in_f:?}, backward {in_b:?}",
                    what()
                ),
            }
        }
        let known: std::collections::HashSet<PlateletId> = brute.iter().map(|b| b.0).collect();
        for (id, t) in fwd.iter().chain(&back) {
            assert!(
                known.contains(id),
                "{}: walk hit {id:?} at {t}, brute force does not",
                what()
            );
        }
    }
    println!(
        "{} segments: {hits} disc crossings, {ambiguous} within 1e-4 of a rim or an end",
        segments.len()
    );
    assert!(hits > 3_000, "too few hits for a test: {hits}");
    assert!(ambiguous * 100 < hits, "{ambiguous} ambiguous of {hits}");
    // The same disc reached from both ends: a direct check of one long segment through the touching
    // population, as DVec3 sums of the crossing points.
    let (o, d) = (
        Vec3::new(-0.9, -0.7, -0.8),
        Vec3::new(1.0, 0.8, 0.9).normalize(),
    );
    let f = walk_all(&pops[1..2], o, d, 2.5);
    let b = walk_all(&pops[1..2], o + d * 2.5, -d, 2.5);
    let mut bf: Vec<PlateletId> = b.iter().rev().map(|h| h.0).collect();
    let ff: Vec<PlateletId> = f.iter().map(|h| h.0).collect();
    // Hits at equal distances may swap places; compare as sets and in order where distinct.
    assert!(f.len() > 20, "{} hits", f.len());
    let pf: DVec3 = f.iter().map(|h| (o + d * h.1).as_dvec3()).sum();
    let pb: DVec3 = b.iter().map(|h| (o + d * 2.5 - d * h.1).as_dvec3()).sum();
    assert!((pf - pb).length() < 1e-3, "{pf} vs {pb}");
    bf.sort_by_key(|i| (i.population, i.cell, i.index));
    let mut fs = ff.clone();
    fs.sort_by_key(|i| (i.population, i.cell, i.index));
    assert_eq!(fs, bf);
}

/// A platelet scene renders bit-identically on 1 and 2 threads: copper (rough) and mirror
/// platelets in two populations (uniform, and aligned 10° about a tilted axis) in a rough,
/// scattering cabochon on the studio stage (floor, gradient sky, three area lights, the recipe's
/// Sobol' sampler and Gaussian filter); 24 × 16 pixels, 8 spp. Every field of every pixel must be
/// equal as bits, and so must the ray counts. The platelets are seen: with them forced off, more
/// than 20 pixels change.
#[test]
fn platelet_render_is_bit_identical_across_thread_counts() {
    let body = "(ior: 1.54, alpha: 0.05, medium: (scattering: (0.5, 0.7, 1.0), phase: HenyeyGreenstein(g: 0.6)),
                platelets: [
                  (density: 3000.0, radius: (0.01, 0.03), orientation: Uniform,
                   entries: [(2.0, \"copper\"), (1.0, \"mirror\")]),
                  (density: 400.0, radius: (0.02, 0.05), orientation: Aligned(axis: (0.3, 1.0, 0.1), spread: 10.0),
                   entries: [(1.0, \"copper_smooth\")], seed: 5),
                ])";
    let stage = "(render: (width: 24, height: 16, spp: 8, max_depth: 48))";
    let (scene, world) = build(&gem(body, stage));
    assert_eq!(world.platelets.len(), 2);
    let one = render_on(&world, &scene, 1, Strategy::Mis);
    let two = render_on(&world, &scene, 2, Strategy::Mis);
    assert!(one.film.samples() == 24 * 16 * 8 && one.stats.dropped == 0);
    let (n, first) = differences(&one.film, &two.film);
    assert_eq!(
        n, 0,
        "{n} pixels differ between 1 and 2 threads; first: {first:?}"
    );
    assert_eq!(one.stats.rays, two.stats.rays);
    // The platelets are in the picture.
    let mut off = super::scene(&gem(body, stage));
    let mut acc = lapidary::scene::Accuracy::default();
    acc.force(lapidary::scene::Effect::Platelets, false);
    off.set_accuracy(&acc, "tests/platelets").unwrap();
    let world_off = lapidary::render::World::new(&off).unwrap();
    assert!(world_off.platelets.is_empty());
    let (changed, _) = differences(
        &one.film,
        &render_on(&world_off, &off, 2, Strategy::Mis).film,
    );
    println!("platelets forced off: {changed} of 384 pixels change");
    assert!(changed > 20, "only {changed} pixels show the platelets");
}
