//! Triangle meshes loaded from OBJ files, indexed by a BVH (obvhs) and intersected with the
//! watertight ray/triangle test.

use super::hit::{GeometryError, ShapeHit, valid_query};
use super::ray::Ray;
use glam::Vec3;
use obvhs::{BvhBuildParams, aabb::Aabb, bvh2::Bvh2, bvh2::builder::build_bvh2, ray::RayHit};
use std::path::Path;

mod closed;
mod obj;

/// A triangle mesh in object space (object units): triangles stored in BVH order with their unit
/// geometric normals (counter-clockwise winding = outward) and optional vertex normals.
#[derive(Clone)]
pub struct Mesh {
    tris: Vec<[Vec3; 3]>,
    ng: Vec<Vec3>,
    /// Unit vertex normals per triangle (empty if no triangle has any; all zero for a triangle
    /// without valid ones).
    normals: Vec<[Vec3; 3]>,
    bvh: Bvh2,
    lo: Vec3,
    hi: Vec3,
    /// Half the padding of the BVH boxes, the margin of the root box test.
    pad: f32,
    diag: f32,
    skipped: usize,
}

impl std::fmt::Debug for Mesh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Mesh")
            .field("triangles", &self.tris.len())
            .field("vertex_normals", &!self.normals.is_empty())
            .field("bounds", &(self.lo, self.hi))
            .field("bvh_nodes", &self.bvh.nodes.len())
            .finish()
    }
}

/// A ray prepared for the watertight test: the axis `kz` of the largest direction component
/// (the ray's local z), the two others, and the shear `(Sx, Sy, Sz)` mapping the ray onto +z.
struct ShearedRay {
    o: Vec3,
    k: [usize; 3],
    s: Vec3,
}

impl ShearedRay {
    fn new(o: Vec3, d: Vec3) -> Self {
        let a = d.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let s = Vec3::new(d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]);
        ShearedRay {
            o,
            k: [kx, ky, kz],
            s,
        }
    }

    /// Watertight ray/triangle intersection (Woop, Benthin and Wald, "Watertight Ray/Triangle
    /// Intersection", JCGT 2(1), 2013), both sides: `(t, b0, b1, b2)` with `0 < t < t_max` and
    /// the barycentric weights of the three vertices. Edges shared by two triangles give the same
    /// edge functions in both, so a ray cannot slip between them; exact zeros are re-evaluated in
    /// double precision, as the paper prescribes.
    #[inline]
    fn hit(&self, v: &[Vec3; 3], t_max: f32) -> Option<(f32, f32, f32, f32)> {
        let [kx, ky, kz] = self.k;
        let (a, b, c) = (v[0] - self.o, v[1] - self.o, v[2] - self.o);
        let (ax, ay) = (a[kx] - self.s.x * a[kz], a[ky] - self.s.y * a[kz]);
        let (bx, by) = (b[kx] - self.s.x * b[kz], b[ky] - self.s.y * b[kz]);
        let (cx, cy) = (c[kx] - self.s.x * c[kz], c[ky] - self.s.y * c[kz]);
        let (mut u, mut vv, mut w) = (cx * by - cy * bx, ax * cy - ay * cx, bx * ay - by * ax);
        if u == 0.0 || vv == 0.0 || w == 0.0 {
            let e = |px: f32, py: f32, qx: f32, qy: f32| {
                (px as f64 * qy as f64 - py as f64 * qx as f64) as f32
            };
            (u, vv, w) = (e(cx, cy, bx, by), e(ax, ay, cx, cy), e(bx, by, ax, ay));
        }
        if (u < 0.0 || vv < 0.0 || w < 0.0) && (u > 0.0 || vv > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + vv + w;
        if det == 0.0 {
            return None;
        }
        let tt = u * (self.s.z * a[kz]) + vv * (self.s.z * b[kz]) + w * (self.s.z * c[kz]);
        let t = tt / det;
        (t > 0.0 && t < t_max).then(|| (t, u / det, vv / det, w / det))
    }
}

