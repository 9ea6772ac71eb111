//! The spherical rectangle a rectangular light subtends from a shading point, sampled uniformly
//! in solid angle (Ureña, Fajardo & King, "An Area-Preserving Parametrization for Spherical
//! Rectangles", EGSR 2013, Algorithm 1), in `f64`: the solid angle is the difference of sums of
//! four angles near π/2 each, which cancels digits for a small or edge-on light.

use crate::geometry::Frame;
use glam::{DVec3, Vec2, Vec3};

/// Solid angle in steradians below which a rectangle is sampled by area instead of by solid angle:
/// under it the spherical construction loses digits to cancellation while area sampling is already
/// nearly uniform in solid angle.
pub(super) const MIN_SPHERICAL_SOLID_ANGLE: f64 = 1e-6;

/// The spherical rectangle a rectangle subtends from a point `o` (Ureña et al. 2013, §3), in
/// `f64`: in the local frame `axes = (x, y, z)` the rectangle spans `[x0, x1] × [y0, y1]` at
/// `z = z0 < 0`, with `v0 = (x0, y0, z0)`.
#[derive(Clone, Copy, Debug)]
pub(super) struct SphericalRect {
    axes: [DVec3; 3],
    v0: DVec3,
    x1: f64,
    y1: f64,
    /// `z` of the normals of the planes through `o` and the edges at `y0` and `y1`.
    b: (f64, f64),
    /// `|y|` of the first of those normals, `√(1 − b₀²)` without the cancellation.
    a0: f64,
    k: f64,
    /// Solid angle (sr).
    pub(super) solid_angle: f64,
}

impl SphericalRect {
    /// Ureña et al. 2013, Algorithm 1 (initialisation), or `None` when the solid angle is too small
    /// or not finite.
    ///
    /// # Arguments
    /// * `center`, `frame` – the rectangle's centre and frame (its edges along `frame.s`, `frame.t`).
    /// * `(hx, hy)` – its half-extents along `frame.s` and `frame.t`.
    /// * `p` – the point it is seen from.
    #[inline]
    pub(super) fn new(center: Vec3, frame: Frame, (hx, hy): (f32, f32), p: Vec3) -> Option<Self> {
        let o = p.as_dvec3();
        let (x, y) = (frame.s.as_dvec3(), frame.t.as_dvec3());
        let (exl, eyl) = (2.0 * f64::from(hx), 2.0 * f64::from(hy));
        let corner = center.as_dvec3() - x * f64::from(hx) - y * f64::from(hy);
        let d = corner - o;
        let mut z = x.cross(y);
        let mut z0 = d.dot(z);
        if z0 > 0.0 {
            z = -z;
            z0 = -z0;
        }
        let (x0, y0) = (d.dot(x), d.dot(y));
        let (x1, y1) = (x0 + exl, y0 + eyl);
        // The planes through o and the edges at y0, x1, y1, x0 have the normals
        // (0, z0, −y0)/r0, (−z0, 0, x1)/r1, (0, −z0, y1)/r2 and (z0, 0, −x0)/r3, so the cosines
        // of the angles between neighbours (the negated dot products of the paper's γᵢ) are
        // products of two coordinates over two of the rᵢ: four square roots and no vector
        // normalised.
        let zz = z0 * z0;
        let (r0, r1, r2, r3) = (
            (zz + y0 * y0).sqrt(),
            (zz + x1 * x1).sqrt(),
            (zz + y1 * y1).sqrt(),
            (zz + x0 * x0).sqrt(),
        );
        let angle = |c: f64| c.clamp(-1.0, 1.0).acos();
        let g0 = angle(y0 * x1 / (r0 * r1));
        let g1 = angle(-(x1 * y1) / (r1 * r2));
        let g2 = angle(x0 * y1 / (r2 * r3));
        let g3 = angle(-(x0 * y0) / (r3 * r0));
        let k = 2.0 * std::f64::consts::PI - g2 - g3;
        let solid_angle = g0 + g1 - k;
        let sr = Self {
            axes: [x, y, z],
            v0: DVec3::new(x0, y0, z0),
            x1,
            y1,
            b: (-y0 / r0, y1 / r2),
            a0: -z0 / r0,
            k,
            solid_angle,
        };
        (solid_angle.is_finite() && solid_angle > MIN_SPHERICAL_SOLID_ANGLE).then_some(sr)
    }

    /// Ureña et al. 2013, Algorithm 1 (sampling): the vector from the point it is seen from to the point
    /// on the rectangle whose direction is uniformly distributed over the spherical rectangle,
    /// and its squared length.
    #[inline]
    pub(super) fn sample_offset(&self, u: Vec2) -> (DVec3, f64) {
        let (u, v) = (f64::from(u.x), f64::from(u.y));
        let (
            DVec3 {
                x: x0,
                y: y0,
                z: z0,
            },
            (b0, b1),
        ) = (self.v0, self.b);
        let au = u * self.solid_angle + self.k;
        let (sin, cos) = au.sin_cos();
        let fu = (cos * b0 - b1) / sin;
        // The paper's cu = sign(fu) / √(fu² + b0²) and xu = −cu z0 / √(1 − cu²) in one step:
        // xu = −sign(fu) z0 / √(fu² − (1 − b0²)), with 1 − b0² = a0² and the difference of
        // squares factored (no cancellation where fu ≈ ±a0). Where the root is 0 or not a number
        // the point is an end of [x0, x1], as the paper's clamps make it.
        let root = ((fu - self.a0) * (fu + self.a0)).max(0.0).sqrt();
        let xu = (-(1.0f64.copysign(fu) * z0) / root).clamp(x0, self.x1);
        let xu = if xu.is_nan() { x0 } else { xu };
        let dd = xu * xu + z0 * z0;
        let d = dd.sqrt();
        let h0 = y0 / (dd + y0 * y0).sqrt();
        let h1 = self.y1 / (dd + self.y1 * self.y1).sqrt();
        let hv = h0 + v * (h1 - h0);
        let yv = if hv * hv < 1.0 - 1e-12 {
            (hv * d / (1.0 - hv * hv).sqrt()).clamp(y0, self.y1)
        } else {
            self.y1
        };
        let [x, y, z] = self.axes;
        (x * xu + y * yv + z * z0, dd + yv * yv)
    }
}
