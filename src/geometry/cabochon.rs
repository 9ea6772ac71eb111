//! The cabochon: a half-ellipsoid dome over a flat elliptical base or a shallower lower dome.
//!
//! Both variants are convex, so a ray meets the solid in one interval `[t_in, t_out]`, found as
//! intersections and unions of intervals rather than by testing each surface patch separately
//! and accepting points inside its boundary. There is no acceptance test at the rim to fail by
//! rounding, so rays aimed at the rim cannot slip between the dome and the base.
//!
//! Each ellipsoid is met in its normalised frame, where it is the unit sphere: the ray is scaled
//! by the reciprocal semi-axes (stored with the shape, so a query multiplies rather than
//! divides), and the unit sphere's interval needs one square root (the discriminant's) — its
//! terms are compared squared, never as lengths.

use super::hit::{GeometryError, ShapeHit, first_of_interval, valid_query};
use super::ray::Ray;
use glam::Vec3;

/// A cabochon in object space: the dome `x²/rx² + y²/h² + z²/rz² ≤ 1, y ≥ 0` over the flat base
/// `y = 0` (`base = 0`) or over the lower dome `x²/rx² + y²/base² + z²/rz² ≤ 1, y ≤ 0`. Lengths in
/// object units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cabochon {
    /// Semi-axes of the upper dome (rx, h, rz).
    upper: Vec3,
    /// Semi-axes of the lower dome (rx, base, rz); `base` is 0 for a flat base.
    lower: Vec3,
    /// `1 / upper`, object units⁻¹: object space to the upper dome's normalised frame.
    inv_upper: Vec3,
    /// `1 / lower` (its `y` infinite, and unused, for a flat base), object units⁻¹.
    inv_lower: Vec3,
    /// `h / base`: the upper frame's `y` to the lower frame's (0 for a flat base).
    lower_y: f32,
}

/// Which surface a hit lies on, with the point of the normalised frame its position and normal
/// follow from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Piece {
    /// The flat base, at the upper frame's point `q` (its `y` is 0 up to rounding).
    Base(Vec3),
    /// The upper dome, at the point `u` of the unit sphere of its frame.
    Upper(Vec3),
    /// The lower dome, at the point `u` of the unit sphere of its frame.
    Lower(Vec3),
}

/// The part of a query that depends on its origin alone: the origin in the upper dome's
/// normalised frame and `|o|² − 1` in the upper and the lower frame (the constant term of each
/// unit sphere's quadratic). A fan of rays from one point shares it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct FrameOrigin {
    o: Vec3,
    c_upper: f32,
    c_lower: f32,
}

/// The parameters `t0 ≤ t1` where the line `o + t·d` crosses the unit sphere centred at the
/// origin (`t` in units of `d`; `c = |o|² − 1`), or `None` if it misses (or only touches at
/// `t = 0`).
///
/// The sphere's `sphere_interval` at radius 1, with the same two precision measures (the
/// discriminant from the point `l` of the line closest to the centre, `a·(1 − |l|²)`, and the
/// stable roots `c/q`, `q/a`), but `1 − |l|²` and `c` from squared lengths: at radius 1 they are
/// as exact as the factored forms `(1 − |l|)(1 + |l|)` (both carry an absolute error of a few
/// ulps of 1), without the two square roots.
#[inline(always)]
fn unit_sphere_interval(o: Vec3, c: f32, d: Vec3) -> Option<(f32, f32)> {
    let a = d.length_squared();
    let inv_a = a.recip();
    let b = o.dot(d);
    let disc = 1.0 - (o - d * (b * inv_a)).length_squared();
    if !(disc >= 0.0) {
        return None;
    }
    let q = -(b + (a * disc).sqrt().copysign(b));
    if q == 0.0 {
        return None;
    }
    let (t0, t1) = (c / q, q * inv_a);
    if !(t0.is_finite() && t1.is_finite()) {
        return None;
    }
    Some((t0.min(t1), t0.max(t1)))
}

/// `t` range of the half-space `y ≥ 0` (`up`) or `y ≤ 0` along `o + t·d` (`oy`, `dy` its `y`
/// components), as `(lo, hi)` with `NaN`-free infinities; `None` if the line runs parallel
/// outside it.
#[inline(always)]
fn half_space(oy: f32, dy: f32, up: bool) -> Option<(f32, f32)> {
    let (oy, dy) = if up { (oy, dy) } else { (-oy, -dy) };
    if dy > 0.0 {
        Some((-oy / dy, f32::INFINITY))
    } else if dy < 0.0 {
        Some((f32::NEG_INFINITY, -oy / dy))
    } else {
        (oy >= 0.0).then_some((f32::NEG_INFINITY, f32::INFINITY))
    }
}

