//! The crystal-facet bump map (course fig. 5.2, component 4): one constant tilted normal per filled
//! Voronoi cell, so a glitter particle is a flat mirror-like facet at its own angle.
//!
//! **Tilt distributions.** A facet normal `n` is given in the tangent space of the surface (`z` is
//! the unbumped shading normal) and drawn from the cell id, so it is constant over the cell:
//! - `Cone { half_angle }`: uniform over the solid angle of the cone `θ ≤ half_angle`:
//!   `cos θ = 1 − u₁(1 − cos θmax)`, `φ = 2πu₂`; pdf `1 / (2π(1 − cos θmax))` per steradian.
//! - `Beckmann { rms }`: the Beckmann slope distribution with `α = tan(rms)` (the course's roughness
//!   convention: `rms` is the RMS slope angle; docs/design.md §4): `tan²θ = −α² ln(1 − u₁)`, `φ = 2πu₂`;
//!   pdf `exp(−tan²θ/α²) / (π α² cos³θ)` per steradian (the microfacet `D(n) cos θ`).
//!
//! **The rule for facets that turn away from the viewer.** A tilted facet can face away from `wo`
//! although the surface faces it (`wo·n ≤ 0 < wo·z`). Then [`visible_normal`] tips the facet back
//! toward `z`, in the plane of `z` and `n`, just far enough that `wo·n' = MIN_COS_WO`. The normal
//! stays continuous in `wo` (no popping), finite, and the facet still glints at the most grazing
//! angle it can show. It gains no energy: the renderer evaluates the BSDF in the facet's frame,
//! weights by `|wi·n'|` and drops any `wi` below the unbumped surface, so the reflected fraction is
//! at most the BSDF's albedo in that frame (≤ 1); tested in `tests/maps.rs`.

use crate::geometry::Frame;
use crate::sampler::{mix64, to_unit_f32};
use glam::Vec3;
use std::f32::consts::PI;

/// Smallest cosine between `wo` and a facet normal the renderer is given (≈ 89.4°).
pub const MIN_COS_WO: f32 = 0.01;

/// How facet tilts are distributed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Tilt {
    /// Uniform in solid angle inside a cone around the surface normal; `half_angle` in degrees,
    /// 0 … 89.
    Cone {
        /// Cone half-angle in degrees.
        half_angle: f32,
    },
    /// Beckmann-distributed normals with RMS slope angle `rms` in degrees, 0 … 60.
    Beckmann {
        /// RMS slope angle in degrees.
        rms: f32,
    },
}

/// A facet bump map: the tilt distribution of the facets.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FacetBump {
    /// The distribution every cell's normal is drawn from.
    pub tilt: Tilt,
}

impl FacetBump {
    /// The facet normal of the cell with id `id`, in tangent space (`z` = unbumped normal).
    pub fn normal(&self, id: u64) -> Vec3 {
        let bits = mix64(id ^ 0x7a3c_5e1f_b0d2_9846);
        self.normal_from(to_unit_f32(bits), to_unit_f32(bits << 24))
    }

    /// The facet normal for uniforms `(u1, u2) ∈ [0,1)²` (see the module docs).
    pub fn normal_from(&self, u1: f32, u2: f32) -> Vec3 {
        let cos_t = match self.tilt {
            Tilt::Cone { half_angle } => 1.0 - u1 * (1.0 - half_angle.to_radians().cos()),
            Tilt::Beckmann { rms } => {
                let a2 = rms.to_radians().tan().powi(2);
                let tan2 = -a2 * (-u1).ln_1p();
                1.0 / (1.0 + tan2).sqrt()
            }
        };
        let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
        let phi = 2.0 * PI * u2;
        Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t)
    }

    /// Density of [`FacetBump::normal`] per steradian of the normal `n` (unit, tangent space).
    pub fn pdf(&self, n: Vec3) -> f32 {
        let cos_t = n.z;
        if cos_t <= 0.0 {
            return 0.0;
        }
        match self.tilt {
            Tilt::Cone { half_angle } => {
                let c = half_angle.to_radians().cos();
                let solid = 2.0 * PI * (1.0 - c);
                if solid <= 0.0 || cos_t < c {
                    0.0
                } else {
                    1.0 / solid
                }
            }
            Tilt::Beckmann { rms } => {
                let a2 = rms.to_radians().tan().powi(2);
                if a2 <= 0.0 {
                    return 0.0;
                }
                let c2 = cos_t * cos_t;
                let tan2 = (1.0 - c2) / c2;
                (-tan2 / a2).exp() / (PI * a2 * c2 * cos_t)
            }
        }
    }
}

