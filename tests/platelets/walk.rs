//! Claim 7, the walk is exact: `grid::intersect` (each cell generated once per walk, a
//! bounding-sphere test before the plane test, the walk ended at the first cell whose exit lies
//! beyond the nearest hit) returns, bit for bit, the hit a brute force finds — every disc of every
//! cell of the segment's bounding box grown by one cell, tested with the same ray–disc arithmetic,
//! the nearest `t` in `(t_min, t_max]` kept, ties to the smaller id. Same `t` bits, normal bits,
//! material and id, or no hit in both.
//!
//! Rays, for each of five populations (the aventurine glass's, the Oregon sunstone's, touching
//! discs, `min == max` radii at spread 0, a 90° cone) and for the five together: random short
//! segments, segments through a 2-unit stone, axis-aligned rays from cell corners, grazing rays (in
//! a disc's plane or tilted from it by 10⁻³ … 10⁻⁷ rad, across the disc), and rays that start on a
//! disc (skipping it, from `t_min = 0` and from a `t_min` on the ray). The walk of the previous
//! version (each cell's discs and its neighbours' regenerated for every cell, hits kept only inside
//! the cell) is kept here as `old_walk`: the test prints how many queries it differs from the
//! brute force on (0 on this sweep, so the new walk changes no result of the old).

use glam::Vec3;
use lapidary::platelet::grid::intersect;
use lapidary::platelet::{Orientation, Platelet, PlateletHit, PlateletId, Population};
use lapidary::sampler::Rng;

/// The populations of the sweep.
fn populations() -> Vec<Population> {
    let aligned = |axis: Vec3, spread: f32| Orientation::Aligned {
        axis: axis.normalize(),
        spread: spread.to_radians(),
    };
    vec![
        Population::new(
            8000.0,
            (0.01, 0.04),
            Orientation::Uniform,
            vec![(1.0, 7)],
            1,
        ),
        Population::new(
            800.0,
            (0.015, 0.04),
            aligned(Vec3::Y, 4.0),
            vec![(1.0, 8)],
            2,
        ),
        Population::new(
            1500.0,
            (0.1, 0.1),
            Orientation::Uniform,
            vec![(0.5, 1), (1.0, 2)],
            3,
        ),
        Population::new(
            200.0,
            (0.05, 0.05),
            aligned(Vec3::X, 0.0),
            vec![(1.0, 3)],
            4,
        ),
        Population::new(
            900.0,
            (0.02, 0.05),
            aligned(Vec3::new(1.0, 1.0, 0.0), 90.0),
            vec![(1.0, 4)],
            5,
        ),
    ]
    .into_iter()
    .map(|p| p.expect("population"))
    .collect()
}

/// The ray–disc test of `grid.rs`, operation for operation.
fn hit_disc(p: &Platelet, o: Vec3, d: Vec3, t_min: f32, t_max: f32) -> Option<f32> {
    let dn = d.dot(p.normal);
    if dn.abs() < 1e-12 {
        return None;
    }
    let t = (p.center - o).dot(p.normal) / dn;
    if !(t > t_min && t <= t_max) {
        return None;
    }
    let q = o + d * t - p.center;
    (q.length_squared() <= p.radius * p.radius).then_some(t)
}

