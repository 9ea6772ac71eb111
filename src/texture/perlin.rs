//! Seedable 3-D gradient noise without a period, and its fractal sums.
//!
//! The noise is Perlin's "improved noise" (K. Perlin, "Improving Noise", SIGGRAPH 2002): gradients
//! from the 12 cube-edge directions at the lattice corners, blended with the quintic fade
//! `6t⁵ − 15t⁴ + 10t³` (C² continuous). Instead of a 256-entry permutation table — which repeats
//! every 256 lattice units, a period that shows in a stone's fine octaves (octave 8 of an fBm repeats
//! every 2 base units) — each corner's gradient comes from a 32-bit hash of `(seed, x, y, z)`, so the
//! pattern repeats only after 2³² lattice units and any 32-bit seed gives independent gradients. The
//! noise of every seed vanishes on the integer lattice, so [`Octaves`] also shifts each octave's
//! lattice by a hashed fraction of a cell: without it, turbulence (`|noise|`) of different seeds
//! correlates (r ≈ 0.05, measured in `tests/maps.rs`).
//!
//! Why not the `noise` crate: its `Perlin` is the permutation-table kind (period 256, seeds shuffle
//! one 256-entry table), and its `Fbm` keeps a `Vec` of sources built at construction; we want one
//! `Copy` value per field in flat runtime tables. `benches/texture.rs` measures both implementations
//! side by side (the figures are in `docs/cost.md`).
//!
//! Coordinates are floored in `f64` so the lattice stays exact for large inputs; the remainder is
//! `f32`. Output of [`perlin`] lies in about `[−1, 1]` (zero at every lattice point).

use glam::{DVec3, Vec3};

/// The 32-bit integer hash "lowbias32" (C. Wellons, *hash-prospector*, 2018: two multiply–xorshift
/// rounds with bias ≈ 0.17 ‰), used to pick corner gradients.
#[inline(always)]
fn hash32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^ (x >> 16)
}

/// Dot product of corner gradient `h` (one of the 12 cube edges, 4 repeated to make 16, as in
/// Perlin 2002) with the offset `(x, y, z)` from that corner.
#[inline(always)]
fn grad(h: u32, x: f32, y: f32, z: f32) -> f32 {
    let h = h >> 28; // the hash's best-mixed bits
    let u = if h < 8 { x } else { y };
    let v = if h < 4 {
        y
    } else if h == 12 || h == 14 {
        x
    } else {
        z
    };
    (if h & 1 == 0 { u } else { -u }) + (if h & 2 == 0 { v } else { -v })
}

#[inline(always)]
fn fade(t: f32) -> f32 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

#[inline(always)]
fn lerp(t: f32, a: f32, b: f32) -> f32 {
    a + t * (b - a)
}

/// Perlin gradient noise at `p` (lattice units) for `seed`; about `[−1, 1]`, finite for every
/// input (non-finite inputs read as the origin).
pub fn perlin(p: Vec3, seed: u32) -> f32 {
    let (lattice, f) = locate(p);
    noise_at(lattice, f, hash32(seed ^ 0x9e37_79b9))
}

/// [`perlin`] at `N` points side by side, as loops over the points that the compiler turns into
/// vector instructions where the caller is compiled for them (the lane loop's kernel,
/// `render::lanes`): the same operations on each point, so the same bits as `N` calls (tested).
#[inline(always)]
pub fn perlin_side_by_side<const N: usize>(p: &[Vec3; N], seed: u32) -> [f32; N] {
    let mut lattice = [[0u32; 3]; N];
    let mut f = [Vec3::ZERO; N];
    for k in 0..N {
        (lattice[k], f[k]) = locate(p[k]);
    }
    let s = hash32(seed ^ 0x9e37_79b9);
    let mut out = [0.0f32; N];
    for k in 0..N {
        out[k] = noise_at(lattice[k], f[k], s);
    }
    out
}