/// The facet normal the renderer shades with, for a viewer in direction `wo` (both in tangent
/// space, `wo.z > 0`): `facet` itself when `wo·facet ≥ MIN_COS_WO`, otherwise `facet` tipped back
/// toward `z` until `wo·n = MIN_COS_WO` (the module's rule). Returns `z` when `wo` itself is within
/// `MIN_COS_WO` of the horizon or an input is not finite.
pub fn visible_normal(facet: Vec3, wo: Vec3) -> Vec3 {
    if !(facet.is_finite() && wo.is_finite()) || wo.z <= MIN_COS_WO || facet.z <= 0.0 {
        return Vec3::Z;
    }
    if wo.dot(facet) >= MIN_COS_WO {
        return facet;
    }
    // n(β) = cos β·z + sin β·u, u the unit tangent part of the facet; find the largest β ≤ tilt
    // with wo·n(β) = MIN_COS_WO: a cos β + b sin β = R cos(β − φ₀).
    let tangent = Vec3::new(facet.x, facet.y, 0.0);
    let len = tangent.length();
    if len < 1e-7 {
        return Vec3::Z;
    }
    let u = tangent / len;
    let (a, b) = (wo.z, wo.dot(u));
    let r = (a * a + b * b).sqrt();
    let beta = (MIN_COS_WO / r).clamp(-1.0, 1.0).acos() + b.atan2(a);
    let beta = beta.clamp(0.0, facet.z.acos());
    (Vec3::Z * beta.cos() + u * beta.sin()).normalize()
}

/// The shading frame for a facet: `frame` is the unbumped shading frame, `facet` the cell's normal
/// in its tangent space, `wo` the world direction toward the viewer. Applies [`visible_normal`] and
/// rebuilds the frame around the result ([`Frame::tilted`]). The caller evaluates the BSDF in the
/// returned frame and must still reject directions below the unbumped surface (module docs).
pub fn facet_frame(frame: &Frame, facet: Vec3, wo: Vec3) -> Frame {
    frame.tilted(visible_normal(facet, frame.to_local(wo)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normals_are_unit_and_inside_the_support() {
        let cone = FacetBump {
            tilt: Tilt::Cone { half_angle: 20.0 },
        };
        let beck = FacetBump {
            tilt: Tilt::Beckmann { rms: 15.0 },
        };
        for id in 0..10_000u64 {
            let n = cone.normal(id);
            assert!((n.length() - 1.0).abs() < 1e-5);
            assert!(n.z >= 20f32.to_radians().cos() - 1e-6 && cone.pdf(n) > 0.0);
            let m = beck.normal(id);
            assert!((m.length() - 1.0).abs() < 1e-5 && m.z > 0.0 && beck.pdf(m).is_finite());
        }
        // Zero tilt is the flat normal.
        let flat = FacetBump {
            tilt: Tilt::Cone { half_angle: 0.0 },
        };
        assert_eq!(flat.normal(3), Vec3::Z);
        assert_eq!(flat.normal_from(0.999_999_9, 0.3).z, 1.0);
        let f = FacetBump {
            tilt: Tilt::Beckmann { rms: 0.0 },
        };
        assert_eq!(f.normal_from(0.999_999_9, 0.3), Vec3::Z);
    }

    #[test]
    fn visible_normal_rule() {
        let facet = Vec3::new(0.6, 0.0, 0.8);
        // A viewer on the facet's side keeps it.
        let wo = Vec3::new(0.5, 0.0, 0.866);
        assert_eq!(visible_normal(facet, wo), facet);
        // A grazing viewer on the other side: tipped back to exactly MIN_COS_WO, between z and the
        // facet, and continuous as wo moves.
        let mut prev: Option<Vec3> = None;
        for i in 0..=200 {
            let t = (10.0 + 79.0 * i as f32 / 200.0).to_radians();
            let wo = Vec3::new(-t.sin(), 0.0, t.cos());
            let n = visible_normal(facet, wo);
            assert!((n.length() - 1.0).abs() < 1e-5 && n.z > 0.0 && n.z >= facet.z - 1e-6);
            assert!(wo.dot(n) >= MIN_COS_WO - 1e-4, "{wo:?} {n:?}");
            if let Some(p) = prev {
                assert!((n - p).length() < 0.05, "jump at {i}: {p:?} → {n:?}");
            }
            prev = Some(n);
        }
        assert_eq!(visible_normal(facet, Vec3::new(1.0, 0.0, 0.0)), Vec3::Z);
        assert_eq!(visible_normal(Vec3::NAN, Vec3::Z), Vec3::Z);
    }

    #[test]
    fn facet_frame_faces_the_viewer() {
        let frame = Frame::from_normal(Vec3::new(0.2, -0.1, 0.97).normalize());
        let facet = Vec3::new(0.5, 0.0, 0.866);
        for wo_local in [
            Vec3::new(0.3, 0.1, 0.95).normalize(),
            Vec3::new(-0.99, 0.0, 0.14).normalize(),
        ] {
            let wo = frame.to_world(wo_local);
            let f = facet_frame(&frame, facet, wo);
            assert!(f.n.dot(wo) >= MIN_COS_WO - 1e-4, "{wo_local:?}");
            assert!(f.n.dot(frame.n) > 0.0);
        }
    }
}