/// The nearest hit over every disc of every cell of the segment's bounding box grown by a cell.
fn brute(
    pops: &[Population],
    o: Vec3,
    d: Vec3,
    t_min: f32,
    t_max: f32,
    skip: Option<PlateletId>,
) -> Option<PlateletHit> {
    let mut best: Option<PlateletHit> = None;
    let mut buf = vec![];
    for (k, pop) in pops.iter().enumerate() {
        let (a, b) = (o + d * t_min, o + d * t_max);
        let lo = (a.min(b) / pop.cell).floor() - 1.0;
        let hi = (a.max(b) / pop.cell).floor() + 1.0;
        for x in lo.x as i32..=hi.x as i32 {
            for y in lo.y as i32..=hi.y as i32 {
                for z in lo.z as i32..=hi.z as i32 {
                    pop.cell_platelets([x, y, z], &mut buf);
                    for (i, p) in buf.iter().enumerate() {
                        let id = PlateletId {
                            population: k as u32,
                            cell: [x, y, z],
                            index: i as u32,
                        };
                        if skip == Some(id) {
                            continue;
                        }
                        let Some(t) = hit_disc(p, o, d, t_min, t_max) else {
                            continue;
                        };
                        if best.is_none_or(|h| t < h.t || (t == h.t && id < h.id)) {
                            best = Some(PlateletHit {
                                t,
                                normal: p.normal,
                                material: p.material,
                                id,
                            });
                        }
                    }
                }
            }
        }
    }
    best
}

/// The previous version's walk: in each cell, the discs of the cell and of the neighbours its part
/// of the segment comes within `r_max` of, regenerated for every cell; hits kept inside the cell.
fn old_walk(
    pops: &[Population],
    o: Vec3,
    d: Vec3,
    t_min: f32,
    t_max: f32,
    skip: Option<PlateletId>,
) -> Option<PlateletHit> {
    let mut best: Option<PlateletHit> = None;
    for (k, pop) in pops.iter().enumerate() {
        let limit = best.map_or(t_max, |h| h.t);
        if let Some(h) = old_one(pop, k as u32, o, d, t_min, limit, skip) {
            best = Some(h);
        }
    }
    best
}

#[allow(clippy::neg_cmp_op_on_partial_ord)]
fn old_one(
    pop: &Population,
    index: u32,
    o: Vec3,
    d: Vec3,
    t_min: f32,
    t_max: f32,
    skip: Option<PlateletId>,
) -> Option<PlateletHit> {
    if !(t_max > t_min) {
        return None;
    }
    let (cell, reach, start) = (pop.cell, pop.radius.1, o + d * t_min);
    let mut c = (start / cell).floor();
    let step = d.signum();
    let (mut t_next, mut t_delta) = (Vec3::INFINITY, Vec3::INFINITY);
    for a in 0..3 {
        if d[a] != 0.0 {
            let boundary = (c[a] + if d[a] > 0.0 { 1.0 } else { 0.0 }) * cell;
            t_next[a] = t_min + (boundary - start[a]) / d[a];
            t_delta[a] = cell / d[a].abs();
        }
    }
    let mut t_enter = t_min;
    for _ in 0..1 << 16 {
        let t_exit = t_next.min_element().min(t_max);
        let (p0, p1) = (o + d * t_enter, o + d * t_exit);
        let (lo, hi, low) = (p0.min(p1), p0.max(p1), c * cell);
        let mut found: Option<PlateletHit> = None;
        for dx in if lo.x - low.x < reach { -1 } else { 0 }..=if low.x + cell - hi.x < reach {
            1
        } else {
            0
        } {
            for dy in if lo.y - low.y < reach { -1 } else { 0 }..=if low.y + cell - hi.y < reach {
                1
            } else {
                0
            } {
                for dz in if lo.z - low.z < reach { -1 } else { 0 }
                    ..=if low.z + cell - hi.z < reach { 1 } else { 0 }
                {
                    let ci = [c.x as i32 + dx, c.y as i32 + dy, c.z as i32 + dz];
                    pop.each_in_cell(ci, |i, p| {
                        let id = PlateletId {
                            population: index,
                            cell: ci,
                            index: i,
                        };
                        let hi_t = found.map_or(t_exit, |h| h.t);
                        if skip != Some(id)
                            && let Some(t) = hit_disc(&p, o, d, t_enter.max(t_min), hi_t)
                        {
                            found = Some(PlateletHit {
                                t,
                                normal: p.normal,
                                material: p.material,
                                id,
                            });
                        }
                        false
                    });
                }
            }
        }
        if found.is_some() || t_exit >= t_max {
            return found;
        }
        let a = if t_next.x <= t_next.y && t_next.x <= t_next.z {
            0
        } else if t_next.y <= t_next.z {
            1
        } else {
            2
        };
        t_enter = t_next[a];
        c[a] += step[a];
        t_next[a] += t_delta[a];
    }
    None
}

