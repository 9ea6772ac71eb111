//! What both manifold walks share: the bounds of Newton's method, the tangent coordinates of a
//! direction, and the bounded Newton step of a 2 × 2 system.

use crate::geometry::Frame;
use glam::{Vec2, Vec3};

/// Most Newton iterations of one walk.
pub const MAX_ITERATIONS: u32 = 24;
/// Largest change of direction per Newton step, radians.
pub const MAX_STEP: f32 = 0.2;
/// The walk has converged when the refracted direction is within this angle (radians) of the
/// direction to the light point.
pub const TOLERANCE: f32 = 1e-5;
/// Most halvings of one Newton step while the residual grows that a walk may be given (the
/// `manifold-halvings` knob's upper end).
pub const MAX_HALVINGS: u32 = crate::scene::stage::MAX_MANIFOLD_HALVINGS;

/// How hard a walk tries before it gives up: the render's `manifold-halvings` and
/// `manifold-continuation` knobs. A walk that gives up leaves its connection to BSDF sampling,
/// which the MIS weight's own walk (run with the same effort) accounts for, so any effort is
/// unbiased; more effort finds more connections at more cost (docs/accuracy.md has the table;
/// a render's default is its settings', `crate::scene::stage::DEFAULT_MANIFOLD_HALVINGS`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WalkEffort {
    /// Most halvings of a Newton step that does not lower the residual, 0 ..= [`MAX_HALVINGS`]:
    /// when even the shortest step fails, the walk gives up (the exact walk) or takes the
    /// Jacobian afresh (Broyden's).
    pub halvings: u32,
    /// Whether a walk that fails from the straight line retries by the continuation in the
    /// index ([`super::solve`]).
    pub continuation: bool,
}

impl WalkEffort {
    /// The most thorough walk: six halvings and the continuation ([`super::solve`]; what the
    /// cheaper settings are measured against).
    pub const THOROUGH: WalkEffort = WalkEffort {
        halvings: 6,
        continuation: true,
    };
}

/// When one Newton walk stops.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stop {
    /// Converged when the constraint's length is below this.
    pub tolerance: f32,
    /// Most halvings of a step that does not lower the constraint ([`WalkEffort::halvings`]).
    pub halvings: u32,
}

/// `d` turned by the tangent coordinates `a` (radians, small) in `frame` (whose normal is `d`).
#[inline]
pub fn turn(frame: &Frame, a: Vec2) -> Vec3 {
    (frame.n + frame.s * a.x + frame.t * a.y).normalize()
}

/// The determinant of a 2 × 2 matrix (rows).
#[inline]
pub fn det(j: &[[f32; 2]; 2]) -> f32 {
    j[0][0] * j[1][1] - j[0][1] * j[1][0]
}

/// The Newton step `−J⁻¹ r`, shortened to [`MAX_STEP`]; `None` where `J` is singular.
#[inline]
pub fn step(j: &[[f32; 2]; 2], r: Vec2) -> Option<Vec2> {
    let dt = det(j);
    if !(dt.abs() > 1e-12 && dt.is_finite()) {
        return None;
    }
    let mut step = -Vec2::new(j[1][1] * r.x - j[0][1] * r.y, j[0][0] * r.y - j[1][0] * r.x) / dt;
    if step.length() > MAX_STEP {
        step *= MAX_STEP / step.length();
    }
    Some(step)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn turn_moves_by_the_tangent_angle() {
        let f = Frame::from_normal(Vec3::new(0.3, -0.2, 0.9).normalize());
        let d = turn(&f, Vec2::new(1e-3, 0.0));
        // The angle from its sine (acos near 1 loses the digits in f32).
        let angle = d.cross(f.n).length().asin();
        assert!((angle - 1e-3).abs() < 2e-6, "{angle}");
        assert!(d.dot(f.s) > 0.0);
    }

    #[test]
    fn step_solves_the_system_and_is_bounded() {
        let j = [[2.0, 1.0], [0.5, 3.0]];
        let r = Vec2::new(0.01, -0.02);
        let s = step(&j, r).unwrap();
        let back = Vec2::new(j[0][0] * s.x + j[0][1] * s.y, j[1][0] * s.x + j[1][1] * s.y);
        assert!((back + r).length() < 1e-7, "{back}");
        let far = step(&j, Vec2::new(10.0, 10.0)).unwrap();
        assert!((far.length() - MAX_STEP).abs() < 1e-6);
        assert_eq!(step(&[[1.0, 2.0], [2.0, 4.0]], r), None);
    }
}
