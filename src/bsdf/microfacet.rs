//! Micro-facet normal distributions, with their masking–shadowing ([`super::masking`]).
//!
//! Roughness is the course's RMS slope angle `m` in degrees, `α = tan m`, or `α` itself (the unit
//! of pbrt-v4 and Mitsuba 3). Three distributions share it:
//! - normalised Blinn (course eq. 3.7): `D(h) = (e+2)/(2π) cos^e θh`, `e = 2/α² − 2`;
//! - Beckmann: `D(h) = exp(−tan²θh/α²) / (π α² cos⁴θh)`;
//! - GGX / Trowbridge–Reitz (Walter et al. 2007 eq. 33): `D(h) = α² / (π cos⁴θh (α² + tan²θh)²)`.
//!
//! All are normalised so that `∫ D(h) cos θh dω = 1` and sampled exactly from that density
//! ([`MicrofacetDistribution::sample_h`]). Scattering lobes sample **visible** normals where a
//! sampler exists ([`MicrofacetDistribution::sample_visible`]):
//! - with V-cavity masking (any distribution), the construction of Heitz & d'Eon, "Importance
//!   sampling microfacet-based BSDFs using the distribution of visible normals", EGSR 2014, §5:
//!   draw `h` from `D cos`, form the cavity's other facet `h' = (−hx, −hy, hz)` and keep one of the
//!   two with probability proportional to its projected area toward `wo`; the density is exactly
//!   `D_wo(h) = G1(wo, h) ⟨wo·h⟩ D(h) / cos θo` with the V-cavity `G1`, so a reflection's weight is
//!   `F · G / G1 ≤ 1`;
//! - with Smith masking and GGX, Heitz, "Sampling the GGX distribution of visible normals", JCGT
//!   7(4) 2018 — exact, density `G1 ⟨wo·h⟩ D / cos θo` with Smith's `G1`;
//! - with Smith masking and Beckmann or Blinn, `D cos θh` itself (their exact visible-normal
//!   samplers need an inverse error function per sample; the weight's tail is bounded by
//!   `G ⟨wo·h⟩ / (cos θo cos θh)` and the chi-square tests cover it), back-facing normals failing.
//!
//! Near-mirror roughness (m = 0.01°, `e ≈ 6.6e7`) is handled by never forming `cos θh` from a
//! difference: `cos^e θh = exp(e/2 · ln(1 − sin²θh))` with `sin²θh = hx² + hy²`, and the samplers
//! invert their CDFs with `expm1`/`ln_1p` (docs/design.md §5.3). Blinn's exponent and its
//! sampler run in `f64` through the inline kernels of [`super::fastmath`] (accurate to ~1e-14).

use super::fastmath;
pub use super::masking::{Masking, v_cavity_g, v_cavity_g1};
use super::masking::{lambda_beckmann, lambda_ggx};
use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};
use std::f32::consts::PI;

/// Which micro-facet distribution a material uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Distribution {
    /// Normalised Blinn, course eq. 3.7 (the course's choice; default).
    #[default]
    Blinn,
    /// Beckmann.
    Beckmann,
    /// GGX / Trowbridge–Reitz.
    Ggx,
}

/// The shape of `D` with its precomputed constants.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Ndf {
    /// Normalised Blinn with exponent `e` (≥ 0 for m ≤ 45°, in (−2, 0) beyond).
    Blinn {
        exponent: f32,
    },
    Beckmann,
    Ggx,
}

/// A micro-facet distribution with its roughness and masking bound in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MicrofacetDistribution {
    ndf: Ndf,
    /// `α` (`tan m`).
    alpha: f32,
    masking: Masking,
}

impl MicrofacetDistribution {
    /// Builds the distribution for RMS slope angle `m_deg` in degrees (0 < m < 90), V-cavity
    /// masking.
    pub fn new(kind: Distribution, m_deg: f32) -> Self {
        Self::from_alpha_f64(kind, (f64::from(m_deg).to_radians()).tan())
    }

    /// Builds the distribution for roughness `alpha` (> 0), V-cavity masking.
    pub fn from_alpha(kind: Distribution, alpha: f32) -> Self {
        Self::from_alpha_f64(kind, f64::from(alpha))
    }

