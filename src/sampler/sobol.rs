//! Owen-scrambled Sobol' points by hashing (Burley, "Practical Hash-based Owen Scrambling",
//! JCGT 9(4), 2020).
//!
//! Only the first two Sobol' dimensions are used: together they form a (0, 2)-sequence, so every
//! power-of-two prefix of `n` points has exactly one point in each elementary interval of area
//! `1/n`. Higher dimensions are built from independent copies of this pair ("padding"): each pair of
//! dimensions gets its own nested-uniform (Owen) scramble of the sample index — a random shuffle of
//! the points that keeps every power-of-two prefix a (0, 2)-net — and its own Owen scramble of the
//! coordinates. Scrambling is a pure function of a 32-bit seed, so each value is
//! `f(seed, pixel, sample, dimension)` and a render does not depend on thread count or tile order.

/// The `n`-th point of Sobol' dimension 0 (the van der Corput sequence in base 2), as 32 bits.
#[inline]
pub fn sobol_dim0(n: u32) -> u32 {
    n.reverse_bits()
}

/// Generator column `k` of Sobol' dimension 1 (primitive polynomial `x + 1`, all direction numbers
/// `m_k = 1`), as 32 bits: `v_k = v_{k−1} ⊕ (v_{k−1} >> 1)`, `v_0 = 2³¹`.
const fn dim1_column(k: u32) -> u32 {
    let mut v = 1u32 << 31;
    let mut i = 0;
    while i < k {
        v ^= v >> 1;
        i += 1;
    }
    v
}

/// `DIM1[b][x]`: the XOR of the generator columns `8b + j` for the set bits `j` of byte `x`, so a
/// point is four lookups instead of a loop over the (after scrambling, usually 32) index bits.
/// Computed at compile time; 4 KiB.
static DIM1: [[u32; 256]; 4] = {
    let mut t = [[0u32; 256]; 4];
    let mut b = 0;
    while b < 4 {
        let mut x = 0;
        while x < 256 {
            let mut acc = 0u32;
            let mut j = 0;
            while j < 8 {
                if x & (1 << j) != 0 {
                    acc ^= dim1_column(8 * b as u32 + j);
                }
                j += 1;
            }
            t[b][x] = acc;
            x += 1;
        }
        b += 1;
    }
    t
};

/// The `n`-th point of Sobol' dimension 1 (primitive polynomial `x + 1`, all direction numbers
/// `m_k = 1`), as 32 bits: the XOR of the generator columns of `n`'s set bits (see [`DIM1`]).
#[inline]
pub fn sobol_dim1(n: u32) -> u32 {
    DIM1[0][(n & 0xff) as usize]
        ^ DIM1[1][((n >> 8) & 0xff) as usize]
        ^ DIM1[2][((n >> 16) & 0xff) as usize]
        ^ DIM1[3][(n >> 24) as usize]
}

/// The Laine–Karras permutation with the constants of Burley (2020), §3: a hash in which each bit
/// depends only on itself and the bits *below* it, so applied to bit-reversed values it permutes
/// every dyadic interval as a whole — a nested uniform scramble.
#[inline]
fn laine_karras(mut x: u32, seed: u32) -> u32 {
    x = x.wrapping_add(seed);
    x ^= x.wrapping_mul(0x6c50_b47c);
    x ^= x.wrapping_mul(0xb82f_1e52);
    x ^= x.wrapping_mul(0xc7af_e638);
    x ^= x.wrapping_mul(0x8d22_f6e6);
    x
}

/// Nested uniform (Owen) scramble of a 32-bit fixed-point value in `[0, 1)` (Burley 2020, §3).
#[inline]
pub fn owen_scramble(x: u32, seed: u32) -> u32 {
    laine_karras(x.reverse_bits(), seed).reverse_bits()
}