/// The lattice cell holding `p` (coordinates wrapping at 2³² — far beyond any recipe, see the
/// module docs) and the offset within it; a non-finite `p` reads as the origin.
#[inline(always)]
fn locate(p: Vec3) -> ([u32; 3], Vec3) {
    let p = if p.is_finite() {
        p.as_dvec3()
    } else {
        DVec3::ZERO
    };
    let cell = p.floor();
    let f = (p - cell).as_vec3();
    (
        [
            cell.x as i64 as u32,
            cell.y as i64 as u32,
            cell.z as i64 as u32,
        ],
        f,
    )
}

/// The noise of lattice cell `[xi, yi, zi]` at offset `f` within it; `s` is the hashed seed.
#[inline(always)]
fn noise_at([xi, yi, zi]: [u32; 3], f: Vec3, s: u32) -> f32 {
    let hz = [hash32(s ^ zi), hash32(s ^ zi.wrapping_add(1))];
    let hyz = |y: u32, z: usize| hash32(hz[z] ^ y.wrapping_mul(0x85eb_ca6b));
    let corner = |x: u32, y: u32, z: usize| hash32(hyz(y, z) ^ x.wrapping_mul(0xc2b2_ae35));
    let (x1, y1) = (xi.wrapping_add(1), yi.wrapping_add(1));
    let (u, v, w) = (fade(f.x), fade(f.y), fade(f.z));
    let (fx, fy, fz) = (f.x, f.y, f.z);
    let z0 = lerp(
        v,
        lerp(
            u,
            grad(corner(xi, yi, 0), fx, fy, fz),
            grad(corner(x1, yi, 0), fx - 1.0, fy, fz),
        ),
        lerp(
            u,
            grad(corner(xi, y1, 0), fx, fy - 1.0, fz),
            grad(corner(x1, y1, 0), fx - 1.0, fy - 1.0, fz),
        ),
    );
    let z1 = lerp(
        v,
        lerp(
            u,
            grad(corner(xi, yi, 1), fx, fy, fz - 1.0),
            grad(corner(x1, yi, 1), fx - 1.0, fy, fz - 1.0),
        ),
        lerp(
            u,
            grad(corner(xi, y1, 1), fx, fy - 1.0, fz - 1.0),
            grad(corner(x1, y1, 1), fx - 1.0, fy - 1.0, fz - 1.0),
        ),
    );
    lerp(w, z0, z1)
}

/// Parameters of a fractal sum of [`perlin`] octaves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Octaves {
    /// Number of octaves, 1 … 16.
    pub octaves: u32,
    /// Amplitude ratio between successive octaves (0 … 1; 0.5 is classic fBm).
    pub gain: f32,
    /// Frequency ratio between successive octaves (> 1; 2 is classic).
    pub lacunarity: f32,
    /// Noise seed; octave `k` uses the seed `hash(seed, k)` and a hashed sub-lattice offset, so
    /// octaves and fields with different seeds are independent (see [`Octaves::octave`]).
    pub seed: u32,
}

impl Octaves {
    /// Fractional Brownian motion: `Σ gainᵏ · perlin(lacunarityᵏ p) / Σ gainᵏ`, about `[−1, 1]`.
    pub fn fbm(&self, p: Vec3) -> f32 {
        self.sum(p, |n| n)
    }

    /// Turbulence (Perlin 1985): `Σ gainᵏ · |perlin(lacunarityᵏ p)| / Σ gainᵏ`, in `[0, 1]`.
    pub fn turbulence(&self, p: Vec3) -> f32 {
        self.sum(p, f32::abs)
    }

