//! The 3×3×3 block of a nearest-point lookup, all 27 cells at once in SIMD registers.
//!
//! [`Voronoi::nearest`] hashes a cell, places its feature point and measures its distance; cells
//! are independent, so the block's 27 cells are one loop the compiler vectorises (the SplitMix64
//! hash in 64-bit lanes, the offsets and distances in `f64` lanes), compiled for the widest
//! instruction set this machine has (AVX-512, AVX2 or the x86-64 baseline, chosen at run time by
//! `pulp`) and kept out of line so that the caller's search cannot undo the vectorisation. Each
//! lane performs the scalar lookup's operations on the same numbers (no fused multiply-adds, the
//! same association), so every distance is the scalar one bit for bit; the nearest point is then
//! the first of the minimum distance in the block's order, which is the cell the pruned scalar
//! scan keeps (a pruned cell's distance is never below the minimum: see [`Voronoi::nearest`]).

use super::{LIMIT, NEIGHBOURS, Voronoi};
use crate::sampler::mix64;
use glam::{DVec3, IVec3};

/// Lanes of the block: the 27 cells padded to a multiple of eight `f64` lanes.
pub(super) const LANES: usize = 32;

/// [`NEIGHBOURS`] per axis, padded with the home cell (padding lanes are never read).
const OFFSETS: [[i32; LANES]; 3] = {
    let mut out = [[0; LANES]; 3];
    let mut i = 0;
    while i < NEIGHBOURS.len() {
        out[0][i] = NEIGHBOURS[i].x;
        out[1][i] = NEIGHBOURS[i].y;
        out[2][i] = NEIGHBOURS[i].z;
        i += 1;
    }
    out
};

/// The block's nearest feature point: the first of the minimum squared distance in
/// [`NEIGHBOURS`] order.
pub(super) struct Nearest {
    /// Squared distance.
    pub d: f64,
    /// Index into [`NEIGHBOURS`].
    pub k: usize,
    /// The cell's id.
    pub id: u64,
}

/// The block's squared distances and cell ids, in [`NEIGHBOURS`] order (lanes 27… padding).
struct Block {
    d: [f64; LANES],
    id: [u64; LANES],
}

impl Block {
    /// The first lane of the minimum distance among the 27 cells: the minimum by a tree of
    /// lane-wise minima (exact, so its order does not matter), its first lane from a mask.
    #[inline(always)]
    fn nearest(&self) -> Nearest {
        const CELLS: usize = NEIGHBOURS.len();
        let mut m = [f64::INFINITY; 8];
        for chunk in 0..LANES / 8 {
            for (l, m) in m.iter_mut().enumerate() {
                let i = chunk * 8 + l;
                let d = if i < CELLS { self.d[i] } else { f64::INFINITY };
                *m = if d < *m { d } else { *m };
            }
        }
        let d = m
            .iter()
            .fold(f64::INFINITY, |a, &b| if b < a { b } else { a });
        let mut mask = 0u32;
        for i in 0..CELLS {
            mask |= u32::from(self.d[i] == d) << i;
        }
        let k = (mask.trailing_zeros() as usize).min(CELLS - 1);
        Nearest {
            d,
            k,
            id: self.id[k],
        }
    }
}

impl Voronoi {
    /// Whether [`Voronoi::block`] may be used around the cell `bc`: every neighbour's coordinates
    /// lie in the range where [`Voronoi::cell_id`] packs them into one word.
    #[inline]
    pub(super) fn block_applies(bc: IVec3) -> bool {
        bc.abs().max_element() < LIMIT - 1
    }

