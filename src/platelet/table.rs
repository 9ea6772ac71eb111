//! The stone's cells drawn once: for every cell around the stone, the list of the platelets that
//! reach into it, for the grid walk to read instead of drawing the cell and its neighbours anew.
//!
//! Drawing a cell costs a hash of the cell, a Poisson count and four uniform numbers per disc, and
//! a walk draws each cell it visits and the neighbours its segment comes near; the walks of a
//! render visit the same few thousand cells millions of times. [`Population::prepare`] draws the
//! cells around the stone's bounding box once, with [`Population::stream`] — so the table holds
//! exactly the numbers the walk would draw — and lists, for each cell of the box (grown by one
//! cell), every disc whose bounding sphere comes within a margin of the cell: a disc crossing a
//! segment inside the cell is in its list. The walk then tests only the list of each cell it
//! visits — no neighbours — as long as its segment's part in the cell lies within the margin of
//! the cell (rounding could carry it further; such a part, and every cell outside the table, is
//! walked by drawing as before).
//!
//! A list stores its discs four by four, each coordinate of a group in one [`Vec4`] ([`Quad`]), so
//! the walk tests four discs at once (a group's unused places have a NaN radius and a zero normal,
//! which no test accepts). The table draws each disc's normal and material once, from the disc's
//! own stream as the walk would: the walk meets each disc's plane four at a time instead of
//! drawing a normal for every disc whose bounding sphere meets its segment.
//!
//! The table is a cache: it changes no result, only where the walk reads the numbers. It is
//! bounded ([`MAX_CELLS`], [`MAX_ENTRIES`]); a stone whose box needs more is walked without it.

use super::Population;
use glam::{Vec3, Vec4};
use std::sync::Arc;

/// Most cells one table lists.
pub const MAX_CELLS: u64 = 1 << 20;
/// Most places (four per [`Quad`]) in one table's lists: 32 bytes each, plus 32 per disc drawn.
pub const MAX_ENTRIES: u64 = 1 << 20;

/// Four discs of a cell's list (module docs): centres, radii and where each one was drawn.
#[derive(Clone, Debug)]
pub(crate) struct Quad {
    /// Centres' `x`, object space.
    pub x: Vec4,
    /// Centres' `y`.
    pub y: Vec4,
    /// Centres' `z`.
    pub z: Vec4,
    /// Radii, object units (NaN for an unused place).
    pub r: Vec4,
    /// Unit normals' `x` (0 for an unused place).
    pub nx: Vec4,
    /// Unit normals' `y`.
    pub ny: Vec4,
    /// Unit normals' `z`.
    pub nz: Vec4,
    /// Each disc's place in [`CellTable::drawn`].
    pub disc: [u32; 4],
}

/// Where a disc was drawn (its cell and its index there) and what its stream drew after its
/// centre ([`super::CellStream::finish`]): its normal and material.
#[derive(Clone, Debug)]
pub(crate) struct Drawn {
    /// The disc's cell.
    pub cell: [i32; 3],
    /// Its index in the cell.
    pub index: u32,
    /// Its unit normal, object space.
    pub normal: Vec3,
    /// Its material index.
    pub material: u32,
}

/// The lists of a box of cells of one population (module docs).
#[derive(Debug)]
pub struct CellTable {
    /// What the table was drawn for: the population's seed and the bits of its cell edge, mean
    /// count and radii (a population copied with another of them must not read it).
    key: [u64; 5],
    /// The box's lowest cell.
    lo: [i32; 3],
    /// Cells along each axis.
    size: [u32; 3],
    /// How far beyond its cell's box a listed disc's bounding sphere may be, object units.
    margin: f32,
    /// Per cell (z fastest, then y, then x), the index of its list's first group; one more at the
    /// end.
    start: Vec<u32>,
    /// The lists, cell by cell.
    quads: Vec<Quad>,
    /// Every disc drawn, cell by cell, each cell's in drawing order.
    drawn: Vec<Drawn>,
}

