//! Mean sampled weights: the directional albedo `R + T` (importance transport), the `1/η'²`
//! radiance scaling of transmission, and the hemispherical transmittance of the two sides.

use super::checks::{SampleStats, check_modes};
use glam::Vec3;
use lapidary::bsdf::{Bxdf, RoughDielectric, sample_cosine_hemisphere};
use lapidary::sampler::Rng;

/// Means of the weights of `n` samples at one `wo` (failed samples count as 0), per lobe and
/// mode, with the standard error of the importance-mode total.
#[derive(Default, Debug)]
pub struct Means {
    /// Reflection, importance (the same in radiance).
    pub r: f64,
    /// Transmission, importance.
    pub t_imp: f64,
    /// Transmission, radiance.
    pub t_rad: f64,
    /// Standard error of `r + t_imp`.
    pub se: f64,
    /// Standard error of `t_imp`.
    pub se_t: f64,
    /// Share of the calls that returned a transmission sample.
    pub share_t: f64,
    /// Mean angle (degrees) between the sampled `wi` and `target(wi side)`, when given.
    pub mean_angle_deg: f64,
    pub stats: SampleStats,
}

/// Accumulates weights of samples whose `wo` comes from `wo_of(rng)`.
struct Acc {
    n: u64,
    r: f64,
    t_imp: f64,
    t_rad: f64,
    sq: f64,
    sq_t: f64,
    trans: u64,
    angle: f64,
    angles: u64,
}

impl Acc {
    fn new() -> Self {
        Acc {
            n: 0,
            r: 0.0,
            t_imp: 0.0,
            t_rad: 0.0,
            sq: 0.0,
            sq_t: 0.0,
            trans: 0,
            angle: 0.0,
            angles: 0,
        }
    }

    fn finish(self, stats: SampleStats) -> Means {
        let n = self.n as f64;
        let total = (self.r + self.t_imp) / n;
        let var = (self.sq / n - total * total).max(0.0);
        let t = self.t_imp / n;
        let var_t = (self.sq_t / n - t * t).max(0.0);
        Means {
            r: self.r / n,
            t_imp: t,
            t_rad: self.t_rad / n,
            se: (var / n).sqrt(),
            se_t: (var_t / n).sqrt(),
            share_t: self.trans as f64 / n,
            mean_angle_deg: if self.angles > 0 {
                self.angle / self.angles as f64
            } else {
                0.0
            },
            stats,
        }
    }
}

/// Samples `bsdf` `n` times (both modes per draw, checked by [`check_modes`]) with `wo` from
/// `wo_of`; `target(wo, wi)` gives the direction the sample should be near (the smooth
/// interface's), for the mean angular deviation.
#[allow(clippy::too_many_arguments)]
pub fn means(
    bsdf: &dyn Bxdf,
    rough: Option<&RoughDielectric>,
    eta: f32,
    n: u64,
    seed: u64,
    wo_of: &dyn Fn(&mut Rng) -> Option<Vec3>,
    target: Option<&dyn Fn(Vec3, Vec3) -> Option<Vec3>>,
) -> Means {
    let mut rng = Rng::new(seed);
    let mut st = SampleStats::default();
    let mut a = Acc::new();
    for _ in 0..n {
        a.n += 1;
        let Some(wo) = wo_of(&mut rng) else {
            continue;
        };
        let (uc, u) = (rng.uniform(), rng.uniform2());
        let Some((sr, si)) = check_modes(bsdf, rough, eta, wo, uc, u, &mut st) else {
            continue;
        };
        let w = f64::from(si.weight[0]);
        a.sq += w * w;
        if si.flags.is_transmission() {
            a.trans += 1;
            a.t_imp += w;
            a.sq_t += w * w;
            a.t_rad += f64::from(sr.weight[0]);
        } else {
            a.r += w;
        }
        if let Some(t) = target
            && let Some(expected) = t(wo, si.wi)
        {
            let c = f64::from(expected.normalize().dot(si.wi)).clamp(-1.0, 1.0);
            a.angle += c.acos().to_degrees();
            a.angles += 1;
        }
    }
    a.finish(st)
}

/// [`means`] at one fixed `wo`.
pub fn at_wo(
    bsdf: &dyn Bxdf,
    rough: Option<&RoughDielectric>,
    eta: f32,
    wo: Vec3,
    n: u64,
    seed: u64,
) -> Means {
    means(bsdf, rough, eta, n, seed, &|_| Some(wo), None)
}

/// [`means`] with `wo` cosine-distributed over the upper (`below == false`) or lower hemisphere:
/// then `t_imp` estimates the hemispherical transmittance `(1/π) ∫ T(wo) |cos θo| dωo` of that
/// side.
pub fn hemispherical(
    bsdf: &dyn Bxdf,
    rough: Option<&RoughDielectric>,
    eta: f32,
    below: bool,
    n: u64,
    seed: u64,
) -> Means {
    let wo_of = move |rng: &mut Rng| {
        let w = sample_cosine_hemisphere(rng.uniform2())?;
        Some(if below { Vec3::new(w.x, w.y, -w.z) } else { w })
    };
    means(bsdf, rough, eta, n, seed, &wo_of, None)
}
