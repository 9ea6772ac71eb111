//! The per-pixel sample generator of the renderer: every number is a pure function of
//! `(seed, pixel, sample index, dimension)`, so a render is bit-identical for any thread count and
//! any order of tiles (docs/design.md §8).

use super::sobol::{fixed_to_unit, scrambled_pair_reversed, scrambled_pairs_reversed};
use super::{mix64, to_unit_f32};
use glam::Vec2;

/// How pixel samples are generated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SamplerKind {
    /// Independent uniforms, each a hash of `(seed, pixel, sample, dimension)`.
    Independent,
    /// Owen-scrambled Sobol' pairs, padded with independent scrambles per pair of dimensions
    /// ([`super::sobol`]); best with a power-of-two sample count.
    Sobol,
}

impl SamplerKind {
    /// The name used on the command line and in recipes.
    pub fn name(self) -> &'static str {
        match self {
            SamplerKind::Independent => "independent",
            SamplerKind::Sobol => "sobol",
        }
    }
}

/// The numbers of one sample of one pixel, drawn dimension by dimension.
///
/// Each call to [`PixelSampler::get1d`] or [`PixelSampler::get2d`] consumes one *dimension slot*;
/// the integrator draws them in a fixed order per bounce, so slot `k` means the same thing for
/// every sample of a pixel. A 2-D draw is one stratified Sobol' pair; a 1-D draw uses the first
/// coordinate of its own pair.
#[derive(Clone, Debug)]
pub struct PixelSampler {
    kind: SamplerKind,
    pixel_key: u64,
    index: u32,
    /// `index` bit-reversed (what the Sobol' scramble starts from), formed once per sample.
    reversed_index: u32,
    slot: u32,
    /// The scramble seeds of the first [`CACHED_SLOTS`] slots, kept between the samples of the
    /// pixel ([`PixelSampler::restart`]): they depend on the pixel and the slot, not the sample.
    seeds: SeedCache,
}

/// Dimension slots whose seeds a [`PixelSampler`] keeps (the camera's two and ten bounces).
const CACHED_SLOTS: usize = 64;

/// The seeds of the slots drawn so far ([`seeds_of`]); bit `k` of `filled` says slot `k` is set.
#[derive(Clone, Debug)]
struct SeedCache {
    filled: u64,
    seeds: [[u32; 3]; CACHED_SLOTS],
}

impl PixelSampler {
    /// The generator for sample `index` of pixel `pixel` (any unique integer per pixel, e.g.
    /// `y · width + x`) of a render with `seed`.
    pub fn new(kind: SamplerKind, seed: u64, pixel: u64, index: u32) -> Self {
        PixelSampler {
            kind,
            pixel_key: mix64(mix64(seed ^ 0x5bd1_e995_7f4a_7c15).wrapping_add(pixel)),
            index,
            reversed_index: index.reverse_bits(),
            slot: 0,
            seeds: SeedCache {
                filled: 0,
                seeds: [[0; 3]; CACHED_SLOTS],
            },
        }
    }

    /// Starts sample `index` of the same pixel: the same numbers as a new sampler of that sample,
    /// without forming the pixel's slot seeds again.
    #[inline]
    pub fn restart(&mut self, index: u32) {
        self.index = index;
        self.reversed_index = index.reverse_bits();
        self.slot = 0;
    }

    /// The sample index.
    pub fn index(&self) -> u32 {
        self.index
    }

    /// Dimension slots consumed so far.
    pub fn slots_used(&self) -> u32 {
        self.slot
    }

    /// Moves to slot `slot` (slots below it are skipped); lets an integrator give each bounce a
    /// fixed block of slots so optional draws never shift later ones.
    pub fn skip_to(&mut self, slot: u32) {
        self.slot = self.slot.max(slot);
    }

    /// The key of dimension slot `slot` of this pixel: with a sample index, it determines the
    /// slot's pair. The same for every sample of the pixel, so the sampler keeps the seeds made
    /// from it between samples ([`PixelSampler::restart`]).
    #[inline]
    pub fn key_of(&self, slot: u32) -> u64 {
        mix64(self.pixel_key ^ u64::from(slot).wrapping_mul(0x9e37_79b9_7f4a_7c15))
    }

    /// The seeds of slot `slot` (kept for the slots below [`CACHED_SLOTS`]).
    #[inline(always)]
    fn seeds_at(&mut self, slot: u32) -> [u32; 3] {
        if slot as usize >= CACHED_SLOTS {
            return seeds_of(self.kind, self.key_of(slot));
        }
        let bit = 1u64 << slot;
        if self.seeds.filled & bit == 0 {
            self.seeds.seeds[slot as usize] = seeds_of(self.kind, self.key_of(slot));
            self.seeds.filled |= bit;
        }
        self.seeds.seeds[slot as usize]
    }

