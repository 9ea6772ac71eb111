//! A faceted stone: the intersection of half-spaces, intersected exactly — no triangles, no BVH.
//!
//! A ray `o + t d` is inside the half-space `n · x ≤ dᵢ` on an interval bounded by
//! `tᵢ = (dᵢ − n · o) / (n · d)`: from `tᵢ` on where `n · d > 0` (it leaves there), up to `tᵢ`
//! where `n · d < 0` (it enters there), everywhere or nowhere where `n · d = 0`. The solid's
//! interval is the intersection of all of them, `[max entering tᵢ, min leaving tᵢ]` — the slab
//! method of Kay & Kajiya ("Ray Tracing Complex Scenes", SIGGRAPH 1986) for any convex polytope
//! (Haines, "Fast Ray–Convex Polyhedron Intersection", Graphics Gems II, 1991). The hit's facet is
//! the plane that set the bound. **Watertight**: there are no facet polygons whose edges rays
//! could slip between; a ray whose interval is non-empty hits, whichever of the planes meeting at
//! an edge or vertex sets the bound (tested with rays aimed at every edge and vertex).
//!
//! The planes are stored as structure-of-arrays in `f32` with the redundant ones (bounding no
//! face) left out, and a bounding sphere rejects most misses before the planes are read. The
//! bounds are found without branches, eight planes side by side; the plane that set the bound is
//! found afterwards, for hits only, by recomputing the same quotients in the lanes that hold it.

use super::clip::{FacetPlane, Hull, HullError};
use super::hit::{GeometryError, ShapeHit, first_of_interval, valid_query};
use super::ray::Ray;
use glam::Vec3;

/// Planes intersected side by side (8: one AVX register of `f32`, two SSE ones).
const LANES: usize = 8;

/// A convex faceted solid, ready to intersect.
#[derive(Clone, Debug)]
pub struct Polytope {
    nx: Vec<f32>,
    ny: Vec<f32>,
    nz: Vec<f32>,
    d: Vec<f32>,
    /// The facet index of each stored plane.
    facet: Vec<u32>,
    /// Bounding sphere (centre, radius²).
    centre: Vec3,
    radius2: f32,
    bounds: (Vec3, Vec3),
    hull: Hull,
    /// The instruction set pass 1 runs with (detected once).
    arch: pulp::Arch,
}

impl Polytope {
    /// The solid bounded by `planes` (object space); fails when they enclose nothing or leave it
    /// open. `shape` names the design in errors.
    pub fn new(planes: &[FacetPlane], shape: &'static str) -> Result<Polytope, GeometryError> {
        let extent = planes.iter().map(|p| p.d.abs()).fold(1.0f64, f64::max) * 1e3;
        let hull = Hull::new(planes, extent).map_err(|e| GeometryError::Degenerate {
            shape,
            detail: e.to_string(),
        })?;
        let used: Vec<&FacetPlane> = {
            let mut idx: Vec<usize> = hull.faces.iter().filter_map(|f| f.plane).collect();
            idx.sort_unstable();
            idx.dedup();
            idx.iter().map(|&i| &planes[i]).collect()
        };
        let (lo, hi) = hull.bounds();
        let centre = (lo + hi) * 0.5;
        let radius = hull
            .vertices()
            .iter()
            .map(|v| (*v - centre).length())
            .fold(0.0f64, f64::max);
        // Padded so that rounding never rejects a ray that grazes a corner.
        let r = (radius * (1.0 + 1e-5) + 1e-6 * radius.max(1.0)) as f32;
        // Padded to whole groups of `LANES` with planes that bound nothing: a zero normal at
        // distance 1 is neither entered nor left, and no ray is outside it.
        let padded = used.len().div_ceil(LANES) * LANES;
        let pad = |v: Vec<f32>, x: f32| {
            let mut v = v;
            v.resize(padded, x);
            v
        };
        Ok(Polytope {
            nx: pad(used.iter().map(|p| p.normal.x as f32).collect(), 0.0),
            ny: pad(used.iter().map(|p| p.normal.y as f32).collect(), 0.0),
            nz: pad(used.iter().map(|p| p.normal.z as f32).collect(), 0.0),
            d: pad(used.iter().map(|p| p.d as f32).collect(), 1.0),
            facet: used.iter().map(|p| p.facet).collect(),
            centre: centre.as_vec3(),
            radius2: r * r,
            bounds: (lo.as_vec3(), hi.as_vec3()),
            hull,
            arch: pulp::Arch::new(),
        })
    }

