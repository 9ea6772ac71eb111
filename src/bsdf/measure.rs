//! Measurements of a BSDF used by the CLI, the tests and the benchmarks: directional albedo by
//! sampling, and by integrating `eval` (independent of the sampler).

use super::{Bxdf, spherical_direction};
use crate::sampler::{Rng, hash_words};
use crate::spectrum::RgbSample;
use glam::{Vec2, Vec3};

/// A Monte Carlo estimate per channel with its standard error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// Sample mean per channel.
    pub mean: RgbSample,
    /// Standard error of the mean per channel.
    pub std_error: RgbSample,
    /// Number of samples.
    pub samples: u64,
}

fn finish(sum: [f64; 3], sum2: [f64; 3], n: u64) -> Estimate {
    let nf = n.max(1) as f64;
    let mut mean = [0.0f32; 3];
    let mut se = [0.0f32; 3];
    for c in 0..3 {
        let m = sum[c] / nf;
        let var = (sum2[c] / nf - m * m).max(0.0) * nf / (nf - 1.0).max(1.0);
        mean[c] = m as f32;
        se[c] = (var / nf).sqrt() as f32;
    }
    Estimate {
        mean: RgbSample(mean),
        std_error: RgbSample(se),
        samples: n,
    }
}

/// Local direction for a viewing angle `theta_deg` from the normal at azimuth `phi_deg`.
pub fn direction_deg(theta_deg: f32, phi_deg: f32) -> Vec3 {
    spherical_direction(theta_deg.to_radians(), phi_deg.to_radians())
}

/// Directional albedo `∫ f cos dωi` as the mean `sample` weight over `n` independent samples
/// (failed samples count as 0). Deterministic for a given `seed`.
pub fn albedo_by_sampling(b: &impl Bxdf, wo: Vec3, n: u64, seed: u64) -> Estimate {
    let mut rng = Rng::new(hash_words(&[seed, 0x00a1_bed0]));
    let (mut s1, mut s2) = ([0.0f64; 3], [0.0f64; 3]);
    for _ in 0..n {
        if let Some(s) = b.sample(wo, rng.uniform(), rng.uniform2()) {
            for c in 0..3 {
                let w = f64::from(s.weight[c]);
                s1[c] += w;
                s2[c] += w * w;
            }
        }
    }
    finish(s1, s2, n)
}

/// Directional albedo by integrating `b.eval` with directions drawn from a fixed mixture: half
/// cosine-weighted, half from `proposal`'s sampler, weighted by the mixture density. `proposal`
/// must have an exact `pdf` (a Lambert, a component, or a stack under an analytic model — for the
/// Reference model pass the Corrected model of the same stack), so the estimate depends on `b`
/// only through `eval`.
pub fn albedo_by_eval(
    b: &impl Bxdf,
    proposal: &impl Bxdf,
    wo: Vec3,
    n: u64,
    seed: u64,
) -> Estimate {
    let mut rng = Rng::new(hash_words(&[seed, 0xe7a1]));
    let (mut s1, mut s2) = ([0.0f64; 3], [0.0f64; 3]);
    for _ in 0..n {
        let pick = rng.uniform();
        let (uc, u) = (rng.uniform(), rng.uniform2());
        let wi = if pick < 0.5 {
            super::sample_cosine_hemisphere(u)
        } else {
            proposal.sample(wo, uc, u).map(|s| s.wi)
        };
        let Some(wi) = wi else { continue };
        let p = 0.5 * wi.z.max(0.0) * std::f32::consts::FRAC_1_PI + 0.5 * proposal.pdf(wo, wi);
        if !(p > 0.0) {
            continue;
        }
        let v = b.eval(wo, wi) * (wi.z.abs() / p);
        for c in 0..3 {
            let w = f64::from(v[c]);
            s1[c] += w;
            s2[c] += w * w;
        }
    }
    finish(s1, s2, n)
}

/// A stratified set of `n × n` uniform pairs (one per stratum, jittered), for quadrature.
pub fn stratified(n: usize, seed: u64) -> Vec<Vec2> {
    let mut rng = Rng::new(seed);
    let mut v = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n {
            v.push(Vec2::new(
                (i as f32 + rng.uniform()) / n as f32,
                (j as f32 + rng.uniform()) / n as f32,
            ));
        }
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::Lambert;

    #[test]
    fn lambert_albedo_both_ways() {
        let l = Lambert {
            albedo: RgbSample::rgb(0.25, 0.5, 1.0),
        };
        let wo = direction_deg(40.0, 0.0);
        let a = albedo_by_sampling(&l, wo, 10_000, 1);
        assert!((a.mean - l.albedo).map(f32::abs).max_channel() < 1e-5);
        let b = albedo_by_eval(&l, &l, wo, 100_000, 1);
        for c in 0..3 {
            assert!((b.mean[c] - l.albedo[c]).abs() < 4.0 * b.std_error[c] + 1e-6);
        }
    }
}
