//! Walking a ray through the platelet grid (3-D DDA, Amanatides & Woo 1987) and hitting discs.
//!
//! The walk sees exactly the platelets [`Population::each_in_cell`] gives (thinned when the
//! population's density is modulated: a disc is tested first and asked [`Population::kept`] only
//! when it is hit); the cells, and so the walk's steps, are those of the unmodulated population.
//!
//! The walk visits the cells along the segment in order. In each it needs the discs of the cell
//! and of the neighbours its part of the segment comes within `r_max` of (a disc reaches at most
//! `r_max` beyond its own cell). Consecutive cells share most of those neighbours, so a cell is
//! generated once per walk: a 27-bit mask remembers which cells of the 3 × 3 × 3 block around the
//! current cell were generated, and slides with the walk. Every disc generated is tested against
//! the whole segment, first by its bounding sphere (its normal is drawn only when the sphere meets
//! the segment), then exactly; the nearest hit so far is kept, and the walk ends at the first cell
//! whose exit lies beyond it — every disc that could be hit before that exit has been tested.
//!
//! The result is the nearest hit over all discs, bit for bit the one a brute force over the cells
//! around the segment finds, and the one the previous walk (each cell's neighbours regenerated for
//! every cell, hits kept only inside the cell) found (`tests/platelets/walk.rs`); it is about three
//! times faster (`benches/platelets.rs`, docs/platelets.md).

use super::block::{near_cells, slide};
use super::discs::{Segment, test_cell, test_list};
use super::{PlateletHit, PlateletId, Population};
use glam::Vec3;

/// Most cells one walk visits. World building and the recipe compiler refuse a stone whose
/// [`span`] exceeds [`MAX_SPAN`], so no walk inside a body stops early.
pub const MAX_CELLS: u32 = 1 << 16;

/// Largest [`span`] a stone may have: the walk's [`MAX_CELLS`] less one cell per axis for the
/// rounding of the walk's steps at cell faces.
pub const MAX_SPAN: u64 = MAX_CELLS as u64 - 3;

/// The nearest platelet of any population along `o + t d` with `t_min < t ≤ t_max` (object space;
/// `d` need not be unit: `t` is the caller's parameter), skipping platelet `skip` (the one a ray
/// leaves from). Of hits at the same `t` the smaller [`PlateletId`] wins.
pub fn intersect(
    populations: &[Population],
    o: Vec3,
    d: Vec3,
    t_min: f32,
    t_max: f32,
    skip: Option<PlateletId>,
) -> Option<PlateletHit> {
    let mut best: Option<PlateletHit> = None;
    if !(t_max > t_min) || !d.is_finite() || !o.is_finite() || d == Vec3::ZERO {
        return None;
    }
    let inv_dd = d.length_squared().recip();
    for (k, pop) in populations.iter().enumerate() {
        let ray = Segment {
            o,
            d,
            inv_dd,
            t_min,
            t_max,
            skip,
            index: k as u32,
        };
        walk(pop, &ray, &mut best);
    }
    best
}