    /// Closest hit with `0 < t < t_max` (object space, `t` in units of `ray.dir`), the facet
    /// index in [`ShapeHit::facet`].
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<ShapeHit> {
        if !valid_query(ray, t_max) {
            return None;
        }
        let (o, dir) = (ray.origin, ray.dir);
        // Bounding sphere: the ray's closest approach to the centre.
        let oc = o - self.centre;
        let dd = dir.length_squared();
        let along = oc.dot(dir);
        let closest2 = oc.length_squared() - along * along / dd;
        if closest2 > self.radius2 {
            return None;
        }
        let Bounds { lo, hi, outside } = self.bounds_of(o, dir);
        let t_in = lo.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        let t_out = hi.iter().copied().fold(f32::INFINITY, f32::min);
        if outside.iter().any(|&x| x) || !(t_in <= t_out) {
            return None;
        }
        let (t, leaving) = first_of_interval(t_in, t_out, t_max)?;
        // Pass 2, for hits only: the plane that set the bound (the same arithmetic gives the
        // same quotient; tracking indices in pass 1 keeps the compiler from vectorising it). Only
        // the lanes holding the bound can hold that plane: the first of their planes in storage
        // order whose quotient is the bound (the plane a scan of all planes would find first).
        let bound = if leaving { &hi } else { &lo };
        let i = (0..LANES)
            .filter(|&l| bound[l] == t)
            .filter_map(|l| {
                (l..self.d.len()).step_by(LANES).find(|&i| {
                    let den = self.nx[i] * dir.x + self.ny[i] * dir.y + self.nz[i] * dir.z;
                    let num = self.d[i] - (self.nx[i] * o.x + self.ny[i] * o.y + self.nz[i] * o.z);
                    (if leaving { den > 0.0 } else { den < 0.0 }) && num / den == t
                })
            })
            .min()
            .unwrap_or(0);
        let ng = Vec3::new(self.nx[i], self.ny[i], self.nz[i]);
        // The point moved onto the facet's plane (it is on it to within rounding already).
        let p = ray.at(t);
        let p = p - ng * (ng.dot(p) - self.d[i]);
        Some(ShapeHit {
            t,
            ng,
            ns: ng,
            p,
            facet: Some(self.facet[i]),
        })
    }

