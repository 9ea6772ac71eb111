//! A sphere centred at the origin, and the numerically careful ray/sphere interval shared with the
//! cabochon's ellipsoids.

use super::hit::{GeometryError, ShapeHit, first_of_interval, valid_query};
use super::ray::Ray;
use glam::Vec3;

/// The parameters `t0 ≤ t1` where the line `o + t·d` crosses the sphere `|p| = r` centred at the
/// origin (`t` in units of `d`), or `None` if it misses (or only touches at `t = 0`).
///
/// Both precision fixes of Haines, Günther and Akenine-Möller, "Precision Improvements for
/// Ray/Sphere Intersection" (Ray Tracing Gems, ch. 7, 2019; also pbrt-v4 §6.8.1):
/// - the discriminant `b² − a·c` is evaluated as `a·(r² − |l|²)`, `l` the point of the line
///   closest to the centre, so a small sphere seen from far away does not lose it to cancellation;
/// - the roots are `c/q` and `q/a` with `q = −(b + sign(b)·√(b² − a·c))`, which never subtracts
///   nearly equal numbers (the classic stable quadratic, Press et al., Numerical Recipes §5.6).
///
/// Here `b` is the half coefficient `o·d`, so the equation is `a·t² + 2b·t + c = 0`.
///
/// `None` also where a line from outside the sphere (`c > 0`) moves away from the centre
/// (`b > 0`): both roots are then negative (`q < 0`, so `c/q < 0` and `q/a < 0`), which the
/// interval's one caller ([`Sphere::intersect`]) would reject. Tested before the square roots
/// and divisions, this turns away every ray that leaves the sphere's surface outward.
#[inline]
pub(crate) fn sphere_interval(o: Vec3, d: Vec3, r: f32) -> Option<(f32, f32)> {
    let b = o.dot(d);
    let len = o.length();
    let c = (len - r) * (len + r);
    if b > 0.0 && c > 0.0 {
        return None;
    }
    let a = d.length_squared();
    let l = (o - d * (b / a)).length();
    let disc = (r - l) * (r + l);
    if !(disc >= 0.0) {
        return None;
    }
    let q = -(b + (a * disc).sqrt().copysign(b));
    if q == 0.0 {
        return None;
    }
    let (t0, t1) = (c / q, q / a);
    if !(t0.is_finite() && t1.is_finite()) {
        return None;
    }
    Some((t0.min(t1), t0.max(t1)))
}

/// A sphere of radius `radius` (object units) centred at the origin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    radius: f32,
}

impl Sphere {
    /// A sphere of radius `radius`, which must be finite and positive.
    pub fn new(radius: f32) -> Result<Sphere, GeometryError> {
        if !(radius > 0.0 && (radius * radius).is_finite()) {
            return Err(GeometryError::Degenerate {
                shape: "sphere",
                detail: format!("radius must be finite and positive, got {radius}"),
            });
        }
        Ok(Sphere { radius })
    }

    /// The radius, object units.
    pub fn radius(&self) -> f32 {
        self.radius
    }

    /// Closest hit with `0 < t < t_max` (object space, `t` in units of `ray.dir`).
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<ShapeHit> {
        if !valid_query(ray, t_max) {
            return None;
        }
        let (t0, t1) = sphere_interval(ray.origin, ray.dir, self.radius)?;
        let (t, _) = first_of_interval(t0, t1, t_max)?;
        // Reproject onto the surface: the normal is exact to rounding and the point no longer
        // carries the error of `t` (pbrt-v4 §6.8.5).
        let n = ray.at(t).normalize_or(Vec3::Y);
        Some(ShapeHit {
            t,
            ng: n,
            ns: n,
            p: n * self.radius,
            facet: None,
        })
    }

    /// Object-space bounds `(min, max)`.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        (Vec3::splat(-self.radius), Vec3::splat(self.radius))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::solid::Solid;
    use crate::geometry::solid::test_util::*;
    use crate::sampler::Rng;

    /// The interval without the receding-ray shortcut (the computation before it).
    fn full_interval(o: Vec3, d: Vec3, r: f32) -> Option<(f32, f32)> {
        let a = d.length_squared();
        let b = o.dot(d);
        let l = (o - d * (b / a)).length();
        let disc = (r - l) * (r + l);
        if !(disc >= 0.0) {
            return None;
        }
        let q = -(b + (a * disc).sqrt().copysign(b));
        if q == 0.0 {
            return None;
        }
        let len = o.length();
        let c = (len - r) * (len + r);
        let (t0, t1) = (c / q, q / a);
        if !(t0.is_finite() && t1.is_finite()) {
            return None;
        }
        Some((t0.min(t1), t0.max(t1)))
    }

