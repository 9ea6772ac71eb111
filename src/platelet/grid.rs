//! Walking a ray through the platelet grid (3-D DDA, Amanatides & Woo 1987) and hitting discs.
//!
//! The walk sees exactly the platelets [`Population::each_in_cell`] gives (thinned when the
//! population's density is modulated); the cells, and so the walk's steps, are those of the
//! unmodulated population.

use super::{PlateletHit, PlateletId, Population};
use glam::Vec3;

/// Most cells one walk visits (the recipe compiler keeps a stone within far fewer cells across).
pub const MAX_CELLS: u32 = 1 << 16;

/// The nearest platelet of any population along `o + t d` with `t_min < t < t_max` (object space;
/// `d` need not be unit: `t` is the caller's parameter), skipping platelet `skip` (the one a ray
/// leaves from).
pub fn intersect(
    populations: &[Population],
    o: Vec3,
    d: Vec3,
    t_min: f32,
    t_max: f32,
    skip: Option<PlateletId>,
) -> Option<PlateletHit> {
    let mut best: Option<PlateletHit> = None;
    for (k, pop) in populations.iter().enumerate() {
        let limit = best.map_or(t_max, |h| h.t);
        if let Some(h) = walk(pop, k as u32, o, d, t_min, limit, skip) {
            best = Some(h);
        }
    }
    best
}

/// Ray–disc intersection: the ray parameter in `(t_min, t_max)`, if any.
#[inline]
fn hit_disc(
    center: Vec3,
    normal: Vec3,
    radius: f32,
    o: Vec3,
    d: Vec3,
    t_min: f32,
    t_max: f32,
) -> Option<f32> {
    let dn = d.dot(normal);
    if dn.abs() < 1e-12 {
        return None;
    }
    let t = (center - o).dot(normal) / dn;
    if !(t > t_min && t < t_max) {
        return None;
    }
    let q = o + d * t - center;
    (q.length_squared() <= radius * radius).then_some(t)
}

