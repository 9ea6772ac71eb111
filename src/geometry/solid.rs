//! The stone's shape in object space: a closed set of solids behind one enum (static dispatch),
//! their hit record and the errors building them can raise.

use super::cabochon::Cabochon;
pub use super::hit::{GeometryError, ShapeHit};
use super::mesh::Mesh;
use super::polytope::Polytope;
use super::ray::Ray;
use super::shape::Shape;
use super::slab::Slab;
use super::sphere::Sphere;
use glam::Vec3;

/// The stone's shape in object space, ready to intersect.
// One per scene: the size of the mesh variant does not matter, and boxing it would cost a
// pointer chase on every ray.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
pub enum Solid {
    /// A sphere centred at the origin.
    Sphere(Sphere),
    /// A cabochon: an elliptical dome over a flat or domed base.
    Cabochon(Cabochon),
    /// An axis-aligned box resting on y = 0.
    Slab(Slab),
    /// A faceted stone: half-spaces intersected exactly.
    Polytope(Polytope),
    /// A triangle mesh with its BVH.
    Mesh(Mesh),
}

impl Solid {
    /// Builds the solid for `shape` (loading and indexing the OBJ file for a mesh). Sizes must be
    /// finite and positive (a cabochon's `base` may be 0).
    pub fn new(shape: &Shape) -> Result<Solid, GeometryError> {
        Ok(match shape {
            Shape::Sphere { radius } => Solid::Sphere(Sphere::new(*radius)?),
            Shape::Cabochon {
                radius,
                height,
                base,
            } => Solid::Cabochon(Cabochon::new(radius.0, *height, radius.1, *base)?),
            Shape::Slab { size } => Solid::Slab(Slab::new(*size)?),
            Shape::Faceted(f) => Solid::Polytope(Polytope::new(&f.planes, "faceted stone")?),
            Shape::Mesh { path, scale } => Solid::Mesh(Mesh::load(path, *scale)?),
        })
    }

    /// Closest hit with `0 < t < t_max` along an object-space ray (`dir` need not be unit length:
    /// `t` is in units of `dir`). Rays with non-finite components or a zero direction miss.
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<ShapeHit> {
        match self {
            Solid::Sphere(s) => s.intersect(ray, t_max),
            Solid::Cabochon(c) => c.intersect(ray, t_max),
            Solid::Slab(s) => s.intersect(ray, t_max),
            Solid::Polytope(p) => p.intersect(ray, t_max),
            Solid::Mesh(m) => m.intersect(ray, t_max),
        }
    }

    /// Whether anything is hit with `0 < t < t_max` (may stop at the first hit found).
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        match self {
            Solid::Mesh(m) => m.occluded(ray, t_max),
            _ => self.intersect(ray, t_max).is_some(),
        }
    }

    /// Object-space axis-aligned bounds `(min, max)`.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        match self {
            Solid::Sphere(s) => s.bounds(),
            Solid::Cabochon(c) => c.bounds(),
            Solid::Slab(s) => s.bounds(),
            Solid::Polytope(p) => p.bounds(),
            Solid::Mesh(m) => m.bounds(),
        }
    }

    /// Number of triangles (0 for the analytic shapes).
    pub fn triangles(&self) -> usize {
        match self {
            Solid::Mesh(m) => m.triangle_count(),
            _ => 0,
        }
    }
}

#[cfg(test)]
pub(crate) mod test_util {
    //! Shared helpers for the shape tests.
    use super::*;
    use crate::sampler::Rng;

    /// A point uniformly in the cube `[-r, r]³`.
    pub fn point_in_cube(rng: &mut Rng, r: f32) -> Vec3 {
        Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * (2.0 * r) - Vec3::splat(r)
    }

    /// A uniform unit direction.
    pub fn direction(rng: &mut Rng) -> Vec3 {
        let z = 1.0 - 2.0 * rng.uniform();
        let phi = std::f32::consts::TAU * rng.uniform();
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }

