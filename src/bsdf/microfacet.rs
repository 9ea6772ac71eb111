//! Micro-facet normal distributions and the V-cavity masking–shadowing term.
//!
//! Roughness is the course's RMS slope angle `m` in degrees. Two distributions share it:
//! - normalised Blinn (course eq. 3.7): `D(h) = (e+2)/(2π) cos^e θh`, `e = 2/tan²m − 2`;
//! - Beckmann: `D(h) = exp(−tan²θh/α²) / (π α² cos⁴θh)`, `α = tan m`.
//!
//! Both are normalised so that `∫ D(h) cos θh dω = 1` and sampled exactly from that density
//! ([`MicrofacetDistribution::sample_h`]). Scattering lobes sample the **visible** normals of the
//! V-cavity model instead ([`MicrofacetDistribution::sample_visible`], Heitz & d'Eon, "Importance
//! sampling microfacet-based BSDFs using the distribution of visible normals", EGSR 2014, §5): draw
//! `h` from `D cos`, form the cavity's other facet `h' = (−hx, −hy, hz)` and keep one of the two with
//! probability proportional to its projected area toward `wo`. The density is exactly
//! `D_wo(h) = G1(wo, h) ⟨wo·h⟩ D(h) / cos θo` with the V-cavity `G1`, so a reflection's weight is
//! `F · G / G1 ≤ 1` — no heavy tails, also at grazing angles.
//! Near-mirror roughness (m = 0.01°, `e ≈ 6.6e7`) is handled by never forming `cos θh` from a
//! difference: `cos^e θh = exp(e/2 · ln(1 − sin²θh))` with `sin²θh = hx² + hy²`, and the sampler
//! inverts the CDF with `expm1`/`ln_1p` (docs/design.md §5.3).

use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};
use std::f32::consts::PI;

/// Which micro-facet distribution a material uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Distribution {
    /// Normalised Blinn, course eq. 3.7 (the course's choice; default).
    #[default]
    Blinn,
    /// Beckmann, for comparisons with other renderers.
    Beckmann,
}

/// A micro-facet distribution with its roughness bound in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MicrofacetDistribution {
    /// Normalised Blinn with exponent `e` (≥ 0 for m ≤ 45°, in (−2, 0) beyond).
    Blinn {
        /// Blinn exponent.
        exponent: f32,
    },
    /// Beckmann with RMS slope `alpha`.
    Beckmann {
        /// RMS slope `tan m`.
        alpha: f32,
    },
}

impl MicrofacetDistribution {
    /// Builds the distribution for RMS slope angle `m_deg` in degrees (0 < m < 90).
    pub fn new(kind: Distribution, m_deg: f32) -> Self {
        let alpha = (f64::from(m_deg).to_radians()).tan();
        match kind {
            Distribution::Blinn => MicrofacetDistribution::Blinn {
                exponent: (2.0 / (alpha * alpha) - 2.0) as f32,
            },
            Distribution::Beckmann => MicrofacetDistribution::Beckmann {
                alpha: alpha as f32,
            },
        }
    }