/// One population's walk: in each cell along the segment, the discs of the cell and of the
/// neighbours within `r_max` of the segment's part in it; hits are kept only inside the cell, so
/// the first cell with one holds the nearest.
fn walk(
    pop: &Population,
    index: u32,
    o: Vec3,
    d: Vec3,
    t_min: f32,
    t_max: f32,
    skip: Option<PlateletId>,
) -> Option<PlateletHit> {
    if !(t_max > t_min) || !d.is_finite() || !o.is_finite() {
        return None;
    }
    let cell = pop.cell;
    let reach = pop.radius.1;
    let start = o + d * t_min;
    let mut c = (start / cell).floor();
    let step = d.signum();
    let mut t_next = Vec3::ZERO;
    let mut t_delta = Vec3::ZERO;
    for a in 0..3 {
        if d[a] == 0.0 {
            t_next[a] = f32::INFINITY;
            t_delta[a] = f32::INFINITY;
        } else {
            let boundary = (c[a] + if d[a] > 0.0 { 1.0 } else { 0.0 }) * cell;
            t_next[a] = t_min + (boundary - start[a]) / d[a];
            t_delta[a] = cell / d[a].abs();
        }
    }
    let mut t_enter = t_min;
    for _ in 0..MAX_CELLS {
        let t_exit = t_next.min_element().min(t_max);
        // The segment's part in this cell, and the neighbours it comes within `reach` of.
        let (p0, p1) = (o + d * t_enter, o + d * t_exit);
        let (lo, hi) = (p0.min(p1), p0.max(p1));
        let low = c * cell;
        let mut range = [[0i32; 2]; 3];
        for a in 0..3 {
            range[a][0] = if lo[a] - low[a] < reach { -1 } else { 0 };
            range[a][1] = if low[a] + cell - hi[a] < reach { 1 } else { 0 };
        }
        let mut found: Option<PlateletHit> = None;
        for dx in range[0][0]..=range[0][1] {
            for dy in range[1][0]..=range[1][1] {
                for dz in range[2][0]..=range[2][1] {
                    let ci = [c.x as i32 + dx, c.y as i32 + dy, c.z as i32 + dz];
                    // Every drawn disc is tested; only a hit asks whether the disc survived
                    // thinning (the modulation's field is evaluated for hits alone).
                    pop.each_drawn(ci, |k, p| {
                        let id = PlateletId {
                            population: index,
                            cell: ci,
                            index: k,
                        };
                        if skip == Some(id) {
                            return false;
                        }
                        // Hits inside this cell only: `t_enter ≤ t ≤ t_exit`.
                        let lo_t = t_enter.max(t_min);
                        let hi_t = found.map_or(t_exit, |h| h.t);
                        if let Some(t) =
                            hit_disc(p.center, p.normal, p.radius, o, d, lo_t, hi_t * 1.000_001)
                            && t <= hi_t.max(lo_t)
                            && pop.kept(ci, k, &p)
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
        if found.is_some() {
            return found;
        }
        if t_exit >= t_max {
            return None;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::platelet::{Orientation, Platelet};
    use crate::sampler::Rng;

    /// The walk finds the same nearest hit as testing every platelet of every cell the segment's
    /// bounding box touches.
    #[test]
    fn walk_matches_brute_force() {
        let pop =
            Population::new(400.0, (0.02, 0.06), Orientation::Uniform, vec![(1.0, 0)], 3).unwrap();
        check_walk(&pop, 200);
    }

    /// So does the walk of a thinned population (a modulation that is 0 for `x < −0.3`, 1 for
    /// `x > 0.3` and a ramp between): it meets only the discs that survived.
    #[test]
    fn walk_of_a_modulated_population_matches_brute_force() {
        use crate::texture::{FieldNode, FieldTable, Octaves};
        let mut t = FieldTable::default();
        let x = t
            .add(FieldNode::Marble {
                inv_scale: 0.05,
                axis: Vec3::X,
                turbulence: 0.0,
                octaves: Octaves {
                    octaves: 1,
                    gain: 0.5,
                    lacunarity: 2.0,
                    seed: 1,
                },
            })
            .unwrap();
        // ½ + ½ sin(2π·0.05 x) ≈ ½ + 0.157 x near 0: remapped to 0 … 1 over x ∈ [−0.3, 0.3].
        let ramp = t
            .add(FieldNode::Remap {
                input: x,
                from: [0.453, 0.547],
                to: [0.0, 1.0],
                clamp: true,
            })
            .unwrap();
        let pop = Population::new(400.0, (0.02, 0.06), Orientation::Uniform, vec![(1.0, 0)], 3)
            .unwrap()
            .with_modulation(crate::platelet::Modulation::new(t, ramp));
        check_walk(&pop, 80);
    }

    fn check_walk(pop: &Population, min_hits: usize) {
        let mut rng = Rng::new(11);
        let mut scratch: Vec<Platelet> = vec![];
        let mut hits = 0;
        for _ in 0..2000 {
            let o = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - 1.0;
            let d = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - 1.0;
            let t_max = 0.6;
            let walked = intersect(std::slice::from_ref(pop), o, d, 0.0, t_max, None);
            // Brute force over the cells of the segment's bounding box.
            let (a, b) = (o, o + d * t_max);
            // Discs reach one cell beyond their own.
            let lo = (a.min(b) / pop.cell).floor() - 1.0;
            let hi = (a.max(b) / pop.cell).floor() + 1.0;
            let mut best: Option<f32> = None;
            for x in lo.x as i32..=hi.x as i32 {
                for y in lo.y as i32..=hi.y as i32 {
                    for z in lo.z as i32..=hi.z as i32 {
                        pop.cell_platelets([x, y, z], &mut scratch);
                        for p in &scratch {
                            let limit = best.unwrap_or(t_max);
                            if let Some(t) =
                                hit_disc(p.center, p.normal, p.radius, o, d, 0.0, limit)
                            {
                                best = Some(t);
                            }
                        }
                    }
                }
            }
            assert_eq!(walked.map(|h| h.t), best, "o {o} d {d}");
            hits += usize::from(best.is_some());
        }
        assert!(hits > min_hits, "the test needs hits: {hits}");
    }
}