/// Where a query starts: the ray (direction normalised, origin possibly advanced toward the
/// mesh), the parameter offset of the advance, and the direction's length.
struct Query {
    sheared: ShearedRay,
    bvh_ray: obvhs::ray::Ray,
    t0: f32,
    len: f32,
}

impl Mesh {
    /// A mesh from triangles given directly (object units, counter-clockwise = outward), with
    /// optional per-triangle vertex normals (same length). Degenerate triangles are skipped.
    pub fn from_triangles(
        tris: Vec<[Vec3; 3]>,
        normals: Option<Vec<[Vec3; 3]>>,
    ) -> Result<Mesh, GeometryError> {
        let path = Path::new("<in-memory triangles>");
        if tris.iter().flatten().any(|v| !v.is_finite()) {
            return Err(GeometryError::NonFinite {
                path: path.to_owned(),
                scale: 1.0,
            });
        }
        let normals = normals.unwrap_or_else(|| vec![[Vec3::ZERO; 3]; tris.len()]);
        Mesh::build(tris, normals, path)
    }

    fn build(
        tris: Vec<[Vec3; 3]>,
        normals: Vec<[Vec3; 3]>,
        path: &Path,
    ) -> Result<Mesh, GeometryError> {
        let total = tris.len();
        let mut kept: Vec<([Vec3; 3], Vec3, [Vec3; 3])> = Vec::with_capacity(total);
        for (i, v) in tris.into_iter().enumerate() {
            let cross = (v[1] - v[0]).cross(v[2] - v[0]);
            let len = cross.length();
            if !(len > 0.0 && len.is_finite()) {
                continue;
            }
            let mut n = normals
                .get(i)
                .copied()
                .unwrap_or([Vec3::ZERO; 3])
                .map(|n| n.normalize_or_zero());
            if n.contains(&Vec3::ZERO) {
                n = [Vec3::ZERO; 3];
            }
            kept.push((v, cross / len, n));
        }
        if kept.is_empty() {
            return Err(GeometryError::NoTriangles {
                path: path.to_owned(),
            });
        }
        let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        for (v, _, _) in &kept {
            for p in v {
                (lo, hi) = (lo.min(*p), hi.max(*p));
            }
        }
        let diag = (hi - lo).length();
        // Padding the boxes makes the BVH's float slab tests conservative (cf. Ize, "Robust BVH
        // Ray Traversal", JCGT 2(2), 2013): a box is missed only if the ray passes farther than
        // the pad from it, which covers the rounding of origins within a few diagonals.
        let pad = 4e-6 * diag + 1e-6 * lo.abs().max(hi.abs()).max_element();
        let aabbs: Vec<Aabb> = kept
            .iter()
            .map(|(v, _, _)| {
                let (a, b) = (v[0].min(v[1]).min(v[2]), v[0].max(v[1]).max(v[2]));
                Aabb::new((a - pad).into(), (b + pad).into())
            })
            .collect();
        let bvh = build_bvh2(
            &aabbs,
            BvhBuildParams::medium_build(),
            &mut Default::default(),
        );
        let order = bvh.primitive_indices.iter().map(|&i| &kept[i as usize]);
        let tris = order.clone().map(|k| k.0).collect();
        let ng = order.clone().map(|k| k.1).collect();
        let any_normals = kept.iter().any(|k| k.2[0] != Vec3::ZERO);
        let normals = if any_normals {
            order.map(|k| k.2).collect()
        } else {
            Vec::new()
        };
        let skipped = total - kept.len();
        Ok(Mesh {
            tris,
            ng,
            normals,
            bvh,
            lo,
            hi,
            pad: 0.5 * pad,
            diag,
            skipped,
        })
    }

