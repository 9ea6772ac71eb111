//! Testing a cell's discs against the grid walk's segment: a bounding sphere first (a disc's
//! normal is drawn only when its sphere meets the segment), then the exact ray–disc test; the
//! nearest hit so far is kept. The discs come from drawing the cell ([`test_cell`]) or from a
//! cell's list in the population's table ([`test_list`], four bounding spheres at once).

use super::table::{CellTable, Quad};
use super::{Platelet, PlateletHit, PlateletId, Population};
use crate::sampler::Rng;
use glam::{Vec3, Vec4};

/// The segment one population is walked along.
pub(super) struct Segment {
    /// Origin (object space).
    pub o: Vec3,
    /// Direction (object space, not necessarily unit).
    pub d: Vec3,
    /// `1 / |d|²`.
    pub inv_dd: f32,
    /// Hits need `t_min < t ≤ t_max`.
    pub t_min: f32,
    pub t_max: f32,
    /// The platelet the ray leaves from.
    pub skip: Option<PlateletId>,
    /// The population's index.
    pub index: u32,
}

/// Ray–disc intersection: the ray parameter in `(t_min, t_max]`, if any.
#[inline]
pub(super) fn hit_disc(
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
    if !(t > t_min && t <= t_max) {
        return None;
    }
    let q = o + d * t - center;
    (q.length_squared() <= radius * radius).then_some(t)
}

/// Whether a hit at `t` with id `id` beats `best` (nearer, or as near with a smaller id).
#[inline]
fn beats(t: f32, id: PlateletId, best: &Option<PlateletHit>) -> bool {
    best.is_none_or(|b| t < b.t || (t == b.t && id < b.id))
}

/// The bounding-sphere test's margin for discs of cells around `corner` (a cell's lowest corner,
/// object space): far above the rounding of the plane test (so it never rejects a disc that test
/// would accept), growing with the coordinates of the discs and with `slack`, the rounding of the
/// segment's points.
#[inline]
fn margin(pop: &Population, corner: Vec3, slack: f32) -> f32 {
    slack + 1e-4 * (corner.abs().max_element() + 2.0 * pop.cell + pop.radius.1)
}

/// Tests every disc of cell `cell`, drawn from its stream, against the segment, keeping the best
/// hit in `best`.
#[inline]
pub(super) fn test_cell(
    pop: &Population,
    ray: &Segment,
    cell: [i32; 3],
    slack: f32,
    best: &mut Option<PlateletHit>,
) {
    let corner = Vec3::new(cell[0] as f32, cell[1] as f32, cell[2] as f32) * pop.cell;
    let margin = margin(pop, corner, slack);
    let skip = ray
        .skip
        .filter(|s| s.population == ray.index && s.cell == cell)
        .map(|s| s.index);
    let test = Test {
        pop,
        ray,
        margin,
        reach_max: pop.radius.1 + margin,
    };
    let mut stream = pop.stream(cell);
    while let Some((k, center, radius)) = stream.next_centre() {
        if skip != Some(k) {
            test.disc(cell, k, center, || radius.draw(), || stream.rest(), best);
        }
    }
}

