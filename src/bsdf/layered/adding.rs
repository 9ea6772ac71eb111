//! The directional albedo of a stack by the adding method over bins of `cos θ` — a deterministic
//! solution of the same transport the Reference walk samples, computed at build time.
//!
//! The directional albedo `E(wo) = ∫ f(wo, wi) cos θi dωi` of an isotropic stack needs only the
//! azimuthal mean (the zeroth Fourier mode) of each component: after any number of events, how a
//! path continues depends on its direction only through `|cos θ|`. So the walk reduces to a Markov
//! chain over `|cos θ|` and the side of each interface it travels on, and its expectation to the
//! adding equations of radiative transfer (van de Hulst, "Multiple light scattering", 1980;
//! Jakob, d'Eon, Jakob & Marschner, "A comprehensive framework for rendering layered materials",
//! SIGGRAPH 2014, §5, with Fourier order 0). Per coat, with `R`, `T` the interface's reflection and
//! transmission operators from above (`a`) and below (`b`), `A` the varnish's transmittance along
//! one leg and `R'` the reflection of everything below:
//!
//! ```text
//! R = R_a + T_ba · X · (I + (R_b X) + (R_b X)² + …) · T_ab,       X = A R' A
//! ```
//!
//! The operators are matrices over [`BINS`] bins uniform in `cos² θ` (equal projected solid angle:
//! a refraction maps them to uniform bins of the other side's `cos² θ`), estimated from the
//! components' own samplers in radiance transport — the walk's events, including the interfaces'
//! multiple-scattering lobes and a compensated base — by stratified sampling. The series is
//! summed to 256 bounces (the walk's default depth) by doubling. Only the first event at the top,
//! from the exact `wo`, is not binned.
//!
//! Binning assumes that light within a bin is spread uniformly over it; a chain of near-specular
//! events keeps its exact angle and so is approximated where a bin straddles a sharp change (the
//! critical angle). `tests/adding.rs` measures the difference from the walk.

use super::{LayeredBsdf, Level};
use crate::bsdf::dielectric::Lobes;
use crate::bsdf::table::{Table, for_strata};
use crate::bsdf::{Bsdf, Bxdf, TransportMode};
use crate::sampler::{Rng, hash_words};
use crate::spectrum::RgbSample;
use glam::{Vec2, Vec3};

/// Bins over `cos² θ` per side.
pub const BINS: usize = 64;

/// Sampling grid per bin (`GRID² · UC_STRATA` samples).
const GRID: usize = 16;

/// Doublings of the inner series: `2^8 = 256` bounces.
const DOUBLINGS: usize = 8;

/// Bin of a cosine.
#[inline]
fn bin(mu: f32) -> usize {
    ((mu * mu * BINS as f32) as usize).min(BINS - 1)
}

/// A square matrix over bins, one per colour channel: `m[c][to · BINS + from]`.
#[derive(Clone, Debug)]
struct Matrix([Vec<f64>; 3]);

impl Matrix {
    fn zero() -> Self {
        Matrix(std::array::from_fn(|_| vec![0.0; BINS * BINS]))
    }

    fn identity() -> Self {
        let mut m = Matrix::zero();
        for c in 0..3 {
            for i in 0..BINS {
                m.0[c][i * BINS + i] = 1.0;
            }
        }
        m
    }

    fn add(&self, o: &Matrix) -> Matrix {
        Matrix(std::array::from_fn(|c| {
            self.0[c].iter().zip(&o.0[c]).map(|(a, b)| a + b).collect()
        }))
    }

    /// `self · o` (apply `o` first).
    fn mul(&self, o: &Matrix) -> Matrix {
        let mut out = Matrix::zero();
        for c in 0..3 {
            let (a, b, r) = (&self.0[c], &o.0[c], &mut out.0[c]);
            for i in 0..BINS {
                for k in 0..BINS {
                    let aik = a[i * BINS + k];
                    if aik == 0.0 {
                        continue;
                    }
                    let row = &b[k * BINS..(k + 1) * BINS];
                    for (x, &y) in r[i * BINS..(i + 1) * BINS].iter_mut().zip(row) {
                        *x += aik * y;
                    }
                }
            }
        }
        out
    }

    /// `diag(left) · self · diag(right)`.
    fn scale(&self, left: &[RgbSample], right: &[RgbSample]) -> Matrix {
        let mut out = self.clone();
        for c in 0..3 {
            for i in 0..BINS {
                for j in 0..BINS {
                    out.0[c][i * BINS + j] *= f64::from(left[i][c] * right[j][c]);
                }
            }
        }
        out
    }

    /// Column sums: the total weight leaving each source bin.
    fn column_sums(&self) -> [Vec<f64>; 3] {
        std::array::from_fn(|c| {
            (0..BINS)
                .map(|j| (0..BINS).map(|i| self.0[c][i * BINS + j]).sum())
                .collect()
        })
    }
}

/// `Σ_{k < 2^DOUBLINGS} P^k` by doubling: `S ← S + P^n S`, `P^n ← P^n P^n`.
fn series(p: &Matrix) -> Matrix {
    let mut s = Matrix::identity().add(p);
    let mut pn = p.mul(p);
    for _ in 1..DOUBLINGS {
        s = s.add(&pn.mul(&s));
        pn = pn.mul(&pn);
    }
    s
}