    fn from_alpha_f64(kind: Distribution, alpha: f64) -> Self {
        let ndf = match kind {
            Distribution::Blinn => Ndf::Blinn {
                exponent: (2.0 / (alpha * alpha) - 2.0) as f32,
            },
            Distribution::Beckmann => Ndf::Beckmann,
            Distribution::Ggx => Ndf::Ggx,
        };
        MicrofacetDistribution {
            ndf,
            alpha: alpha as f32,
            masking: Masking::VCavity,
        }
    }

    /// The same distribution with another masking–shadowing term.
    pub fn with_masking(mut self, masking: Masking) -> Self {
        self.masking = masking;
        self
    }

    /// Which distribution.
    pub fn kind(&self) -> Distribution {
        match self.ndf {
            Ndf::Blinn { .. } => Distribution::Blinn,
            Ndf::Beckmann => Distribution::Beckmann,
            Ndf::Ggx => Distribution::Ggx,
        }
    }

    /// Roughness `α`.
    pub fn alpha(&self) -> f32 {
        self.alpha
    }

    /// The masking–shadowing term.
    pub fn masking(&self) -> Masking {
        self.masking
    }

    /// `D(h)` per steradian of micro-normal; `h` is a unit vector, zero for `h.z ≤ 0`.
    #[inline]
    pub fn d(&self, h: Vec3) -> f32 {
        if h.z <= 0.0 {
            return 0.0;
        }
        let s2 = super::sin2_theta(h);
        let d = match self.ndf {
            Ndf::Blinn { exponent: e } => {
                // ln cos θh from the tangential part near the normal (where 1 − z² cancels) and
                // from z near the horizon (where sin² θh rounds to 1 in f32 although cos θh > 0:
                // D is not 0 there for e ≤ 0, and both argument orders of a pair must agree).
                // In f64 by the inline kernels of [`super::fastmath`]: `1 − s2` is exact there
                // for every `s2` that matters, and one rounding to f32 at the end.
                if fastmath::cos_power_underflows(e, s2, h.z) {
                    return 0.0;
                }
                let log_cos = if s2 < 0.5 {
                    0.5 * fastmath::ln(1.0 - f64::from(s2))
                } else {
                    fastmath::ln(f64::from(h.z))
                };
                (e + 2.0) / (2.0 * PI) * fastmath::exp(f64::from(e) * log_cos) as f32
            }
            Ndf::Beckmann => {
                let c2 = if s2 < 0.5 { 1.0 - s2 } else { h.z * h.z };
                let a2 = self.alpha * self.alpha;
                let t2 = s2 / c2;
                (-t2 / a2).exp() / (PI * a2 * c2 * c2)
            }
            Ndf::Ggx => {
                // α² / (π (α² cos²θ + sin²θ)²): the cos⁴ folded in, finite at the horizon.
                let c2 = if s2 < 0.5 { 1.0 - s2 } else { h.z * h.z };
                let a2 = self.alpha * self.alpha;
                let k = a2 * c2 + s2;
                a2 / (PI * k * k)
            }
        };
        if d.is_finite() { d } else { 0.0 }
    }

    /// Density of [`Self::sample_h`]: `D(h) cos θh` per steradian of `h`.
    #[inline]
    pub fn pdf_h(&self, h: Vec3) -> f32 {
        self.d(h) * h.z.max(0.0)
    }