    /// Pass 1 of [`Polytope::intersect`], branch-free over `LANES` planes at a time, compiled for
    /// the widest instruction set this machine has (AVX-512, AVX2 or the x86-64 baseline, chosen
    /// at run time by `pulp`; the same IEEE operations, so the same bits on every machine) and
    /// kept out of line, where it stays vectorised whatever pass 2 does with the lanes: per lane
    /// the interval's bounds and whether the ray runs outside a parallel plane.
    #[inline(never)]
    fn bounds_of(&self, o: Vec3, dir: Vec3) -> Bounds {
        struct Scan<'a> {
            planes: &'a Polytope,
            o: Vec3,
            dir: Vec3,
        }
        impl pulp::WithSimd for Scan<'_> {
            type Output = Bounds;
            #[inline(always)]
            fn with_simd<S: pulp::Simd>(self, _: S) -> Bounds {
                self.planes.scan(self.o, self.dir)
            }
        }
        self.arch.dispatch(Scan {
            planes: self,
            o,
            dir,
        })
    }

    /// [`Polytope::bounds_of`]'s loop (the compiler keeps the lanes in SIMD registers).
    #[inline(always)]
    fn scan(&self, o: Vec3, dir: Vec3) -> Bounds {
        let (mut lo, mut hi) = ([f32::NEG_INFINITY; LANES], [f32::INFINITY; LANES]);
        let mut outside = [false; LANES];
        let chunks = self
            .nx
            .chunks_exact(LANES)
            .zip(self.ny.chunks_exact(LANES))
            .zip(self.nz.chunks_exact(LANES))
            .zip(self.d.chunks_exact(LANES));
        for (((nx, ny), nz), d) in chunks {
            for l in 0..LANES {
                let den = nx[l] * dir.x + ny[l] * dir.y + nz[l] * dir.z;
                let num = d[l] - (nx[l] * o.x + ny[l] * o.y + nz[l] * o.z);
                let t = num / den;
                lo[l] = if den < 0.0 { lo[l].max(t) } else { lo[l] };
                hi[l] = if den > 0.0 { hi[l].min(t) } else { hi[l] };
                outside[l] |= den == 0.0 && num < 0.0;
            }
        }
        Bounds { lo, hi, outside }
    }

    /// Object-space bounds `(min, max)`.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.bounds
    }

    /// The faces, vertices and volume of the solid.
    pub fn hull(&self) -> &Hull {
        &self.hull
    }

    /// Number of planes that bound the solid.
    pub fn planes(&self) -> usize {
        self.facet.len()
    }
}

/// Per lane of [`Polytope::bounds_of`]: the latest entry and earliest exit, and whether the ray
/// runs outside a plane parallel to it.
struct Bounds {
    lo: [f32; LANES],
    hi: [f32; LANES],
    outside: [bool; LANES],
}

