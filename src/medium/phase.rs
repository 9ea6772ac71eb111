//! The Henyey–Greenstein phase function (Henyey & Greenstein, "Diffuse radiation in the Galaxy",
//! Astrophysical Journal 93, 1941): `p(θ) = (1 − g²) / (4π (1 + g² − 2g cos θ)^{3/2})`, sr⁻¹, with
//! `θ` the angle between the propagation directions before and after scattering (see
//! [`super`] for the direction convention). `g = 0` is isotropic (`1/4π`); `g` is the mean cosine.
//! Sampled exactly by inverting its CDF in `cos θ` (e.g. Pharr, Jakob & Humphreys, *Physically
//! Based Rendering*, 4th ed., §11.3.1).

use crate::geometry::Frame;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Largest `|g|` a medium may have (closer to ±1 the lobe becomes a delta that `f32` cannot
/// resolve).
pub const G_LIMIT: f32 = 0.99;

/// A Henyey–Greenstein phase function with asymmetry `g ∈ [−0.99, 0.99]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HenyeyGreenstein {
    /// Mean cosine of the scattering angle: > 0 forward, < 0 backward, 0 isotropic.
    pub g: f32,
}

/// A direction sampled from a phase function. The phase function is its own density, so the
/// path weight is exactly 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhaseSample {
    /// The new propagation direction (unit, world space).
    pub wi: Vec3,
    /// Its density per steradian (equal to the phase function's value).
    pub pdf: f32,
}

impl HenyeyGreenstein {
    /// The phase function, `g` clamped to ±[`G_LIMIT`].
    pub fn new(g: f32) -> Self {
        HenyeyGreenstein {
            g: g.clamp(-G_LIMIT, G_LIMIT),
        }
    }

    /// `p` for the cosine between the old and the new propagation direction, sr⁻¹.
    #[inline]
    pub fn value_cos(&self, cos_theta: f32) -> f32 {
        let g = self.g;
        let denom = (1.0 + g * g - 2.0 * g * cos_theta).max(1e-12);
        (1.0 - g * g) / (4.0 * PI * denom * denom.sqrt())
    }

    /// `p(wo, wi)`: `wo` points back along the incoming ray, `wi` along the outgoing one.
    #[inline]
    pub fn value(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.value_cos(-wo.dot(wi))
    }

    /// Samples the outgoing direction for `wo` (pointing back along the incoming ray) from two
    /// uniform numbers.
    pub fn sample(&self, wo: Vec3, u: Vec2) -> Option<PhaseSample> {
        let g = self.g;
        let cos_theta = if g.abs() < 1e-3 {
            1.0 - 2.0 * u.x
        } else {
            let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u.x);
            (1.0 + g * g - s * s) / (2.0 * g)
        }
        .clamp(-1.0, 1.0);
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        let phi = 2.0 * PI * u.y;
        let frame = Frame::from_normal(-wo);
        let local = Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta);
        let wi = frame.to_world(local).normalize();
        let pdf = self.value_cos(cos_theta);
        (wi.is_finite() && pdf.is_finite() && pdf > 0.0).then_some(PhaseSample { wi, pdf })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(theta: f32, phi: f32) -> Vec3 {
        Vec3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        )
    }

    /// `∫ p dω = 1` (midpoint rule in cos θ) for backward, isotropic and forward lobes.
    #[test]
    fn normalised() {
        for g in [-0.9, -0.3, 0.0, 0.5, 0.9] {
            let hg = HenyeyGreenstein::new(g);
            let n = 200_000;
            let s: f64 = (0..n)
                .map(|i| {
                    let c = -1.0 + 2.0 * (i as f64 + 0.5) / n as f64;
                    f64::from(hg.value_cos(c as f32)) * 2.0 * std::f64::consts::PI * 2.0 / n as f64
                })
                .sum();
            assert!((s - 1.0).abs() < 2e-3, "g {g}: {s}");
        }
    }

    /// The sampled cosine has mean `g` (HG's defining property), and samples report `p` as pdf.
    #[test]
    fn sampling_mean_cosine_is_g() {
        for g in [-0.7, 0.0, 0.3, 0.85] {
            let hg = HenyeyGreenstein::new(g);
            let wo = dir(0.7, 1.1);
            let n = 200_000;
            let mut sum = 0.0f64;
            for i in 0..n {
                let u = Vec2::new(
                    (i as f32 + 0.5) / n as f32,
                    ((i as f32) * 0.618_034).fract(),
                );
                let s = hg.sample(wo, u).expect("a sample");
                assert!((s.wi.length() - 1.0).abs() < 1e-4);
                assert!((s.pdf - hg.value(wo, s.wi)).abs() <= 1e-3 * s.pdf);
                sum += f64::from(-wo.dot(s.wi));
            }
            let mean = sum / n as f64;
            assert!((mean - f64::from(g)).abs() < 2e-3, "g {g}: mean cos {mean}");
        }
    }

    /// Reciprocal: `p(wo, wi) = p(−wi, −wo)`.
    #[test]
    fn reciprocal() {
        let hg = HenyeyGreenstein::new(0.6);
        let (a, b) = (dir(0.3, 0.2), dir(2.0, 4.0));
        assert!((hg.value(a, b) - hg.value(-b, -a)).abs() < 1e-6);
    }
}