/// Maps a 32-bit fixed-point value to an `f32` in `[0, 1)` (top 24 bits, never 1.0).
#[inline]
pub fn fixed_to_unit(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// `DIM1R[b][x]`: [`DIM1`] bit-reversed, so that `sobol_dim1(n).reverse_bits()` is four lookups
/// without the reversal (a reversal distributes over XOR).
static DIM1R: [[u32; 256]; 4] = {
    let mut t = [[0u32; 256]; 4];
    let mut b = 0;
    while b < 4 {
        let mut x = 0;
        while x < 256 {
            t[b][x] = DIM1[b][x].reverse_bits();
            x += 1;
        }
        b += 1;
    }
    t
};

/// Point `index` of an Owen-scrambled Sobol' pair: the index is shuffled with `seeds[0]`, the two
/// coordinates scrambled with `seeds[1]` and `seeds[2]`. That is
/// `i = owen(index, s0)`, `(owen(dim0(i), s1), owen(dim1(i), s2))` with
/// `owen(x, s) = rev(LK(rev(x), s))` — computed with four bit reversals instead of seven: `dim0` is
/// itself a reversal, so `owen(dim0(i), s1) = rev(LK(i, s1))`, and `rev(dim1(i))` is read from
/// reversed tables ([`DIM1R`]). The same bits as the definition (tested against it).
#[inline]
pub fn scrambled_pair(index: u32, seeds: [u32; 3]) -> (u32, u32) {
    scrambled_pair_reversed(index.reverse_bits(), seeds)
}

/// [`scrambled_pair`] of the sample index whose bit reversal is `reversed_index`: a sampler that
/// draws many pairs of one sample reverses its index once.
#[inline]
pub fn scrambled_pair_reversed(reversed_index: u32, seeds: [u32; 3]) -> (u32, u32) {
    let i = laine_karras(reversed_index, seeds[0]).reverse_bits();
    (
        laine_karras(i, seeds[1]).reverse_bits(),
        laine_karras(dim1_reversed(i), seeds[2]).reverse_bits(),
    )
}

/// `sobol_dim1(i).reverse_bits()`: four reads of [`DIM1R`].
#[inline(always)]
fn dim1_reversed(i: u32) -> u32 {
    DIM1R[0][(i & 0xff) as usize]
        ^ DIM1R[1][((i >> 8) & 0xff) as usize]
        ^ DIM1R[2][((i >> 16) & 0xff) as usize]
        ^ DIM1R[3][(i >> 24) as usize]
}

/// [`scrambled_pair_reversed`] for `N` slots of one sample side by side (`seeds[k]` slot `k`'s),
/// written as loops over the slots that the compiler turns into vector instructions (the lane
/// loop, `render::lanes`, draws a bounce's numbers for all its paths at once). The same bits as
/// `N` calls (tested).
// Plain loops over arrays: `std::array::from_fn` goes through a function that is not inlined
// into a caller compiled for a wider instruction set, and is then not vectorised.
#[inline(always)]
pub fn scrambled_pairs_reversed<const N: usize>(
    reversed_index: u32,
    seeds: &[[u32; 3]; N],
) -> [(u32, u32); N] {
    let mut i = [0u32; N];
    for k in 0..N {
        i[k] = laine_karras(reversed_index, seeds[k][0]).reverse_bits();
    }
    let mut dim1 = [0u32; N];
    for k in 0..N {
        dim1[k] = dim1_reversed(i[k]);
    }
    let mut out = [(0u32, 0u32); N];
    for k in 0..N {
        out[k] = (
            laine_karras(i[k], seeds[k][1]).reverse_bits(),
            laine_karras(dim1[k], seeds[k][2]).reverse_bits(),
        );
    }
    out
}

#[cfg(test)]
mod tests {

    /// The generator matrix applied bit by bit, as the definition reads.
    fn sobol_dim1_by_bits(mut n: u32) -> u32 {
        let mut v = 1u32 << 31;
        let mut x = 0u32;
        while n != 0 {
            if n & 1 != 0 {
                x ^= v;
            }
            n >>= 1;
            v ^= v >> 1;
        }
        x
    }

    #[test]
    fn table_lookup_equals_the_generator_matrix() {
        let mut n = 0x1234_5678u32;
        for k in 0..200_000u32 {
            // Small indices, every single bit, and a pseudo-random walk over all 32 bits.
            for m in [k, 1u32.rotate_left(k), n] {
                assert_eq!(sobol_dim1(m), sobol_dim1_by_bits(m), "n = {m:#x}");
            }
            n = n.wrapping_mul(0x9e37_79b9).wrapping_add(0x7f4a_7c15);
        }
        assert_eq!(sobol_dim1(u32::MAX), sobol_dim1_by_bits(u32::MAX));
    }
    use super::*;

    /// Whether `pts` (2^m points, 32-bit coordinates) put exactly one point in every elementary
    /// interval `[a/2^i, (a+1)/2^i) × [b/2^j, (b+1)/2^j)` with `i + j = m`.
    fn is_02_net(pts: &[(u32, u32)]) -> bool {
        let m = pts.len().trailing_zeros();
        (0..=m).all(|i| {
            let j = m - i;
            let mut seen = vec![false; pts.len()];
            pts.iter().all(|&(x, y)| {
                let a = if i == 0 { 0 } else { (x >> (32 - i)) as usize };
                let b = if j == 0 { 0 } else { (y >> (32 - j)) as usize };
                let k = (a << j) | b;
                !std::mem::replace(&mut seen[k], true)
            })
        })
    }

    #[test]
    fn first_points_match_the_published_sequence() {
        // Sobol' dimension 1 in Gray-code order starts 0, 1/2, 3/4, 1/4, 3/8, 7/8, 5/8, 1/8 (Joe &
        // Kuo's listing); indexed directly, as here, each power-of-two block holds the same points
        // in another order: 0, 1/2, 3/4, 1/4, 5/8, 1/8, 3/8, 7/8.
        let expect = [0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875];
        for (n, &e) in expect.iter().enumerate() {
            assert_eq!(
                f64::from(sobol_dim1(n as u32)) / 2f64.powi(32),
                e,
                "n = {n}"
            );
        }
        assert_eq!(sobol_dim0(1), 1 << 31);
        assert_eq!(sobol_dim0(3), 3 << 30);
    }

    #[test]
    fn every_power_of_two_prefix_is_a_02_net_scrambled_or_not() {
        for m in 0..=10u32 {
            let n = 1u32 << m;
            let plain: Vec<_> = (0..n).map(|i| (sobol_dim0(i), sobol_dim1(i))).collect();
            assert!(is_02_net(&plain), "unscrambled, 2^{m}");
            for seed in 0..8u32 {
                let s = [seed.wrapping_mul(0x9e37_79b9), seed ^ 0x1234_5678, !seed];
                let pts: Vec<_> = (0..n).map(|i| scrambled_pair(i, s)).collect();
                assert!(is_02_net(&pts), "scrambled seed {seed}, 2^{m}");
            }
        }
    }

    #[test]
    fn scramble_is_a_permutation_of_the_dyadic_cells() {
        // On 8-bit prefixes the scramble must be a bijection for any seed.
        for seed in [0u32, 1, 0xdead_beef] {
            let mut seen = [false; 256];
            for x in 0..256u32 {
                let y = owen_scramble(x << 24, seed) >> 24;
                assert!(!std::mem::replace(&mut seen[y as usize], true));
            }
        }
    }

    #[test]
    fn the_fast_pair_is_the_definition_bit_for_bit() {
        let definition = |index: u32, s: [u32; 3]| {
            let i = owen_scramble(index, s[0]);
            (
                owen_scramble(sobol_dim0(i), s[1]),
                owen_scramble(sobol_dim1(i), s[2]),
            )
        };
        let mut x = 0x2468_ace1u32;
        for k in 0..100_000u32 {
            x = x.wrapping_mul(0x9e37_79b9).wrapping_add(0x7f4a_7c15);
            let s = [x, x.rotate_left(11) ^ k, !x.rotate_right(7)];
            for index in [k, x, k.wrapping_mul(0x0101_0101), u32::MAX - k] {
                assert_eq!(
                    scrambled_pair(index, s),
                    definition(index, s),
                    "{index} {s:?}"
                );
            }
        }
    }

    #[test]
    fn pairs_side_by_side_are_the_pairs_one_by_one() {
        let mut h = 0x2545_f491u32;
        let mut next = || {
            h ^= h << 13;
            h ^= h >> 17;
            h ^= h << 5;
            h
        };
        for _ in 0..2000 {
            let index = next();
            let seeds: [[u32; 3]; 8] = std::array::from_fn(|_| [next(), next(), next()]);
            let side_by_side = scrambled_pairs_reversed(index.reverse_bits(), &seeds);
            for (k, s) in seeds.iter().enumerate() {
                assert_eq!(side_by_side[k], scrambled_pair(index, *s));
            }
        }
    }

    #[test]
    fn scrambles_with_different_seeds_differ() {
        let a: Vec<_> = (0..16).map(|i| scrambled_pair(i, [1, 2, 3])).collect();
        let b: Vec<_> = (0..16).map(|i| scrambled_pair(i, [4, 5, 6])).collect();
        assert_ne!(a, b);
        assert!(fixed_to_unit(u32::MAX) < 1.0);
    }
}
