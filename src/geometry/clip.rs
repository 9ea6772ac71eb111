//! The boundary of a convex polytope given by half-spaces: its faces as polygons, built by
//! clipping a large box by each plane in turn (in `f64`). The intersector ([`super::polytope`])
//! needs only the planes; this gives what the planes alone do not say — which planes bound the
//! solid, each face's outline and area, the vertices, bounds and volume — for `lapidary info`,
//! the cut report, tests aimed at edges and vertices, and OBJ export.

use glam::DVec3;

/// A half-space `normal · x ≤ d` bounding a faceted stone (object space, object units); `facet`
/// is the facet's index in its design (several planes never share one, but a plane may bound
/// nothing: see [`Hull::faces`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FacetPlane {
    /// Unit outward normal.
    pub normal: DVec3,
    /// Distance of the plane from the origin along `normal`.
    pub d: f64,
    /// The facet's index in its design.
    pub facet: u32,
}

impl FacetPlane {
    /// The plane through `a`, `b`, `c` whose outward side is away from `inside` (a point strictly
    /// inside the solid); `None` when the points are collinear or `inside` lies on the plane.
    pub fn through(a: DVec3, b: DVec3, c: DVec3, inside: DVec3, facet: u32) -> Option<FacetPlane> {
        let n = (b - a).cross(c - a).try_normalize()?;
        let d = n.dot(a);
        let side = n.dot(inside) - d;
        if side.abs() < 1e-12 {
            return None;
        }
        let (normal, d) = if side < 0.0 { (n, d) } else { (-n, -d) };
        Some(FacetPlane { normal, d, facet })
    }

    /// The plane with outward normal `normal` (normalised here) through `point`.
    pub fn with_normal(normal: DVec3, point: DVec3, facet: u32) -> Option<FacetPlane> {
        let normal = normal.try_normalize()?;
        Some(FacetPlane {
            normal,
            d: normal.dot(point),
            facet,
        })
    }
}

/// One face of the polytope: a convex polygon, counter-clockwise seen from outside.
#[derive(Clone, Debug, PartialEq)]
pub struct Face {
    /// The plane's index in the list the hull was built from (`None`: a side of the initial box,
    /// which a bounded design never leaves).
    pub plane: Option<usize>,
    /// The polygon's corners.
    pub points: Vec<DVec3>,
}

impl Face {
    /// The polygon's area.
    pub fn area(&self) -> f64 {
        let p = &self.points;
        (1..p.len().saturating_sub(1))
            .map(|i| (p[i] - p[0]).cross(p[i + 1] - p[0]))
            .sum::<DVec3>()
            .length()
            * 0.5
    }
}

/// The faces of a convex polytope.
#[derive(Clone, Debug, PartialEq)]
pub struct Hull {
    /// Its faces (only planes that bound the solid with a positive area).
    pub faces: Vec<Face>,
}

/// Why a set of planes is not a bounded, non-empty solid.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum HullError {
    /// A plane is not finite or its normal is not unit length.
    #[error("plane {0} is not finite or has no direction")]
    BadPlane(usize),
    /// The planes leave nothing.
    #[error("the facets enclose no volume")]
    Empty,
    /// The planes do not close the solid in some direction.
    #[error("the facets do not close the stone (it is open toward {0:?})")]
    Unbounded([f64; 3]),
}

/// Relative tolerance of the clipping: points within `EPS × size` of a plane lie on it.
const EPS: f64 = 1e-10;

impl Hull {
    /// Clips a box of half-size `extent` (larger than the solid) by every plane.
    pub fn new(planes: &[FacetPlane], extent: f64) -> Result<Hull, HullError> {
        for (i, p) in planes.iter().enumerate() {
            if !(p.d.is_finite() && p.normal.is_finite() && (p.normal.length() - 1.0).abs() < 1e-6)
            {
                return Err(HullError::BadPlane(i));
            }
        }
        let e = extent;
        let corner = |i: u32| {
            DVec3::new(
                if i & 1 != 0 { e } else { -e },
                if i & 2 != 0 { e } else { -e },
                if i & 4 != 0 { e } else { -e },
            )
        };
        // The box's six faces, counter-clockwise seen from outside.
        let quads: [[u32; 4]; 6] = [
            [0, 4, 6, 2], // −x
            [1, 3, 7, 5], // +x
            [0, 1, 5, 4], // −y
            [2, 6, 7, 3], // +y
            [0, 2, 3, 1], // −z
            [4, 5, 7, 6], // +z
        ];
        let mut faces: Vec<Face> = quads
            .iter()
            .map(|q| Face {
                plane: None,
                points: q.iter().map(|&i| corner(i)).collect(),
            })
            .collect();
        let eps = EPS * e;
        for (i, p) in planes.iter().enumerate() {
            faces = clip(faces, p, i, eps);
            if faces.len() < 4 {
                return Err(HullError::Empty);
            }
        }
        if let Some(f) = faces.iter().find(|f| f.plane.is_none()) {
            let c: DVec3 = f.points.iter().sum::<DVec3>() / f.points.len() as f64;
            let dir = c.normalize_or_zero();
            return Err(HullError::Unbounded([dir.x, dir.y, dir.z]));
        }
        let hull = Hull { faces };
        if hull.volume() <= 0.0 {
            return Err(HullError::Empty);
        }
        Ok(hull)
    }

