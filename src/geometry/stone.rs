//! The stone: its solid placed in the world by an affine transform.

use super::hit::GeometryError;
use super::placed::{PlacedCabochon, placed};
use super::shape::Shape;
use super::solid::Solid;
use glam::{Affine3A, Mat3A, Vec3};

/// A ray/stone intersection in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StoneHit {
    /// Distance along the (unit) world ray, world units.
    pub t: f32,
    /// World-space hit point.
    pub p: Vec3,
    /// Object-space hit point (for solid textures), object units.
    pub p_object: Vec3,
    /// Unit world-space geometric normal, pointing out of the stone.
    pub ng: Vec3,
    /// Unit world-space shading normal (in `ng`'s hemisphere).
    pub ns: Vec3,
    /// The facet of a faceted stone (its index in the design); `None` for the other shapes.
    pub facet: Option<u32>,
}

/// The stone's solid and its placement: object → world (`to_world`), its inverse, and the matrix
/// that carries object normals to world normals (the inverse transpose of the linear part).
#[derive(Clone, Debug)]
pub struct Stone {
    solid: Solid,
    to_world: Affine3A,
    to_object: Affine3A,
    normal_to_world: Mat3A,
    /// A cabochon met in its world-placed normalised frames (module `fan`); `None` for the
    /// other solids.
    placed: Option<PlacedCabochon>,
    /// A sphere's shape-operator field `F = N A⁻¹ / r` (module `fan`), formed once; `None` for
    /// the other solids.
    sphere_field: Option<Mat3A>,
}

impl Stone {
    /// Builds the solid for `shape` and places it with `to_world` (object → world; any finite
    /// invertible affine transform, mirrors included).
    pub fn new(shape: &Shape, to_world: Affine3A) -> Result<Stone, GeometryError> {
        Stone::from_solid(Solid::new(shape)?, to_world)
    }

    /// Places an already built solid.
    pub fn from_solid(solid: Solid, to_world: Affine3A) -> Result<Stone, GeometryError> {
        let det = to_world.matrix3.determinant();
        if !(to_world.is_finite() && det != 0.0 && det.is_finite()) {
            return Err(GeometryError::Transform);
        }
        let to_object = to_world.inverse();
        if !to_object.is_finite() {
            return Err(GeometryError::Transform);
        }
        let normal_to_world = to_object.matrix3.transpose();
        let sphere_field = match &solid {
            Solid::Sphere(s) => Some(normal_to_world * to_object.matrix3 * s.radius().recip()),
            _ => None,
        };
        Ok(Stone {
            placed: placed(&solid, to_object, normal_to_world),
            sphere_field,
            solid,
            to_world,
            to_object,
            normal_to_world,
        })
    }

    /// The solid, in object space.
    pub fn solid(&self) -> &Solid {
        &self.solid
    }

    /// Object → world transform.
    pub fn to_world(&self) -> Affine3A {
        self.to_world
    }

    /// The matrix carrying object normals to world normals (the inverse transpose of
    /// `to_world`'s linear part).
    pub fn normal_to_world(&self) -> Mat3A {
        self.normal_to_world
    }

    /// World → object transform.
    pub fn to_object(&self) -> Affine3A {
        self.to_object
    }

    /// A sphere's field `N A⁻¹ / r` ([`crate::geometry::Curvature`]), if the solid is one.
    pub(crate) fn sphere_field(&self) -> Option<Mat3A> {
        self.sphere_field
    }

    /// The placed cabochon, if the solid is one.
    pub(crate) fn placed(&self) -> Option<&PlacedCabochon> {
        self.placed.as_ref()
    }