    /// `D(h)` per steradian of micro-normal; `h` is a unit vector, zero for `h.z ≤ 0`.
    #[inline]
    pub fn d(&self, h: Vec3) -> f32 {
        if h.z <= 0.0 {
            return 0.0;
        }
        let s2 = super::sin2_theta(h);
        if s2 >= 1.0 {
            return 0.0;
        }
        match *self {
            MicrofacetDistribution::Blinn { exponent: e } => {
                let log_cos_e = 0.5 * e * (-s2).ln_1p();
                (e + 2.0) / (2.0 * PI) * log_cos_e.exp()
            }
            MicrofacetDistribution::Beckmann { alpha } => {
                let c2 = if s2 < 0.5 { 1.0 - s2 } else { h.z * h.z };
                let a2 = alpha * alpha;
                let t2 = s2 / c2;
                (-t2 / a2).exp() / (PI * a2 * c2 * c2)
            }
        }
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
        let s2 = match *self {
            MicrofacetDistribution::Blinn { exponent: e } => {
                // CDF of cos θh: 1 − cos^(e+2) θh = u  ⇒  sin²θh = 1 − (1−u)^(2/(e+2)).
                -((2.0 / (e + 2.0)) * (-u0).ln_1p()).exp_m1()
            }
            MicrofacetDistribution::Beckmann { alpha } => {
                // tan²θh = −α² ln(1 − u).
                let t2 = -alpha * alpha * (-u0).ln_1p();
                if !t2.is_finite() {
                    return None;
                }
                t2 / (1.0 + t2)
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

    /// Samples a micro-normal (`h.z > 0`) visible from `wo` (either side of the surface; a `wo`
    /// below is mirrored above), by the V-cavity construction in the module docs. Returns the
    /// normal and `uc` remapped to a fresh uniform number for the caller's next choice.
    #[inline]
    pub fn sample_visible(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<(Vec3, f32)> {
        let w = if wo.z < 0.0 { -wo } else { wo };
        if w.z <= 0.0 {
            return None;
        }
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

    /// Density of [`Self::sample_visible`]: `G1(wo, h) ⟨wo·h⟩ D(h) / |cos θo|` (with `wo`
    /// mirrored above the surface when it lies below).
    #[inline]
    pub fn pdf_visible(&self, wo: Vec3, h: Vec3) -> f32 {
        let w = if wo.z < 0.0 { -wo } else { wo };
        let wh = w.dot(h);
        if w.z <= 0.0 || wh <= 0.0 {
            return 0.0;
        }
        // (wh / w.z) first: with D deep in the subnormal range a product with a small cosine
        // would underflow to 0 while f (divided by cosines) is still positive.
        let p = v_cavity_g1(w, h) * self.d(h) * (wh / w.z);
        if p.is_finite() { p } else { 0.0 }
    }
}

/// The V-cavity masking term of one direction, `G1(w, h) = min(1, 2|n·h||n·w|/|w·h|)`.
#[inline]
pub fn v_cavity_g1(w: Vec3, h: Vec3) -> f32 {
    let wh = w.dot(h).abs();
    if wh > 0.0 {
        (2.0 * h.z.abs() * w.z.abs() / wh).min(1.0)
    } else {
        1.0
    }
}

/// The V-cavity masking–shadowing term of Torrance & Sparrow (the course's `geom`, §3.3.1),
/// written with absolute values so that it also serves transmission:
/// `G = min(1, 2|n·h||n·wo|/|wo·h|, 2|n·h||n·wi|/|wi·h|)`.
#[inline]
pub fn v_cavity_g(wo: Vec3, wi: Vec3, h: Vec3) -> f32 {
    let nh = h.z.abs();
    let term = |w: Vec3| {
        let wh = w.dot(h).abs();
        if wh > 0.0 {
            2.0 * nh * w.z.abs() / wh
        } else {
            1.0
        }
    };
    term(wo).min(term(wi)).clamp(0.0, 1.0)
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
        for kind in [Distribution::Blinn, Distribution::Beckmann] {
            for &m in &[0.5f32, 5.0, 20.0, 45.0] {
                let d = MicrofacetDistribution::new(kind, m);
                let tmax = (m.to_radians() * 8.0).min(std::f32::consts::FRAC_PI_2) as f64;
                let s = normalisation(&d, tmax);
                assert!((s - 1.0).abs() < 2e-3, "{kind:?} m={m}: {s}");
            }
        }
    }

    #[test]
    fn blinn_exponent_matches_design() {
        if let MicrofacetDistribution::Blinn { exponent } =
            MicrofacetDistribution::new(Distribution::Blinn, 0.01)
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
        // ∫ D_wo(h) dω = 1 for every wo (the V-cavity satisfies ∫ G1 ⟨wo·h⟩ D dω = cos θo).
        for &m in &[5.0f32, 30.0] {
            let d = MicrofacetDistribution::new(Distribution::Blinn, m);
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
                assert!((sum - 1.0).abs() < 5e-3, "m {m} θo {t}: {sum}");
            }
        }
    }

    #[test]
    fn v_cavity_properties() {
        let h = Vec3::Z;
        let w = Vec3::new(0.6, 0.0, 0.8);
        assert_eq!(v_cavity_g(w, w, h), 1.0);
        let g = v_cavity_g(
            Vec3::new(1.0, 0.0, 1e-7).normalize(),
            w,
            Vec3::new(0.1, 0.0, 1.0).normalize(),
        );
        assert!((0.0..=1.0).contains(&g));
        assert_eq!(v_cavity_g(Vec3::X, Vec3::X, Vec3::Z), 1.0);
    }
}
