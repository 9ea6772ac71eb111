//! An exact, seedable 3-D Voronoi (Worley) basis.
//!
//! Each integer lattice cell `c` holds one feature point `c + ½ + jitter·(r − ½)`, `r ∈ [0,1)³`
//! hashed from `(seed, c)` (SplitMix64, [`crate::sampler`]). A lookup returns the nearest and
//! second-nearest distances F1 ≤ F2 (Worley, "A cellular texture basis function", SIGGRAPH 1996),
//! the nearest point's cell and its 64-bit hashed **cell id**, the feature point, and the **exact**
//! Euclidean distance to the Voronoi cell's boundary: the minimum over all other feature points of
//! the distance to the bisector plane, `(|x−pj|² − |x−p1|²) / (2|pj−p1|)`.
//!
//! The search is exact, not the usual fixed 3×3×3 block: it visits the 3×3×3 neighbourhood and then
//! whole shells of cells at Chebyshev distance 2, 3, … while a shell could still hold a closer
//! point (for F1, F2) or a closer bisector (a point `pj` can only matter if
//! `|x − pj| < F1 + 2·edge`). The `noise` crate's Worley was not used: it offers 256 cell values,
//! no F2 or edge distance, an incomplete neighbourhood and is `!Send` (docs/design.md §6).
//!
//! Cells a point cannot reach are culled by their box distance before they are hashed, so a typical
//! lookup hashes 8–15 of the 27 neighbours; [`Voronoi::nearest`] (F1 and the id only) stops as soon
//! as no cell can beat F1, [`Voronoi::sample`] continues for F2 and the edge distance.
//!
//! Precision: cells are found with `f64` floors and offsets are formed relative to the cell, so the
//! arithmetic is exact to ±2³¹ cells. The limit is the `f32` input: a coordinate `x` (in cell units)
//! is known to `ulp(x) = 2^(⌊log₂|x|⌋ − 23)`. The cell a point falls in is therefore exact while
//! `|x| < 2²⁴ = 16 777 216` cells (every integer is representable), the pattern inside a cell keeps
//! better than 1/1000 of a cell below `|x| < 2¹³ = 8192` cells, and it is resolved only to 1/16 of a
//! cell at `|x| = 10⁶`. Recipes divide object coordinates (≈ 1) by cell sizes (≥ 10⁻³), so they stay
//! below 10⁴ cells.

use crate::sampler::mix64;
use glam::{DVec3, IVec3, Vec3};

mod block;
mod shells;

use shells::{NEIGHBOURS, box_distance_sq, far_box_distance_sq, for_shell, shell_min};

/// Cell coordinates below this in magnitude are packed into one word by [`Voronoi::cell_id`].
const LIMIT: i32 = 1 << 20;

/// A Voronoi basis: `scale` is applied by the caller (positions are in cell units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Voronoi {
    /// Seed of the feature-point hash.
    pub seed: u64,
    /// Feature-point jitter, 0 (regular grid of cell centres) … 1 (anywhere in the cell).
    pub jitter: f32,
    /// `mix64(seed)`, the key every cell hash starts from.
    key: u64,
}

/// The result of a nearest-point lookup ([`Voronoi::nearest`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VoronoiNearest {
    /// Distance to the nearest feature point.
    pub f1: f32,
    /// Lattice cell of the nearest feature point.
    pub cell: IVec3,
    /// 64-bit hashed id of that cell (depends on the seed).
    pub id: u64,
}

/// The result of one lookup.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VoronoiSample {
    /// Distance to the nearest feature point.
    pub f1: f32,
    /// Distance to the second-nearest feature point (`f1 ≤ f2`).
    pub f2: f32,
    /// Exact distance to the boundary of the nearest point's Voronoi cell (≥ 0).
    pub edge: f32,
    /// Lattice cell of the nearest feature point.
    pub cell: IVec3,
    /// 64-bit hashed id of that cell (depends on the seed).
    pub id: u64,
    /// The nearest feature point, in the caller's coordinates.
    pub feature: Vec3,
}