    /// Number of triangles kept.
    pub fn triangle_count(&self) -> usize {
        self.tris.len()
    }

    /// Number of degenerate (zero-area) triangles skipped at load.
    pub fn skipped_triangles(&self) -> usize {
        self.skipped
    }

    /// Whether the mesh has vertex (shading) normals.
    pub fn has_vertex_normals(&self) -> bool {
        !self.normals.is_empty()
    }

    /// Object-space bounds `(min, max)`.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        (self.lo, self.hi)
    }

    /// Sets up a query, or `None` if the ray misses the (padded) bounds before `t_max`. The
    /// direction is normalised for the BVH (its safe reciprocal clamps tiny components, harmless
    /// only at unit length) and an origin far outside is first advanced to one diagonal before
    /// the bounds, keeping the slab tests' rounding within the boxes' padding.
    fn query(&self, ray: &Ray, t_max: f32) -> Option<Query> {
        if !valid_query(ray, t_max) {
            return None;
        }
        let len = ray.dir.length();
        let d = ray.dir / len;
        let (lo, hi) = (self.lo - self.pad, self.hi + self.pad);
        let (a, b) = ((lo - ray.origin) / d, (hi - ray.origin) / d);
        let t_in = a.min(b).max_element();
        let t_out = a.max(b).min_element();
        // An origin exactly on a padded box plane, the ray parallel to it (0/0 = NaN, ignored by
        // min/max), counts as a miss: no triangle lies within the padding.
        if t_in > t_out || t_out < 0.0 || t_in >= t_max * len {
            return None;
        }
        let t0 = if t_in > 2.0 * self.diag {
            t_in - self.diag
        } else {
            0.0
        };
        let o = ray.origin + d * t0;
        let bvh_ray = obvhs::ray::Ray::new(o.into(), d.into(), 0.0, t_max * len - t0);
        Some(Query {
            sheared: ShearedRay::new(o, d),
            bvh_ray,
            t0,
            len,
        })
    }

    /// Tests triangle `i` for `q`, with `t_local` the bound in the query's units and `t_max` in
    /// the caller's: `(t in the caller's units, barycentrics)`.
    #[inline]
    fn test(&self, q: &Query, i: usize, t_local: f32, t_max: f32) -> Option<(f32, f32, [f32; 3])> {
        let (tl, b0, b1, b2) = q.sheared.hit(&self.tris[i], t_local)?;
        let t = (q.t0 + tl) / q.len;
        (t > 0.0 && t < t_max).then_some((tl, t, [b0, b1, b2]))
    }

    /// Closest hit with `0 < t < t_max` (object space, `t` in units of `ray.dir`).
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<ShapeHit> {
        let q = self.query(ray, t_max)?;
        let mut best: Option<(usize, f32, [f32; 3])> = None;
        let mut rh = RayHit::none();
        self.bvh.ray_traverse(q.bvh_ray, &mut rh, |r, i| {
            match self.test(&q, i, r.tmax, t_max) {
                Some((tl, t, b)) => {
                    best = Some((i, t, b));
                    tl
                }
                None => f32::INFINITY,
            }
        });
        let (i, t, b) = best?;
        Some(self.hit_record(i, t, b))
    }

    /// The hit record for triangle `i` at `t` with barycentrics `b`.
    fn hit_record(&self, i: usize, t: f32, b: [f32; 3]) -> ShapeHit {
        let v = &self.tris[i];
        let p = v[0] * b[0] + v[1] * b[1] + v[2] * b[2];
        let ng = self.ng[i];
        let ns = match self.normals.get(i) {
            Some(n) if n[0] != Vec3::ZERO => {
                let ns = (n[0] * b[0] + n[1] * b[1] + n[2] * b[2]).normalize_or(ng);
                if ns.dot(ng) < 0.0 { -ns } else { ns }
            }
            _ => ng,
        };
        ShapeHit {
            t,
            ng,
            ns,
            p,
            facet: None,
        }
    }

    /// Whether any triangle is hit with `0 < t < t_max` (the BVH's early-exit traversal).
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        let Some(q) = self.query(ray, t_max) else {
            return false;
        };
        !self.bvh.ray_traverse_miss(q.bvh_ray, |r, i| {
            self.test(&q, i, r.tmax, t_max)
                .map_or(f32::INFINITY, |h| h.0)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::solid::Solid;
    use crate::geometry::solid::test_util::*;
    use crate::sampler::Rng;
    use std::path::PathBuf;

    fn data(name: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(name)
    }

    /// Closest hit by testing every triangle, in the ray's own units (no normalisation).
    fn brute_force(m: &Mesh, ray: &Ray, t_max: f32) -> Option<(f32, usize)> {
        let s = ShearedRay::new(ray.origin, ray.dir);
        let mut best = None;
        for (i, tri) in m.tris.iter().enumerate() {
            let bound = best.map_or(t_max, |b: (f32, usize)| b.0);
            if let Some((t, ..)) = s.hit(tri, bound) {
                best = Some((t, i));
            }
        }
        best
    }

    #[test]
    fn bvh_closest_hit_equals_brute_force() {
        let m = Mesh::from_triangles(test_mesh(24, 300, 1), None).unwrap();
        assert_eq!(
            m.triangle_count(),
            24 * 48 * 2 + 300 - m.skipped_triangles()
        );
        let solid = Solid::Mesh(m.clone());
        let hits = check_occluded_agrees(&solid, 2.0, 2);
        assert!(hits > 4000, "{hits}");
        let mut rng = Rng::new(3);
        for k in 0..10_000 {
            let ray = random_ray(&mut rng, 2.0);
            let t_max = if k % 2 == 0 {
                f32::INFINITY
            } else {
                3.0 * rng.uniform()
            };
            let bvh = m.intersect(&ray, t_max);
            let brute = brute_force(&m, &ray, t_max);
            assert_eq!(bvh.is_some(), brute.is_some(), "{ray:?}");
            let (Some(h), Some((t, i))) = (bvh, brute) else {
                continue;
            };
            assert!((h.t - t).abs() <= 1e-5 * t.max(1.0), "{h:?} {t}");
            if (h.t - t).abs() < 1e-7 {
                assert_eq!(h.ng, m.ng[i]);
            }
            assert!((h.p - ray.at(h.t)).length() < 1e-5 && h.ns == h.ng);
        }
    }

    #[test]
    fn tetra_vertex_normals_are_interpolated() {
        let m = Mesh::load(&data("tetra.obj"), 1.0).unwrap();
        assert!(m.has_vertex_normals() && m.triangle_count() == 4);
        let vn = |p: Vec3| (p - Vec3::splat(0.25)).normalize();
        let b = [0.6, 0.3, 0.1];
        let target = Vec3::new(b[0], b[1], b[2]);
        let dir = Vec3::new(-1.0, -0.5, -0.8).normalize();
        let h = m
            .intersect(&Ray::new(target - 2.0 * dir, dir), f32::INFINITY)
            .unwrap();
        let expect = (b[0] * vn(Vec3::X) + b[1] * vn(Vec3::Y) + b[2] * vn(Vec3::Z)).normalize();
        assert!((h.t - 2.0).abs() < 1e-5 && (h.p - target).length() < 1e-6);
        assert!((h.ng - Vec3::ONE.normalize()).length() < 1e-6);
        assert!(
            (h.ns - expect).length() < 1e-5 && (h.ns - h.ng).length() > 0.05,
            "{h:?}"
        );
        // From inside, through the bottom face: ns stays in ng's hemisphere.
        let h = m
            .intersect(&Ray::new(Vec3::new(0.2, 0.1, 0.3), Vec3::NEG_Y), 1e9)
            .unwrap();
        assert!((h.t - 0.1).abs() < 1e-6 && h.ng == Vec3::NEG_Y && h.ns.dot(h.ng) > 0.0);
        // Scaling multiplies coordinates.
        let big = Mesh::load(&data("tetra.obj"), 3.0).unwrap();
        assert_eq!(big.bounds(), (Vec3::ZERO, Vec3::splat(3.0)));
    }

    #[test]
    fn bad_files_and_degenerate_input() {
        let err = |name: &str, scale: f32| Mesh::load(&data(name), scale).unwrap_err();
        let e = err("does-not-exist.obj", 1.0);
        assert!(
            matches!(e, GeometryError::Read { .. }) && e.to_string().contains("does-not-exist.obj")
        );
        let e = err("garbage.obj", 1.0);
        assert!(
            matches!(e, GeometryError::Parse { .. }) && e.to_string().contains("garbage.obj"),
            "{e}"
        );
        let e = err("lines.obj", 1.0);
        assert!(
            matches!(e, GeometryError::NoTriangles { .. }) && e.to_string().contains("lines.obj")
        );
        let e = err("nan.obj", 1.0).to_string();
        assert!(e.contains("nan.obj") && e.contains("line 3:"), "{e}");
        let e = err("cube.obj", 3e38).to_string();
        assert!(e.contains("× scale") && e.contains("line "), "{e}");
        let e = err("garbage.obj", 1.0).to_string();
        assert!(e.contains("line 3:") && e.contains("`zero`"), "{e}");
        for scale in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            assert!(matches!(
                err("cube.obj", scale),
                GeometryError::Degenerate { .. }
            ));
        }
        // A degenerate triangle is skipped; a single triangle still builds a BVH.
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let m =
            Mesh::from_triangles(vec![tri, [Vec3::ZERO, Vec3::X, 2.0 * Vec3::X]], None).unwrap();
        assert_eq!((m.triangle_count(), m.skipped_triangles()), (1, 1));
        let h = m
            .intersect(&Ray::new(Vec3::new(0.2, 0.2, 1.0), Vec3::NEG_Z), 1e9)
            .unwrap();
        assert!((h.t - 1.0).abs() < 1e-6 && h.ng == Vec3::Z);
        assert!(Mesh::from_triangles(vec![[Vec3::ZERO; 3]], None).is_err());
        assert!(Mesh::from_triangles(vec![[Vec3::NAN, Vec3::X, Vec3::Y]], None).is_err());
        check_bad_rays(&Solid::Mesh(m));
    }

    #[test]
    fn rays_at_shared_vertices_and_edges_hit() {
        // A convex lat-long polyhedron (vertices on the unit sphere): each vertex is shared by up
        // to six triangles, each edge by two. Oblique rays aimed at them from outside, near and
        // far (origin advance), all hit there: no cracks.
        let tris: Vec<[Vec3; 3]> = test_mesh(12, 0, 9)
            .into_iter()
            .map(|t| t.map(|v| v.normalize()))
            .collect();
        let m = Mesh::from_triangles(tris.clone(), None).unwrap();
        let mut rng = Rng::new(10);
        for dist in [1.0, 100.0] {
            for tri in &tris {
                let u = rng.uniform();
                for target in [
                    tri[0],
                    tri[1] + (tri[2] - tri[1]) * u,
                    0.5 * (tri[0] + tri[2]),
                ] {
                    let out = target.normalize();
                    let d = direction(&mut rng);
                    let d = (d - out * (d.dot(out).max(0.0) + 0.5 + rng.uniform())).normalize();
                    let ray = Ray::new(target - dist * d, d);
                    let h = m.intersect(&ray, f32::INFINITY);
                    let h = h.unwrap_or_else(|| panic!("slipped through at {target}: {ray:?}"));
                    assert!((h.t - dist).abs() < 1e-4 * dist && m.occluded(&ray, 2.0 * dist));
                }
            }
        }
    }
}
