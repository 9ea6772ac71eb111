//! A lat-long radiance map of an [`super::EnvironmentLight`]: lookup by direction, rotation, and
//! the checks that refuse a map no light can be made of. The direction convention is in the
//! parent module's docs.

use crate::color::Rgb;
use crate::image::{ImageError, RgbImage};
use crate::light::distribution::Distribution2D;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// A lat-long map ready for lookup and sampling.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Map {
    pub(super) width: usize,
    pub(super) height: usize,
    /// Radiance per pixel, intensity applied, invalid values zeroed; row-major, top row first.
    pub(super) pixels: Vec<Rgb>,
    pub(super) distribution: Distribution2D,
    /// `cos α`, `sin α` of the rotation about +y.
    pub(super) rotation: Vec2,
    /// Sample by `distribution` (else uniformly over the sphere: the importance effect off).
    pub(super) importance: bool,
}

impl Map {
    /// World direction → map direction: `R_y(−α)`.
    pub(super) fn to_map(&self, w: Vec3) -> Vec3 {
        let (c, s) = (self.rotation.x, self.rotation.y);
        Vec3::new(w.x * c - w.z * s, w.y, w.x * s + w.z * c)
    }

    /// Map direction → world direction: `R_y(α)`.
    pub(super) fn to_world(&self, m: Vec3) -> Vec3 {
        let (c, s) = (self.rotation.x, self.rotation.y);
        Vec3::new(m.x * c + m.z * s, m.y, -m.x * s + m.z * c)
    }

    /// Image coordinates `(u, v) ∈ [0, 1)²` of a direction in map space; `None` if not finite.
    pub(super) fn uv(&self, m: Vec3) -> Option<Vec2> {
        let v = m.y.clamp(-1.0, 1.0).acos() / PI;
        let mut u = m.x.atan2(-m.z) / (2.0 * PI) + 0.5;
        if u >= 1.0 {
            u -= 1.0;
        }
        let below_one = 1.0 - f32::EPSILON / 2.0;
        let uv = Vec2::new(u.clamp(0.0, below_one), v.clamp(0.0, below_one));
        uv.is_finite().then_some(uv)
    }

    /// Pixel index of image coordinates.
    pub(super) fn cell(&self, uv: Vec2) -> usize {
        let c = ((uv.x * self.width as f32) as usize).min(self.width - 1);
        let r = ((uv.y * self.height as f32) as usize).min(self.height - 1);
        r * self.width + c
    }
}

/// Largest value of a map pixel's channel: far above any real sky or sun stored relative to the
/// scene, and low enough that the sampling sums over the largest map (2²⁷ pixels, times an
/// `intensity` of up to 1e6) stay finite in `f32`.
pub const MAX_MAP_VALUE: f32 = 1e12;

/// Refuses a map no light can be made of: an infinite or absurd pixel (its radiance, and the
/// sampling weight of every other pixel beside it, would be meaningless) or every pixel NaN.
pub(super) fn refuse_unusable(path: &std::path::Path, img: &RgbImage) -> Result<(), ImageError> {
    let invalid = |reason: String| ImageError::Invalid {
        path: path.into(),
        reason,
    };
    let w = img.width.max(1) as usize;
    let infinite = |p: &[f32; 3]| p.iter().any(|c| c.is_infinite());
    if let Some(i) = img.pixels.iter().position(infinite) {
        return Err(invalid(format!(
            "pixel ({}, {}) is infinite: an environment map must hold finite radiance",
            i % w,
            i / w
        )));
    }
    let absurd = |p: &[f32; 3]| p.iter().any(|&c| c > MAX_MAP_VALUE);
    if let Some(i) = img.pixels.iter().position(absurd) {
        return Err(invalid(format!(
            "pixel ({}, {}) = {:?} is out of range: each channel allowed up to {MAX_MAP_VALUE:e}",
            i % w,
            i / w,
            img.pixels[i]
        )));
    }
    if !img.pixels.is_empty() && img.pixels.iter().all(|p| p.iter().any(|c| c.is_nan())) {
        return Err(invalid(
            "every pixel is NaN (not a number): the map holds no radiance".into(),
        ));
    }
    Ok(())
}