    /// World-space axis-aligned bounds `(min, max)` of the transformed object bounds (Arvo,
    /// "Transforming Axis-Aligned Bounding Boxes", Graphics Gems, 1990).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let (lo, hi) = self.solid.bounds();
        let (c, e) = (0.5 * (lo + hi), 0.5 * (hi - lo));
        let m = self.to_world.matrix3;
        let abs = Mat3A::from_cols(m.x_axis.abs(), m.y_axis.abs(), m.z_axis.abs());
        let c = self.to_world.transform_point3(c);
        let e = Vec3::from(abs * glam::Vec3A::from(e));
        (c - e, c + e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::mesh::Mesh;
    use crate::geometry::ray::Ray;
    use crate::geometry::solid::test_util::{random_ray, test_mesh};
    use crate::sampler::Rng;
    use glam::Quat;

    fn shapes() -> Vec<Shape> {
        let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/cube.obj");
        vec![
            Shape::Sphere { radius: 0.8 },
            Shape::Cabochon {
                radius: (1.0, 0.7),
                height: 0.5,
                base: 0.0,
            },
            Shape::Cabochon {
                radius: (1.0, 0.7),
                height: 0.5,
                base: 0.3,
            },
            Shape::Slab {
                size: Vec3::new(1.5, 0.4, 1.0),
            },
            Shape::Mesh {
                path: data,
                scale: 0.5,
            },
        ]
    }

    fn placement() -> Affine3A {
        Affine3A::from_scale_rotation_translation(
            Vec3::splat(2.5),
            Quat::from_euler(glam::EulerRot::YXZ, 0.7, -0.4, 0.2),
            Vec3::new(3.0, -1.0, 0.5),
        )
    }

    #[test]
    fn world_hits_are_transformed_object_hits() {
        let m = placement();
        let inv = m.inverse();
        for shape in shapes() {
            let stone = Stone::new(&shape, m).unwrap();
            let solid = Solid::new(&shape).unwrap();
            let mut rng = Rng::new(11);
            let mut hits = 0;
            for _ in 0..10_000 {
                let r = random_ray(&mut rng, 2.0);
                // A unit world ray through the transformed object-space test ray.
                let ray = Ray::new(
                    m.transform_point3(r.origin),
                    m.transform_vector3(r.dir).normalize(),
                );
                let w = stone.intersect(&ray, f32::INFINITY);
                assert_eq!(w.is_some(), stone.occluded(&ray, f32::INFINITY));
                let obj = Ray::new(
                    inv.transform_point3(ray.origin),
                    inv.transform_vector3(ray.dir),
                );
                let o = solid.intersect(&obj, f32::INFINITY);
                assert_eq!(w.is_some(), o.is_some(), "{shape:?} {ray:?}");
                let (Some(w), Some(o)) = (w, o) else { continue };
                hits += 1;
                assert!((w.t - o.t).abs() < 1e-5 * w.t.max(1.0), "{w:?} {o:?}");
                assert!(
                    (w.p - ray.at(w.t)).length() < 1e-4,
                    "{shape:?} {w:?} {ray:?}"
                );
                assert!((w.p - m.transform_point3(o.p)).length() < 1e-5);
                // Uniform scale × rotation: normals just rotate.
                let n = m.transform_vector3(o.ng).normalize();
                assert!((w.ng - n).length() < 1e-5 && (w.ng.length() - 1.0).abs() < 1e-5);
                assert!(w.ng.dot(w.ns) > 0.0);
            }
            assert!(hits > 1000, "{shape:?}: {hits}");
            let (lo, hi) = stone.bounds();
            let (olo, ohi) = solid.bounds();
            for i in 0..8 {
                let c = Vec3::select(
                    glam::BVec3::new(i & 1 != 0, i & 2 != 0, i & 4 != 0),
                    olo,
                    ohi,
                );
                let w = m.transform_point3(c);
                assert!(w.cmpge(lo - 1e-5).all() && w.cmple(hi + 1e-5).all());
            }
        }
    }

    #[test]
    fn anisotropic_transform_uses_inverse_transpose() {
        // A sphere squashed into an ellipsoid: the normal must be the ellipsoid's gradient.
        let s = Vec3::new(2.0, 0.5, 1.0);
        let m = Affine3A::from_scale(s);
        let stone = Stone::new(&Shape::Sphere { radius: 1.0 }, m).unwrap();
        let u = Vec3::new(0.5, 0.6, -0.3).normalize();
        let target = u * s;
        let dir = Vec3::new(-1.0, -0.3, 0.4).normalize();
        let h = stone
            .intersect(&Ray::new(target - 4.0 * dir, dir), f32::INFINITY)
            .unwrap();
        assert!((h.t - 4.0).abs() < 1e-5 && (h.p - target).length() < 1e-5);
        assert!((h.ng - (target / (s * s)).normalize()).length() < 1e-5);
        assert!((h.p_object - u).length() < 1e-5);
        // A mirror keeps normals outward.
        let mirror = Stone::new(
            &Shape::Sphere { radius: 1.0 },
            Affine3A::from_scale(Vec3::new(-1.0, 1.0, 1.0)),
        )
        .unwrap();
        let h = mirror
            .intersect(&Ray::new(Vec3::new(-5.0, 0.0, 0.0), Vec3::X), 1e9)
            .unwrap();
        assert_eq!(h.ng, Vec3::NEG_X);
        for bad in [
            Affine3A::from_scale(Vec3::new(1.0, 0.0, 1.0)),
            Affine3A::from_translation(Vec3::NAN),
        ] {
            assert!(matches!(
                Stone::new(&Shape::Sphere { radius: 1.0 }, bad),
                Err(GeometryError::Transform)
            ));
        }
        let nan = Ray::new(Vec3::NAN, Vec3::X);
        assert!(stone.intersect(&nan, 1e9).is_none() && !stone.occluded(&nan, 1e9));
    }

    #[test]
    fn far_camera_hits_mesh_and_sphere() {
        // A ray from 10⁴ units away: the mesh advances its origin before the BVH, the sphere
        // relies on its precise quadratic.
        let m = Mesh::from_triangles(test_mesh(16, 0, 6), None).unwrap();
        let m = Stone::from_solid(Solid::Mesh(m), Affine3A::IDENTITY).unwrap();
        let s = Stone::new(&Shape::Sphere { radius: 1.0 }, Affine3A::IDENTITY).unwrap();
        for d in [
            Vec3::Z,
            Vec3::new(1e-9, -2e-8, 1.0),
            Vec3::new(0.0, -0.0, 3.0),
        ] {
            let ray = Ray::new(Vec3::new(0.1, 0.2, -1e4), d);
            let h = m.intersect(&ray, f32::INFINITY).unwrap();
            assert!((ray.at(h.t).z + 1.0).abs() < 0.06 && h.ng.z < 0.0, "{h:?}");
            assert!(m.occluded(&ray, f32::INFINITY) && !m.occluded(&ray, 0.9 * h.t));
            let h = s.intersect(&ray, f32::INFINITY).unwrap();
            assert!(
                (h.p.z + (1.0f32 - 0.05).sqrt()).abs() < 1e-3 && h.ng.z < 0.0,
                "{h:?}"
            );
        }
    }

    /// Build time and throughput of a ~100k-triangle mesh placed by a transform: run with
    /// `cargo test --release --lib geometry::stone::tests::mesh_timing -- --ignored --nocapture`.
    #[test]
    #[ignore]
    fn mesh_timing() {
        let tris = test_mesh(158, 0, 7);
        let n = tris.len();
        let start = std::time::Instant::now();
        let m = Mesh::from_triangles(tris, None).unwrap();
        let m = Stone::from_solid(Solid::Mesh(m), placement()).unwrap();
        let build = start.elapsed();
        let mut rng = Rng::new(8);
        let rays: Vec<Ray> = (0..1_000_000)
            .map(|_| {
                let r = random_ray(&mut rng, 2.0);
                let d = placement().transform_vector3(r.dir).normalize();
                Ray::new(placement().transform_point3(r.origin), d)
            })
            .collect();
        let start = std::time::Instant::now();
        let hits = rays
            .iter()
            .filter(|r| m.intersect(r, f32::INFINITY).is_some())
            .count();
        let closest = start.elapsed();
        let start = std::time::Instant::now();
        let occl = rays.iter().filter(|r| m.occluded(r, f32::INFINITY)).count();
        let any = start.elapsed();
        assert_eq!(hits, occl);
        let rate = |d: std::time::Duration| rays.len() as f64 / d.as_secs_f64() / 1e6;
        println!(
            "{n} triangles: build {build:?}; closest hit {:.2} Mrays/s, occlusion {:.2} Mrays/s \
             ({hits} hits), one thread",
            rate(closest),
            rate(any)
        );
    }
}