fn unit(rng: &mut Rng) -> Vec3 {
    let z = 1.0 - 2.0 * rng.uniform();
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * rng.uniform();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// A random disc near the origin: its id and platelet.
fn some_disc(pops: &[Population], k: usize, rng: &mut Rng) -> Option<(PlateletId, Platelet)> {
    let pop = &pops[k];
    let mut buf = vec![];
    let c =
        ((Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - 1.0) / pop.cell).floor();
    let cell = [c.x as i32, c.y as i32, c.z as i32];
    pop.cell_platelets(cell, &mut buf);
    let i = ((rng.uniform() * buf.len() as f32) as usize).min(buf.len().checked_sub(1)?);
    Some((
        PlateletId {
            population: k as u32,
            cell,
            index: i as u32,
        },
        buf[i],
    ))
}

/// Unit vectors spanning the plane of `n`.
fn plane_of(n: Vec3) -> (Vec3, Vec3) {
    let a = if n.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
    let u = n.cross(a).normalize();
    (u, n.cross(u))
}

/// One query: `(kind, o, d, t_min, t_max, skip)`; `d` is not necessarily unit.
type Query = (&'static str, Vec3, Vec3, f32, f32, Option<PlateletId>);

/// The sweep's queries against `pops` (populations `0..pops.len()` for the disc-based kinds).
fn queries(pops: &[Population], rng: &mut Rng, n: usize) -> Vec<Query> {
    let mut out = vec![];
    for _ in 0..n {
        let o = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - 1.0;
        let d = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - 1.0;
        out.push(("random", o, d, 0.0, 0.6 * rng.uniform() + 1e-3, None));
        let o = unit(rng);
        let d = {
            let v = unit(rng);
            if v.dot(o) > 0.0 { -v } else { v }
        };
        if out.len() % 4 == 1 {
            // Through a 2-unit stone (`d` of length ½: `t` runs to twice the chord's length).
            out.push(("chord", o, d * 0.5, 0.0, -4.0 * o.dot(d), None));
        }
        let cell = pops[0].cell;
        let corner =
            (Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 20.0 - 10.0).floor() * cell;
        let axis = [Vec3::X, Vec3::NEG_Y, Vec3::Z][out.len() % 3];
        out.push(("axis", corner, axis, 0.0, 0.8, None));
        let k = (rng.uniform() * pops.len() as f32) as usize % pops.len();
        let Some((id, p)) = some_disc(pops, k, rng) else {
            continue;
        };
        let (u, v) = plane_of(p.normal);
        let phi = std::f32::consts::TAU * rng.uniform();
        let across = u * phi.cos() + v * phi.sin();
        let tilt = [0.0, 1e-3, 1e-5, 1e-7][out.len() % 4];
        let off = (u * rng.uniform() + v * rng.uniform()) * p.radius;
        let d = (across + p.normal * tilt).normalize();
        out.push((
            "grazing",
            p.center + off - across * 2.0 * p.radius,
            d,
            0.0,
            4.0 * p.radius + 0.2,
            None,
        ));
        let on = p.center + (u * phi.sin() - v * phi.cos()) * p.radius * rng.uniform().sqrt();
        let d = unit(rng);
        out.push(("on-disc", on, d, 0.0, 0.5, Some(id)));
        out.push(("on-disc", on - d * 0.1, d, 0.1, 0.6, Some(id)));
    }
    out
}

/// Field-by-field bit comparison of two answers.
fn same(a: &Option<PlateletHit>, b: &Option<PlateletHit>) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some(a), Some(b)) => {
            a.t.to_bits() == b.t.to_bits()
                && a.normal.to_array().map(f32::to_bits) == b.normal.to_array().map(f32::to_bits)
                && a.material == b.material
                && a.id == b.id
        }
        _ => false,
    }
}

