//! The slab: an axis-aligned box centred on the y axis, resting on y = 0.

use super::hit::{GeometryError, ShapeHit, first_of_interval, valid_query};
use super::ray::Ray;
use glam::Vec3;

/// The box `[−sx/2, sx/2] × [0, sy] × [−sz/2, sz/2]` in object space (object units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slab {
    lo: Vec3,
    hi: Vec3,
}

impl Slab {
    /// A box of full sizes `size`, each finite and positive.
    pub fn new(size: Vec3) -> Result<Slab, GeometryError> {
        if !(size.cmpgt(Vec3::ZERO).all() && size.is_finite()) {
            return Err(GeometryError::Degenerate {
                shape: "slab",
                detail: format!("sizes must be finite and positive, got {size}"),
            });
        }
        let h = 0.5 * size;
        Ok(Slab {
            lo: Vec3::new(-h.x, 0.0, -h.z),
            hi: Vec3::new(h.x, size.y, h.z),
        })
    }

    /// Closest hit with `0 < t < t_max` (object space, `t` in units of `ray.dir`), by the slab
    /// method (Kay & Kajiya, "Ray Tracing Complex Scenes", SIGGRAPH 1986). Axes the ray runs
    /// parallel to are handled explicitly, so there is no `0·∞`.
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<ShapeHit> {
        if !valid_query(ray, t_max) {
            return None;
        }
        let (o, d) = (ray.origin, ray.dir);
        let (mut t_in, mut t_out) = (f32::NEG_INFINITY, f32::INFINITY);
        for i in 0..3 {
            if d[i] == 0.0 {
                if o[i] < self.lo[i] || o[i] > self.hi[i] {
                    return None;
                }
                continue;
            }
            let a = (self.lo[i] - o[i]) / d[i];
            let b = (self.hi[i] - o[i]) / d[i];
            t_in = t_in.max(a.min(b));
            t_out = t_out.min(a.max(b));
        }
        if !(t_in <= t_out) {
            return None;
        }
        let (t, _) = first_of_interval(t_in, t_out, t_max)?;
        // The face is the axis of largest coordinate relative to the half size: robust at edges
        // and corners, where the slab that set `t` may be ambiguous.
        let centre = 0.5 * (self.lo + self.hi);
        let half = 0.5 * (self.hi - self.lo);
        let mut p = ray.at(t).clamp(self.lo, self.hi);
        let rel = (p - centre) / half;
        let axis = if rel.x.abs() >= rel.y.abs() && rel.x.abs() >= rel.z.abs() {
            0
        } else if rel.y.abs() >= rel.z.abs() {
            1
        } else {
            2
        };
        let mut ng = Vec3::ZERO;
        ng[axis] = 1.0f32.copysign(rel[axis]);
        p[axis] = if ng[axis] > 0.0 {
            self.hi[axis]
        } else {
            self.lo[axis]
        };
        Some(ShapeHit {
            t,
            ng,
            ns: ng,
            p,
            facet: None,
        })
    }

    /// Object-space bounds `(min, max)`.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        (self.lo, self.hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::solid::Solid;
    use crate::geometry::solid::test_util::*;
    use crate::sampler::Rng;

    const SIZE: Vec3 = Vec3::new(2.0, 1.0, 3.0);

    fn solid() -> Solid {
        Solid::Slab(Slab::new(SIZE).unwrap())
    }

    #[test]
    fn known_hits() {
        let s = solid();
        let cases = [
            (Vec3::new(0.1, 0.5, -5.0), Vec3::Z, 3.5, Vec3::NEG_Z),
            (Vec3::new(0.1, 0.5, 5.0), Vec3::NEG_Z, 3.5, Vec3::Z),
            (Vec3::new(-4.0, 0.2, 0.3), Vec3::X, 3.0, Vec3::NEG_X),
            (Vec3::new(0.3, 4.0, 0.3), Vec3::NEG_Y, 3.0, Vec3::Y),
            (Vec3::new(0.3, -2.0, 0.3), 2.0 * Vec3::Y, 1.0, Vec3::NEG_Y),
            // Inside: the exit.
            (Vec3::new(0.0, 0.5, 0.0), Vec3::X, 1.0, Vec3::X),
        ];
        for (o, d, t, n) in cases {
            let h = s.intersect(&Ray::new(o, d), f32::INFINITY).unwrap();
            assert!(
                (h.t - t).abs() < 1e-6 && h.ng == n && h.ns == n,
                "{o} {d} {h:?}"
            );
        }
        // Oblique, aimed at a known point of the top face.
        let target = Vec3::new(0.4, 1.0, -1.1);
        let dir = Vec3::new(0.3, -1.0, 0.5).normalize();
        let h = s
            .intersect(&Ray::new(target - 2.5 * dir, dir), 1e9)
            .unwrap();
        assert!((h.t - 2.5).abs() < 1e-5 && h.ng == Vec3::Y && (h.p - target).length() < 1e-5);
        // Misses: beside, parallel outside, pointing away.
        assert!(
            s.intersect(&Ray::new(Vec3::new(1.01, 0.5, -5.0), Vec3::Z), 1e9)
                .is_none()
        );
        assert!(
            s.intersect(&Ray::new(Vec3::new(0.0, 1.5, -5.0), Vec3::Z), 1e9)
                .is_none()
        );
        assert!(
            s.intersect(&Ray::new(Vec3::new(0.0, 0.5, 5.0), Vec3::Z), 1e9)
                .is_none()
        );
        let ray = Ray::new(Vec3::new(0.1, 0.5, -5.0), Vec3::Z);
        assert!(s.intersect(&ray, 3.49).is_none() && !s.occluded(&ray, 3.49));
        assert!(s.occluded(&ray, 3.51));
        check_bad_rays(&s);
        for size in [
            Vec3::new(0.0, 1.0, 1.0),
            Vec3::new(1.0, -1.0, 1.0),
            Vec3::splat(f32::NAN),
        ] {
            assert!(Slab::new(size).is_err());
        }
    }

