//! Deterministic random numbers.
//!
//! Every random number in lapidary is a pure function of integers it is derived from (a render's
//! `hash(seed, pixel, sample, dimension)`, or a BSDF's directions), so results never depend on thread
//! count or scheduling. The primitives are the SplitMix64 output function (Steele, Lea & Flood,
//! "Fast splittable pseudorandom number generators", OOPSLA 2014) used as a 64-bit mixer, and a
//! counter-based stream built on it. `rand`'s generators are seeded streams, not keyed hashes of
//! coordinates, which is why this small piece is our own.
//!
//! [`PixelSampler`] draws a render's numbers slot by slot: independent hashes, or Owen-scrambled
//! Sobol' points ([`sobol`], Burley 2020), both pure functions of `(seed, pixel, sample, slot)`.

//!
//! # Slot layout (written once, here)
//!
//! A camera path draws its numbers from fixed *slots*, so an optional draw never shifts the meaning
//! of a later one and every slot is its own padded Sobol' pair (the key of a slot is a hash, so
//! slot numbers need not be contiguous and a high slot is as good as a low one):
//!
//! | slots | what |
//! |---|---|
//! | [`slots::FILM`] = 0 | position in the pixel (reconstruction filter) |
//! | [`slots::LENS`] = 1 | point on the lens |
//! | [`slots::bounce`]`(b)` + 0 … 5 = `2 + 6b` … | bounce `b`: map switch, light choice, light point (2-D), lobe choice, direction (2-D), Russian roulette |
//! | [`slots::WAVELENGTH`] = 2³¹ | the path's wavelengths (drawn only by a spectral variant) |
//! | [`slots::medium`]`(b)` = 2³¹ + 1 + `b` | the distance sample of the ray segment before bounce `b` in a medium (2-D: distance, channel) |
//! | [`slots::platelet`]`(b)` = 2³¹ + 1 + 2²⁰ + `b` | the statistical platelets' collision before bounce `b` (2-D) |
//! | [`slots::fluorescence`]`(b)` = 2³¹ + 1 + 2²¹ + `b` | bounce `b` on a fluorescent base: lobe choice, excitation wavelengths (2-D) |
//!
//! The wavelength and medium slots live far above the bounce blocks: adding them left every
//! number an RGB render of an opaque scene draws exactly where it was (the golden references kept
//! their noise). They are read with [`PixelSampler::get2d_at`], which does not move the counter.

pub mod pixel;
pub mod sobol;
pub mod warp;

/// The slot layout of a camera path (module docs).
pub mod slots {
    /// Position in the pixel.
    pub const FILM: u32 = 0;
    /// Point on the lens.
    pub const LENS: u32 = 1;
    /// Slots per bounce.
    pub const PER_BOUNCE: u32 = 6;
    /// The wavelengths of a path.
    pub const WAVELENGTH: u32 = 1 << 31;
    /// Most bounces that own a medium slot (deeper bounces reuse the last; paths are bounded by
    /// `max-depth ≤ 1024` anyway).
    pub const MEDIUM_BOUNCES: u32 = 1 << 20;

    /// First slot of bounce `b`'s block.
    #[inline]
    pub const fn bounce(b: u32) -> u32 {
        2 + PER_BOUNCE * b
    }

    /// The medium slot of the segment before bounce `b`.
    #[inline]
    pub const fn medium(b: u32) -> u32 {
        let b = if b < MEDIUM_BOUNCES {
            b
        } else {
            MEDIUM_BOUNCES - 1
        };
        WAVELENGTH + 1 + b
    }

    /// The statistical-platelet slot of the segment before bounce `b` (issue 18): a collision
    /// distance and a platelet normal, read without moving the counter.
    #[inline]
    pub const fn platelet(b: u32) -> u32 {
        let b = if b < MEDIUM_BOUNCES {
            b
        } else {
            MEDIUM_BOUNCES - 1
        };
        WAVELENGTH + 1 + MEDIUM_BOUNCES + b
    }

    /// The fluorescence slot of bounce `b` (issue 20): the choice between a fluorescent base's
    /// fluorescent and elastic lobes, and the excitation wavelengths, read without moving the
    /// counter.
    #[inline]
    pub const fn fluorescence(b: u32) -> u32 {
        let b = if b < MEDIUM_BOUNCES {
            b
        } else {
            MEDIUM_BOUNCES - 1
        };
        WAVELENGTH + 1 + 2 * MEDIUM_BOUNCES + b
    }
}