/// Tests the discs of a cell's list in `table` (the cell's lowest corner at `corner`) against the
/// segment, keeping the best hit in `best`: four discs at once, each with [`Test::disc`]'s
/// operations — the bounding sphere, then [`hit_disc`]'s plane test with the normal the table
/// drew — lane by lane the same numbers, so the same hits as [`test_cell`].
#[inline]
pub(super) fn test_list(
    pop: &Population,
    table: &CellTable,
    quads: &[Quad],
    ray: &Segment,
    corner: Vec3,
    slack: f32,
    best: &mut Option<PlateletHit>,
) {
    let margin = margin(pop, corner, slack);
    let (o, d) = (ray.o, ray.d);
    let t_min = Vec4::splat(ray.t_min);
    let tiny = Vec4::splat(1e-12);
    for q in quads {
        let hi = Vec4::splat(best.map_or(ray.t_max, |h| h.t));
        // `Test::disc`'s bounding sphere (a NaN `tc` is clamped to `t_min`).
        let (wx, wy, wz) = (q.x - o.x, q.y - o.y, q.z - o.z);
        let tc = (wx * d.x + wy * d.y + wz * d.z) * ray.inv_dd;
        let tc = Vec4::select(tc.cmpge(t_min), tc, t_min);
        let tc = Vec4::select(tc.cmpgt(hi), hi, tc);
        let (ex, ey, ez) = (wx - tc * d.x, wy - tc * d.y, wz - tc * d.z);
        let reach = q.r + margin;
        // A NaN radius (an unused place) fails.
        let near = (ex * ex + ey * ey + ez * ez).cmple(reach * reach);
        // Most groups have no disc near the segment.
        if !near.any() {
            continue;
        }
        // `hit_disc`: the plane (an unused place's zero normal fails) and the disc.
        let dn = d.x * q.nx + d.y * q.ny + d.z * q.nz;
        let t = (wx * q.nx + wy * q.ny + wz * q.nz) / dn;
        let (qx, qy, qz) = (
            (o.x + d.x * t) - q.x,
            (o.y + d.y * t) - q.y,
            (o.z + d.z * t) - q.z,
        );
        let inside = (qx * qx + qy * qy + qz * qz).cmple(q.r * q.r);
        let hit = near & dn.abs().cmpge(tiny) & t.cmpgt(t_min) & t.cmple(hi) & inside;
        let mut lanes = hit.bitmask();
        while lanes != 0 {
            let lane = lanes.trailing_zeros() as usize;
            lanes &= lanes - 1;
            let drawn = table.drawn(q.disc[lane]);
            let id = PlateletId {
                population: ray.index,
                cell: drawn.cell,
                index: drawn.index,
            };
            if ray.skip == Some(id) || !beats(t[lane], id, best) {
                continue;
            }
            let platelet = Platelet {
                center: Vec3::new(q.x[lane], q.y[lane], q.z[lane]),
                normal: drawn.normal,
                radius: q.r[lane],
                material: drawn.material,
            };
            if pop.kept(drawn.cell, drawn.index, &platelet) {
                *best = Some(PlateletHit {
                    t: t[lane],
                    normal: drawn.normal,
                    material: drawn.material,
                    id,
                });
            }
        }
    }
}

/// What the tests of one cell's discs share.
struct Test<'a> {
    pop: &'a Population,
    ray: &'a Segment,
    /// The bounding-sphere test's margin ([`margin`]).
    margin: f32,
    /// The largest disc's radius plus the margin: a first test before the radius is drawn.
    reach_max: f32,
}

impl Test<'_> {
    /// Tests disc `k` of cell `cell` (centre `center`, its radius and the stream positioned at
    /// its normal given on demand) against the segment, keeping the best hit in `best`.
    #[inline(always)]
    fn disc(
        &self,
        cell: [i32; 3],
        k: u32,
        center: Vec3,
        radius: impl FnOnce() -> f32,
        rest: impl FnOnce() -> Rng,
        best: &mut Option<PlateletHit>,
    ) {
        let (ray, o, d) = (self.ray, self.ray.o, self.ray.d);
        let hi = best.map_or(ray.t_max, |h| h.t);
        // Bounding sphere against the segment `[t_min, hi]` (a NaN `tc` is clamped to `t_min`).
        let w = center - o;
        let mut tc = w.dot(d) * ray.inv_dd;
        if !(tc >= ray.t_min) {
            tc = ray.t_min;
        }
        if tc > hi {
            tc = hi;
        }
        let dist2 = (w - d * tc).length_squared();
        if dist2 > self.reach_max * self.reach_max {
            return;
        }
        let radius = radius();
        let reach = radius + self.margin;
        if dist2 > reach * reach {
            return;
        }
        let (normal, material) = self.pop.finish_disc(&mut rest());
        let id = PlateletId {
            population: ray.index,
            cell,
            index: k,
        };
        if let Some(t) = hit_disc(center, normal, radius, o, d, ray.t_min, hi)
            && beats(t, id, best)
            && self.pop.kept(
                cell,
                k,
                &Platelet {
                    center,
                    normal,
                    radius,
                    material,
                },
            )
        {
            *best = Some(PlateletHit {
                t,
                normal,
                material,
                id,
            });
        }
    }
}
