//! BSDFs: the components of the course's layered model and the layer stack itself.
//!
//! # Conventions (written once, here; docs/design.md §4)
//!
//! - Directions are unit vectors in the **local shading frame**: `z` is the shading normal and
//!   `cos θ(w) = w.z`. Nothing in this module knows about world space.
//! - `wo` points toward the viewer (the path's previous vertex), `wi` toward the light (the sampled
//!   direction); both point **away** from the surface.
//! - `eval(wo, wi)` is `f(wo, wi)` in sr⁻¹ and **excludes** the cosine `|wi.z|`.
//! - `pdf(wo, wi)` is a density per steradian of `wi`.
//! - `sample(wo, uc, u)` consumes one uniform number `uc` (lobe choice) and two in `u` (direction)
//!   and returns `Option<BsdfSample>`; the path weight is `f · |wi.z| / pdf`, stored as `weight`.
//!   `None` means the sample failed (e.g. the reflected direction went below the horizon, or a
//!   refracted direction inside a coat cannot leave it): the caller terminates or retries the path,
//!   it never sees a NaN.
//! - Roughness `m` is the course's **RMS micro-facet slope angle in degrees**; Beckmann
//!   `α = tan m`, normalised Blinn exponent `e = 2/α² − 2` (Walter et al. 2007, eq. 31), and
//!   `D(h) = (e+2)/(2π) · cos^e θh` (course eq. 3.7).
//! - Oren–Nayar `σ` is in radians. IORs are absolute in descriptions and relative (below / above) at
//!   an interface. Stored colours are [`crate::color::Rgb`]; values are transported light
//!   ([`crate::spectrum::Spectral`], [`RgbSample`] in the RGB variant).
//! - Every result is finite and non-negative for every input the types allow, including grazing
//!   `cos θ` down to 1e-7, `wo == wi`, `wo == -wi` and `u` exactly 0 or 1 (docs/design.md §5.3); whenever
//!   `f > 0` for a direction that `sample` can produce, its `pdf > 0`.

pub mod dielectric;
pub mod dispersion;
pub mod fastmath;
pub mod fresnel;
mod hero;
pub mod interface_energy;
pub mod lambert;
pub mod layered;
pub mod masking;
pub mod measure;
pub mod memo;
pub mod metal_spectra;
pub mod microfacet;
pub mod names;
pub mod oren_nayar;
pub mod record;
pub mod smooth_dielectric;
pub mod spectral;
pub mod store;
pub mod table;
pub mod torrance_sparrow;

pub use dielectric::RoughDielectric;
pub use fresnel::{Fresnel, FresnelMode, Metal};
pub use lambert::Lambert;
pub use layered::{
    Base, Coat, ConductorIor, LayeredBsdf, Model, ReferenceParams, StackDesc, StackError,
};
pub use microfacet::{Distribution, Masking, MicrofacetDistribution};
pub use oren_nayar::OrenNayar;
pub use record::{BsdfSample, Lobe, LobeFlags, LobeKind, TransportMode};
pub use smooth_dielectric::SmoothDielectric;
pub use spectral::Scatter;
pub use torrance_sparrow::TorranceSparrow;

use crate::spectrum::{RgbSample, Spectral};
use glam::{Vec2, Vec3};

