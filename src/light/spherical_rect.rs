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
    /// The point it is seen from.
    pub(super) o: DVec3,
    axes: [DVec3; 3],
    v0: DVec3,
    x1: f64,
    y1: f64,
    /// `z` of the normals of the planes through `o` and the edges at `y0` and `y1`.
    b: (f64, f64),
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
        // Normals of the four planes through o and an edge.
        let n0 = DVec3::new(0.0, z0, -y0).normalize();
        let n1 = DVec3::new(-z0, 0.0, x1).normalize();
        let n2 = DVec3::new(0.0, -z0, y1).normalize();
        let n3 = DVec3::new(z0, 0.0, -x0).normalize();
        let angle = |a: DVec3, b: DVec3| (-a.dot(b)).clamp(-1.0, 1.0).acos();
        let (g0, g1, g2, g3) = (angle(n0, n1), angle(n1, n2), angle(n2, n3), angle(n3, n0));
        let k = 2.0 * std::f64::consts::PI - g2 - g3;
        let solid_angle = g0 + g1 - k;
        let sr = Self {
            o,
            axes: [x, y, z],
            v0: DVec3::new(x0, y0, z0),
            x1,
            y1,
            b: (n0.z, n2.z),
            k,
            solid_angle,
        };
        (solid_angle.is_finite() && solid_angle > MIN_SPHERICAL_SOLID_ANGLE).then_some(sr)
    }

    /// Ureña et al. 2013, Algorithm 1 (sampling): the point on the rectangle whose direction is
    /// uniformly distributed over the spherical rectangle.
    #[inline]
    pub(super) fn sample(&self, u: Vec2) -> DVec3 {
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
        let fu = (au.cos() * b0 - b1) / au.sin();
        let cu = (1.0f64.copysign(fu) / (fu * fu + b0 * b0).sqrt()).clamp(-1.0, 1.0);
        let xu = (-(cu * z0) / (1.0 - cu * cu).max(0.0).sqrt()).clamp(x0, self.x1);
        let xu = if xu.is_nan() { x0 } else { xu };
        let d = (xu * xu + z0 * z0).sqrt();
        let h0 = y0 / (d * d + y0 * y0).sqrt();
        let h1 = self.y1 / (d * d + self.y1 * self.y1).sqrt();
        let hv = h0 + v * (h1 - h0);
        let yv = if hv * hv < 1.0 - 1e-12 {
            (hv * d / (1.0 - hv * hv).sqrt()).clamp(y0, self.y1)
        } else {
            self.y1
        };
        let [x, y, z] = self.axes;
        self.o + x * xu + y * yv + z * z0
    }
}
