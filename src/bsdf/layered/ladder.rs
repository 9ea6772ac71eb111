//! A coated stack whose diffuse base has a measured albedo spectrum, read per wavelength.
//!
//! A stack's tables (top-lobe albedo, the lower layers' albedo, the light the coat traps, the
//! multiple-reflection lobe, the albedo calibration) are built per RGB channel from the base's
//! RGB albedo; its value is not linear in that albedo (the light the coat's underside returns to
//! the base is reflected again: `ρ̄/(1 − ρ̄ r_int)`, and the calibration depends on it). So the
//! value at a wavelength `λ` is not the stack's RGB value as a spectrum, nor that value with its
//! single-scatter term corrected: it is the stack with a grey base of albedo `ρ(λ)`.
//!
//! The ladder holds the same stack built with grey bases at the albedos `k/8`, `k = 0 … 8` (three
//! stacks, three rungs each: one per RGB channel, since channels are independent), and reads
//! `f(wo, wi; ρ)` for any `ρ` as `f(0) + ρ h(ρ)`, the base's share per unit albedo `h` by cubic
//! (Lagrange) interpolation through the four nearest rungs ([`interpolate`]). The value is
//! strongly convex in `ρ` (a clear η 1.5 coat over white reflects 2.5 times what `ρ` times its
//! value at small albedos predicts): linear interpolation of `f` between rungs was off by up to
//! 6 % at small albedos, a cubic of `f` by 0.55 %; interpolating `h` stays within 0.3 %
//! (tests/spectral.rs compares wavelengths across the range with stacks built at exactly their
//! albedo). It is built only for spectral renders
//! ([`crate::render::World`] builds it when the `spectral` effect is on): three more stacks'
//! tables at setup, and three stack evaluations instead of one at each spectral hit of such a
//! material.
//!
//! It applies where the coats do not absorb and the base does not fluoresce: an absorbing coat's
//! optical depth is itself per channel (a measured tint is its RGB projection), so its channels
//! could not serve as rungs; a fluorescent base has its own per-wavelength lobe
//! ([`super::fluorescent`]).

use super::{Base, LayeredBsdf, StackDesc, StackError};
use crate::bsdf::{Bxdf, TransportMode};
use crate::color::Rgb;
use crate::spectrum::RgbSample;
use glam::Vec3;

/// The cubic through the four points `(k, g[k])`, `k ∈ lo ..= hi`, nearest `x` (one-sided at the
/// ends, extrapolating below `lo`), at `x`.
fn cubic(g: &[f32; STEPS + 1], lo: usize, hi: usize, x: f32) -> f32 {
    let k0 = (x.floor().max(0.0) as usize)
        .saturating_sub(1)
        .clamp(lo, hi - 3);
    let mut sum = 0.0;
    for i in 0..4 {
        let mut w = 1.0;
        for j in 0..4 {
            if j != i {
                w *= (x - (k0 + j) as f32) / (i as f32 - j as f32);
            }
        }
        sum += w * g[k0 + i];
    }
    sum
}

/// `f(ρ)` from the rungs `f[k] = f(k / STEPS)`: the value is `f(0) + ρ h(ρ)` with `h`, the
/// base's share per unit albedo, smooth and slowly varying (from `T T/η²/π` at small albedos to
/// 2.5 times that over white under a clear η 1.5 coat); `h` is interpolated by a cubic through
/// the rungs `1 ..= STEPS` (extrapolated below the first), so the interpolation error is
/// relative to the albedo's own share, not to the convexity of `f` itself.
fn interpolate(f: &[f32; STEPS + 1], rho: f32) -> f32 {
    let mut h = [0.0f32; STEPS + 1];
    for k in 1..=STEPS {
        h[k] = (f[k] - f[0]) * STEPS as f32 / k as f32;
    }
    f[0] + rho * cubic(&h, 1, STEPS, rho * STEPS as f32)
}

/// Intervals between the rungs over albedo 0 … 1.
const STEPS: usize = 8;

/// The stack at grey base albedos `0, 1/8, …, 1` (module docs).
#[derive(Clone, Debug)]
pub struct AlbedoLadder {
    /// Stack `j` holds the rungs `3j, 3j + 1, 3j + 2` in its R, G, B channels.
    stacks: [LayeredBsdf; 3],
}

impl AlbedoLadder {
    /// The ladder of `desc`, or `None` where it does not apply (no measured diffuse base, no
    /// coats, an absorbing coat or a fluorescent base). `absorption` is the world's forcing of
    /// the absorption effect, applied to the rungs as to the stack itself.
    pub fn build(desc: &StackDesc, absorption: Option<bool>) -> Result<Option<Self>, StackError> {
        let applies = desc.base_spectrum.is_some()
            && !desc.coats.is_empty()
            && desc.fluorescence.is_none()
            && desc.coats.iter().all(|c| c.absorption == Rgb::ZERO)
            && matches!(desc.base, Base::Lambert { .. } | Base::OrenNayar { .. });
        if !applies {
            return Ok(None);
        }
        let rung = |k: usize| k as f32 / STEPS as f32;
        let stack = |j: usize| {
            let albedo = Rgb::new(rung(3 * j), rung(3 * j + 1), rung(3 * j + 2));
            let mut d = desc.clone();
            d.base_spectrum = None;
            d.base = match d.base {
                Base::OrenNayar { sigma, .. } => Base::OrenNayar { albedo, sigma },
                _ => Base::Lambert { albedo },
            };
            let mut s = LayeredBsdf::new(&d)?;
            s.force_absorption(absorption);
            Ok(s)
        };
        Ok(Some(AlbedoLadder {
            stacks: [stack(0)?, stack(1)?, stack(2)?],
        }))
    }

    /// `f(wo, wi)` (sr⁻¹, cosine excluded) of the stack with a grey base of albedo `rho[i]`
    /// (clamped to 0 … 1), for each `i`.
    pub fn eval(&self, wo: Vec3, wi: Vec3, mode: TransportMode, rho: [f32; 4]) -> [f32; 4] {
        let mut f = [0.0f32; STEPS + 1];
        for (j, s) in self.stacks.iter().enumerate() {
            let v: RgbSample = s.eval_mode(wo, wi, mode);
            f[3 * j..3 * j + 3].copy_from_slice(&v.0);
        }
        rho.map(|r| interpolate(&f, r.clamp(0.0, 1.0)).max(0.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_interpolation_is_exact_for_cubic_shares() {
        // f(ρ) = f0 + ρ h(ρ) with a cubic h: reproduced exactly, rungs included.
        let h = |x: f32| 0.3 - 0.2 * x + 0.05 * x * x - 0.004 * x * x * x;
        let f_of = |rho: f32| 0.01 + rho * h(rho * STEPS as f32);
        let f: [f32; STEPS + 1] = std::array::from_fn(|k| f_of(k as f32 / STEPS as f32));
        for i in 0..=100 {
            let rho = i as f32 / 100.0;
            assert!((interpolate(&f, rho) - f_of(rho)).abs() < 1e-5, "{rho}");
        }
    }
}