    /// Samples a micro-normal from `D(h) cos θh`. `None` when `u` maps to the horizon (density 0).
    #[inline]
    pub fn sample_h(&self, u: Vec2) -> Option<Vec3> {
        let u0 = u.x.clamp(0.0, 1.0);
        let s2 = match self.ndf {
            Ndf::Blinn { exponent: e } => {
                // CDF of cos θh: 1 − cos^(e+2) θh = u  ⇒  sin²θh = 1 − (1−u)^(2/(e+2)).
                let c = 2.0 / (f64::from(e) + 2.0) * fastmath::ln_1p(-f64::from(u0));
                -fastmath::exp_m1(c) as f32
            }
            Ndf::Beckmann => {
                // tan²θh = −α² ln(1 − u).
                let t2 = -self.alpha * self.alpha * (-u0).ln_1p();
                if !t2.is_finite() {
                    return None;
                }
                t2 / (1.0 + t2)
            }
            Ndf::Ggx => {
                // tan²θh = α² u / (1 − u)  ⇒  sin²θh = α² u / (α² u + 1 − u).
                let a2u = self.alpha * self.alpha * u0;
                let den = a2u + (1.0 - u0);
                if !(den > 0.0) {
                    return None;
                }
                a2u / den
            }
        };
        if !(s2 < 1.0) {
            return None;
        }
        let s2 = s2.max(0.0);
        let (sin_t, cos_t) = (s2.sqrt(), (1.0 - s2).sqrt());
        let (sp, cp) = (2.0 * PI * u.y).sin_cos();
        (cos_t > 0.0).then(|| Vec3::new(sin_t * cp, sin_t * sp, cos_t))
    }

    /// Smith's `Λ(w)` of this distribution (used by the Smith masking forms).
    #[inline]
    pub fn lambda(&self, w: Vec3) -> f32 {
        match self.ndf {
            Ndf::Ggx => lambda_ggx(w, self.alpha),
            Ndf::Beckmann | Ndf::Blinn { .. } => lambda_beckmann(w, self.alpha),
        }
    }

    /// Masking of direction `w` (either side) for micro-normal `h` (`h.z > 0`): 0 when `w` sees
    /// the back of the facet (Smith), else the model's `G1`.
    #[inline]
    pub fn g1(&self, w: Vec3, h: Vec3) -> f32 {
        match self.masking {
            Masking::VCavity => v_cavity_g1(w, h),
            Masking::Smith | Masking::SmithSeparable => {
                if w.dot(h) * w.z <= 0.0 {
                    0.0
                } else {
                    1.0 / (1.0 + self.lambda(w))
                }
            }
        }
    }

    /// Masking–shadowing of the pair `(wo, wi)` for micro-normal `h` (`h.z > 0`); a transmission
    /// pair has `wo.z · wi.z < 0`.
    #[inline]
    pub fn g(&self, wo: Vec3, wi: Vec3, h: Vec3) -> f32 {
        match self.masking {
            Masking::VCavity => v_cavity_g(wo, wi, h),
            Masking::Smith | Masking::SmithSeparable => {
                if wo.dot(h) * wo.z <= 0.0 || wi.dot(h) * wi.z <= 0.0 {
                    return 0.0;
                }
                let (lo, li) = (self.lambda(wo), self.lambda(wi));
                let g = if self.masking == Masking::Smith && wo.z * wi.z > 0.0 {
                    1.0 / (1.0 + lo + li)
                } else {
                    1.0 / ((1.0 + lo) * (1.0 + li))
                };
                if g.is_finite() { g } else { 0.0 }
            }
        }
    }

