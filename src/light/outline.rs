//! An area light's outline (a rectangle or a disc, in the light's own frame) and a beam's cone:
//! the shapes [`super::Area`] samples and tests points and directions against.

use glam::Vec3;

/// The outline in the light's own frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Outline {
    /// Half-extents along `frame.s` and `frame.t`.
    Rect { hx: f32, hy: f32 },
    /// Radius around the centre.
    Disc { radius: f32 },
}

impl Outline {
    /// Whether the point `(a, b)` of the light's plane (coordinates along `frame.s`, `frame.t`
    /// from the centre) lies on the light, its outline grown by the relative `slack`.
    #[inline(always)]
    pub(super) fn contains(&self, a: f32, b: f32, slack: f32) -> bool {
        match *self {
            Outline::Rect { hx, hy } => {
                a.abs() <= hx * (1.0 + slack) && b.abs() <= hy * (1.0 + slack)
            }
            Outline::Disc { radius } => a * a + b * b <= (radius * (1.0 + slack)).powi(2),
        }
    }
}

/// The cone of a beam of half-angle `θ`, kept as `sin² θ` and `tan θ` (computed in `f64` from the
/// angle): near the axis `cos θ` rounds to within an ulp of 1, while `|w × n|² ≤ sin² θ` resolves a
/// 0.3° cone to 1e-7 of its width.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Beam {
    /// `sin² θ`.
    pub(super) sin2: f32,
    /// `tan θ`.
    pub(super) tan: f32,
}

impl Beam {
    /// The cone of half-angle `half_angle` (radians, clamped to 0 ..= 1.5).
    pub(super) fn new(half_angle: f32) -> Beam {
        let t = f64::from(half_angle.clamp(0.0, 1.5));
        Beam {
            sin2: t.sin().powi(2) as f32,
            tan: t.tan() as f32,
        }
    }

    /// Whether the unit direction `w` (leaving the light) lies in the cone about `n`, with a
    /// relative slack of 1e-5 on `sin² θ`, so that the footprint's rim, sampled by
    /// the beam strategy of [`super::Area`], is inside after rounding.
    #[inline]
    pub(super) fn admits(&self, w: Vec3, n: Vec3) -> bool {
        w.dot(n) > 0.0 && w.cross(n).length_squared() <= self.sin2 * (1.0 + 1e-5)
    }
}
