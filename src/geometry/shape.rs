//! The plain description of the stone's shape in object space (what a [`super::Solid`] is built
//! from; the runtime stage re-exports it as `scene::stage::Shape`).

use super::clip::{FacetPlane, Hull, HullError};
use glam::{DVec3, Vec3};
use std::path::PathBuf;
use std::sync::Arc;

/// The stone's shape in object space.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// A sphere of `radius` centred at the origin.
    Sphere {
        /// Radius.
        radius: f32,
    },
    /// Half-ellipsoid dome of semi-axes (`radius.0`, `height`, `radius.1`) above y = 0 over a flat
    /// base (`base = 0`) or a lower half-ellipsoid of depth `base`.
    Cabochon {
        /// Semi-axes along x and z.
        radius: (f32, f32),
        /// Dome height.
        height: f32,
        /// Lower dome depth (0: flat).
        base: f32,
    },
    /// A box of full sizes `size`, centred on the y axis, resting on y = 0.
    Slab {
        /// Full sizes along x, y, z.
        size: Vec3,
    },
    /// A faceted stone: the intersection of half-spaces (a parametric cut or a GemCad design).
    Faceted(Arc<Facets>),
    /// A triangle mesh to be loaded from an OBJ file.
    Mesh {
        /// Resolved path of the file.
        path: PathBuf,
        /// Uniform scale of its coordinates.
        scale: f32,
    },
}

/// A faceted stone's description: its half-spaces, the names of its facets (by facet index) and
/// the corners of the solid they bound (for bounds and support queries before the solid is
/// built).
#[derive(Clone, Debug, PartialEq)]
pub struct Facets {
    /// The half-spaces, object space.
    pub planes: Vec<FacetPlane>,
    /// Facet names by facet index (`"pavilion main 3"`).
    pub names: Vec<String>,
    /// What the design is (`"round brilliant"`, `"GemCad design cut.asc"`).
    pub label: String,
    /// The solid's corners.
    pub vertices: Vec<DVec3>,
    /// The planes (indices into `planes`) that bound a face of positive area.
    pub bounding: Vec<usize>,
    /// The solid's volume, object units³.
    pub volume: f64,
}

impl Facets {
    /// The solid of `planes`, checked to be bounded and non-empty.
    pub fn new(
        planes: Vec<FacetPlane>,
        names: Vec<String>,
        label: String,
    ) -> Result<Facets, HullError> {
        let extent = planes.iter().map(|p| p.d.abs()).fold(1.0f64, f64::max) * 1e3;
        let hull = Hull::new(&planes, extent)?;
        let mut bounding: Vec<usize> = hull.faces.iter().filter_map(|f| f.plane).collect();
        bounding.sort_unstable();
        bounding.dedup();
        Ok(Facets {
            vertices: hull.vertices(),
            volume: hull.volume(),
            bounding,
            planes,
            names,
            label,
        })
    }

    /// The facets (by index) whose planes bound no face: cut away by the others.
    pub fn missing(&self) -> Vec<u32> {
        let mut present: Vec<u32> = self
            .bounding
            .iter()
            .map(|&i| self.planes[i].facet)
            .collect();
        present.sort_unstable();
        (0..self.names.len() as u32)
            .filter(|f| present.binary_search(f).is_err())
            .collect()
    }
}

impl Shape {
    /// The centre of the shape's object-space bounding box; `None` for a mesh (not loaded yet).
    pub fn centre(&self) -> Option<Vec3> {
        match *self {
            Shape::Sphere { .. } => Some(Vec3::ZERO),
            Shape::Cabochon { height, base, .. } => {
                Some(Vec3::new(0.0, 0.5 * (height - base), 0.0))
            }
            Shape::Slab { size } => Some(Vec3::new(0.0, 0.5 * size.y, 0.0)),
            Shape::Faceted(ref f) => {
                let lo = f.vertices.iter().fold(DVec3::INFINITY, |a, v| a.min(*v));
                let hi = f
                    .vertices
                    .iter()
                    .fold(DVec3::NEG_INFINITY, |a, v| a.max(*v));
                Some(((lo + hi) * 0.5).as_vec3())
            }
            Shape::Mesh { .. } => None,
        }
    }