    /// Samples a micro-normal (`h.z > 0`) for `wo` (either side of the surface; a `wo` below is
    /// mirrored above) by the sampler of the module docs for this distribution and masking.
    /// Returns the normal and a uniform number for the caller's next choice (`uc` remapped when
    /// the sampler consumed it, else `uc` itself).
    #[inline]
    pub fn sample_visible(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<(Vec3, f32)> {
        let w = if wo.z < 0.0 { -wo } else { wo };
        if w.z <= 0.0 {
            return None;
        }
        match (self.masking, self.ndf) {
            (Masking::VCavity, _) => self.sample_v_cavity(w, uc, u),
            (_, Ndf::Ggx) => self.sample_ggx_visible(w, u).map(|h| (h, uc)),
            _ => self.sample_h(u).map(|h| (h, uc)),
        }
    }

    fn sample_v_cavity(&self, w: Vec3, uc: f32, u: Vec2) -> Option<(Vec3, f32)> {
        let h = self.sample_h(u)?;
        let h2 = Vec3::new(-h.x, -h.y, h.z);
        let (a, b) = (w.dot(h).max(0.0), w.dot(h2).max(0.0));
        if !(a + b > 0.0) {
            return None;
        }
        let p2 = b / (a + b);
        let uc = uc.clamp(0.0, 1.0);
        if uc < p2 {
            Some((h2, (uc / p2).min(1.0)))
        } else if p2 < 1.0 {
            Some((h, ((uc - p2) / (1.0 - p2)).clamp(0.0, 1.0)))
        } else {
            Some((h2, uc))
        }
    }

    /// Heitz 2018 (JCGT 7(4), listing 1): stretch `w` to the hemisphere configuration, sample the
    /// projected disc with its half-disc warp, unstretch.
    fn sample_ggx_visible(&self, w: Vec3, u: Vec2) -> Option<Vec3> {
        let a = self.alpha;
        let vh = Vec3::new(a * w.x, a * w.y, w.z).normalize();
        let len2 = vh.x * vh.x + vh.y * vh.y;
        let t1 = if len2 > 0.0 {
            Vec3::new(-vh.y, vh.x, 0.0) / len2.sqrt()
        } else {
            Vec3::X
        };
        let t2 = vh.cross(t1);
        let r = u.x.clamp(0.0, 1.0).sqrt();
        let (sp, cp) = (2.0 * PI * u.y).sin_cos();
        let p1 = r * cp;
        let s = 0.5 * (1.0 + vh.z);
        let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * (r * sp);
        let nh = p1 * t1 + p2 * t2 + (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt() * vh;
        let h = Vec3::new(a * nh.x, a * nh.y, nh.z.max(0.0));
        let l = h.length();
        (l > 0.0 && h.z > 0.0).then(|| h / l)
    }

    /// Density per steradian of the normals [`Self::sample_visible`] draws: `G1(wo, h) ⟨wo·h⟩
    /// D(h) / |cos θo|` for the visible-normal samplers, `D(h) cos θh` (where `wo·h > 0`) for
    /// Smith with Beckmann or Blinn; `wo` is mirrored above the surface when it lies below.
    #[inline]
    pub fn pdf_visible(&self, wo: Vec3, h: Vec3) -> f32 {
        self.pdf_visible_with_d(wo, h, self.d(h))
    }

    /// `pdf_visible(wo, h) / D(h)`: what a sample weight `f cos / pdf` keeps of the density
    /// once `D` cancels (`G1 ⟨wo·h⟩ / |cos θo|`, or `cos θh` for Smith with Beckmann or Blinn);
    /// 0 where the density is 0.
    #[inline]
    pub fn visible_over_d(&self, wo: Vec3, h: Vec3) -> f32 {
        let w = if wo.z < 0.0 { -wo } else { wo };
        let wh = w.dot(h);
        if w.z <= 0.0 || wh <= 0.0 {
            return 0.0;
        }
        match (self.masking, self.ndf) {
            (Masking::VCavity, _) => v_cavity_g1(w, h) * (wh / w.z),
            (_, Ndf::Ggx) => self.g1(w, h) * (wh / w.z),
            _ => h.z.max(0.0),
        }
    }

    /// [`Self::pdf_visible`] with `d = self.d(h)` already evaluated (a caller that needs both `f`
    /// and the density evaluates `D` once); the same result bit for bit.
    #[inline]
    pub fn pdf_visible_with_d(&self, wo: Vec3, h: Vec3, d: f32) -> f32 {
        let w = if wo.z < 0.0 { -wo } else { wo };
        let wh = w.dot(h);
        if w.z <= 0.0 || wh <= 0.0 {
            return 0.0;
        }
        let p = match (self.masking, self.ndf) {
            // (wh / w.z) first: with D deep in the subnormal range a product with a small cosine
            // would underflow to 0 while f (divided by cosines) is still positive.
            (Masking::VCavity, _) => v_cavity_g1(w, h) * d * (wh / w.z),
            (_, Ndf::Ggx) => self.g1(w, h) * d * (wh / w.z),
            _ => d * h.z.max(0.0),
        };
        if p.is_finite() { p } else { 0.0 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫ D cos θh dω over the hemisphere, by midpoint quadrature in a slope-scaled θ.
    fn normalisation(d: &MicrofacetDistribution, theta_max: f64) -> f64 {
        let n = 20_000;
        let mut sum = 0.0;
        for i in 0..n {
            let t = (i as f64 + 0.5) / n as f64 * theta_max;
            let h = Vec3::new(t.sin() as f32, 0.0, t.cos() as f32);
            sum += f64::from(d.d(h))
                * t.cos()
                * t.sin()
                * (theta_max / n as f64)
                * 2.0
                * std::f64::consts::PI;
        }
        sum
    }

    #[test]
    fn distributions_are_normalised() {
        for kind in [
            Distribution::Blinn,
            Distribution::Beckmann,
            Distribution::Ggx,
        ] {
            for &m in &[0.5f32, 5.0, 20.0, 45.0] {
                let d = MicrofacetDistribution::new(kind, m);
                // GGX's tail is long (∝ tan⁻⁴): integrate it to the horizon.
                let tmax = match kind {
                    Distribution::Ggx => std::f64::consts::FRAC_PI_2,
                    _ => f64::from((m.to_radians() * 8.0).min(std::f32::consts::FRAC_PI_2)),
                };
                let s = normalisation(&d, tmax);
                assert!((s - 1.0).abs() < 2e-3, "{kind:?} m={m}: {s}");
            }
        }
    }

    #[test]
    fn blinn_exponent_matches_design() {
        if let Ndf::Blinn { exponent } = MicrofacetDistribution::new(Distribution::Blinn, 0.01).ndf
        {
            assert!((exponent / 6.566e7 - 1.0).abs() < 1e-3, "{exponent}");
        } else {
            unreachable!()
        }
    }

    #[test]
    fn near_mirror_is_finite_and_peaked() {
        let d = MicrofacetDistribution::new(Distribution::Blinn, 0.01);
        let peak = d.d(Vec3::Z);
        assert!(peak.is_finite() && peak > 1e6);
        let off = d.d(Vec3::new(0.01, 0.0, (1.0f32 - 1e-4).sqrt()));
        assert_eq!(off, 0.0);
        for &u in &[0.0f32, 1e-9, 0.5, 0.999_999, 1.0] {
            if let Some(h) = d.sample_h(Vec2::new(u, 0.3)) {
                assert!(h.is_finite() && h.z > 0.0);
                assert!(d.pdf_h(h).is_finite() && d.pdf_h(h) > 0.0, "u={u}");
            }
        }
    }

    #[test]
    fn visible_normals_integrate_to_one() {
        // ∫ D_wo(h) dω = 1 for every wo: the V-cavity and Smith's G1 both satisfy
        // ∫ G1 ⟨wo·h⟩ D dω = cos θo (Smith exactly for its own distribution, Heitz 2014 eq. 25).
        let cases = [
            (Distribution::Blinn, Masking::VCavity),
            (Distribution::Ggx, Masking::VCavity),
            (Distribution::Ggx, Masking::Smith),
            (Distribution::Ggx, Masking::SmithSeparable),
        ];
        for (&m, (kind, masking)) in [5.0f32, 30.0].iter().flat_map(|m| cases.map(|c| (m, c))) {
            let d = MicrofacetDistribution::new(kind, m).with_masking(masking);
            for &t in &[0.0f32, 40.0, 80.0, 89.0] {
                let wo = crate::bsdf::spherical_direction(t.to_radians(), 0.3);
                let (nt, np) = (800, 400);
                let mut sum = 0.0f64;
                for i in 0..nt {
                    let th = (i as f64 + 0.5) / nt as f64 * std::f64::consts::FRAC_PI_2;
                    for j in 0..np {
                        let ph = (j as f64 + 0.5) / np as f64 * 2.0 * std::f64::consts::PI;
                        let h = crate::bsdf::spherical_direction(th as f32, ph as f32);
                        sum += f64::from(d.pdf_visible(wo, h)) * th.sin();
                    }
                }
                sum *= std::f64::consts::FRAC_PI_2 / nt as f64 * 2.0 * std::f64::consts::PI
                    / np as f64;
                assert!(
                    (sum - 1.0).abs() < 5e-3,
                    "{kind:?} {masking:?} m {m} θo {t}: {sum}"
                );
            }
        }
    }
}