pub use pixel::{PixelSampler, SamplerKind, pairs_side_by_side};
pub use warp::concentric_disc;

/// SplitMix64's finaliser: a bijective 64-bit mixer with full avalanche.
#[inline]
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Hashes a sequence of 64-bit words into one (order-sensitive).
#[inline]
pub fn hash_words(words: &[u64]) -> u64 {
    let mut h = 0x9e37_79b9_7f4a_7c15u64;
    for &w in words {
        h = mix64(h ^ w.wrapping_add(0x9e37_79b9_7f4a_7c15).wrapping_add(h << 6));
    }
    h
}

/// Hashes the bit patterns of some `f32`s (directions, random numbers) into a seed.
#[inline]
pub fn hash_f32s(values: &[f32]) -> u64 {
    let mut h = 0x6a09_e667_f3bc_c908u64;
    for &v in values {
        h = mix64(h ^ u64::from(v.to_bits()).wrapping_mul(0x9e37_79b9_7f4a_7c15));
    }
    h
}

/// Maps 64 random bits to a uniform `f32` in `[0, 1)` (24 significant bits, never 1.0).
#[inline]
pub fn to_unit_f32(bits: u64) -> f32 {
    (bits >> 40) as f32 * (1.0 / 16_777_216.0)
}

/// A counter-based random stream: the `i`-th number is `mix64(key + i·γ)`, so streams with different
/// keys are independent and a stream can be replayed from its key alone.
#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
}

impl Rng {
    /// A stream keyed by `key` (any 64-bit value; use [`hash_words`] or [`hash_f32s`] to build one).
    pub fn new(key: u64) -> Self {
        Rng { state: mix64(key) }
    }
    /// Next 64 random bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        mix64(self.state)
    }
    /// Skips the next `n` numbers of the stream (what `n` calls of [`Rng::next_u64`] would do,
    /// without mixing them).
    #[inline]
    pub fn skip(&mut self, n: u64) {
        self.state = self
            .state
            .wrapping_add(n.wrapping_mul(0x9e37_79b9_7f4a_7c15));
    }
    /// Next uniform number in `[0, 1)`.
    #[inline]
    pub fn uniform(&mut self) -> f32 {
        to_unit_f32(self.next_u64())
    }
    /// Next pair of uniform numbers in `[0, 1)²`.
    #[inline]
    pub fn uniform2(&mut self) -> glam::Vec2 {
        glam::Vec2::new(self.uniform(), self.uniform())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stream_is_replayable_and_keyed() {
        let a: Vec<u64> = (0..4)
            .map({
                let mut r = Rng::new(7);
                move |_| r.next_u64()
            })
            .collect();
        let b: Vec<u64> = (0..4)
            .map({
                let mut r = Rng::new(7);
                move |_| r.next_u64()
            })
            .collect();
        let c: Vec<u64> = (0..4)
            .map({
                let mut r = Rng::new(8);
                move |_| r.next_u64()
            })
            .collect();
        assert_eq!(a, b);
        assert_ne!(a, c);
    }

    #[test]
    fn skip_is_drawing_and_discarding() {
        let (mut a, mut b) = (Rng::new(9), Rng::new(9));
        for _ in 0..3 {
            a.next_u64();
        }
        b.skip(3);
        assert_eq!(a.next_u64(), b.next_u64());
    }

    #[test]
    fn uniform_mean_and_range() {
        let mut r = Rng::new(42);
        let n = 100_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let u = r.uniform();
            assert!((0.0..1.0).contains(&u));
            sum += f64::from(u);
        }
        // Mean of U(0,1) has sd 1/sqrt(12 n) ≈ 9.1e-4; 5 sd bound.
        assert!((sum / n as f64 - 0.5).abs() < 4.6e-3);
    }

    #[test]
    fn float_hash_sees_every_bit() {
        assert_ne!(hash_f32s(&[1.0, 0.0]), hash_f32s(&[0.0, 1.0]));
        assert_ne!(hash_f32s(&[0.0]), hash_f32s(&[-0.0]));
    }
}