    /// A random ray: origin in `[-r, r]³`, direction either uniform or aimed at a point of
    /// `[-r/2, r/2]³` (so most rays hit), length in `[0.5, 2)` to check `t` is in units of `dir`.
    pub fn random_ray(rng: &mut Rng, r: f32) -> Ray {
        let origin = point_in_cube(rng, r);
        let aim = rng.uniform() < 0.7;
        let dir = if aim {
            (point_in_cube(rng, 0.5 * r) - origin).normalize_or(Vec3::X)
        } else {
            direction(rng)
        };
        Ray::new(origin, dir * (0.5 + 1.5 * rng.uniform()))
    }

    /// A closed lat-long sphere of `n × 2n` quads (with degenerate triangles at the poles), its
    /// radius jittered per vertex, plus `loose` random triangles (an open, intersecting soup).
    pub fn test_mesh(n: usize, loose: usize, key: u64) -> Vec<[Vec3; 3]> {
        let mut rng = Rng::new(key);
        let (rows, cols) = (n, 2 * n);
        let mut v = Vec::new();
        for i in 0..=rows {
            let theta = std::f32::consts::PI * i as f32 / rows as f32;
            let (sin, cos) = if i == 0 || i == rows {
                (0.0, theta.cos())
            } else {
                theta.sin_cos()
            };
            for j in 0..cols {
                let phi = std::f32::consts::TAU * j as f32 / cols as f32;
                let r = if sin == 0.0 {
                    1.0
                } else {
                    1.0 + 0.05 * rng.uniform()
                };
                v.push(r * Vec3::new(sin * phi.cos(), cos, sin * phi.sin()));
            }
        }
        let at = |i: usize, j: usize| v[i * cols + j % cols];
        let mut tris = Vec::new();
        for i in 0..rows {
            for j in 0..cols {
                let (a, b, c, d) = (at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j));
                tris.extend([[a, b, c], [a, c, d]]);
            }
        }
        for _ in 0..loose {
            let p = point_in_cube(&mut rng, 1.5);
            tris.push([
                p,
                p + 0.3 * direction(&mut rng),
                p + 0.3 * direction(&mut rng),
            ]);
        }
        tris
    }

    /// Checks `occluded` against `intersect` over many random rays and `t_max` values, and returns
    /// the number of hits.
    pub fn check_occluded_agrees(solid: &Solid, r: f32, key: u64) -> usize {
        let mut rng = Rng::new(key);
        let mut hits = 0;
        for i in 0..10_000 {
            let ray = random_ray(&mut rng, r);
            let t_max = if i % 3 == 0 {
                f32::INFINITY
            } else {
                4.0 * r * rng.uniform()
            };
            let hit = solid.intersect(&ray, t_max);
            assert_eq!(
                hit.is_some(),
                solid.occluded(&ray, t_max),
                "ray {ray:?} t_max {t_max}"
            );
            if let Some(h) = hit {
                assert!(h.t > 0.0 && h.t < t_max);
                assert!((h.ng.length() - 1.0).abs() < 1e-5 && (h.ns.length() - 1.0).abs() < 1e-5);
                hits += 1;
            }
        }
        hits
    }

    /// Rays with NaN or infinite components, or a zero direction, or a NaN `t_max`, miss.
    pub fn check_bad_rays(solid: &Solid) {
        let good = Ray::new(Vec3::new(0.1, 0.2, -10.0), Vec3::Z);
        let bad = [
            (Ray::new(Vec3::new(f32::NAN, 0.0, -10.0), Vec3::Z), 1e9),
            (Ray::new(Vec3::new(0.0, f32::INFINITY, -10.0), Vec3::Z), 1e9),
            (
                Ray::new(Vec3::new(0.1, 0.2, -10.0), Vec3::new(0.0, f32::NAN, 1.0)),
                1e9,
            ),
            (
                Ray::new(
                    Vec3::new(0.1, 0.2, -10.0),
                    Vec3::new(f32::INFINITY, 0.0, 1.0),
                ),
                1e9,
            ),
            (Ray::new(Vec3::new(0.1, 0.2, -10.0), Vec3::ZERO), 1e9),
            (good, f32::NAN),
            (good, -1.0),
        ];
        for (ray, t_max) in bad {
            assert!(solid.intersect(&ray, t_max).is_none(), "{ray:?} {t_max}");
            assert!(!solid.occluded(&ray, t_max), "{ray:?} {t_max}");
        }
    }
}