    /// The volume (object units³), by the divergence theorem over the faces.
    pub fn volume(&self) -> f64 {
        self.faces
            .iter()
            .map(|f| {
                let p = &f.points;
                (1..p.len().saturating_sub(1))
                    .map(|i| p[0].dot(p[i].cross(p[i + 1])))
                    .sum::<f64>()
            })
            .sum::<f64>()
            / 6.0
    }

    /// The distinct vertices (corners shared by faces appear once, to within the tolerance).
    pub fn vertices(&self) -> Vec<DVec3> {
        let mut out: Vec<DVec3> = vec![];
        let size = self.extent().max(1e-300);
        for p in self.faces.iter().flat_map(|f| &f.points) {
            if !out.iter().any(|q| (*q - *p).length() <= 1e-9 * size) {
                out.push(*p);
            }
        }
        out
    }

    /// Axis-aligned bounds `(min, max)`.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        let pts = self.faces.iter().flat_map(|f| &f.points);
        let lo = pts.clone().fold(DVec3::INFINITY, |a, p| a.min(*p));
        let hi = pts.fold(DVec3::NEG_INFINITY, |a, p| a.max(*p));
        (lo, hi)
    }

    /// The largest coordinate magnitude of any corner.
    fn extent(&self) -> f64 {
        self.faces
            .iter()
            .flat_map(|f| &f.points)
            .map(|p| p.abs().max_element())
            .fold(0.0, f64::max)
    }

    /// The edges, each once, as pairs of points (for tests aimed at edges).
    pub fn edges(&self) -> Vec<(DVec3, DVec3)> {
        let mut out: Vec<(DVec3, DVec3)> = vec![];
        let tol = 1e-9 * self.extent().max(1e-300);
        for f in &self.faces {
            for (k, a) in f.points.iter().enumerate() {
                let b = f.points[(k + 1) % f.points.len()];
                let seen = out.iter().any(|(p, q)| {
                    ((*p - b).length() < tol && (*q - *a).length() < tol)
                        || ((*p - *a).length() < tol && (*q - b).length() < tol)
                });
                if !seen {
                    out.push((*a, b));
                }
            }
        }
        out
    }
}

/// Clips every face by the half-space of plane `p` (number `index`) and closes the cut with a new
/// face on the plane.
fn clip(faces: Vec<Face>, p: &FacetPlane, index: usize, eps: f64) -> Vec<Face> {
    let side = |x: DVec3| p.normal.dot(x) - p.d;
    let mut out = Vec::with_capacity(faces.len() + 1);
    let mut cut: Vec<DVec3> = vec![];
    // A face lying in the plane already (a repeated plane): no new face.
    let mut coincident = false;
    for f in faces {
        let n = f.points.len();
        let s: Vec<f64> = f.points.iter().map(|&x| side(x)).collect();
        coincident |= s.iter().all(|v| v.abs() <= eps);
        if s.iter().all(|&v| v <= eps) {
            // Wholly inside; its points on the plane belong to the cut too.
            cut.extend(
                f.points
                    .iter()
                    .zip(&s)
                    .filter(|(_, v)| v.abs() <= eps)
                    .map(|(x, _)| *x),
            );
            out.push(f);
            continue;
        }
        let mut kept = Vec::with_capacity(n + 1);
        for k in 0..n {
            let (a, b) = (f.points[k], f.points[(k + 1) % n]);
            let (sa, sb) = (s[k], s[(k + 1) % n]);
            if sa <= eps {
                kept.push(a);
                if sa.abs() <= eps {
                    cut.push(a);
                }
            }
            if (sa < -eps && sb > eps) || (sa > eps && sb < -eps) {
                let x = a + (b - a) * (sa / (sa - sb));
                kept.push(x);
                cut.push(x);
            }
        }
        let kept = dedup_ring(kept, eps);
        if kept.len() >= 3 {
            let face = Face {
                plane: f.plane,
                points: kept,
            };
            if face.area() > eps * eps {
                out.push(face);
            }
        }
    }
    // The new face: the cut's points ordered counter-clockwise about the outward normal.
    let mut pts: Vec<DVec3> = vec![];
    for x in cut {
        if !pts.iter().any(|q| (*q - x).length() <= 4.0 * eps) {
            pts.push(x);
        }
    }
    if pts.len() >= 3 && !coincident {
        let c: DVec3 = pts.iter().sum::<DVec3>() / pts.len() as f64;
        let u = p.normal.any_orthonormal_vector();
        let v = p.normal.cross(u);
        pts.sort_by(|a, b| {
            let (da, db) = (*a - c, *b - c);
            let ta = da.dot(v).atan2(da.dot(u));
            let tb = db.dot(v).atan2(db.dot(u));
            ta.total_cmp(&tb)
        });
        let face = Face {
            plane: Some(index),
            points: pts,
        };
        if face.area() > eps * eps {
            out.push(face);
        }
    }
    out
}