impl Voronoi {
    /// A basis with the given seed and jitter (clamped to 0 … 1).
    pub fn new(seed: u64, jitter: f32) -> Self {
        Voronoi {
            seed,
            jitter: if jitter.is_finite() {
                jitter.clamp(0.0, 1.0)
            } else {
                1.0
            },
            key: mix64(seed ^ 0x5851_f42d_4c95_7f2d),
        }
    }

    /// The 64-bit id of lattice cell `c`: one SplitMix64 round over the three coordinates packed
    /// into 63 bits (a bijection while every |coordinate| < 2²⁰ cells, far beyond recipes), two
    /// rounds beyond that.
    #[inline]
    pub fn cell_id(&self, c: IVec3) -> u64 {
        if c.abs().max_element() < LIMIT {
            let pack = |v: i32| u64::from((v + LIMIT) as u32);
            mix64(self.key ^ (pack(c.x) | pack(c.y) << 21 | pack(c.z) << 42))
        } else {
            let xy = u64::from(c.x as u32) | (u64::from(c.y as u32) << 32);
            mix64(mix64(self.key ^ xy ^ (1 << 63)) ^ u64::from(c.z as u32))
        }
    }

    /// Feature point of the cell with id `id`, relative to the cell's corner, in `[0, 1)³`: three
    /// 21-bit uniforms taken from the id's bits (the id is already a full-avalanche hash; the
    /// entry pick and fill use further hashes of it).
    #[inline]
    fn offset(&self, id: u64) -> DVec3 {
        const UNIT: f64 = 1.0 / (1u64 << 21) as f64;
        const MASK: u64 = (1 << 21) - 1;
        let r = DVec3::new(
            (id & MASK) as f64 * UNIT,
            ((id >> 21) & MASK) as f64 * UNIT,
            ((id >> 42) & MASK) as f64 * UNIT,
        );
        DVec3::splat(0.5) + f64::from(self.jitter) * (r - DVec3::splat(0.5))
    }

    /// Nearest feature point only (F1, its cell and id): the cheap lookup maps use to pick a
    /// cell. Agrees with [`Voronoi::sample`] on `f1`, `cell` and `id`.
    ///
    /// The 3×3×3 block is measured whole in SIMD lanes ([`block`](mod@block)) and its nearest point is the
    /// first of the minimum distance in [`NEIGHBOURS`] order. That is the point a scan in that
    /// order keeps while it skips every cell whose box is no nearer than the best so far (the
    /// scalar path below, for cells beyond the packing range): rounding is monotone, so a point
    /// in a box is never computed nearer than the box (each axis term `(q − x)²` of a point
    /// with `q ≤ 0` is at least `x²`, with `q ≥ 1` at least `(1 − x)²`, summed in the same order).
    pub fn nearest(&self, p: Vec3) -> VoronoiNearest {
        let p = clamp_input(p);
        let base = p.floor();
        let local = p - base;
        let bc = IVec3::new(base.x as i32, base.y as i32, base.z as i32);
        let mut d1 = f64::INFINITY;
        let (mut c1, mut id1) = (bc, 0u64);
        if Voronoi::block_applies(bc) {
            let n = self.block_nearest(bc, local);
            (d1, c1, id1) = (n.d, bc + NEIGHBOURS[n.k], n.id);
        } else {
            let (lo, hi) = (local * local, (DVec3::ONE - local) * (DVec3::ONE - local));
            for &o in &NEIGHBOURS {
                if box_distance_sq(o, lo, hi) >= d1 {
                    continue;
                }
                let c = bc + o;
                let id = self.cell_id(c);
                let d = (o.as_dvec3() + self.offset(id) - local).length_squared();
                if d < d1 {
                    (d1, c1, id1) = (d, c, id);
                }
            }
        }
        // Shells beyond the 3×3×3 block can hold the nearest point only for high jitter.
        let mut k = 2;
        while k <= 4 && shell_min(local, k).powi(2) < d1 {
            for_shell(k, |o| {
                if far_box_distance_sq(o, local) >= d1 {
                    return;
                }
                let c = bc + o;
                let id = self.cell_id(c);
                let d = (o.as_dvec3() + self.offset(id) - local).length_squared();
                if d < d1 {
                    (d1, c1, id1) = (d, c, id);
                }
            });
            k += 1;
        }
        VoronoiNearest {
            f1: d1.sqrt() as f32,
            cell: c1,
            id: id1,
        }
    }