    /// Seed and lattice offset of octave `k`. Every seed's noise vanishes on its integer lattice;
    /// shifting each octave's lattice by a hashed fraction of a cell keeps those zeros (and with
    /// them `|noise|`) from lining up between seeds, which would correlate turbulence fields.
    #[inline(always)]
    pub fn octave(&self, k: u32) -> (u32, Vec3) {
        let h = hash32(hash32(self.seed ^ 0x68e3_1da4).wrapping_add(k.wrapping_mul(0x9e37_79b9)));
        let (a, b, c) = (hash32(h ^ 1), hash32(h ^ 2), hash32(h ^ 3));
        let unit = |x: u32| (x >> 8) as f32 * (1.0 / 16_777_216.0);
        (h, Vec3::new(unit(a), unit(b), unit(c)))
    }

    /// [`Octaves::fbm`] at `N` points side by side (see [`perlin_side_by_side`]).
    #[inline(always)]
    pub fn fbm_side_by_side<const N: usize>(&self, p: &[Vec3; N]) -> [f32; N] {
        self.sum_side_by_side(p, |n| n)
    }

    /// [`Octaves::turbulence`] at `N` points side by side (see [`perlin_side_by_side`]).
    #[inline(always)]
    pub fn turbulence_side_by_side<const N: usize>(&self, p: &[Vec3; N]) -> [f32; N] {
        self.sum_side_by_side(p, f32::abs)
    }

    /// [`Octaves::sum`] at `N` points: each point's terms in the same order.
    #[inline(always)]
    fn sum_side_by_side<const N: usize>(
        &self,
        p: &[Vec3; N],
        shape: impl Fn(f32) -> f32,
    ) -> [f32; N] {
        let (mut total, mut norm) = ([0.0f32; N], 0.0f32);
        let (mut amp, mut freq) = (1.0f32, 1.0f32);
        for k in 0..self.octaves.max(1) {
            let (seed, offset) = self.octave(k);
            let mut q = [Vec3::ZERO; N];
            for i in 0..N {
                q[i] = p[i] * freq + offset;
            }
            let n = perlin_side_by_side(&q, seed);
            for i in 0..N {
                total[i] += amp * shape(n[i]);
            }
            norm += amp;
            amp *= self.gain;
            freq *= self.lacunarity;
        }
        let mut out = [0.0f32; N];
        for i in 0..N {
            out[i] = if norm > 0.0 { total[i] / norm } else { 0.0 };
        }
        out
    }

    /// The fractal sum at one point. Its octaves are independent noises, so they are evaluated
    /// side by side, [`OCTAVE_LANES`] at a time, in a kernel compiled for the widest instruction
    /// set this machine has ([`octave_noises`]); the points, amplitudes and the sum are formed
    /// in the scalar order, so the result is the octave-by-octave loop's bit for bit (tested).
    #[inline]
    fn sum(&self, p: Vec3, shape: impl Fn(f32) -> f32) -> f32 {
        let (mut total, mut norm) = (0.0, 0.0);
        let (mut amp, mut freq) = (1.0f32, 1.0f32);
        let n = self.octaves.max(1);
        for first in (0..n).step_by(OCTAVE_LANES) {
            let lanes = (n - first).min(OCTAVE_LANES as u32) as usize;
            let mut freqs = [0.0f32; OCTAVE_LANES];
            for f in &mut freqs[..lanes] {
                *f = freq;
                freq *= self.lacunarity;
            }
            let noise = octave_noises(self, p, first, &freqs);
            for &v in &noise[..lanes] {
                total += amp * shape(v);
                norm += amp;
                amp *= self.gain;
            }
        }
        if norm > 0.0 { total / norm } else { 0.0 }
    }
}

/// Octaves a fractal sum evaluates at once: eight `f64` lanes fill an AVX-512 register.
pub const OCTAVE_LANES: usize = 8;