/// The interval of the line inside an ellipsoid, given in the ellipsoid's normalised frame (the
/// origin `o` with `c = |o|² − 1`, the direction `d`; scaling leaves `t` unchanged), intersected
/// with the upper or lower half-space (its bound is the same in the frame: `y` is scaled by a
/// positive factor). The flags tell whether each end is on the plane `y = 0` rather than on the
/// ellipsoid.
#[inline(always)]
fn half_ellipsoid(o: Vec3, c: f32, d: Vec3, up: bool) -> Option<(f32, f32, bool, bool)> {
    let (e0, e1) = unit_sphere_interval(o, c, d)?;
    let (h0, h1) = half_space(o.y, d.y, up)?;
    let (t_in, in_plane) = if h0 > e0 { (h0, true) } else { (e0, false) };
    let (t_out, out_plane) = if h1 < e1 { (h1, true) } else { (e1, false) };
    (t_in <= t_out).then_some((t_in, t_out, in_plane, out_plane))
}

impl Cabochon {
    /// A cabochon of semi-axes `rx`, `rz` (horizontal), dome height `h` and lower dome depth
    /// `base` (0 for a flat base). All must be finite, `rx`, `h`, `rz` positive, `base ≥ 0`.
    pub fn new(rx: f32, h: f32, rz: f32, base: f32) -> Result<Cabochon, GeometryError> {
        let ok = |v: f32| v > 0.0 && v.is_finite() && v < 1e18;
        if !(ok(rx) && ok(h) && ok(rz) && (base == 0.0 || ok(base))) {
            return Err(GeometryError::Degenerate {
                shape: "cabochon",
                detail: format!(
                    "radii and height must be finite and positive, base finite and ≥ 0; got \
                     radius ({rx}, {rz}), height {h}, base {base}"
                ),
            });
        }
        let (upper, lower) = (Vec3::new(rx, h, rz), Vec3::new(rx, base, rz));
        Ok(Cabochon {
            upper,
            lower,
            inv_upper: upper.recip(),
            inv_lower: lower.recip(),
            lower_y: if base == 0.0 { 0.0 } else { h / base },
        })
    }

    /// Whether the base is flat.
    pub fn flat_base(&self) -> bool {
        self.lower.y == 0.0
    }

    /// `1 / axes()`: object space to the domes' normalised frames, object units⁻¹ (the lower
    /// `y` is infinite for a flat base).
    pub(crate) fn inv_axes(&self) -> (Vec3, Vec3) {
        (self.inv_upper, self.inv_lower)
    }

    /// `h / base`: the upper frame's `y` to the lower frame's (0 for a flat base).
    pub(crate) fn lower_y(&self) -> f32 {
        self.lower_y
    }