/// `ring` without consecutive points closer than `eps` (the last compared with the first).
fn dedup_ring(ring: Vec<DVec3>, eps: f64) -> Vec<DVec3> {
    let mut out: Vec<DVec3> = Vec::with_capacity(ring.len());
    for x in ring {
        if out.last().is_none_or(|l| (*l - x).length() > eps) {
            out.push(x);
        }
    }
    while out.len() > 1 && (out[0] - out[out.len() - 1]).length() <= eps {
        out.pop();
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(h: f64) -> Vec<FacetPlane> {
        let axes = [
            DVec3::X,
            DVec3::NEG_X,
            DVec3::Y,
            DVec3::NEG_Y,
            DVec3::Z,
            DVec3::NEG_Z,
        ];
        axes.iter()
            .enumerate()
            .map(|(i, &n)| FacetPlane {
                normal: n,
                d: h,
                facet: i as u32,
            })
            .collect()
    }

    #[test]
    fn a_cube_and_a_cut_corner() {
        let hull = Hull::new(&cube(1.0), 10.0).unwrap();
        assert_eq!(hull.faces.len(), 6);
        assert!((hull.volume() - 8.0).abs() < 1e-9);
        assert_eq!(hull.vertices().len(), 8);
        assert_eq!(hull.edges().len(), 12);
        for f in &hull.faces {
            assert!((f.area() - 4.0).abs() < 1e-9);
            // Counter-clockwise seen from outside: the polygon's normal is the plane's.
            let p = &f.points;
            let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
            let plane = cube(1.0)[f.plane.unwrap()];
            assert!((n - plane.normal).length() < 1e-9);
        }
        // Cutting one corner: the tetrahedron x + y + z ≥ 2 (volume 1/6) goes.
        let mut planes = cube(1.0);
        planes.push(FacetPlane::with_normal(DVec3::ONE, DVec3::new(1.0, 1.0, 0.0), 6).unwrap());
        let hull = Hull::new(&planes, 10.0).unwrap();
        assert_eq!(hull.faces.len(), 7);
        assert!((hull.volume() - (8.0 - 1.0 / 6.0)).abs() < 1e-9);
        assert_eq!(hull.vertices().len(), 10);
        // Euler: V − E + F = 2.
        assert_eq!(10 - hull.edges().len() as i64 + 7, 2);
    }

    #[test]
    fn redundant_open_and_empty_sets_of_planes() {
        let mut planes = cube(1.0);
        // A plane outside the cube bounds nothing and makes no face; a repeated one neither.
        planes.push(FacetPlane::with_normal(DVec3::X, DVec3::new(2.0, 0.0, 0.0), 6).unwrap());
        planes.push(FacetPlane::with_normal(DVec3::Y, DVec3::new(0.0, 1.0, 0.0), 7).unwrap());
        let hull = Hull::new(&planes, 10.0).unwrap();
        assert_eq!(hull.faces.len(), 6);
        assert!(
            hull.faces
                .iter()
                .all(|f| f.plane != Some(6) && f.plane != Some(7))
        );
        // Without its −y side the cube is open downward.
        let open: Vec<_> = cube(1.0).into_iter().filter(|p| p.facet != 3).collect();
        match Hull::new(&open, 10.0) {
            Err(HullError::Unbounded(d)) => assert!(d[1] < -0.9, "{d:?}"),
            other => panic!("{other:?}"),
        }
        // Two opposite half-spaces that do not overlap.
        let mut empty = cube(1.0);
        empty.push(FacetPlane::with_normal(DVec3::NEG_X, DVec3::new(1.5, 0.0, 0.0), 6).unwrap());
        assert_eq!(Hull::new(&empty, 10.0).unwrap_err(), HullError::Empty);
        let mut bad = cube(1.0);
        bad[2].d = f64::NAN;
        assert_eq!(Hull::new(&bad, 10.0).unwrap_err(), HullError::BadPlane(2));
    }

    #[test]
    fn through_three_points_faces_away_from_the_inside() {
        let p = FacetPlane::through(
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::ZERO,
            0,
        )
        .unwrap();
        assert!((p.normal - DVec3::ONE.normalize()).length() < 1e-12);
        assert!((p.d - 1.0 / 3f64.sqrt()).abs() < 1e-12);
        assert!(
            FacetPlane::through(DVec3::X, 2.0 * DVec3::X, 3.0 * DVec3::X, DVec3::Y, 0).is_none()
        );
    }
}