/// The two operators of one sampler from one side: weights that stay on the side the path came
/// from (reflection) and weights that cross (transmission), as matrices over bins. `below` says
/// whether the path arrives at the interface from below.
fn kernels(
    key: u64,
    below: bool,
    sample: impl Fn(Vec3, f32, Vec2) -> Events + Sync,
) -> (Matrix, Matrix) {
    use rayon::prelude::*;
    let cols: Vec<[Vec<RgbSample>; 2]> = (0..BINS)
        .into_par_iter()
        .map(|j| {
            let mut same = vec![RgbSample::ZERO; BINS];
            let mut cross = vec![RgbSample::ZERO; BINS];
            let mut rng = Rng::new(hash_words(&[key, j as u64]));
            let n = (GRID * GRID * crate::bsdf::table::UC_STRATA) as f32;
            let mut idx = 0usize;
            for_strata(GRID, hash_words(&[key, j as u64, 1]), |uc, u| {
                // Stratified position within the bin, uniform in cos² θ.
                let t = (idx as f32 + rng.uniform()) / n;
                idx += 1;
                let mu = ((j as f32 + t) / BINS as f32).sqrt().clamp(1e-4, 1.0);
                let wo = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
                // The path arrives travelling towards the surface; `wo` points back along it.
                let wo = if below { -wo } else { wo };
                for (wi, w) in sample(wo, uc, u).into_iter().flatten() {
                    let stays = (wi.z > 0.0) != below;
                    let k = bin(wi.z.abs());
                    if stays {
                        same[k] += w;
                    } else {
                        cross[k] += w;
                    }
                }
            });
            [same, cross].map(|v| v.into_iter().map(|x| x / n).collect())
        })
        .collect();
    let mut same = Matrix::zero();
    let mut cross = Matrix::zero();
    for (j, col) in cols.iter().enumerate() {
        for i in 0..BINS {
            for c in 0..3 {
                same.0[c][i * BINS + j] = f64::from(col[0][i][c]);
                cross.0[c][i * BINS + j] = f64::from(col[1][i][c]);
            }
        }
    }
    (same, cross)
}

/// The reflection operator of a diffuse base by quadrature of `eval` (its lobe is smooth, and
/// sampling would put multinomial noise of a few per cent into each column): two cosine
/// positions per source and destination bin and 12 azimuths over `[0, π]` (the models are even
/// in the azimuth). `∫ f cos θi dωi = ½ ∫∫ f d(cos² θi) dφ`. Exact for Lambert.
fn diffuse_kernel(base: &Bsdf) -> Matrix {
    use rayon::prelude::*;
    const SUB: usize = 2;
    const PHI: usize = 12;
    let weight = 0.5 / (SUB * BINS) as f32 * (2.0 * std::f32::consts::PI / PHI as f32);
    let dir = |mu2: f32, phi: f32| {
        let mu = mu2.sqrt();
        let s = (1.0 - mu2).max(0.0).sqrt();
        Vec3::new(s * phi.cos(), s * phi.sin(), mu)
    };
    let cols: Vec<Vec<RgbSample>> = (0..BINS)
        .into_par_iter()
        .map(|j| {
            let mut col = vec![RgbSample::ZERO; BINS];
            for a in 0..SUB {
                let wo = dir(
                    (j as f32 + (a as f32 + 0.5) / SUB as f32) / BINS as f32,
                    0.0,
                );
                for (i, out) in col.iter_mut().enumerate() {
                    let mut sum = RgbSample::ZERO;
                    for b in 0..SUB {
                        let mu2 = (i as f32 + (b as f32 + 0.5) / SUB as f32) / BINS as f32;
                        for k in 0..PHI {
                            let phi = (k as f32 + 0.5) / PHI as f32 * std::f32::consts::PI;
                            sum += base.eval(wo, dir(mu2, phi));
                        }
                    }
                    *out += sum * (weight / SUB as f32);
                }
            }
            col
        })
        .collect();
    let mut m = Matrix::zero();
    for (j, col) in cols.iter().enumerate() {
        for (i, v) in col.iter().enumerate() {
            for c in 0..3 {
                m.0[c][i * BINS + j] = f64::from(v[c]);
            }
        }
    }
    m
}

/// One leg's transmittance through a coat, averaged over each bin.
fn legs(level: &Level) -> Vec<RgbSample> {
    (0..BINS)
        .map(|k| {
            let sub = 16;
            let mut sum = RgbSample::ZERO;
            for s in 0..sub {
                let mu = ((k as f32 + (s as f32 + 0.5) / sub as f32) / BINS as f32).sqrt();
                sum += level.transmit(mu);
            }
            sum / sub as f32
        })
        .collect()
}