    /// Looks up position `p` (cell units). Finite inputs never produce NaN.
    pub fn sample(&self, p: Vec3) -> VoronoiSample {
        let p = clamp_input(p);
        let base = p.floor();
        let local = p - base; // in [0, 1)
        let bc = IVec3::new(base.x as i32, base.y as i32, base.z as i32);
        // Feature point of cell offset `o` relative to base, in local coordinates.
        let point = |o: IVec3| {
            let c = bc + o;
            let id = self.cell_id(c);
            (o.as_dvec3() + self.offset(id), c, id)
        };
        let shell_min = |k: i32| shell_min(local, k);
        // Best two so far: (squared distance, point, cell, id) of the nearest, squared F2.
        let mut best = (f64::INFINITY, DVec3::ZERO, bc, 0u64, f64::INFINITY);
        let consider = |best: &mut (f64, DVec3, IVec3, u64, f64), o: IVec3| {
            let (q, c, id) = point(o);
            let d = (q - local).length_squared();
            if d < best.0 {
                *best = (d, q, c, id, best.0);
            } else if d < best.4 {
                best.4 = d;
            }
        };
        let (lo, hi) = (local * local, (DVec3::ONE - local) * (DVec3::ONE - local));
        for &o in &NEIGHBOURS {
            // A cell whose box is farther than F2 cannot change F1 or F2.
            if box_distance_sq(o, lo, hi) < best.4 {
                consider(&mut best, o);
            }
        }
        let mut k = 2;
        while k <= 4 && shell_min(k).powi(2) < best.4 {
            for_shell(k, |o| {
                if far_box_distance_sq(o, local) < best.4 {
                    consider(&mut best, o)
                }
            });
            k += 1;
        }
        let (d1, p1, c1, id1, d2) = best;
        let f1 = d1.sqrt();
        // Edge: bisector distances, over shells around the F1 cell's neighbourhood while a shell
        // may hold a point closer than f1 + 2·edge.
        let mut edge = f64::INFINITY;
        let bisector = |o: IVec3, edge: &mut f64| {
            let (q, c, _) = point(o);
            if c == c1 {
                return;
            }
            let dq = (q - local).length_squared();
            let sep = (q - p1).length();
            if sep > 0.0 {
                *edge = edge.min(((dq - d1) / (2.0 * sep)).max(0.0));
            }
        };
        // The 3×3×3 block nearest first, culling boxes that cannot hold a point closer than
        // f1 + 2·edge; then whole shells while one can.
        for &o in &NEIGHBOURS {
            if box_distance_sq(o, lo, hi) < (f1 + 2.0 * edge).powi(2) {
                bisector(o, &mut edge);
            }
        }
        let mut k = 2;
        while k <= 5 && shell_min(k) < f1 + 2.0 * edge {
            for_shell(k, |o| {
                if far_box_distance_sq(o, local) < (f1 + 2.0 * edge).powi(2) {
                    bisector(o, &mut edge)
                }
            });
            k += 1;
        }
        VoronoiSample {
            f1: f1 as f32,
            f2: d2.sqrt() as f32,
            edge: edge as f32,
            cell: c1,
            id: id1,
            feature: (base + p1).as_vec3(),
        }
    }
}

/// Largest |coordinate| looked up, in cells: beyond it inputs are clamped so neighbour-cell
/// arithmetic cannot overflow `i32` (2³⁰, far past the 2²⁴ where `f32` inputs stop resolving cells).
pub const MAX_CELLS: f64 = (1u64 << 30) as f64;