/// The noises of octaves `first + i` of `octaves` at `p` (`perlin(p · freqs[i] + offset, seed)`,
/// [`Octaves::octave`]'s seed and offset) for every lane, compiled for the widest instruction set
/// this machine has (AVX-512, AVX2 or the x86-64 baseline, chosen at run time by `pulp`) and kept
/// out of line so that the caller cannot undo its vectorisation; each lane performs
/// [`Octaves::octave`]'s and [`perlin`]'s operations on its numbers, so the results are their bits.
#[inline(never)]
fn octave_noises(
    octaves: &Octaves,
    p: Vec3,
    first: u32,
    freqs: &[f32; OCTAVE_LANES],
) -> [f32; OCTAVE_LANES] {
    struct Kernel<'a>(&'a Octaves, Vec3, u32, &'a [f32; OCTAVE_LANES]);
    impl pulp::WithSimd for Kernel<'_> {
        type Output = [f32; OCTAVE_LANES];
        #[inline(always)]
        fn with_simd<S: pulp::Simd>(self, _: S) -> Self::Output {
            let Kernel(octaves, p, first, freqs) = self;
            let (mut lattice, mut f) = ([[0u32; 3]; OCTAVE_LANES], [Vec3::ZERO; OCTAVE_LANES]);
            let mut seeds = [0u32; OCTAVE_LANES];
            for k in 0..OCTAVE_LANES {
                let (seed, offset) = octaves.octave(first.wrapping_add(k as u32));
                seeds[k] = hash32(seed ^ 0x9e37_79b9);
                (lattice[k], f[k]) = locate(p * freqs[k] + offset);
            }
            let mut out = [0.0f32; OCTAVE_LANES];
            for k in 0..OCTAVE_LANES {
                out[k] = noise_at(lattice[k], f[k], seeds[k]);
            }
            out
        }
    }
    crate::texture::SIMD.dispatch(Kernel(octaves, p, first, freqs))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::Rng;

    fn points(n: usize, spread: f32, key: u64) -> Vec<Vec3> {
        let mut rng = Rng::new(key);
        (0..n)
            .map(|_| (Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5) * spread)
            .collect()
    }

    #[test]
    fn zero_on_lattice_bounded_and_continuous() {
        for p in [Vec3::ZERO, Vec3::new(3.0, -7.0, 12.0), Vec3::splat(1e6)] {
            assert_eq!(perlin(p, 4), 0.0, "{p:?}");
        }
        let mut max = 0.0f32;
        for p in points(200_000, 50.0, 1) {
            let n = perlin(p, 9);
            assert!(n.is_finite() && n.abs() <= 1.1, "{p:?}: {n}");
            max = max.max(n.abs());
            // Lipschitz: the gradient of improved noise is bounded (< 4 per lattice unit).
            let d = perlin(p + Vec3::new(1e-3, 0.0, 0.0), 9) - n;
            assert!(d.abs() < 4e-3, "{p:?}: step {d}");
        }
        assert!(max > 0.7, "the range is used: max |n| = {max}");
    }

    #[test]
    fn mean_zero_and_seeds_decorrelate() {
        let pts = points(100_000, 200.0, 2);
        let a: Vec<f32> = pts.iter().map(|&p| perlin(p, 1)).collect();
        let b: Vec<f32> = pts.iter().map(|&p| perlin(p, 2)).collect();
        let n = a.len() as f64;
        let mean = a.iter().map(|&x| f64::from(x)).sum::<f64>() / n;
        let var = a.iter().map(|&x| f64::from(x).powi(2)).sum::<f64>() / n;
        let cov = a
            .iter()
            .zip(&b)
            .map(|(&x, &y)| f64::from(x) * f64::from(y))
            .sum::<f64>()
            / n;
        // Points 200 lattice units apart on average are independent: standard errors ≈ √(var/n).
        let se = (var / n).sqrt();
        assert!(mean.abs() < 5.0 * se, "mean {mean} (se {se})");
        assert!(
            (cov / var).abs() < 5.0 / n.sqrt(),
            "correlation {}",
            cov / var
        );
    }

    #[test]
    fn no_period_at_256_and_non_finite_input() {
        // A permutation-table Perlin repeats here; the hashed lattice does not.
        let mut same = 0;
        for p in points(1000, 10.0, 3) {
            if (perlin(p, 5) - perlin(p + Vec3::new(256.0, 0.0, 0.0), 5)).abs() < 1e-6 {
                same += 1;
            }
        }
        assert!(same < 10, "{same} of 1000 repeat");
        assert_eq!(perlin(Vec3::NAN, 1), 0.0);
        assert!(perlin(Vec3::splat(-1e6 + 0.37), 1).is_finite());
    }

    /// The fractal sums with their octaves in lanes equal the octave-by-octave loop bit for bit,
    /// for octave counts below, at and across the lane width (1, 4, 8, 9, 16).
    #[test]
    fn octave_lanes_equal_the_octave_loop() {
        for octaves in [1, 4, 8, 9, 16] {
            let o = Octaves {
                octaves,
                gain: 0.6,
                lacunarity: 1.9,
                seed: 29,
            };
            for p in points(3000, 80.0, 8) {
                let (mut fbm, mut turb, mut norm) = (0.0f32, 0.0f32, 0.0f32);
                let (mut amp, mut freq) = (1.0f32, 1.0f32);
                for k in 0..octaves {
                    let (seed, offset) = o.octave(k);
                    let n = perlin(p * freq + offset, seed);
                    (fbm, turb, norm) = (fbm + amp * n, turb + amp * n.abs(), norm + amp);
                    (amp, freq) = (amp * o.gain, freq * o.lacunarity);
                }
                assert_eq!(
                    o.fbm(p).to_bits(),
                    (fbm / norm).to_bits(),
                    "{octaves} {p:?}"
                );
                assert_eq!(
                    o.turbulence(p).to_bits(),
                    (turb / norm).to_bits(),
                    "{octaves} {p:?}"
                );
            }
        }
    }

    #[test]
    fn side_by_side_is_one_by_one() {
        let o = Octaves {
            octaves: 5,
            gain: 0.55,
            lacunarity: 2.1,
            seed: 11,
        };
        let mut pts = points(8 * 4000, 300.0, 6);
        // Lattice points, huge and non-finite inputs among them.
        pts[..8].copy_from_slice(&[
            Vec3::ZERO,
            Vec3::new(3.0, -7.0, 12.0),
            Vec3::splat(-1e6 + 0.37),
            Vec3::splat(3e9),
            Vec3::NAN,
            Vec3::new(f32::INFINITY, 0.0, 1.0),
            Vec3::splat(-0.0),
            Vec3::splat(f32::MAX),
        ]);
        for chunk in pts.chunks_exact(8) {
            let p: [Vec3; 8] = chunk.try_into().unwrap();
            let (n, f, t) = (
                perlin_side_by_side(&p, 9),
                o.fbm_side_by_side(&p),
                o.turbulence_side_by_side(&p),
            );
            for k in 0..8 {
                assert_eq!(n[k].to_bits(), perlin(p[k], 9).to_bits(), "{:?}", p[k]);
                assert_eq!(f[k].to_bits(), o.fbm(p[k]).to_bits(), "{:?}", p[k]);
                assert_eq!(t[k].to_bits(), o.turbulence(p[k]).to_bits(), "{:?}", p[k]);
            }
        }
    }

    #[test]
    fn fbm_and_turbulence_ranges() {
        let o = Octaves {
            octaves: 6,
            gain: 0.5,
            lacunarity: 2.0,
            seed: 7,
        };
        for p in points(20_000, 20.0, 4) {
            let (f, t) = (o.fbm(p), o.turbulence(p));
            assert!(f.abs() <= 1.1 && (0.0..=1.0).contains(&t), "{f} {t}");
        }
        let one = Octaves { octaves: 1, ..o };
        let p = Vec3::new(0.3, 0.7, 0.1);
        let (seed, offset) = one.octave(0);
        assert_eq!(one.fbm(p), perlin(p + offset, seed));
    }
}
