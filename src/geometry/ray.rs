//! Rays and the offset that keeps a spawned ray from re-hitting the surface it leaves.

use glam::Vec3;

/// A half-line `origin + t·dir`, `t > 0`. `dir` is unit length wherever the renderer builds rays,
/// so `t` is a distance in world units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Start point.
    pub origin: Vec3,
    /// Unit direction.
    pub dir: Vec3,
    /// The medium the ray travels through from its origin.
    pub medium: MediumId,
}

/// The medium a ray travels through: an index into the world's media, [`MediumId::OUTSIDE`]
/// for the space around the stone. A transmission through a stone's surface switches between the
/// outside and the stone's interior (docs/design.md §12).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct MediumId(pub u16);

impl MediumId {
    /// The scene's outside: vacuum or clear air, IOR 1, no extinction.
    pub const OUTSIDE: MediumId = MediumId(0);
}

impl Ray {
    /// A ray from `origin` along `dir` (expected unit length), outside every medium.
    #[inline]
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Ray {
            origin,
            dir,
            medium: MediumId::OUTSIDE,
        }
    }

    /// A ray from `origin` along `dir` travelling through `medium`.
    #[inline]
    pub fn in_medium(origin: Vec3, dir: Vec3, medium: MediumId) -> Self {
        Ray {
            origin,
            dir,
            medium,
        }
    }

    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }
}

/// Relative size of the offset [`offset_origin`] applies, in units of the point's largest
/// coordinate magnitude (at least 1): a few hundred ulps of `f32`, enough for the quadric and
/// triangle intersection errors of this crate's shapes.
pub const OFFSET_SCALE: f32 = 2e-5;

/// `p` moved off its surface along the geometric normal `ng`, to the side `w` leaves into: the
/// origin of a ray spawned at a hit point. The offset grows with `|p|` so it stays above the
/// rounding error of the hit point wherever the stage is placed.
#[inline]
pub fn offset_origin(p: Vec3, ng: Vec3, w: Vec3) -> Vec3 {
    let eps = OFFSET_SCALE * p.abs().max_element().max(1.0);
    if w.dot(ng) >= 0.0 {
        p + ng * eps
    } else {
        p - ng * eps
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offset_goes_to_the_side_of_the_direction() {
        let p = Vec3::new(100.0, 0.0, 0.0);
        let up = offset_origin(p, Vec3::Y, Vec3::new(0.0, 0.5, 1.0));
        let down = offset_origin(p, Vec3::Y, Vec3::new(0.0, -0.5, 1.0));
        assert!(up.y > 0.0 && down.y < 0.0);
        assert!((up.y - 100.0 * OFFSET_SCALE).abs() < 1e-6);
        assert_eq!(Ray::new(p, Vec3::X).at(2.0), Vec3::new(102.0, 0.0, 0.0));
    }
}