/// About 9 000 queries per population and 2 000 for all five together: the walk equals the brute
/// force, bit for bit, on every one, and a fair share of them hit.
#[test]
fn the_walk_is_the_brute_force_bit_for_bit() {
    let pops = populations();
    let mut rng = Rng::new(0x3a1c);
    let mut old_differs = 0usize;
    let mut sets: Vec<(String, Vec<Population>, usize)> = pops
        .iter()
        .enumerate()
        .map(|(k, p)| (format!("population {k}"), vec![p.clone()], 1500))
        .collect();
    sets.push(("all five".into(), pops.clone(), 300));
    for (name, set, n) in &sets {
        let qs = queries(set, &mut rng, *n);
        let mut hits = 0;
        for &(kind, o, d, t_min, t_max, skip) in &qs {
            let walked = intersect(set, o, d, t_min, t_max, skip);
            let reference = brute(set, o, d, t_min, t_max, skip);
            assert!(
                same(&walked, &reference),
                "{name} {kind}: o {o} d {d} t ({t_min}, {t_max}] skip {skip:?}:\n  walk  {walked:?}\n  brute {reference:?}"
            );
            if !same(&old_walk(set, o, d, t_min, t_max, skip), &reference) {
                old_differs += 1;
                eprintln!("{name} {kind}: the old walk differs: o {o} d {d}");
            }
            hits += usize::from(reference.is_some());
        }
        assert!(
            hits * 5 > qs.len(),
            "{name}: only {hits} of {} queries hit",
            qs.len()
        );
        eprintln!("{name}: {} queries, {hits} hits", qs.len());
    }
    eprintln!("the old walk differed from the brute force on {old_differs} queries");
}

/// A stone too large for a population's walk (its diagonal spans more cells than a walk visits)
/// is an error, never a walk that silently stops early: when the recipe is compiled for an
/// analytic shape (tests/recipe_errors.rs, row `platelets_stone_too_large`), and when the world is
/// built for a mesh (whose size the recipe does not know) or for platelets made explicit after
/// compiling. Cells of 0.00585 (10⁷ per unit³): a 200-unit cube spans 102 598 of them, a sphere of
/// radius 60 spans 61 558 (built), one of radius 200 spans 205 198.
#[test]
fn a_stone_too_large_for_the_walk_is_refused() {
    use lapidary::render::{World, WorldError};
    let pops = r#"(ior: 1.5, platelets: [(density: 10000000.0, radius: (0.001, 0.002),
        orientation: Uniform, entries: [(1.0, "mirror")])])"#;
    let refused = |e: Result<World, WorldError>, what: &str| match e {
        Err(e @ WorldError::PlateletSpan(_)) => {
            let msg = e.to_string();
            assert!(
                msg.contains("body.platelets[0]: the stone spans")
                    && msg.contains("platelet cells along its diagonal, at most 65533"),
                "{what}: {msg}"
            );
        }
        Err(e) => panic!("{what}: another error: {e}"),
        Ok(_) => panic!("{what}: the world was built"),
    };
    let cube = super::scene(&super::gem(
        pops,
        r#"(shape: Mesh(file: "tests/data/cube.obj", scale: 100.0))"#,
    ));
    refused(World::new(&cube), "a 200-unit cube mesh");
    let mut big = super::scene(&super::gem(
        pops,
        "(shape: Sphere(radius: 200.0), render: (platelets: Statistical))",
    ));
    assert!(
        World::new(&big).is_ok(),
        "statistical platelets walk no cells"
    );
    big.stage.render.platelets_explicit = true;
    refused(World::new(&big), "a sphere of radius 200, explicit");
    let fits = super::scene(&super::gem(pops, "(shape: Sphere(radius: 60.0))"));
    assert!(World::new(&fits).is_ok(), "a sphere of radius 60 fits");
}