    #[test]
    fn edges_and_corners() {
        let s = solid();
        // Aimed exactly at an edge and at a corner: a hit with one of the adjacent normals.
        let edge = Vec3::new(1.0, 1.0, 0.2);
        let dir = Vec3::new(-1.0, -1.0, 0.0).normalize();
        let h = s.intersect(&Ray::new(edge - 2.0 * dir, dir), 1e9).unwrap();
        assert!((h.t - 2.0).abs() < 1e-5 && (h.ng == Vec3::X || h.ng == Vec3::Y));
        let corner = Vec3::new(-1.0, 0.0, -1.5);
        let dir = Vec3::new(1.0, 1.0, 1.0).normalize();
        let h = s
            .intersect(&Ray::new(corner - 3.0 * dir, dir), 1e9)
            .unwrap();
        assert!((h.t - 3.0).abs() < 1e-5 && h.ng.min_element() == -1.0);
    }

    #[test]
    fn random_rays_on_surface_and_consistent() {
        let s = solid();
        let hits = check_occluded_agrees(&s, 3.0, 5);
        assert!(hits > 3000, "{hits}");
        let (lo, hi) = s.bounds();
        let centre = 0.5 * (lo + hi);
        let mut rng = Rng::new(6);
        for _ in 0..10_000 {
            let ray = random_ray(&mut rng, 3.0);
            let Some(h) = s.intersect(&ray, f32::INFINITY) else {
                continue;
            };
            let p = ray.at(h.t);
            // On the box: inside to rounding, and on the face of the normal.
            assert!(p.cmpge(lo - 1e-5).all() && p.cmple(hi + 1e-5).all(), "{p}");
            let face = if h.ng.max_element() > 0.0 { hi } else { lo };
            assert!((p - face).dot(h.ng).abs() < 1e-5, "{p} {h:?}");
            assert!(h.ng.dot(p - centre) > 0.0);
        }
    }

    /// The OBJ cube `[-1, 1] × [0, 2] × [-1, 1]` scaled by 1/2 is the unit slab.
    #[test]
    fn cube_mesh_matches_slab() {
        let manifest = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let path = manifest.join("tests/data/cube.obj");
        let cube = Solid::new(&crate::geometry::shape::Shape::Mesh { path, scale: 0.5 }).unwrap();
        let slab = Solid::Slab(Slab::new(Vec3::ONE).unwrap());
        assert_eq!(cube.triangles(), 12);
        assert_eq!(cube.bounds(), slab.bounds());
        check_occluded_agrees(&cube, 1.5, 4);
        let mut rng = Rng::new(5);
        for _ in 0..10_000 {
            let ray = random_ray(&mut rng, 1.5);
            let (a, b) = (
                cube.intersect(&ray, f32::INFINITY),
                slab.intersect(&ray, f32::INFINITY),
            );
            assert_eq!(a.is_some(), b.is_some(), "{ray:?}");
            let (Some(a), Some(b)) = (a, b) else { continue };
            assert!(
                (a.t - b.t).abs() < 1e-4 && a.ng == b.ng && a.ns == a.ng,
                "{a:?} {b:?}"
            );
        }
        // Rays aimed at the cube's edges and at face diagonals (edges shared by two triangles),
        // from outside (corners excluded: some rays would only graze them), all hit there.
        for i in 1..1000 {
            let s = i as f32 / 1000.0 - 0.5;
            let up = Vec3::new(0.3, 0.7, 1.0);
            let cases = [
                (Vec3::new(s, 0.5 + s, -0.5), up),
                (Vec3::new(s, 0.0, s), up),
                (Vec3::new(0.5, 1.0, s), Vec3::new(-0.4, -0.6, 0.2)),
                (Vec3::new(-0.5, s + 0.5, 0.5), Vec3::new(1.0, 0.2, -0.7)),
            ];
            for (target, dir) in cases {
                let ray = Ray::new(target - dir, dir);
                let h = cube.intersect(&ray, f32::INFINITY);
                let h = h.unwrap_or_else(|| panic!("no hit at an edge: {ray:?} {s}"));
                assert!((h.t - 1.0).abs() < 1e-5, "{h:?}");
            }
        }
    }
}
