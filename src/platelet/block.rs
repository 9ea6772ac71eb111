//! The 3 × 3 × 3 block of cells around the grid walk's current cell: which of them a segment
//! comes near, and the mask of those a walk has drawn, sliding with the walk.
//!
//! Bit `9 (dx + 1) + 3 (dy + 1) + dz + 1` of a block mask stands for the cell at offset
//! `(dx, dy, dz)` from the current one.

use glam::Vec3;

/// The cells of the 3 × 3 × 3 block around the current cell (bits as in the module docs), other than
/// those of `done`, whose box comes within `reach` of the segment `p0 → p1` inside the current
/// cell (coordinates relative to its lowest corner, edge `cell`): a disc of such a cell may cross
/// that part of the segment.
///
/// Per axis, the segment's bounding box tells which faces it comes within `reach` of. That
/// is the exact distance for the six face neighbours; for an edge or a corner neighbour the
/// nearest point of its box to any point of the cell is on the shared edge or the shared corner,
/// so the exact test is the distance from that edge (the segment projected across it) or corner
/// to the segment — a diagonal segment's box comes near corners the segment itself stays far
/// from.
#[inline]
pub(super) fn near_cells(p0: Vec3, p1: Vec3, cell: f32, reach: f32, done: u32) -> u32 {
    let (lo, hi) = (p0.min(p1), p0.max(p1));
    let axis = |lo: f32, hi: f32, bits: [u32; 3]| {
        bits[1] | if lo < reach { bits[0] } else { 0 } | if cell - hi < reach { bits[2] } else { 0 }
    };
    let near = axis(lo.x, hi.x, AXIS_BITS[0])
        & axis(lo.y, hi.y, AXIS_BITS[1])
        & axis(lo.z, hi.z, AXIS_BITS[2])
        & !done;
    let (v, r2) = (p1 - p0, reach * reach);
    let mut out = near & FACES;
    let mut bits = near & !FACES;
    while bits != 0 {
        let bit = bits.trailing_zeros() as usize;
        bits &= bits - 1;
        // The shared corner (a point of the shared edge), and the axes across the edge.
        let (corner, across) = SHARED[bit];
        let w = (Vec3::from(corner) * cell - p0) * Vec3::from(across);
        let vk = v * Vec3::from(across);
        let vv = vk.length_squared();
        let s = if vv > 0.0 {
            (w.dot(vk) / vv).clamp(0.0, 1.0)
        } else {
            0.0
        };
        // A NaN distance keeps the cell.
        if !((w - vk * s).length_squared() >= r2) {
            out |= 1 << bit;
        }
    }
    out
}

/// Bits of the block's cells whose offset along x, y, z is −1, 0 and +1.
const AXIS_BITS: [[u32; 3]; 3] = [
    [0o777, 0o777 << 9, 0o777 << 18],
    [BOTTOM_Y, BOTTOM_Y << 3, TOP_Y],
    [BOTTOM_Z, BOTTOM_Z << 1, TOP_Z],
];

/// Per bit of the block: the corner its cell shares with the centre cell, in cell units relative
/// to the centre cell's lowest corner (0 on axes where the offset is 0), and 1 on the axes where
/// the offset is not 0.
const SHARED: [([f32; 3], [f32; 3]); 27] = {
    let mut t = [([0.0; 3], [0.0; 3]); 27];
    let mut bit = 0;
    while bit < 27 {
        let off = [bit / 9, bit / 3 % 3, bit % 3];
        let mut a = 0;
        while a < 3 {
            t[bit].0[a] = if off[a] == 2 { 1.0 } else { 0.0 };
            t[bit].1[a] = if off[a] == 1 { 0.0 } else { 1.0 };
            a += 1;
        }
        bit += 1;
    }
    t
};

/// The block's centre cell and its six face neighbours.
const FACES: u32 = 1 << 13 | 1 << 4 | 1 << 22 | 1 << 10 | 1 << 16 | 1 << 12 | 1 << 14;

/// Bits of the block whose offset along y, z is +1.
const TOP_Y: u32 = 0o700_700_700;
const TOP_Z: u32 = 0o444_444_444;
/// The bits of offset −1 along y, z.
const BOTTOM_Y: u32 = 0o007_007_007;
const BOTTOM_Z: u32 = 0o111_111_111;
/// All 27 bits.
const BLOCK: u32 = (1 << 27) - 1;

/// The block's bits after the walk steps by one cell along `axis` (`forward`: +1): a cell's
/// offset moves by one the other way; cells leaving the block can never be needed again (the
/// walk only moves on), and cells entering it have not been generated (every generated cell is
/// within one cell of a cell visited so far).
#[inline]
pub(super) fn slide(bits: u32, axis: usize, forward: bool) -> u32 {
    match (axis, forward) {
        (0, true) => bits >> 9,
        (0, false) => (bits << 9) & BLOCK,
        (1, true) => (bits >> 3) & !TOP_Y,
        (1, false) => (bits << 3) & !BOTTOM_Y & BLOCK,
        (2, true) => (bits >> 1) & !TOP_Z,
        _ => (bits << 1) & !BOTTOM_Z & BLOCK,
    }
}