    /// One uniform number in `[0, 1)`.
    #[inline(always)]
    pub fn get1d(&mut self) -> f32 {
        self.get2d().x
    }

    /// A uniform pair in `[0, 1)²`.
    #[inline(always)] // as `pair`
    pub fn get2d(&mut self) -> Vec2 {
        let seeds = self.seeds_at(self.slot);
        self.slot += 1;
        pair_from_seeds(self.kind, seeds, self.index, self.reversed_index)
    }

    /// The pair of slot `slot`, without moving the counter: for the reserved slots of
    /// [`super::slots`] (wavelengths, medium distances) that live outside the bounce blocks.
    #[inline(always)]
    pub fn get2d_at(&self, slot: u32) -> Vec2 {
        let seeds = seeds_of(self.kind, self.key_of(slot));
        pair_from_seeds(self.kind, seeds, self.index, self.reversed_index)
    }
}

/// The pairs of slot `slots[k]` of sampler `samplers[k]`, side by side: what `skip_to(slots[k])`
/// then `get2d()` would draw from each sampler `k` that is `active[k]` (the others' pairs are
/// meaningless; counters are left as they are). The samplers must draw the same sample index with
/// the same kind (the lane loop's packet: one sample of adjacent pixels); the Sobol' scrambles
/// then run as vector instructions over the samplers.
#[inline(always)]
pub fn pairs_side_by_side<const N: usize>(
    samplers: &mut [PixelSampler; N],
    slots: [u32; N],
    active: [bool; N],
) -> [Vec2; N] {
    let kind = samplers[0].kind;
    let (index, reversed_index) = (samplers[0].index, samplers[0].reversed_index);
    debug_assert!(samplers.iter().all(|s| s.kind == kind && s.index == index));
    let mut seeds = [[0u32; 3]; N];
    for k in 0..N {
        if active[k] {
            seeds[k] = samplers[k].seeds_at(slots[k]);
        }
    }
    let mut out = [Vec2::ZERO; N];
    match kind {
        SamplerKind::Independent => {
            for k in 0..N {
                out[k] = pair_from_seeds(kind, seeds[k], index, reversed_index);
            }
        }
        SamplerKind::Sobol => {
            let pairs = scrambled_pairs_reversed(reversed_index, &seeds);
            for k in 0..N {
                out[k] = Vec2::new(fixed_to_unit(pairs[k].0), fixed_to_unit(pairs[k].1));
            }
        }
    }
    out
}

/// The scramble seeds of the slot with key `key` ([`PixelSampler::key_of`]): the key's two
/// halves, and for Sobol' a third word hashed from it.
#[inline(always)]
fn seeds_of(kind: SamplerKind, key: u64) -> [u32; 3] {
    let third = match kind {
        SamplerKind::Independent => 0,
        SamplerKind::Sobol => mix64(key) as u32,
    };
    [key as u32, (key >> 32) as u32, third]
}