/// The interface every scattering model implements, generic over the transported light `S`
/// (docs/design.md §12). Implementations are plain structs and closed enums (no trait objects on
/// the hot path); the trait exists so the integrator, tests and benches are written once for all
/// of them. Every model implements it for the RGB variant today; a spectral variant adds
/// `impl Bxdf<HeroSample>` beside it, and nothing that calls the trait changes.
///
/// The required methods take a [`TransportMode`]; [`Bxdf::eval`] and [`Bxdf::sample`] are the
/// radiance-mode shorthands the camera paths use.
pub trait Bxdf<S: Spectral = RgbSample> {
    /// The union of the flags of the model's lobes.
    fn flags(&self) -> LobeFlags;
    /// `f(wo, wi)` in sr⁻¹, cosine excluded, for paths carrying `mode`. Zero for directions the
    /// model does not scatter into and for specular lobes.
    fn eval_mode(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> S;
    /// Samples `wi` given `wo`.
    ///
    /// # Arguments
    /// * `wo` – direction toward the viewer (radiance) or the light (importance), local frame.
    /// * `uc` – uniform number in `[0, 1]` that picks a lobe.
    /// * `u` – uniform pair in `[0, 1]²` that picks the direction within the lobe.
    /// * `mode` – what the path carries.
    fn sample_mode(&self, wo: Vec3, uc: f32, u: Vec2, mode: TransportMode)
    -> Option<BsdfSample<S>>;
    /// Density per steradian with which `sample_mode(wo, ·)` produces `wi` (the same in both
    /// modes; 0 for specular lobes).
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32;
    /// `(eval_mode(wo, wi, mode), pdf(wo, wi))`, bit for bit: next-event estimation needs both,
    /// and a model whose value and density share work computes it once.
    #[inline]
    fn eval_pdf_mode(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> (S, f32) {
        (self.eval_mode(wo, wi, mode), self.pdf(wo, wi))
    }
    /// [`Bxdf::eval_mode`] for radiance.
    #[inline]
    fn eval(&self, wo: Vec3, wi: Vec3) -> S {
        self.eval_mode(wo, wi, TransportMode::Radiance)
    }
    /// [`Bxdf::sample_mode`] for radiance.
    #[inline]
    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample<S>> {
        self.sample_mode(wo, uc, u, TransportMode::Radiance)
    }
}

/// Every BSDF lapidary knows, as one closed enum (static dispatch on the hot path).
#[derive(Clone, Debug)]
pub enum Bsdf {
    /// Lambertian reflection.
    Lambert(Lambert),
    /// Oren–Nayar reflection.
    OrenNayar(OrenNayar),
    /// Torrance–Sparrow reflection (dielectric or conductor).
    TorranceSparrow(TorranceSparrow),
    /// Rough dielectric interface: reflection and transmission.
    Dielectric(RoughDielectric),
    /// Smooth dielectric interface: mirror reflection and refraction.
    SmoothDielectric(SmoothDielectric),
    /// A layer stack.
    Layered(Box<LayeredBsdf>),
}

impl Bxdf for Bsdf {
    #[inline]
    fn flags(&self) -> LobeFlags {
        match self {
            Bsdf::Lambert(b) => b.flags(),
            Bsdf::OrenNayar(b) => b.flags(),
            Bsdf::TorranceSparrow(b) => b.flags(),
            Bsdf::Dielectric(b) => b.flags(),
            Bsdf::SmoothDielectric(b) => b.flags(),
            Bsdf::Layered(b) => b.flags(),
        }
    }
    #[inline]
    fn eval_mode(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> RgbSample {
        match self {
            Bsdf::Lambert(b) => b.eval_mode(wo, wi, mode),
            Bsdf::OrenNayar(b) => b.eval_mode(wo, wi, mode),
            Bsdf::TorranceSparrow(b) => b.eval_mode(wo, wi, mode),
            Bsdf::Dielectric(b) => b.eval_mode(wo, wi, mode),
            Bsdf::SmoothDielectric(b) => b.eval_mode(wo, wi, mode),
            Bsdf::Layered(b) => b.eval_mode(wo, wi, mode),
        }
    }
    #[inline]
    fn sample_mode(&self, wo: Vec3, uc: f32, u: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        match self {
            Bsdf::Lambert(b) => b.sample_mode(wo, uc, u, mode),
            Bsdf::OrenNayar(b) => b.sample_mode(wo, uc, u, mode),
            Bsdf::TorranceSparrow(b) => b.sample_mode(wo, uc, u, mode),
            Bsdf::Dielectric(b) => b.sample_mode(wo, uc, u, mode),
            Bsdf::SmoothDielectric(b) => b.sample_mode(wo, uc, u, mode),
            Bsdf::Layered(b) => b.sample_mode(wo, uc, u, mode),
        }
    }
    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self {
            Bsdf::Lambert(b) => b.pdf(wo, wi),
            Bsdf::OrenNayar(b) => b.pdf(wo, wi),
            Bsdf::TorranceSparrow(b) => b.pdf(wo, wi),
            Bsdf::Dielectric(b) => b.pdf(wo, wi),
            Bsdf::SmoothDielectric(b) => b.pdf(wo, wi),
            Bsdf::Layered(b) => b.pdf(wo, wi),
        }
    }
    #[inline]
    fn eval_pdf_mode(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> (RgbSample, f32) {
        match self {
            // Its value does not depend on the mode.
            Bsdf::TorranceSparrow(b) => b.eval_pdf(wo, wi),
            Bsdf::Layered(b) => b.eval_pdf_mode(wo, wi, mode),
            _ => (
                self.eval_mode(wo, wi, mode),
                Bxdf::<RgbSample>::pdf(self, wo, wi),
            ),
        }
    }
}

impl From<LayeredBsdf> for Bsdf {
    fn from(l: LayeredBsdf) -> Bsdf {
        Bsdf::Layered(Box::new(l))
    }
}

/// Values of `f` below this (sr⁻¹) are flushed to exactly 0: they carry no energy, and products
/// deep in the subnormal range (D ≈ 1e-42 times a Fresnel factor) can underflow differently in
/// `eval` and `pdf`, which would break "pdf > 0 wherever f > 0".
pub const F_FLUSH: f32 = 1e-30;

/// Flushes channels below [`F_FLUSH`] to 0.
#[inline]
pub fn flush_tiny<S: Spectral>(f: S) -> S {
    f.map(|v| if v < F_FLUSH { 0.0 } else { v })
}

/// `cos θ` of a local direction.
#[inline]
pub fn cos_theta(w: Vec3) -> f32 {
    w.z
}

/// `|cos θ|` of a local direction.
#[inline]
pub fn abs_cos_theta(w: Vec3) -> f32 {
    w.z.abs()
}

/// `sin² θ` computed from the tangential components, accurate near the normal where `1 − z²`
/// cancels catastrophically.
#[inline]
pub fn sin2_theta(w: Vec3) -> f32 {
    (w.x * w.x + w.y * w.y).min(1.0)
}

/// True when both directions are strictly on the same side of the surface.
#[inline]
pub fn same_hemisphere(a: Vec3, b: Vec3) -> bool {
    a.z * b.z > 0.0
}

/// Mirror reflection of `w` about the unit vector `n`: `2 (w·n) n − w`.
#[inline]
pub fn reflect(w: Vec3, n: Vec3) -> Vec3 {
    2.0 * w.dot(n) * n - w
}

/// Refraction of `w` (pointing away from the surface, on either side) through the unit normal `n`
/// with relative IOR `eta` = IOR on the side `n` points into the surface / IOR on `n`'s side.
/// Returns the transmitted direction (pointing away from the surface on the other side), or `None`
/// under total internal reflection.
#[inline]
pub fn refract(w: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let mut cos_i = w.dot(n);
    let (mut eta, mut n) = (eta, n);
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
        n = -n;
    }
    let sin2_i = (1.0 - cos_i * cos_i).max(0.0);
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((-w / eta + (cos_i / eta - cos_t) * n).normalize())
}

/// Refracts a local direction through the macro (shading) normal `z` of an interface with relative
/// IOR `eta` (below / above), keeping the azimuth: an upward direction above becomes the upward
/// direction below that reaches it, and vice versa. This is the course's construction of `wo'`,
/// `wi'` (eq. 3.1) and is exactly invertible, which keeps eval, sample and pdf of a stack
/// consistent. Returns `None` when the direction cannot cross (total internal reflection).
///
/// # Arguments
/// * `w` – upward direction (`w.z > 0`) on one side.
/// * `eta` – IOR of the side `w` is going to / IOR of the side `w` is on.
#[inline]
pub fn refract_macro(w: Vec3, eta: f32) -> Option<Vec3> {
    let s2 = sin2_theta(w) / (eta * eta);
    if s2 >= 1.0 {
        return None;
    }
    let scale = 1.0 / eta;
    let z = (1.0 - s2).sqrt();
    if z <= 0.0 {
        return None;
    }
    Some(Vec3::new(w.x * scale, w.y * scale, z))
}

/// Power heuristic with exponent 2 (Veach 1997, §9.2.4) for one sample from each strategy.
#[inline]
pub fn power_heuristic(pdf_a: f32, pdf_b: f32) -> f32 {
    let (a, b) = (pdf_a * pdf_a, pdf_b * pdf_b);
    if a == 0.0 {
        return 0.0;
    }
    if !a.is_finite() {
        return if b.is_finite() { 1.0 } else { 0.5 };
    }
    a / (a + b)
}

/// Cosine-weighted hemisphere sample (Malley's method over Shirley–Chiu's concentric disk map).
/// `None` only when the point lands on the disk's rim (`z = 0`, density 0).
#[inline]
pub fn sample_cosine_hemisphere(u: Vec2) -> Option<Vec3> {
    let d = crate::sampler::concentric_disc(u);
    let z = (1.0 - d.x * d.x - d.y * d.y).max(0.0).sqrt();
    (z > 0.0).then(|| Vec3::new(d.x, d.y, z).normalize())
}

/// Builds a unit direction from spherical angles in radians (`theta` from +z, `phi` from +x).
#[inline]
pub fn spherical_direction(theta: f32, phi: f32) -> Vec3 {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    Vec3::new(st * cp, st * sp, ct)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn macro_refraction_inverts() {
        for &eta in &[1.0001f32, 1.5, 4.0] {
            for i in 0..90 {
                let w = spherical_direction((i as f32).to_radians(), 0.7);
                let inner = refract_macro(w, eta).unwrap();
                assert!(inner.z > 0.0 && (inner.length() - 1.0).abs() < 1e-5);
                // Snell: sinθ = η sinθ'.
                assert!((sin2_theta(w).sqrt() - eta * sin2_theta(inner).sqrt()).abs() < 1e-5);
                let back = refract_macro(inner, 1.0 / eta).unwrap();
                assert!((back - w).length() < 1e-4, "eta {eta} theta {i}");
            }
        }
        // Beyond the critical angle from inside: no way out.
        let inside = spherical_direction(60f32.to_radians(), 0.0);
        assert!(refract_macro(inside, 1.0 / 1.5).is_none());
    }

    #[test]
    fn refract_matches_snell_and_tir() {
        let n = Vec3::Z;
        let w = spherical_direction(0.5, 1.0);
        let t = refract(w, n, 1.5).unwrap();
        assert!(t.z < 0.0);
        assert!((sin2_theta(w).sqrt() - 1.5 * sin2_theta(t).sqrt()).abs() < 1e-5);
        let back = refract(t, n, 1.5).unwrap();
        assert!((back - w).length() < 1e-5);
        assert!(refract(spherical_direction(2.0, 0.0), n, 1.5).is_none());
    }

    #[test]
    fn cosine_sampler_edges() {
        for &(a, b) in &[(0.0, 0.0), (1.0, 1.0), (0.5, 0.5), (0.0, 1.0), (1.0, 0.5)] {
            if let Some(w) = sample_cosine_hemisphere(Vec2::new(a, b)) {
                assert!(w.z > 0.0 && w.is_finite());
            }
        }
        assert_eq!(sample_cosine_hemisphere(Vec2::splat(0.5)).unwrap(), Vec3::Z);
    }

    #[test]
    fn power_heuristic_edges() {
        assert_eq!(power_heuristic(0.0, 0.0), 0.0);
        assert_eq!(power_heuristic(1.0, 0.0), 1.0);
        assert!((power_heuristic(1.0, 1.0) - 0.5).abs() < 1e-7);
        assert_eq!(power_heuristic(f32::INFINITY, 1.0), 1.0);
    }
}
