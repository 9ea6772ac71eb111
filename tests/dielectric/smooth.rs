//! The smooth dielectric: the Fresnel split as a binomial experiment, Snell's law, the weights of
//! both modes, total internal reflection; and the rough interface's limit at tiny roughness.
//!
//! A Dirac lobe has no density over the sphere (`pdf()` is 0 by convention and `sample` returns
//! a discrete probability), so the chi-square test of sample() against pdf() does not apply; the
//! only random choice is reflection versus transmission, with probability `F` for reflection: the
//! number of reflections in `n` independent draws of `uc` is Binomial(n, F).

use super::checks::{SampleStats, check_smooth, rel};
use super::common::chi2_p_value;
use glam::Vec3;
use lapidary::bsdf::{BsdfSample, Bxdf, SmoothDielectric, fresnel, refract};
use lapidary::sampler::Rng;

/// The Fresnel reflectance at `wo` (signed cosine with the macro normal).
pub fn fresnel_at(wo: Vec3, eta: f32) -> f32 {
    fresnel::dielectric(wo.z, eta)
}

/// The directions a smooth interface sends `wo` to: the mirror direction, and the refracted one
/// unless `wo` is totally internally reflected.
pub fn smooth_dirs(wo: Vec3, eta: f32) -> (Vec3, Option<Vec3>) {
    (Vec3::new(-wo.x, -wo.y, wo.z), refract(wo, Vec3::Z, eta))
}

/// The geometry and weights of a smooth sample pair (radiance `sr`, importance `si`, the same
/// `uc`): mirror reflection with `pdf = F` and weight 1 in both modes; refraction obeying Snell's
/// law `sin θo = η' sin θi` with the tangential direction reversed, `pdf = 1 − F`, importance
/// weight 1 and radiance weight `1/η'²` (`η' = s.eta`).
pub fn check_geometry(wo: Vec3, eta: f32, sr: &BsdfSample, si: &BsdfSample) -> Result<f64, String> {
    let f = f64::from(fresnel_at(wo, eta));
    let wi = sr.wi;
    let at = || format!("wo {wo:?}, eta {eta}: {sr:?}");
    if !sr.flags.is_transmission() {
        if (wi - Vec3::new(-wo.x, -wo.y, wo.z)).length() > 1e-6 {
            return Err(format!("{}: not the mirror direction", at()));
        }
        if rel(f64::from(sr.pdf), f) > 1e-6 {
            return Err(format!("{}: reflection probability != F = {f}", at()));
        }
        if rel(f64::from(sr.weight[0]), 1.0) > 1e-5 || rel(f64::from(si.weight[0]), 1.0) > 1e-5 {
            return Err(format!("{}: reflection weight != 1", at()));
        }
        return Ok(0.0);
    }
    let etap = sr.eta;
    let sin_o = (wo.x * wo.x + wo.y * wo.y).sqrt();
    let sin_i = (wi.x * wi.x + wi.y * wi.y).sqrt();
    let snell = (f64::from(sin_o) - f64::from(etap) * f64::from(sin_i)).abs();
    if snell > 1e-5 {
        return Err(format!("{}: Snell violated by {snell:e}", at()));
    }
    if (wi.truncate() * etap + wo.truncate()).length() > 1e-5 {
        return Err(format!(
            "{}: not in the plane of incidence or not reversed",
            at()
        ));
    }
    if rel(f64::from(sr.pdf), 1.0 - f) > 1e-5 {
        return Err(format!("{}: transmission probability != 1 − F", at()));
    }
    let e2 = f64::from(etap) * f64::from(etap);
    if rel(f64::from(si.weight[0]), 1.0) > 1e-5 || rel(f64::from(sr.weight[0]), 1.0 / e2) > 1e-5 {
        return Err(format!(
            "{}: weights (imp {}, rad {}) != (1, 1/η'² = {})",
            at(),
            si.weight[0],
            sr.weight[0],
            1.0 / e2
        ));
    }
    Ok(snell)
}

/// One binomial experiment.
pub struct Split {
    pub label: String,
    pub wo_deg: (f32, f32),
    pub n: u64,
    pub reflected: u64,
    /// The Fresnel reflectance the count is compared with.
    pub f: f64,
    pub chi2: f64,
    pub p: f64,
    pub worst_snell: f64,
    pub stats: SampleStats,
    pub geometry_failures: Vec<String>,
}

/// Draws `n` uniform `uc` (and `u`, which a delta ignores) at `wo`, checks every sample pair, and
/// tests the number of reflections against Binomial(n, F(`claimed_eta`)) by Pearson's statistic
/// with one degree of freedom, `(k − nF)² / (nF(1 − F))` (the two-sided normal test).
pub fn split(
    g: &SmoothDielectric,
    claimed_eta: f32,
    wo: Vec3,
    wo_deg: (f32, f32),
    n: u64,
    seed: u64,
) -> Split {
    let mut rng = Rng::new(seed);
    let mut st = SampleStats::default();
    let mut fails = Vec::new();
    let mut worst_snell = 0.0f64;
    for _ in 0..n {
        let (uc, u) = (rng.uniform(), rng.uniform2());
        if let Some((sr, si)) = check_smooth(g, wo, uc, u, &mut st) {
            match check_geometry(wo, g.eta, &sr, &si) {
                Ok(e) => worst_snell = worst_snell.max(e),
                Err(e) => {
                    if fails.len() < 3 {
                        fails.push(e);
                    }
                }
            }
        }
    }
    let f = f64::from(fresnel_at(wo, claimed_eta));
    let k = st.reflected as f64;
    let nf = n as f64;
    let var = nf * f * (1.0 - f);
    let chi2 = if var > 0.0 {
        (k - nf * f).powi(2) / var
    } else {
        f64::INFINITY
    };
    Split {
        label: format!("smooth eta={:.4}", g.eta),
        wo_deg,
        n,
        reflected: st.reflected,
        f,
        chi2,
        p: chi2_p_value(chi2, 1),
        worst_snell,
        stats: st,
        geometry_failures: fails,
    }
}

/// `eval` and `pdf` of a delta are 0 everywhere, including the sampled directions themselves.
pub fn delta_is_invisible(g: &SmoothDielectric, wo: Vec3) -> bool {
    let (r, t) = smooth_dirs(wo, g.eta);
    [Some(r), t, Some(-wo), Some(wo)]
        .into_iter()
        .flatten()
        .all(|wi| g.pdf(wo, wi) == 0.0 && g.eval(wo, wi).max_channel() == 0.0)
}
