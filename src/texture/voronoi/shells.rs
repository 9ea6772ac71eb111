//! The geometry of a Voronoi lookup's search (module docs of [`super`]): the 3×3×3 block's
//! offsets in the order that finds the nearest point early, the squared distance to a cell's box
//! (the cull), and the shells of cells beyond the block.

use glam::{DVec3, IVec3};

/// The 27 offsets of the 3×3×3 block, home cell first, then faces, edges and corners, so the
/// nearest point is usually found early and farther cells are culled by their box distance.
pub(super) const NEIGHBOURS: [IVec3; 27] = {
    let mut out = [IVec3::ZERO; 27];
    let mut n = 0;
    let mut ring = 0;
    while ring <= 3 {
        let mut i = 0;
        while i < 27 {
            let o = IVec3::new(i % 3 - 1, (i / 3) % 3 - 1, i / 9 - 1);
            if o.x.abs() + o.y.abs() + o.z.abs() == ring {
                out[n] = o;
                n += 1;
            }
            i += 1;
        }
        ring += 1;
    }
    out
};

/// Squared distance from the point at `local ∈ [0,1)³` to the box of the neighbour cell at offset
/// `o` (components −1, 0, 1); `lo = local²`, `hi = (1 − local)²` per axis.
#[inline]
pub(super) fn box_distance_sq(o: IVec3, lo: DVec3, hi: DVec3) -> f64 {
    let axis = |o: i32, lo: f64, hi: f64| match o {
        -1 => lo,
        1 => hi,
        _ => 0.0,
    };
    axis(o.x, lo.x, hi.x) + axis(o.y, lo.y, hi.y) + axis(o.z, lo.z, hi.z)
}

/// Squared distance from `local ∈ [0,1)³` to the box of the cell at any offset `o`.
#[inline]
pub(super) fn far_box_distance_sq(o: IVec3, local: DVec3) -> f64 {
    let axis = |o: i32, l: f64| match o {
        o if o < 0 => f64::from(-o - 1) + l,
        o if o > 0 => f64::from(o - 1) + (1.0 - l),
        _ => 0.0,
    };
    let d = DVec3::new(axis(o.x, local.x), axis(o.y, local.y), axis(o.z, local.z));
    d.length_squared()
}

/// Distance from `local` to the nearest point of the cells in shell `k` (Chebyshev radius `k`).
#[inline]
pub(super) fn shell_min(local: DVec3, k: i32) -> f64 {
    f64::from(k - 1) + local.min(DVec3::ONE - local).min_element()
}

/// Calls `f` for every cell offset of search shell `k`: shell 1 is the 3×3×3 block around the
/// origin cell (max-norm ≤ 1), shell `k ≥ 2` the cells at max-norm exactly `k`.
pub(super) fn for_shell(k: i32, mut f: impl FnMut(IVec3)) {
    if k == 1 {
        for z in -1..=1 {
            for y in -1..=1 {
                for x in -1..=1 {
                    f(IVec3::new(x, y, z));
                }
            }
        }
        return;
    }
    for z in -k..=k {
        for y in -k..=k {
            for x in -k..=k {
                if x.abs().max(y.abs()).max(z.abs()) == k {
                    f(IVec3::new(x, y, z));
                }
            }
        }
    }
}