/// What a table depends on in `pop`.
fn key(pop: &Population) -> [u64; 5] {
    [
        pop.seed,
        u64::from(pop.cell.to_bits()),
        u64::from(pop.mean_per_cell.to_bits()),
        u64::from(pop.radius.0.to_bits()),
        u64::from(pop.radius.1.to_bits()),
    ]
}

impl CellTable {
    /// The list of cell `c`, or `None` if the cell is outside the table.
    #[inline]
    pub(crate) fn list(&self, c: [i32; 3]) -> Option<&[Quad]> {
        let at = |a: usize| {
            let i = c[a].wrapping_sub(self.lo[a]) as u32;
            (i < self.size[a]).then_some(i as usize)
        };
        let (x, y, z) = (at(0)?, at(1)?, at(2)?);
        let i = (x * self.size[1] as usize + y) * self.size[2] as usize + z;
        let (a, b) = (*self.start.get(i)?, *self.start.get(i + 1)?);
        self.quads.get(a as usize..b as usize)
    }

    /// The disc at place `i` of [`Quad::disc`].
    #[inline]
    pub(crate) fn drawn(&self, i: u32) -> &Drawn {
        &self.drawn[i as usize]
    }

    /// How far beyond its cell's box a disc of a cell's list may reach (its bounding sphere),
    /// object units: a segment's part in the cell that stays within this of the box meets no disc
    /// outside the list.
    #[inline]
    pub(crate) fn margin(&self) -> f32 {
        self.margin
    }

    /// Whether this table was drawn for `pop`.
    #[inline]
    pub(crate) fn serves(&self, pop: &Population) -> bool {
        self.key == key(pop)
    }

    /// Whether the table lists no cell.
    pub fn is_empty(&self) -> bool {
        self.start.len() <= 1
    }
}