/// Reflection operator of the stack from level `l` down, for paths arriving from above it.
fn reflection(stack: &LayeredBsdf, l: usize, key: u64) -> Matrix {
    let Some(lv) = stack.levels.get(l) else {
        let base = &stack.base;
        if matches!(base, Bsdf::Lambert(_) | Bsdf::OrenNayar(_)) {
            return diffuse_kernel(base);
        }
        return kernels(hash_words(&[key, 0xba5e]), false, |wo, uc, u| {
            [
                base.sample_mode(wo, uc, u, TransportMode::Radiance)
                    .map(|s| (s.wi, s.weight)),
                None,
            ]
        })
        .0;
    };
    let below = reflection(stack, l + 1, key);
    let a = legs(lv);
    let x = below.scale(&a, &a);
    if lv.index_matched {
        return x;
    }
    let iface = interface(stack, lv);
    let (r_a, t_ab) = kernels(hash_words(&[key, l as u64, 0xa]), false, |wo, uc, u| {
        sample_interface(&iface, wo, uc, u)
    });
    let (r_b, t_ba) = kernels(hash_words(&[key, l as u64, 0xb]), true, |wo, uc, u| {
        sample_interface(&iface, wo, uc, u)
    });
    let inner = series(&r_b.mul(&x));
    r_a.add(&t_ba.mul(&x).mul(&inner).mul(&t_ab))
}

/// The interface the Reference walk uses for this coat: with its multiple-scattering lobe when
/// the stack compensates.
fn interface(stack: &LayeredBsdf, lv: &Level) -> crate::bsdf::RoughDielectric {
    if stack.compensation && lv.interface.energy.is_none() {
        lv.interface.clone().with_energy_tables()
    } else {
        lv.interface.clone()
    }
}

/// Up to two weighted events of one sample.
type Events = [Option<(Vec3, RgbSample)>; 2];

/// Reflection and transmission sampled separately with the same numbers, each weight carrying its
/// Fresnel share: no binomial noise from choosing between them (a 4 % reflection estimated from a
/// few thousand choices would be off by several per cent).
#[inline]
fn sample_interface(iface: &crate::bsdf::RoughDielectric, wo: Vec3, uc: f32, u: Vec2) -> Events {
    [Lobes::Reflection, Lobes::Transmission].map(|lobes| {
        iface
            .sample_lobes(wo, uc, u, TransportMode::Radiance, lobes)
            .map(|s| (s.wi, s.weight))
    })
}

/// The adding solution of a stack: everything but the first event at the top, which
/// [`Solution::albedo`] samples from the exact `wo`.
pub struct Solution<'a> {
    stack: &'a LayeredBsdf,
    /// The top interface as the walk sees it (`None` without coats).
    iface: Option<crate::bsdf::RoughDielectric>,
    /// Exit weight, per channel and bin, of a path travelling down just below the top interface.
    exit: [Vec<f64>; 3],
}

impl<'a> Solution<'a> {
    /// Builds the operators of every level and the exit weights below the top (module docs).
    pub fn new(stack: &'a LayeredBsdf) -> Self {
        let key = 0xadd1_u64;
        let Some(top) = stack.levels.first() else {
            return Solution {
                stack,
                iface: None,
                exit: std::array::from_fn(|_| Vec::new()),
            };
        };
        let below = reflection(stack, 1, key);
        let a = legs(top);
        let x = below.scale(&a, &a);
        let iface = interface(stack, top);
        let exit = if top.index_matched {
            x.column_sums()
        } else {
            let (r_b, t_ba) = kernels(hash_words(&[key, 0xb]), true, |wo, uc, u| {
                sample_interface(&iface, wo, uc, u)
            });
            t_ba.mul(&x).mul(&series(&r_b.mul(&x))).column_sums()
        };
        Solution {
            stack,
            iface: (!top.index_matched).then_some(iface),
            exit,
        }
    }

    /// Directional albedo at `cos θo = mu` (outside), from `grid² · UC_STRATA` stratified samples of
    /// the first event.
    pub fn albedo(&self, mu: f32, grid: usize) -> RgbSample {
        let wo = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
        let key = hash_words(&[0xadd2, u64::from(mu.to_bits())]);
        let mut sum = RgbSample::ZERO;
        if self.stack.levels.is_empty() {
            for_strata(grid, key, |uc, u| {
                if let Some(s) = self.stack.base.sample(wo, uc, u) {
                    sum += s.weight;
                }
            });
        } else {
            for_strata(grid, key, |uc, u| {
                // An invisible interface passes the path straight through.
                let events = match &self.iface {
                    None => [Some((-wo, RgbSample::ONE)), None],
                    Some(iface) => sample_interface(iface, wo, uc, u),
                };
                for (wi, w) in events.into_iter().flatten() {
                    if wi.z > 0.0 {
                        sum += w;
                    } else {
                        let k = bin(wi.z.abs());
                        sum += RgbSample(std::array::from_fn(|c| w[c] * self.exit[c][k] as f32));
                    }
                }
            });
        }
        sum / (grid * grid * crate::bsdf::table::UC_STRATA) as f32
    }
}

/// Directional albedo of the whole stack at every table entry `cos θo` (outside), as the Reference
/// walk would measure it with unlimited samples.
pub fn albedo(stack: &LayeredBsdf) -> Table {
    let s = Solution::new(stack);
    Table::build_par(|mu| s.albedo(mu, 24))
}