/// The pair of a slot with seeds `seeds` ([`seeds_of`]) for sample `index` (`reversed_index` its
/// bit reversal).
// Always inlined: it runs a few times per path vertex, and when the integrator grew (the
// spectral variant, stop 28) LLVM stopped inlining it, which cost RGB renders about 3 %.
#[inline(always)]
fn pair_from_seeds(kind: SamplerKind, seeds: [u32; 3], index: u32, reversed_index: u32) -> Vec2 {
    match kind {
        SamplerKind::Independent => {
            let key = u64::from(seeds[0]) | (u64::from(seeds[1]) << 32);
            let a = mix64(key ^ u64::from(index));
            let b = mix64(a ^ 0x2545_f491_4f6c_dd1d);
            Vec2::new(to_unit_f32(a), to_unit_f32(b))
        }
        SamplerKind::Sobol => {
            let (x, y) = scrambled_pair_reversed(reversed_index, seeds);
            Vec2::new(fixed_to_unit(x), fixed_to_unit(y))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn draws(kind: SamplerKind, seed: u64, pixel: u64, index: u32) -> Vec<f32> {
        let mut s = PixelSampler::new(kind, seed, pixel, index);
        (0..8).flat_map(|_| s.get2d().to_array()).collect()
    }

    #[test]
    fn numbers_depend_on_every_coordinate_and_only_on_them() {
        for kind in [SamplerKind::Independent, SamplerKind::Sobol] {
            let a = draws(kind, 1, 2, 3);
            assert_eq!(a, draws(kind, 1, 2, 3));
            assert_ne!(a, draws(kind, 2, 2, 3));
            assert_ne!(a, draws(kind, 1, 3, 3));
            assert_ne!(a, draws(kind, 1, 2, 4));
            assert!(a.iter().all(|v| (0.0..1.0).contains(v)));
        }
    }

    #[test]
    fn a_restarted_sampler_draws_what_a_new_one_draws() {
        for kind in [SamplerKind::Independent, SamplerKind::Sobol] {
            let mut reused = PixelSampler::new(kind, 3, 41, 0);
            // Samples of one pixel in the render loop's order, each drawing a different number of
            // slots (some past the cache), plus a reserved slot.
            for index in [0u32, 1, 2, 7, 3, 1 << 20, u32::MAX] {
                reused.restart(index);
                let mut fresh = PixelSampler::new(kind, 3, 41, index);
                let n = 3 + index % 5 * 20;
                for k in 0..n {
                    assert_eq!(
                        reused.get2d(),
                        fresh.get2d(),
                        "{kind:?} sample {index} slot {k}"
                    );
                }
                assert_eq!(reused.slots_used(), n);
                assert_eq!(
                    reused.get2d_at(super::super::slots::WAVELENGTH),
                    fresh.get2d_at(super::super::slots::WAVELENGTH)
                );
            }
        }
    }

    #[test]
    fn pairs_side_by_side_are_each_samplers_own() {
        for kind in [SamplerKind::Independent, SamplerKind::Sobol] {
            for index in [0u32, 5, 1 << 31] {
                let mut many: [PixelSampler; 8] =
                    std::array::from_fn(|k| PixelSampler::new(kind, 2, 100 + k as u64, index));
                // Per-lane slots, some past the seed cache; twice, the second time from it.
                for slots in [
                    [0u32, 1, 2, 9, 63, 64, 70, 200],
                    [3; 8],
                    [0, 1, 2, 9, 63, 64, 70, 200],
                ] {
                    let active = std::array::from_fn(|k| k != 5);
                    let got = pairs_side_by_side(&mut many, slots, active);
                    for k in (0..8).filter(|&k| active[k]) {
                        let mut one = PixelSampler::new(kind, 2, 100 + k as u64, index);
                        one.skip_to(slots[k]);
                        assert_eq!(got[k], one.get2d(), "{kind:?} {index} lane {k}");
                    }
                }
            }
        }
    }

    #[test]
    fn sobol_pixels_are_stratified_per_slot() {
        // 64 samples of slot 3 of one pixel: one in each of the 8×8 grid cells (a (0,2)-net has one
        // point per 1/8 × 1/8 elementary interval).
        let mut seen = [false; 64];
        for i in 0..64 {
            let mut s = PixelSampler::new(SamplerKind::Sobol, 9, 77, i);
            s.skip_to(3);
            let u = s.get2d();
            let cell = (u.x * 8.0) as usize * 8 + (u.y * 8.0) as usize;
            assert!(
                !std::mem::replace(&mut seen[cell], true),
                "cell {cell} twice"
            );
        }
    }

    #[test]
    fn a_reserved_slot_reads_like_any_other_and_keeps_the_counter() {
        for kind in [SamplerKind::Independent, SamplerKind::Sobol] {
            let mut s = PixelSampler::new(kind, 4, 9, 17);
            let at = s.get2d_at(5);
            s.get2d();
            assert_eq!(s.slots_used(), 1);
            s.skip_to(5);
            assert_eq!(s.get2d(), at);
            let w = s.get2d_at(super::super::slots::WAVELENGTH);
            assert!(w != at && (0.0..1.0).contains(&w.x) && (0.0..1.0).contains(&w.y));
        }
    }

    #[test]
    fn slots_are_uncorrelated() {
        // Correlation between slot 0 and slot 1 over 4096 samples of one pixel; for independent
        // uniforms r has sd 1/√n ≈ 0.016, bound at 4 sd.
        for kind in [SamplerKind::Independent, SamplerKind::Sobol] {
            let n = 4096;
            let (mut sx, mut sy, mut sxy, mut sxx, mut syy) = (0.0f64, 0.0, 0.0, 0.0, 0.0);
            for i in 0..n {
                let mut s = PixelSampler::new(kind, 5, 11, i);
                let (x, y) = (f64::from(s.get1d()), f64::from(s.get1d()));
                sx += x;
                sy += y;
                sxy += x * y;
                sxx += x * x;
                syy += y * y;
            }
            let n = f64::from(n);
            let cov = sxy / n - sx * sy / n / n;
            let r = cov / ((sxx / n - (sx / n).powi(2)) * (syy / n - (sy / n).powi(2))).sqrt();
            assert!(r.abs() < 0.064, "{kind:?}: r = {r}");
        }
    }
}