/// One population's walk (see the module comment), updating `best`.
fn walk(pop: &Population, ray: &Segment, best: &mut Option<PlateletHit>) {
    let (o, d, t_min) = (ray.o, ray.d, ray.t_min);
    // The plane test's rounding grows with the coordinates and the distance along the ray (an
    // endless segment gets no bounding-sphere test).
    let slack = if ray.t_max.is_finite() {
        1e-4 * (o.abs().max_element() + d.abs().max_element() * (ray.t_max.abs() + t_min.abs()))
    } else {
        f32::INFINITY
    };
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
    let table = pop.table.for_population(pop);
    // How far the segment's part may stray from a cell's box for the cell's list to hold every
    // disc it meets (half the lists' margin: the rest covers the rounding of the points).
    let stray = table.map_or(0.0, |t| 0.5 * t.margin());
    // The cells of the 3 × 3 × 3 block around the current one that this walk has drawn.
    let mut generated = 0u32;
    let mut t_enter = t_min;
    for _ in 0..MAX_CELLS {
        let t_exit = t_next.min_element().min(ray.t_max);
        // The segment's part in this cell, up to the nearest hit so far (nothing beyond it can
        // matter), relative to the cell's lowest corner.
        let t_end = match best {
            Some(h) if h.t < t_exit => h.t,
            _ => t_exit,
        };
        let low = c * cell;
        let (p0, p1) = (o + d * t_enter - low, o + d * t_end - low);
        let centre = [c.x as i32, c.y as i32, c.z as i32];
        let list = table.and_then(|t| {
            let inside =
                p0.min(p1).min_element() >= -stray && p0.max(p1).max_element() <= cell + stray;
            inside.then(|| t.list(centre).map(|l| (t, l))).flatten()
        });
        if let Some((t, quads)) = list {
            test_list(pop, t, quads, ray, low, slack, best);
            // The block's cells were not drawn; drawing them later would only repeat tests.
            generated = 0;
        } else {
            // The neighbours the part comes within `reach` of (with a margin far above the
            // rounding of the points), not drawn yet.
            let margin = 1e-4 * (low.abs().max_element() + cell + reach);
            let fresh = near_cells(p0, p1, cell, reach + margin, generated);
            generated |= fresh;
            let mut bits = fresh;
            while bits != 0 {
                let bit = bits.trailing_zeros() as i32;
                bits &= bits - 1;
                // Wrapping: a ray far from the origin saturates the cell coordinates.
                let ci = [
                    centre[0].wrapping_add(bit / 9 - 1),
                    centre[1].wrapping_add(bit / 3 % 3 - 1),
                    centre[2].wrapping_add(bit % 3 - 1),
                ];
                test_cell(pop, ray, ci, slack, best);
            }
        }
        // Every disc that could be hit up to this cell's exit has been tested.
        if best.is_some_and(|h| h.t <= t_exit) || t_exit >= ray.t_max {
            return;
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
        generated = slide(generated, a, step[a] > 0.0);
    }
}

/// The number of cells a walk along the diagonal of the object-space box `[lo, hi]` visits for
/// `pop` (one plus the cell faces it crosses on each axis): the most any walk inside the box
/// visits.
pub fn span(pop: &Population, lo: Vec3, hi: Vec3) -> u64 {
    let cell = f64::from(pop.cell);
    let mut n = 1.0f64;
    for a in 0..3 {
        let crossed = (f64::from(hi[a]) / cell).floor() - (f64::from(lo[a]) / cell).floor();
        // `max` also turns a NaN into 0.
        n += crossed.max(0.0);
    }
    if n < u64::MAX as f64 {
        n as u64
    } else {
        u64::MAX
    }
}

/// A stone too large for a population's walk: its [`span`] exceeds [`MAX_SPAN`].
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error(
    "body.platelets[{population}]: the stone spans {cells} platelet cells along its diagonal, at \
     most {max} (allowed 1 ..= {max}); the cells are {} object units (the larger of 2.2 × the \
     largest radius and the volume holding 2 platelets on average): use a smaller stone (at most \
     about {} object units along its diagonal), larger platelets or a lower density",
    significant(*.cell),
    significant(*.largest)
)]
pub struct SpanError {
    /// Index of the population.
    pub population: usize,
    /// The stone's [`span`] in the population's cells.
    pub cells: u64,
    /// [`MAX_SPAN`].
    pub max: u64,
    /// The population's cell edge, object units.
    pub cell: f32,
    /// The longest diagonal the walk covers, object units (`MAX_SPAN` cells over three axes, a
    /// cube's diagonal).
    pub largest: f32,
}

/// `x` to four significant digits.
fn significant(x: f32) -> String {
    let digits = if x.is_normal() {
        (3 - x.abs().log10().floor() as i32).clamp(0, 12) as usize
    } else {
        0
    };
    format!("{x:.digits$}")
}