impl From<HullError> for GeometryError {
    fn from(e: HullError) -> GeometryError {
        GeometryError::Degenerate {
            shape: "faceted stone",
            detail: e.to_string(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::slab::Slab;
    use crate::geometry::solid::test_util::random_ray;
    use crate::sampler::Rng;
    use glam::DVec3;

    /// The box `[−1, 1] × [0, 1] × [−1.5, 1.5]` as six half-spaces (the slab of size (2, 1, 3)).
    fn box_planes() -> Vec<FacetPlane> {
        let (lo, hi) = (DVec3::new(-1.0, 0.0, -1.5), DVec3::new(1.0, 1.0, 1.5));
        let mut v = vec![];
        for a in 0..3 {
            let mut n = DVec3::ZERO;
            n[a] = 1.0;
            v.push(FacetPlane::with_normal(n, hi, 2 * a as u32).unwrap());
            v.push(FacetPlane::with_normal(-n, lo, 2 * a as u32 + 1).unwrap());
        }
        v
    }

    /// A cube of half-planes hits exactly where the slab does, with the same normals (away from
    /// edges, where the two may name different faces).
    #[test]
    fn a_box_of_planes_is_the_slab() {
        let poly = Polytope::new(&box_planes(), "box").unwrap();
        let slab = Slab::new(Vec3::new(2.0, 1.0, 3.0)).unwrap();
        let mut rng = Rng::new(5);
        let mut hits = 0;
        for _ in 0..100_000 {
            let ray = random_ray(&mut rng, 3.0);
            let (a, b) = (poly.intersect(&ray, 1e9), slab.intersect(&ray, 1e9));
            match (a, b) {
                (Some(a), Some(b)) => {
                    hits += 1;
                    assert!(
                        (a.t - b.t).abs() <= 1e-5 * a.t.max(1.0),
                        "{ray:?} {a:?} {b:?}"
                    );
                    assert!((a.p - b.p).length() < 1e-4);
                    let edge = {
                        let q = (a.p - Vec3::new(0.0, 0.5, 0.0)) / Vec3::new(1.0, 0.5, 1.5);
                        let mut m = q.abs().to_array();
                        m.sort_by(f32::total_cmp);
                        m[2] - m[1] < 1e-3
                    };
                    assert!(edge || a.ng == b.ng, "{ray:?} {a:?} {b:?}");
                    assert!(a.facet.is_some());
                }
                (None, None) => {}
                (a, b) => panic!("{ray:?}: polytope {a:?}, slab {b:?}"),
            }
        }
        assert!(hits > 40_000, "{hits}");
        assert_eq!(poly.planes(), 6);
        assert!((poly.hull().volume() - 6.0).abs() < 1e-9);
    }

    /// Rays aimed at points of every edge and vertex of an irregular polytope, from outside and
    /// into the solid's interior beyond that point: every one hits, at the aimed point.
    #[test]
    fn rays_at_edges_and_vertices_never_slip_through() {
        let mut planes = box_planes();
        // Cut corners and edges at odd angles, so three or more facets meet at vertices.
        let cuts = [
            (DVec3::new(1.0, 1.0, 1.0), DVec3::new(0.7, 1.0, 1.5)),
            (DVec3::new(-1.0, 2.0, 0.3), DVec3::new(-1.0, 0.8, 0.0)),
            (DVec3::new(0.2, -1.0, -1.0), DVec3::new(0.0, 0.0, -1.2)),
            (DVec3::new(1.0, 0.3, -1.0), DVec3::new(1.0, 0.5, -1.1)),
        ];
        for (k, (n, p)) in cuts.iter().enumerate() {
            planes.push(FacetPlane::with_normal(*n, *p, 6 + k as u32).unwrap());
        }
        let poly = Polytope::new(&planes, "test").unwrap();
        let hull = poly.hull();
        let inside = hull.vertices().iter().sum::<DVec3>() / hull.vertices().len() as f64;
        let mut rng = Rng::new(11);
        let mut targets: Vec<DVec3> = hull.vertices();
        for (a, b) in hull.edges() {
            for _ in 0..200 {
                targets.push(a + (b - a) * f64::from(rng.uniform()));
            }
        }
        let mut count = 0;
        for &x in &targets {
            for _ in 0..50 {
                // From a random point outside, through `x`, toward a point inside: the ray's
                // continuation after `x` runs through the interior.
                let toward = inside
                    + (DVec3::new(
                        f64::from(rng.uniform()),
                        f64::from(rng.uniform()),
                        f64::from(rng.uniform()),
                    ) - 0.5)
                        * 0.2;
                let dir = (toward - x).normalize();
                let origin = x - dir * (4.0 + 2.0 * f64::from(rng.uniform()));
                let ray = Ray::new(origin.as_vec3(), dir.as_vec3());
                let h = poly.intersect(&ray, f32::INFINITY);
                let h = h.unwrap_or_else(|| panic!("the ray at {x} slipped through"));
                assert!((h.p.as_dvec3() - x).length() < 1e-4, "{x}: {h:?}");
                count += 1;
            }
        }
        assert!(count > 10_000, "{count}");
    }

    /// Pass 1 dispatched to the machine's widest instruction set gives the baseline build's bits,
    /// and pass 2's lane search names the plane a scan of every plane in storage order finds
    /// (the first whose quotient is the bound), on a solid of 26 planes (four groups of eight)
    /// for 20 000 random rays, many of them hits.
    #[test]
    fn dispatched_bounds_and_the_lane_search_match_the_full_scan() {
        let mut planes = box_planes();
        let mut rng = Rng::new(29);
        for k in 0..20 {
            let n = DVec3::new(
                f64::from(rng.uniform()) - 0.5,
                f64::from(rng.uniform()) - 0.5,
                f64::from(rng.uniform()) - 0.5,
            );
            let p = n.normalize() * 0.9;
            planes.push(FacetPlane::with_normal(n, p, 6 + k).unwrap());
        }
        let poly = Polytope::new(&planes, "test").unwrap();
        assert!(poly.planes() > 16, "{}", poly.planes());
        let mut hits = 0;
        for _ in 0..20_000 {
            let ray = random_ray(&mut rng, 3.0);
            let (o, dir) = (ray.origin, ray.dir);
            let (a, b) = (poly.bounds_of(o, dir), poly.scan(o, dir));
            let bits = |x: &[f32; LANES]| x.map(f32::to_bits);
            assert_eq!(bits(&a.lo), bits(&b.lo));
            assert_eq!(bits(&a.hi), bits(&b.hi));
            assert_eq!(a.outside, b.outside);
            let Some(h) = poly.intersect(&ray, f32::INFINITY) else {
                continue;
            };
            hits += 1;
            let leaving = h.ng.dot(dir) > 0.0;
            let first = (0..poly.d.len())
                .find(|&i| {
                    let den = poly.nx[i] * dir.x + poly.ny[i] * dir.y + poly.nz[i] * dir.z;
                    let num = poly.d[i] - (poly.nx[i] * o.x + poly.ny[i] * o.y + poly.nz[i] * o.z);
                    (if leaving { den > 0.0 } else { den < 0.0 }) && num / den == h.t
                })
                .unwrap();
            assert_eq!(h.facet, Some(poly.facet[first]), "{ray:?}");
        }
        assert!(hits > 2_000, "{hits}");
    }

    /// Rays through the box's edges and corners, where two or three planes give the same
    /// quotient: the hit names the first of them in storage order, as a scan of every plane does.
    #[test]
    fn ties_name_the_first_plane_in_storage_order() {
        let poly = Polytope::new(&box_planes(), "box").unwrap();
        let mut ties = 0;
        for corner in [
            (1.0, 1.0, 1.5),
            (-1.0, 0.0, -1.5),
            (1.0, 0.0, -1.5),
            (-1.0, 1.0, 1.5),
        ] {
            let c = Vec3::new(corner.0, corner.1, corner.2);
            let centre = Vec3::new(0.0, 0.5, 0.0);
            // Toward the corner and toward the middles of the three edges at it.
            let mut aims = vec![c];
            for a in 0..3 {
                let mut m = c;
                m[a] = centre[a];
                aims.push(m);
            }
            for aim in aims {
                for (o, dir) in [(aim + (aim - centre), centre - aim), (centre, aim - centre)] {
                    let Some(h) = poly.intersect(&Ray::new(o, dir), f32::INFINITY) else {
                        continue;
                    };
                    let leaving = h.ng.dot(dir) > 0.0;
                    let q = |i: usize| {
                        let den = poly.nx[i] * dir.x + poly.ny[i] * dir.y + poly.nz[i] * dir.z;
                        let num =
                            poly.d[i] - (poly.nx[i] * o.x + poly.ny[i] * o.y + poly.nz[i] * o.z);
                        ((if leaving { den > 0.0 } else { den < 0.0 }) && num / den == h.t)
                            .then_some(i)
                    };
                    let on: Vec<usize> = (0..poly.d.len()).filter_map(q).collect();
                    ties += usize::from(on.len() > 1);
                    assert_eq!(h.facet, Some(poly.facet[on[0]]), "{o} {dir}: {on:?}");
                }
            }
        }
        assert!(ties >= 8, "{ties}");
    }

    #[test]
    fn degenerate_sets_are_errors() {
        let open: Vec<_> = box_planes().into_iter().take(5).collect();
        assert!(Polytope::new(&open, "open").is_err());
        let mut empty = box_planes();
        empty.push(FacetPlane::with_normal(DVec3::NEG_Y, DVec3::new(0.0, 2.0, 0.0), 9).unwrap());
        let e = Polytope::new(&empty, "empty").unwrap_err().to_string();
        assert!(e.contains("no volume"), "{e}");
    }
}