/// The table of `pop` for the object-space box `[lo, hi]` (the stone's bounds), or `None` if the
/// box is not finite or needs more than [`MAX_CELLS`] cells or [`MAX_ENTRIES`] places.
pub fn draw(pop: &Population, lo: Vec3, hi: Vec3) -> Option<CellTable> {
    // Listed: the cells the box touches and one more on each side (a walk's rounding may step
    // just outside); drawn: one more again (their discs reach into the listed cells).
    let mut first = [0i32; 3];
    let mut size = [0u32; 3];
    let mut cells = 1u64;
    for a in 0..3 {
        let c0 = (f64::from(lo[a]) / f64::from(pop.cell)).floor() - 1.0;
        let c1 = (f64::from(hi[a]) / f64::from(pop.cell)).floor() + 1.0;
        let n = c1 - c0 + 1.0;
        if !(c0 - 1.0 >= f64::from(i32::MIN) && c1 + 1.0 <= f64::from(i32::MAX) && n >= 1.0) {
            return None;
        }
        first[a] = c0 as i32;
        size[a] = n.min(f64::from(u32::MAX)) as u32;
        cells = cells.saturating_mul(u64::from(size[a]));
    }
    // Each disc is listed in about (1 + 2 r/cell)³ cells at most: the expected count decides
    // before anything is drawn, the actual one is checked as it grows.
    let spread = (1.0 + 2.0 * f64::from(pop.radius.1 / pop.cell)).powi(3);
    let drawn_cells: u64 = size.iter().map(|&n| u64::from(n) + 2).product();
    if cells > MAX_CELLS
        || drawn_cells as f64 * f64::from(pop.mean_per_cell) * spread > MAX_ENTRIES as f64
    {
        return None;
    }
    let (n0, n1, n2) = (size[0] as i32 + 2, size[1] as i32 + 2, size[2] as i32 + 2);
    // Every disc of the drawn cells, and where each cell's begin.
    let mut drawn = Vec::new();
    let mut drawn_start = Vec::with_capacity(drawn_cells as usize + 1);
    let mut centres: Vec<(Vec3, f32, Vec3)> = Vec::new();
    for x in 0..n0 {
        for y in 0..n1 {
            for z in 0..n2 {
                drawn_start.push(drawn.len() as u32);
                let cell = [first[0] - 1 + x, first[1] - 1 + y, first[2] - 1 + z];
                let mut stream = pop.stream(cell);
                while let Some((index, center, radius)) = stream.next_disc() {
                    let Some((normal, material)) = stream.finish() else {
                        break;
                    };
                    drawn.push(Drawn {
                        cell,
                        index,
                        normal,
                        material,
                    });
                    centres.push((center, radius, normal));
                }
            }
        }
    }
    drawn_start.push(drawn.len() as u32);
    // The margin: far above the rounding of the listing test and of the walk's points.
    let extent = lo.abs().max(hi.abs()).max_element() + 2.0 * pop.cell;
    let margin = 1e-3 * pop.cell + 1e-5 * extent;
    let mut start = Vec::with_capacity(cells as usize + 1);
    let mut quads: Vec<Quad> = Vec::new();
    let empty = Quad {
        x: Vec4::ZERO,
        y: Vec4::ZERO,
        z: Vec4::ZERO,
        r: Vec4::NAN,
        nx: Vec4::ZERO,
        ny: Vec4::ZERO,
        nz: Vec4::ZERO,
        disc: [0; 4],
    };
    for x in 0..size[0] as i32 {
        for y in 0..size[1] as i32 {
            for z in 0..size[2] as i32 {
                start.push(quads.len() as u32);
                let c = [first[0] + x, first[1] + y, first[2] + z];
                let low = Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32) * pop.cell;
                let high = low + Vec3::splat(pop.cell);
                let mut lane = 4;
                // The 27 drawn cells around `c` (its index in the drawn box is one more per axis).
                for dx in 0..3 {
                    for dy in 0..3 {
                        for dz in 0..3 {
                            let i = (((x + dx) * n1 + y + dy) * n2 + z + dz) as usize;
                            for k in drawn_start[i]..drawn_start[i + 1] {
                                let (center, radius, normal) = centres[k as usize];
                                // Distance from the centre to the cell's box.
                                let gap = (low - center).max(center - high).max(Vec3::ZERO);
                                let reach = radius + margin;
                                if gap.length_squared() > reach * reach {
                                    continue;
                                }
                                if lane == 4 {
                                    quads.push(empty.clone());
                                    lane = 0;
                                }
                                if let Some(q) = quads.last_mut() {
                                    q.x[lane] = center.x;
                                    q.y[lane] = center.y;
                                    q.z[lane] = center.z;
                                    q.r[lane] = radius;
                                    q.nx[lane] = normal.x;
                                    q.ny[lane] = normal.y;
                                    q.nz[lane] = normal.z;
                                    q.disc[lane] = k;
                                }
                                lane += 1;
                            }
                        }
                    }
                }
                if 4 * quads.len() as u64 > MAX_ENTRIES {
                    return None;
                }
            }
        }
    }
    start.push(quads.len() as u32);
    Some(CellTable {
        key: key(pop),
        lo: first,
        size,
        margin,
        start,
        quads,
        drawn,
    })
}

/// A population's table, shared by its copies (a cache: see the module docs).
#[derive(Clone, Debug, Default)]
pub struct Prepared(Option<Arc<CellTable>>);

impl Prepared {
    /// The table, if it was drawn for `pop`.
    #[inline]
    pub(crate) fn for_population(&self, pop: &Population) -> Option<&CellTable> {
        self.0.as_deref().filter(|t| t.serves(pop))
    }

    /// The table, if any.
    pub fn table(&self) -> Option<&CellTable> {
        self.0.as_deref()
    }
}

impl PartialEq for Prepared {
    /// Always equal: the table is a cache, not part of what a population is.
    fn eq(&self, _: &Prepared) -> bool {
        true
    }
}

/// Draws the table of `pop` for the object-space box `[lo, hi]` (the stone's bounds) into it
/// (none if the box is too large, module docs): [`Population::prepare`].
pub(super) fn prepare(pop: &mut Population, lo: Vec3, hi: Vec3) {
    pop.table = Prepared(draw(pop, lo, hi).map(Arc::new));
}