/// The input in `f64`, non-finite read as the origin, clamped to ±[`MAX_CELLS`].
#[inline]
fn clamp_input(p: Vec3) -> DVec3 {
    if p.is_finite() {
        p.as_dvec3()
            .clamp(DVec3::splat(-MAX_CELLS), DVec3::splat(MAX_CELLS))
    } else {
        DVec3::ZERO
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::Rng;

    /// Brute force over a 9×9×9 block: F1, F2 and the edge distance.
    fn brute(v: &Voronoi, p: Vec3) -> (f64, f64, f64, IVec3) {
        let p = p.as_dvec3();
        let bc = p.floor();
        let mut pts = Vec::new();
        for z in -4..=4 {
            for y in -4..=4 {
                for x in -4..=4 {
                    let c = IVec3::new(bc.x as i32 + x, bc.y as i32 + y, bc.z as i32 + z);
                    pts.push((c.as_dvec3() + v.offset(v.cell_id(c)), c));
                }
            }
        }
        pts.sort_by(|a, b| (a.0 - p).length().total_cmp(&(b.0 - p).length()));
        let (p1, c1) = pts[0];
        let d1 = (p1 - p).length_squared();
        let edge = pts[1..]
            .iter()
            .map(|(q, _)| ((q - p).length_squared() - d1) / (2.0 * (q - p1).length()))
            .fold(f64::INFINITY, f64::min);
        ((p1 - p).length(), (pts[1].0 - p).length(), edge, c1)
    }

    #[test]
    fn matches_brute_force_for_full_jitter() {
        let v = Voronoi::new(7, 1.0);
        let mut rng = Rng::new(11);
        for _ in 0..3000 {
            let p =
                Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 40.0 - Vec3::splat(20.0);
            let s = v.sample(p);
            let (f1, f2, edge, c1) = brute(&v, p);
            assert_eq!(s.cell, c1, "{p:?}");
            assert!(
                (f64::from(s.f1) - f1).abs() < 1e-5 && (f64::from(s.f2) - f2).abs() < 1e-5,
                "{p:?}"
            );
            assert!(
                (f64::from(s.edge) - edge).abs() < 1e-5,
                "{p:?}: {} vs {edge}",
                s.edge
            );
            assert!(s.f1 <= s.f2 && s.edge >= 0.0);
        }
    }

    /// The culling by box distances changes nothing: F1, its cell and id, and
    /// F2 equal an exhaustive scan of the 9×9×9 block, bit for bit, at 20 000 points per jitter
    /// (some on cell faces and lattice points).
    #[test]
    fn lookups_equal_an_exhaustive_scan() {
        for jitter in [0.0, 0.3, 1.0] {
            let v = Voronoi::new(7, jitter);
            let mut rng = Rng::new(17);
            for i in 0..20_000 {
                let mut p = (Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5) * 40.0;
                if i % 10 == 0 {
                    p = p.round();
                } else if i % 10 == 1 {
                    p.x = p.x.round();
                }
                let q = clamp_input(p);
                let base = q.floor();
                let local = q - base;
                let bc = IVec3::new(base.x as i32, base.y as i32, base.z as i32);
                let (mut d1, mut d2, mut best) = (f64::INFINITY, f64::INFINITY, (bc, 0));
                let mut tie = false;
                for x in -4..=4 {
                    for y in -4..=4 {
                        for z in -4..=4 {
                            let o = IVec3::new(x, y, z);
                            let id = v.cell_id(bc + o);
                            let d = (o.as_dvec3() + v.offset(id) - local).length_squared();
                            if d < d1 {
                                (d2, d1, best, tie) = (d1, d, (bc + o, id), false);
                            } else if d < d2 {
                                d2 = d;
                                tie |= d == d1;
                            } else {
                                tie |= d == d1;
                            }
                        }
                    }
                }
                let (n, s) = (v.nearest(p), v.sample(p));
                assert_eq!(n.f1, d1.sqrt() as f32, "{p:?}");
                // Equidistant feature points (jitter 0 on lattice points): either may win.
                if !tie {
                    assert_eq!((n.cell, n.id), best, "{p:?}");
                }
                assert_eq!(s.f2, d2.sqrt() as f32, "{p:?}");
            }
        }
    }

    #[test]
    fn nearest_agrees_with_full_lookup() {
        for jitter in [0.0, 0.5, 1.0] {
            let v = Voronoi::new(19, jitter);
            let mut rng = Rng::new(5);
            for _ in 0..5000 {
                let p = (Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5) * 60.0;
                let (a, b) = (v.nearest(p), v.sample(p));
                assert_eq!((a.f1, a.cell, a.id), (b.f1, b.cell, b.id), "{p:?}");
            }
        }
    }

    #[test]
    fn id_is_stable_inside_a_cell_and_changes_across_a_border() {
        let v = Voronoi::new(3, 0.8);
        let s = v.sample(Vec3::new(0.3, 2.7, -1.2));
        let near = v.sample(s.feature + Vec3::splat(1e-3));
        assert_eq!(near.id, s.id);
        // Walk from the feature point toward a neighbour's: the id changes once, at the bisector,
        // where the edge distance is ~0.
        let other = v.sample(s.feature + Vec3::new(1.5, 0.0, 0.0));
        assert_ne!(other.id, s.id);
        let (a, b) = (s.feature, other.feature);
        let (mut lo, mut hi) = (0.0f32, 1.0f32);
        for _ in 0..40 {
            let m = 0.5 * (lo + hi);
            if v.sample(a.lerp(b, m)).id == s.id {
                lo = m
            } else {
                hi = m
            }
        }
        let at = v.sample(a.lerp(b, lo));
        assert!(at.edge < 1e-4, "edge at the border: {}", at.edge);
        assert!((at.f2 - at.f1).abs() < 1e-3);
    }

    #[test]
    fn seeds_decorrelate_and_lookups_are_pure() {
        let (a, b) = (Voronoi::new(1, 1.0), Voronoi::new(2, 1.0));
        let mut same = 0;
        for i in 0..1000 {
            let p = Vec3::new(i as f32 * 0.731, i as f32 * 0.377, 5.0);
            if a.sample(p).id % 9 == b.sample(p).id % 9 {
                same += 1;
            }
            assert_eq!(a.sample(p), a.sample(p));
        }
        // Independent ids agree mod 9 with probability 1/9: 111 ± 10 expected; 5σ bounds.
        assert!((60..=165).contains(&same), "{same}");
        fn send_sync<T: Send + Sync>() {}
        send_sync::<Voronoi>();
    }

    #[test]
    fn lattice_points_and_huge_coordinates_stay_finite() {
        let v = Voronoi::new(5, 1.0);
        for p in [
            Vec3::ZERO,
            Vec3::ONE,
            Vec3::new(-3.0, 7.0, 2.0),
            Vec3::splat(1e6),
            Vec3::splat(-1e6),
            Vec3::new(1e6, -1e6, 0.5),
            Vec3::new(2.2e9, 0.0, -3e38),
            Vec3::splat(f32::MAX),
        ] {
            let s = v.sample(p);
            assert!(
                s.f1.is_finite() && s.f2.is_finite() && s.edge.is_finite() && s.feature.is_finite(),
                "{p:?}"
            );
            assert!(s.f1 <= s.f2 && s.edge >= 0.0);
        }
        let grid = Voronoi::new(5, 0.0).sample(Vec3::new(2.5, 2.5, 2.5));
        assert!(grid.f1 < 1e-6 && (grid.f2 - 1.0).abs() < 1e-6 && (grid.edge - 0.5).abs() < 1e-6);
        assert!(Voronoi::new(5, 1.0).sample(Vec3::NAN).f1.is_finite());
    }
}