/// Checks every population's [`span`] over the stone's object-space bounds `[lo, hi]`.
pub fn check_span(populations: &[Population], lo: Vec3, hi: Vec3) -> Result<(), SpanError> {
    for (k, pop) in populations.iter().enumerate() {
        let cells = span(pop, lo, hi);
        if cells > MAX_SPAN {
            return Err(SpanError {
                population: k,
                cells,
                max: MAX_SPAN,
                cell: pop.cell,
                // A cube's diagonal crosses `(MAX_SPAN − 1) / 3` faces per axis.
                largest: ((MAX_SPAN - 1) / 3) as f32 * pop.cell * 3f32.sqrt(),
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::platelet::Orientation;
    use crate::platelet::Platelet;
    use crate::platelet::discs::hit_disc;
    use crate::sampler::Rng;

    fn pop(density: f32, radius: (f32, f32)) -> Population {
        Population::new(density, radius, Orientation::Uniform, vec![(1.0, 0)], 3).unwrap()
    }

    #[test]
    fn span_counts_the_cells_along_the_diagonal() {
        let p = pop(400.0, (0.02, 0.05));
        let c = p.cell;
        // One cell, then one face crossed per axis.
        assert_eq!(span(&p, Vec3::splat(0.1 * c), Vec3::splat(0.9 * c)), 1);
        assert_eq!(span(&p, Vec3::splat(0.5 * c), Vec3::splat(1.5 * c)), 4);
        assert_eq!(
            span(&p, Vec3::ZERO, Vec3::new(10.5 * c, 0.5 * c, 2.5 * c)),
            13
        );
        // A NaN box spans one cell; an endless one saturates.
        assert_eq!(span(&p, Vec3::NAN, Vec3::NAN), 1);
        assert_eq!(span(&p, Vec3::ZERO, Vec3::splat(f32::INFINITY)), u64::MAX);
    }

    #[test]
    fn a_stone_too_large_for_the_walk_is_refused() {
        let p = pop(1e7, (0.001, 0.002));
        let ok = check_span(
            std::slice::from_ref(&p),
            Vec3::splat(-1.0),
            Vec3::splat(1.0),
        );
        assert_eq!(ok, Ok(()));
        let pops = [pop(10.0, (0.01, 0.02)), p];
        let e = check_span(&pops, Vec3::splat(-100.0), Vec3::splat(100.0)).unwrap_err();
        assert_eq!(e.population, 1);
        assert!(e.cells > MAX_SPAN, "{e:?}");
        let msg = e.to_string();
        assert!(
            msg.contains("body.platelets[1]: the stone spans")
                && msg.contains(&format!("at most {MAX_SPAN}")),
            "{msg}"
        );
        // The largest stone it names passes.
        let half = Vec3::splat(0.49 * e.largest / 3f32.sqrt());
        assert_eq!(check_span(&pops[1..], -half, half), Ok(()));
    }

    /// The walk of a thinned population meets only the discs that survived, as a brute force
    /// over the cells around the segment does (a modulation that is 0 for `x < −0.3`, 1 for
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

    /// The cells drawn once ([`Population::prepare`]) change no hit: the walk of a prepared
    /// population and of the same population unprepared return the same hit, bit for bit, for
    /// 4000 segments inside, across and outside the table's box (plain and thinned populations),
    /// and each segment again from its hit on, skipping the disc it leaves.
    #[test]
    fn a_prepared_population_walks_as_an_unprepared_one() {
        use crate::texture::{FieldNode, FieldTable};
        let mut t = FieldTable::default();
        let half = t.add(FieldNode::Constant(0.5)).unwrap();
        let plain = pop(400.0, (0.02, 0.06));
        let thinned = plain
            .clone()
            .with_modulation(crate::platelet::Modulation::new(t, half));
        for unprepared in [plain, thinned] {
            let mut prepared = unprepared.clone();
            prepared.prepare(Vec3::splat(-0.5), Vec3::splat(0.5));
            assert!(
                prepared
                    .table
                    .for_population(&prepared)
                    .is_some_and(|t| !t.is_empty())
            );
            let mut rng = Rng::new(23);
            let mut hits = 0;
            for _ in 0..4000 {
                // Origins in [−0.8, 0.8]³: some segments leave the box, some never enter it.
                let o = (Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - 1.0) * 0.8;
                let d = (Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - 1.0)
                    .normalize_or(Vec3::X);
                let t_max = if rng.uniform() < 0.1 {
                    f32::INFINITY
                } else {
                    0.7
                };
                let a = intersect(std::slice::from_ref(&prepared), o, d, 0.0, t_max, None);
                let b = intersect(std::slice::from_ref(&unprepared), o, d, 0.0, t_max, None);
                assert_eq!(
                    a.map(|h| (h.t.to_bits(), h.id)),
                    b.map(|h| (h.t.to_bits(), h.id))
                );
                assert_eq!(a.map(|h| h.normal), b.map(|h| h.normal));
                assert_eq!(a.map(|h| h.material), b.map(|h| h.material));
                hits += usize::from(a.is_some());
                // On from the hit point, skipping the disc it leaves (which lies at t ≈ 0).
                if let Some(h) = a {
                    let from = o + d * h.t;
                    let again = |p: &Population| {
                        intersect(std::slice::from_ref(p), from, d, 0.0, t_max, Some(h.id))
                            .map(|h| (h.t.to_bits(), h.id, h.normal.to_array(), h.material))
                    };
                    let next = again(&prepared);
                    assert_eq!(next, again(&unprepared));
                    assert!(next.is_none_or(|n| n.1 != h.id));
                }
            }
            assert!(hits > 400, "the test needs hits: {hits}");
        }
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