    /// The nearest of the feature points of the 27 cells around `bc` to `local` (the lookup
    /// point relative to the corner of cell `bc`). Requires [`Voronoi::block_applies`].
    #[inline(never)]
    pub(super) fn block_nearest(&self, bc: IVec3, local: DVec3) -> Nearest {
        struct Kernel<'a> {
            basis: &'a Voronoi,
            bc: IVec3,
            local: DVec3,
        }
        impl pulp::WithSimd for Kernel<'_> {
            type Output = Nearest;
            #[inline(always)]
            fn with_simd<S: pulp::Simd>(self, _: S) -> Nearest {
                self.basis.block_lanes(self.bc, self.local).nearest()
            }
        }
        crate::texture::SIMD.dispatch(Kernel {
            basis: self,
            bc,
            local,
        })
    }

    /// [`Voronoi::block_nearest`]'s loop: [`Voronoi::cell_id`] (the packed branch), [`Voronoi::offset`]
    /// and the distance, written out per lane with the scalar code's operations in its order.
    // The lane index addresses five arrays; the loop in this form is the one LLVM vectorises.
    #[allow(clippy::needless_range_loop)]
    #[inline(always)]
    fn block_lanes(&self, bc: IVec3, local: DVec3) -> Block {
        const UNIT: f64 = 1.0 / (1u64 << 21) as f64;
        const MASK: u64 = (1 << 21) - 1;
        const TWO52: u64 = 0x4330_0000_0000_0000;
        let (key, jitter) = (self.key, f64::from(self.jitter));
        let mut out = Block {
            d: [0.0; LANES],
            id: [0; LANES],
        };
        for l in 0..LANES {
            let pack = |v: i32| u64::from((v + LIMIT) as u32);
            let (ox, oy, oz) = (OFFSETS[0][l], OFFSETS[1][l], OFFSETS[2][l]);
            let id = mix64(key ^ (pack(bc.x + ox) | pack(bc.y + oy) << 21 | pack(bc.z + oz) << 42));
            // `(bits & MASK) as f64`, exactly, without a 64-bit integer conversion (AVX2 has
            // none): the 21 bits as the mantissa of 2⁵² + bits, minus 2⁵².
            let r = |shift: u32| {
                (f64::from_bits(TWO52 | ((id >> shift) & MASK)) - f64::from_bits(TWO52)) * UNIT
            };
            let q = |o: i32, r: f64, x: f64| f64::from(o) + (0.5 + jitter * (r - 0.5)) - x;
            let (qx, qy, qz) = (
                q(ox, r(0), local.x),
                q(oy, r(21), local.y),
                q(oz, r(42), local.z),
            );
            out.d[l] = qx * qx + qy * qy + qz * qz;
            out.id[l] = id;
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::Rng;

    /// Every lane's distance and id equal the scalar lookup's for that cell, bit for bit, for
    /// random points (some on lattice planes) at three jitters, on both sides of the origin and
    /// near the packing limit.
    #[test]
    fn lanes_equal_the_scalar_cells() {
        for jitter in [0.0, 0.4, 1.0] {
            let v = Voronoi::new(23, jitter);
            let mut rng = Rng::new(3);
            for i in 0..4000 {
                let far = if i % 4 == 0 { (LIMIT - 3) as f64 } else { 50.0 };
                let mut p = (DVec3::new(
                    rng.uniform().into(),
                    rng.uniform().into(),
                    rng.uniform().into(),
                ) - 0.5)
                    * 2.0
                    * far;
                if i % 7 == 0 {
                    p = p.round();
                }
                let base = p.floor();
                let (local, bc) = (p - base, base.as_ivec3());
                assert!(Voronoi::block_applies(bc));
                let b = v.block_lanes(bc, local);
                let mut first = (f64::INFINITY, 0);
                for (k, &o) in NEIGHBOURS.iter().enumerate() {
                    let id = v.cell_id(bc + o);
                    let d = (o.as_dvec3() + v.offset(id) - local).length_squared();
                    assert_eq!(
                        (b.d[k].to_bits(), b.id[k]),
                        (d.to_bits(), id),
                        "{p:?} {o:?}"
                    );
                    if d < first.0 {
                        first = (d, k);
                    }
                }
                let n = v.block_nearest(bc, local);
                assert_eq!(
                    (n.d.to_bits(), n.k, n.id),
                    (first.0.to_bits(), first.1, b.id[first.1])
                );
            }
        }
        assert!(!Voronoi::block_applies(IVec3::new(0, LIMIT - 1, 0)));
    }
}