    /// The support function `h(d) = max { d · x : x in the solid }` (object space, any `d`): how
    /// far the solid reaches along `d`. Exact for every analytic shape (each is convex); `None`
    /// for a mesh (not loaded yet).
    ///
    /// A faceted stone reaches farthest at one of its corners.
    ///
    /// A cabochon is the upper half of the ellipsoid with semi-axes `(r₀, height, r₁)` joined at
    /// `y = 0` to the lower half of `(r₀, base, r₁)`: along a `d` with `d_y ≥ 0` the farthest point
    /// of the upper ellipsoid has `y ≥ 0` and lies on the solid, so `h(d) = |diag(r₀, height, r₁) d|`;
    /// along `d_y < 0` the same holds with `base`.
    pub fn support(&self, d: Vec3) -> Option<f32> {
        match *self {
            Shape::Sphere { radius } => Some(radius * d.length()),
            Shape::Cabochon {
                radius,
                height,
                base,
            } => {
                let y = if d.y >= 0.0 { height } else { base };
                Some(Vec3::new(radius.0 * d.x, y * d.y, radius.1 * d.z).length())
            }
            Shape::Slab { size } => {
                Some(0.5 * (d.x.abs() * size.x + d.z.abs() * size.z) + (d.y * size.y).max(0.0))
            }
            Shape::Faceted(ref f) => {
                let d = d.as_dvec3();
                Some(f.vertices.iter().map(|v| v.dot(d)).fold(f64::MIN, f64::max) as f32)
            }
            Shape::Mesh { .. } => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The support function against the largest `d · x` over points spread on each solid's
    /// surface (a brute-force maximum from below, within the sampling's resolution).
    #[test]
    fn support_matches_a_brute_force_maximum() {
        let shapes = [
            Shape::Sphere { radius: 1.3 },
            Shape::Cabochon {
                radius: (1.0, 0.7),
                height: 0.55,
                base: 0.0,
            },
            Shape::Cabochon {
                radius: (0.8, 0.8),
                height: 0.4,
                base: 0.2,
            },
            Shape::Slab {
                size: Vec3::new(2.0, 0.3, 1.0),
            },
        ];
        // Points on each surface: ellipsoid halves by angles, the slab by its corners.
        let points = |s: &Shape| -> Vec<Vec3> {
            let mut v = vec![];
            match *s {
                Shape::Slab { size } => {
                    for k in 0..8 {
                        let b = |i: u32| if k & (1 << i) != 0 { 0.5 } else { -0.5 };
                        v.push(Vec3::new(
                            b(0) * size.x,
                            (b(1) + 0.5) * size.y,
                            b(2) * size.z,
                        ));
                    }
                }
                _ => {
                    let (a, h, b, lo) = match *s {
                        Shape::Sphere { radius } => (radius, radius, radius, radius),
                        Shape::Cabochon {
                            radius,
                            height,
                            base,
                        } => (radius.0, height, radius.1, base),
                        _ => unreachable!(),
                    };
                    for i in 0..=400 {
                        for j in 0..400 {
                            let t = std::f32::consts::PI * i as f32 / 400.0;
                            let p = std::f32::consts::TAU * j as f32 / 400.0;
                            let (st, ct) = t.sin_cos();
                            let y = if ct >= 0.0 { h * ct } else { lo * ct };
                            v.push(Vec3::new(a * st * p.cos(), y, b * st * p.sin()));
                        }
                    }
                }
            }
            v
        };
        for s in &shapes {
            let pts = points(s);
            for k in 0..50 {
                let t = k as f32 * 0.7;
                let d = Vec3::new(t.sin() * 1.5, (t * 1.3).cos(), (t * 0.4).sin() - 0.2);
                let h = s.support(d).unwrap();
                let brute = pts.iter().map(|p| p.dot(d)).fold(f32::MIN, f32::max);
                assert!(brute <= h + 1e-4, "{s:?} {d}: {brute} > {h}");
                assert!(h - brute < 2e-3 * d.length(), "{s:?} {d}: {h} vs {brute}");
            }
        }
        assert_eq!(
            Shape::Mesh {
                path: "m.obj".into(),
                scale: 1.0
            }
            .support(Vec3::Y),
            None
        );
    }
}
