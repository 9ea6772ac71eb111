//! Masking–shadowing of micro-facet surfaces: the course's V-cavity term and Smith's.
//!
//! - **V-cavity** (Torrance & Sparrow 1967; the course's `geom`, §3.3.1): every facet is one side
//!   of a symmetric V-groove, `G1(w, h) = min(1, 2 |n·h| |n·w| / |w·h|)`,
//!   `G = min(1, G1(wo), G1(wi))`. It does not depend on the distribution. The course's choice
//!   and lapidary's default.
//! - **Smith** (Smith 1967; Walter, Marschner, Li & Torrance, EGSR 2007, §5; Heitz, "Understanding
//!   the masking-shadowing function in microfacet-based BRDFs", JCGT 3(2) 2014): heights
//!   uncorrelated with slopes, `G1(w) = 1/(1 + Λ(w))` with the distribution's `Λ`:
//!   - GGX / Trowbridge–Reitz: `Λ = (√(1 + α² tan²θ) − 1)/2` (exact; Heitz 2014 eq. 86);
//!   - Beckmann: `a = 1/(α tan θ)`, `Λ = (erf a − 1)/2 + e^{−a²}/(2a√π)`, evaluated with
//!     Walter et al.'s rational fit of `G1` (2007 eq. 27, `(3.535a + 2.181a²)/(1 + 2.276a +
//!     2.577a²)` below `a = 1.6`, else 1; relative error < 0.35 %), which is also what Mitsuba 3
//!     evaluates, so renders compare like with like;
//!   - normalised Blinn: the Beckmann form with Walter's `a = √(0.5e + 1)/tan θ` (2007 §5.2),
//!     which with `e = 2/α² − 2` is the Beckmann `a` of the same `α`.
//!
//!   [`Masking::Smith`] couples the two directions *height-correlated* for reflection,
//!   `G = 1/(1 + Λ(wo) + Λ(wi))` (Heitz 2014 eq. 99; pbrt-v4's choice), and *separably* for
//!   transmission, `G = G1(wo) G1(wi)` (Walter et al. 2007 eq. 23).
//!   [`Masking::SmithSeparable`] uses the separable product for both (Mitsuba 3's choice).
//!
//! Every form is written with absolute cosines so it serves directions on either side.

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// How a micro-facet surface masks and shadows itself.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Masking {
    /// The course's V-cavity term (default).
    #[default]
    VCavity,
    /// Smith: height-correlated for reflection, separable for transmission (pbrt-v4, Walter 2007).
    Smith,
    /// Smith, separable for reflection and transmission (Mitsuba 3).
    SmithSeparable,
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

/// `tan²θ` of a direction, from its tangential components (accurate near the normal).
#[inline]
fn tan2(w: Vec3) -> f32 {
    let s2 = (w.x * w.x + w.y * w.y).min(1.0);
    let c2 = if s2 < 0.5 { 1.0 - s2 } else { w.z * w.z };
    if c2 > 0.0 { s2 / c2 } else { f32::INFINITY }
}

/// Smith `Λ(w)` of GGX with roughness `alpha` (exact).
#[inline]
pub fn lambda_ggx(w: Vec3, alpha: f32) -> f32 {
    let t2 = tan2(w);
    if !t2.is_finite() {
        return f32::INFINITY;
    }
    let a2t2 = alpha * alpha * t2;
    // (√(1+x) − 1)/2 = x / (2 (√(1+x) + 1)): no cancellation for small x.
    a2t2 / (2.0 * ((1.0 + a2t2).sqrt() + 1.0))
}

/// Smith `Λ(w)` of Beckmann with roughness `alpha`, from Walter et al.'s rational `G1`
/// (module docs): `Λ = 1/G1 − 1`.
#[inline]
pub fn lambda_beckmann(w: Vec3, alpha: f32) -> f32 {
    let t2 = tan2(w);
    if t2 == 0.0 {
        return 0.0;
    }
    if !t2.is_finite() {
        return f32::INFINITY;
    }
    let a = 1.0 / (alpha * t2.sqrt());
    if a >= 1.6 {
        return 0.0;
    }
    let g1 = (3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a);
    1.0 / g1 - 1.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::spherical_direction;

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

    /// Λ against the closed forms in f64: GGX exactly, Beckmann's rational fit within its stated
    /// 0.35 % of the erf form in G1.
    #[test]
    fn smith_lambda_matches_closed_forms() {
        fn erf(x: f64) -> f64 {
            // Abramowitz & Stegun 7.1.26 is too coarse for a reference: integrate instead.
            let n = 20_000;
            let h = x / n as f64;
            let mut s = 0.0;
            for i in 0..n {
                let t = (i as f64 + 0.5) * h;
                s += (-t * t).exp();
            }
            s * h * 2.0 / std::f64::consts::PI.sqrt()
        }
        for &alpha in &[0.05f32, 0.2, 0.5, 1.0] {
            for deg in [0.0f32, 20.0, 45.0, 70.0, 85.0, 89.5] {
                let w = spherical_direction(deg.to_radians(), 0.4);
                let t = f64::from(deg).to_radians().tan();
                let a2t2 = f64::from(alpha).powi(2) * t * t;
                let ggx = ((1.0 + a2t2).sqrt() - 1.0) / 2.0;
                let got = f64::from(lambda_ggx(w, alpha));
                assert!(
                    (got - ggx).abs() <= 1e-5 * ggx.max(1.0),
                    "GGX α {alpha} θ {deg}: {got} vs {ggx}"
                );
                if t > 0.0 {
                    let a = 1.0 / (f64::from(alpha) * t);
                    let exact = ((erf(a) - 1.0) / 2.0
                        + (-a * a).exp() / (2.0 * a * std::f64::consts::PI.sqrt()))
                    .max(0.0);
                    let (g_exact, g_fit) = (
                        1.0 / (1.0 + exact),
                        1.0 / (1.0 + f64::from(lambda_beckmann(w, alpha))),
                    );
                    assert!(
                        (g_fit - g_exact).abs() < 4e-3 * g_exact,
                        "Beckmann α {alpha} θ {deg}: G1 {g_fit} vs {g_exact}"
                    );
                }
            }
        }
        assert_eq!(lambda_ggx(Vec3::Z, 0.3), 0.0);
        assert_eq!(lambda_beckmann(Vec3::Z, 0.3), 0.0);
        assert!(lambda_ggx(Vec3::X, 0.3).is_infinite());
    }
}