    /// A vector of the upper dome's normalised frame in the lower dome's.
    #[inline(always)]
    fn lower_frame(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.x, v.y * self.lower_y, v.z)
    }

    /// The origin-only part of a query whose origin is `o` in the upper dome's normalised frame.
    #[inline(always)]
    pub(crate) fn frame_origin(&self, o: Vec3) -> FrameOrigin {
        let c_lower = if self.flat_base() {
            0.0
        } else {
            self.lower_frame(o).length_squared() - 1.0
        };
        FrameOrigin {
            o,
            c_upper: o.length_squared() - 1.0,
            c_lower,
        }
    }

    /// The solid's interval along the ray from `org` along `d` (the upper frame's direction),
    /// `(t_in, t_out)`, and for a flat base whether each end lies on the base; `None` if the line
    /// misses, or for a flat base where the solid lies wholly behind the origin.
    #[inline(always)]
    fn span(&self, org: &FrameOrigin, d: Vec3) -> Option<(f32, f32, bool, bool)> {
        let o = org.o;
        if self.flat_base() {
            // A line from outside the ellipsoid (`c > 0`) moving away from its centre (`o·d > 0`)
            // meets it only at negative `t` (both of `unit_sphere_interval`'s roots are negative:
            // `q < 0`), so the piece it would return ends before 0 and both callers reject it.
            // Tested first, this turns away most rays that leave the stone or pass by it.
            if org.c_upper > 0.0 && o.dot(d) > 0.0 {
                return None;
            }
            // Convex: ellipsoid ∩ {y ≥ 0}; the plane ends are the base disc.
            return half_ellipsoid(o, org.c_upper, d, true);
        }
        // Domed base: the union of the two half-ellipsoids, convex because they share the
        // equator and the surface normal is continuous across it. The union of the two pieces'
        // intervals is the solid's interval; an end on the plane y = 0 can only survive the
        // union at the rim (a rounding tie), where both ellipsoids and their normals agree.
        let up = half_ellipsoid(o, org.c_upper, d, true);
        let down = half_ellipsoid(self.lower_frame(o), org.c_lower, self.lower_frame(d), false);
        match (up, down) {
            (Some(a), Some(b)) => Some((a.0.min(b.0), a.1.max(b.1), false, false)),
            (Some(a), None) | (None, Some(a)) => Some((a.0, a.1, false, false)),
            (None, None) => None,
        }
    }

    /// Whether the ray from `org` along the upper frame's direction `d` meets the solid with
    /// `0 < t < t_max`: exactly when [`Cabochon::first_hit`] finds a hit.
    #[inline(always)]
    pub(crate) fn meets(&self, org: &FrameOrigin, d: Vec3, t_max: f32) -> bool {
        self.span(org, d)
            .and_then(|(t_in, t_out, ..)| first_of_interval(t_in, t_out, t_max))
            .is_some()
    }

    /// The closest hit with `0 < t < t_max` of the ray from `org` along the upper frame's
    /// direction `d`: its `t` and the piece of surface with its normalised-frame point.
    #[inline(always)]
    pub(crate) fn first_hit(&self, org: &FrameOrigin, d: Vec3, t_max: f32) -> Option<(f32, Piece)> {
        let (t_in, t_out, in_plane, out_plane) = self.span(org, d)?;
        let (t, exit) = first_of_interval(t_in, t_out, t_max)?;
        let q = org.o + d * t;
        let piece = if if exit { out_plane } else { in_plane } {
            Piece::Base(q)
        } else if q.y >= 0.0 || self.flat_base() {
            Piece::Upper(q.normalize_or(Vec3::Y))
        } else {
            let ql = self.lower_frame(org.o) + self.lower_frame(d) * t;
            Piece::Lower(ql.normalize_or(Vec3::Y))
        };
        Some((t, piece))
    }

    /// The object-space point of a hit's piece (on the surface to rounding).
    #[inline(always)]
    pub(crate) fn point(&self, piece: Piece) -> Vec3 {
        match piece {
            Piece::Base(q) => Vec3::new(q.x * self.upper.x, 0.0, q.z * self.upper.z),
            Piece::Upper(u) => {
                let p = u * self.upper;
                Vec3::new(p.x, p.y.max(0.0), p.z)
            }
            Piece::Lower(u) => u * self.lower,
        }
    }

    /// Closest hit with `0 < t < t_max` (object space, `t` in units of `ray.dir`).
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<ShapeHit> {
        if !valid_query(ray, t_max) {
            return None;
        }
        let org = self.frame_origin(ray.origin * self.inv_upper);
        let (t, piece) = self.first_hit(&org, ray.dir * self.inv_upper, t_max)?;
        // The outward normal is the gradient `(x/a², y/b², z/c²)`: the unit-sphere point
        // scaled by the reciprocal semi-axes.
        let n = match piece {
            Piece::Base(_) => Vec3::NEG_Y,
            Piece::Upper(u) => (u * self.inv_upper).normalize_or(Vec3::Y),
            Piece::Lower(u) => (u * self.inv_lower).normalize_or(Vec3::Y),
        };
        Some(ShapeHit {
            t,
            ng: n,
            ns: n,
            p: self.point(piece),
            facet: None,
        })
    }

    /// Object-space bounds `(min, max)`.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let (a, b) = (self.upper, self.lower);
        (Vec3::new(-a.x, -b.y, -a.z), a)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::solid::Solid;
    use crate::geometry::solid::test_util::*;
    use crate::sampler::Rng;

    const RX: f32 = 1.2;
    const H: f32 = 0.7;
    const RZ: f32 = 0.9;

    /// The flat base's shortcut for rays from outside moving away from the centre turns away
    /// exactly the rays the full interval rejects: for 200 000 rays from points near, on and far
    /// from the stone in random directions, the first hit (`t` and the piece) is the one found
    /// from `half_ellipsoid` without the shortcut, bit for bit, and the shortcut fires often.
    #[test]
    fn receding_rays_are_turned_away_as_the_full_interval_turns_them_away() {
        let c = Cabochon::new(RX, H, RZ, 0.0).unwrap();
        let mut rng = Rng::new(41);
        let mut fired = 0;
        for i in 0..200_000 {
            let mut u = || rng.uniform() * 2.0 - 1.0;
            let mut o = Vec3::new(u(), u(), u());
            // Points on the dome (pushed out by a few ulps or not), near it and far away.
            o = match i % 3 {
                0 => o.normalize_or(Vec3::Y) * (1.0 + 1e-6 * u()),
                1 => o * 1.5,
                _ => o * 20.0,
            };
            let d = Vec3::new(u(), u(), u()).normalize_or(Vec3::X) * (1.0 + 0.5 * u());
            let org = c.frame_origin(o);
            let full = half_ellipsoid(o, org.c_upper, d, true)
                .and_then(|(t_in, t_out, ..)| first_of_interval(t_in, t_out, f32::INFINITY));
            let got = c.first_hit(&org, d, f32::INFINITY);
            assert_eq!(
                got.map(|h| h.0.to_bits()),
                full.map(|h| h.0.to_bits()),
                "{o} {d}"
            );
            if org.c_upper > 0.0 && o.dot(d) > 0.0 {
                fired += 1;
            }
        }
        assert!(fired > 50_000, "{fired}");
    }

    fn solid(base: f32) -> Solid {
        Solid::Cabochon(Cabochon::new(RX, H, RZ, base).unwrap())
    }

    /// Distance-like residual of `p` from the cabochon's surface (0 on it).
    fn residual(p: Vec3, base: f32) -> f32 {
        let e = |c: f32| (p.x / RX).powi(2) + (p.y / c).powi(2) + (p.z / RZ).powi(2) - 1.0;
        if p.y >= 0.0 {
            let dome = e(H).abs();
            if base == 0.0 {
                let disc = p.y.abs() + (e(1.0) - p.y * p.y).max(0.0);
                dome.min(disc)
            } else {
                dome
            }
        } else if base == 0.0 {
            p.y.abs() + (e(1.0) - p.y * p.y).max(0.0)
        } else {
            e(base).abs()
        }
    }

    #[test]
    fn known_hits_flat_and_domed() {
        for base in [0.0, 0.4] {
            let c = solid(base);
            let h = c
                .intersect(&Ray::new(Vec3::new(0.0, 5.0, 0.0), Vec3::NEG_Y), 1e9)
                .unwrap();
            assert!((h.t - (5.0 - H)).abs() < 1e-6 && h.ng == Vec3::Y, "{h:?}");
            let h = c
                .intersect(&Ray::new(Vec3::new(0.0, -5.0, 0.0), Vec3::Y), 1e9)
                .unwrap();
            assert!(
                (h.t - (5.0 - base)).abs() < 1e-6 && h.ng == Vec3::NEG_Y,
                "{h:?}"
            );
            let h = c
                .intersect(&Ray::new(Vec3::new(-5.0, 0.3, 0.0), Vec3::X), 1e9)
                .unwrap();
            let x = RX * (1.0 - (0.3f32 / H).powi(2)).sqrt();
            assert!((h.t - (5.0 - x)).abs() < 1e-5 && h.ng.x < 0.0 && h.ng.y > 0.0);
            // Oblique ray aimed at a known dome point.
            let u = Vec3::new(0.3, 0.8, -0.4).normalize();
            let target = u * Vec3::new(RX, H, RZ);
            let n = (u / Vec3::new(RX, H, RZ)).normalize();
            let dir = Vec3::new(-0.3, -1.0, 0.2).normalize();
            let h = c
                .intersect(&Ray::new(target - 3.0 * dir, dir), 1e9)
                .unwrap();
            assert!(
                (h.t - 3.0).abs() < 1e-5 && (h.ng - n).length() < 1e-5,
                "{h:?}"
            );
            // Inside: exits through the dome top.
            let h = c
                .intersect(&Ray::new(Vec3::new(0.0, 0.1, 0.0), Vec3::Y), 1e9)
                .unwrap();
            assert!((h.t - (H - 0.1)).abs() < 1e-6 && h.ng == Vec3::Y);
            // Misses and t_max.
            assert!(
                c.intersect(&Ray::new(Vec3::new(0.0, 0.1, -5.0), Vec3::X), 1e9)
                    .is_none()
            );
            assert!(
                c.intersect(&Ray::new(Vec3::new(2.0, 5.0, 0.0), Vec3::NEG_Y), 1e9)
                    .is_none()
            );
            let ray = Ray::new(Vec3::new(0.0, 5.0, 0.0), Vec3::NEG_Y);
            assert!(c.intersect(&ray, 5.0 - H - 1e-3).is_none());
            assert!(!c.occluded(&ray, 5.0 - H - 1e-3) && c.occluded(&ray, 5.0 - H + 1e-3));
            check_bad_rays(&c);
        }
        // A flat base seen from below below the rim, slightly oblique.
        let c = solid(0.0);
        let dir = Vec3::new(0.1, 1.0, 0.05).normalize();
        let h = c
            .intersect(&Ray::new(Vec3::new(0.2, -2.0, 0.1), dir), 1e9)
            .unwrap();
        assert!((h.t - 2.0 / dir.y).abs() < 1e-5 && h.ng == Vec3::NEG_Y && h.p.y == 0.0);
        for (rx, h, rz, b) in [
            (0.0, 1.0, 1.0, 0.0),
            (1.0, -1.0, 1.0, 0.0),
            (1.0, 1.0, 1.0, -0.1),
        ] {
            assert!(Cabochon::new(rx, h, rz, b).is_err());
        }
        assert!(Cabochon::new(1.0, 1.0, f32::NAN, 0.0).is_err());
    }

    #[test]
    fn rim_rays_do_not_slip_through() {
        // A dense fan of rays from outside aimed exactly at rim points, from above, below and the
        // side; all must hit near the aimed point (the ray does enter the solid there).
        for base in [0.0, 0.4] {
            let c = solid(base);
            let mut rng = Rng::new(7);
            for i in 0..20_000 {
                let phi = i as f32 * (std::f32::consts::TAU / 20_000.0);
                let rim = Vec3::new(RX * phi.cos(), 0.0, RZ * phi.sin());
                let outward = Vec3::new(phi.cos() / RX, 0.0, phi.sin() / RZ).normalize();
                // Directions that enter the solid at the rim: an inward horizontal component
                // plus a vertical one, upward only for the flat base (downward ones would just
                // graze its edge). Every 10th ray is horizontal, in the plane of the rim.
                let vy = match (i % 10, base == 0.0) {
                    (0, _) => 0.0,
                    (_, true) => 0.02 + rng.uniform(),
                    (_, false) => 2.0 * rng.uniform() - 1.0,
                };
                let dir = (-outward * (0.2 + rng.uniform()) + Vec3::Y * vy).normalize();
                let origin = rim - dir * (1.0 + 3.0 * rng.uniform());
                let ray = Ray::new(origin, dir);
                let h = c.intersect(&ray, f32::INFINITY);
                let h = h.unwrap_or_else(|| panic!("slipped through: {ray:?}, base {base}"));
                assert!((ray.at(h.t) - rim).length() < 1e-4, "{h:?}");
                assert!(c.occluded(&ray, f32::INFINITY));
            }
        }
    }

    #[test]
    fn random_rays_on_surface_and_consistent() {
        for base in [0.0, 0.4] {
            let c = solid(base);
            let hits = check_occluded_agrees(&c, 2.0, 3);
            assert!(hits > 2000, "{hits}");
            let mut rng = Rng::new(4);
            for _ in 0..10_000 {
                let ray = random_ray(&mut rng, 2.0);
                let Some(h) = c.intersect(&ray, f32::INFINITY) else {
                    continue;
                };
                let p = ray.at(h.t);
                assert!(residual(p, base) < 1e-5, "{p} {h:?}");
                assert!(residual(h.p, base) < 1e-5, "{h:?}");
                // Convex with the origin inside: the outward normal faces away from it.
                assert!(h.ng.dot(p - Vec3::new(0.0, 0.1, 0.0)) > 0.0, "{p} {h:?}");
                assert!((h.ng.length() - 1.0).abs() < 1e-5);
            }
        }
    }
}