    /// The shortcut for rays from outside moving away from the centre turns away exactly the rays
    /// the full computation turns away: for 200 000 rays from points on the sphere (a few ulps
    /// in or out), near it and far from it in random directions, the first hit is the one of
    /// the full interval, bit for bit, and the shortcut fires often.
    #[test]
    fn receding_rays_are_turned_away_as_the_full_interval_turns_them_away() {
        let r = 1.3;
        let mut rng = Rng::new(5);
        let mut fired = 0;
        for i in 0..200_000 {
            let mut u = || rng.uniform() * 2.0 - 1.0;
            let mut o = Vec3::new(u(), u(), u());
            o = match i % 3 {
                0 => o.normalize_or(Vec3::Y) * r * (1.0 + 1e-6 * u()),
                1 => o * 2.0,
                _ => o * 30.0,
            };
            let d = Vec3::new(u(), u(), u()).normalize_or(Vec3::X) * (1.0 + 0.5 * u());
            let first = |iv: Option<(f32, f32)>| {
                iv.and_then(|(t0, t1)| first_of_interval(t0, t1, f32::INFINITY))
                    .map(|(t, exit)| (t.to_bits(), exit))
            };
            let (got, full) = (sphere_interval(o, d, r), full_interval(o, d, r));
            assert_eq!(first(got), first(full), "{o} {d}");
            let len = o.length();
            if o.dot(d) > 0.0 && (len - r) * (len + r) > 0.0 {
                fired += 1;
            }
        }
        assert!(fired > 50_000, "{fired}");
    }

    fn solid(r: f32) -> Solid {
        Solid::Sphere(Sphere::new(r).unwrap())
    }

    #[test]
    fn axis_and_oblique_hits() {
        let s = solid(2.0);
        let h = s
            .intersect(&Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z), f32::INFINITY)
            .unwrap();
        assert!((h.t - 3.0).abs() < 1e-6 && h.ng == Vec3::NEG_Z && h.ns == h.ng);
        // A direction of length 2 halves t.
        let h = s
            .intersect(&Ray::new(Vec3::new(0.0, 0.0, -5.0), 2.0 * Vec3::Z), 10.0)
            .unwrap();
        assert!((h.t - 1.5).abs() < 1e-6);
        // Aimed at a known surface point from an oblique direction.
        let target = Vec3::new(1.0, 1.0, 1.0).normalize() * 2.0;
        let dir = Vec3::new(-0.2, -0.1, -1.0).normalize();
        let h = s
            .intersect(&Ray::new(target - 7.0 * dir, dir), f32::INFINITY)
            .unwrap();
        assert!((h.t - 7.0).abs() < 1e-5 && (h.p - target).length() < 1e-5);
        assert!((h.ng - target / 2.0).length() < 1e-5);
    }

    #[test]
    fn misses_inside_and_t_max() {
        let s = solid(1.0);
        assert!(
            s.intersect(&Ray::new(Vec3::new(0.0, 1.01, -5.0), Vec3::Z), 1e9)
                .is_none()
        );
        assert!(
            s.intersect(&Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::Z), 1e9)
                .is_none()
        );
        // From inside: the exit point, normal outward.
        let h = s
            .intersect(&Ray::new(Vec3::new(0.0, 0.5, 0.0), Vec3::Y), 1e9)
            .unwrap();
        assert!((h.t - 0.5).abs() < 1e-6 && h.ng == Vec3::Y);
        // t_max just below and above the hit.
        let ray = Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z);
        assert!(s.intersect(&ray, 3.999).is_none() && !s.occluded(&ray, 3.999));
        assert!(s.intersect(&ray, 4.001).is_some() && s.occluded(&ray, 4.001));
        check_bad_rays(&s);
        for r in [0.0, -1.0, f32::NAN, f32::INFINITY, 1e30] {
            assert!(Sphere::new(r).is_err());
        }
    }

    #[test]
    fn small_far_sphere_is_precise() {
        // The cancellation the Haines et al. discriminant avoids: radius 1e-3 at distance 1e4.
        let s = solid(1e-3);
        let ray = Ray::new(Vec3::new(0.0, 0.0, -1e4), Vec3::Z);
        let h = s.intersect(&ray, f32::INFINITY).unwrap();
        assert!((h.t - (1e4 - 1e-3)).abs() < 2e-3 && h.ng == Vec3::NEG_Z);
        let off = Ray::new(Vec3::new(0.9e-3, 0.0, -1e4), Vec3::Z);
        assert!(s.intersect(&off, f32::INFINITY).is_some());
    }

    #[test]
    fn random_rays_on_surface_and_consistent() {
        let s = solid(1.5);
        let hits = check_occluded_agrees(&s, 3.0, 1);
        assert!(hits > 3000, "{hits}");
        let mut rng = Rng::new(2);
        for _ in 0..10_000 {
            let ray = random_ray(&mut rng, 3.0);
            if let Some(h) = s.intersect(&ray, f32::INFINITY) {
                let p = ray.at(h.t);
                assert!((p.length() / 1.5 - 1.0).abs() < 1e-5, "{p}");
                assert!((h.p.length() / 1.5 - 1.0).abs() < 1e-6);
                assert!(h.ng.dot(p) > 0.0 && (h.ng.length() - 1.0).abs() < 1e-6);
            }
        }
    }
}
