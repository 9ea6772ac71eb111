//! What every shape shares: the hit record, the errors building a shape can raise, and the
//! checks and helpers of the intersection routines.

use super::ray::Ray;
use glam::Vec3;
use std::path::PathBuf;

/// A ray/shape intersection, everything in the shape's object space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeHit {
    /// Ray parameter of the hit, in units of the ray's direction (a distance if it is unit length).
    pub t: f32,
    /// Unit geometric normal, pointing out of the solid (for meshes: given by the triangle's
    /// counter-clockwise winding, which an open or inconsistently wound OBJ may get wrong; the
    /// renderer faces it toward the incoming ray where it needs to).
    pub ng: Vec3,
    /// Unit shading normal: equal to `ng` for analytic shapes; for meshes with vertex normals the
    /// interpolated normal, flipped into `ng`'s hemisphere.
    pub ns: Vec3,
    /// The hit point, object space. Projected back onto the analytic surface (or computed from the
    /// barycentric coordinates of the triangle), so it lies on the surface to within rounding,
    /// slightly more accurately than `ray.at(t)`.
    pub p: Vec3,
    /// The facet of a faceted stone (its index in the design); `None` for the other shapes.
    pub facet: Option<u32>,
}

/// Why a shape cannot be built.
#[derive(thiserror::Error, Debug)]
pub enum GeometryError {
    /// The OBJ file could not be read (missing, unreadable, …).
    #[error("cannot read OBJ file `{}`: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The OBJ file is not valid OBJ.
    #[error("cannot parse OBJ file `{}`: {message}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// What the parser reported.
        message: String,
    },
    /// The OBJ file holds no non-degenerate triangle.
    #[error("OBJ file `{}` has no (non-degenerate) triangles", path.display())]
    NoTriangles {
        /// The file.
        path: PathBuf,
    },
    /// The OBJ file has NaN or infinite coordinates (possibly after scaling).
    #[error("OBJ file `{}` has non-finite vertex coordinates (after scaling by {scale})", path.display())]
    NonFinite {
        /// The file.
        path: PathBuf,
        /// The scale applied.
        scale: f32,
    },
    /// A size parameter is zero, negative or not finite.
    #[error("degenerate {shape}: {detail}")]
    Degenerate {
        /// Which shape.
        shape: &'static str,
        /// What is wrong.
        detail: String,
    },
    /// The object-to-world transform is not finite or not invertible.
    #[error("the stone's placement is not a finite invertible affine transform")]
    Transform,
}

/// Whether a ray and a `t_max` can be intersected at all: finite origin and direction, non-zero
/// direction and `t_max > 0` (infinite allowed, NaN not).
#[inline]
pub(crate) fn valid_query(ray: &Ray, t_max: f32) -> bool {
    // `x · 0` is ±0 for a finite `x` and NaN for an infinite or NaN one, and the NaN survives
    // the sum: one test for all six components.
    let z = ray.origin * 0.0 + ray.dir * 0.0;
    z.x + z.y + z.z == 0.0 && ray.dir != Vec3::ZERO && t_max > 0.0
}

/// [`valid_query`] for a ray whose origin is known to be finite: a finite, non-zero `dir` and
/// `t_max > 0`.
#[inline]
pub(crate) fn valid_direction(dir: Vec3, t_max: f32) -> bool {
    let z = dir * 0.0;
    z.x + z.y + z.z == 0.0 && dir != Vec3::ZERO && t_max > 0.0
}

/// The first parameter of a ray/convex-solid interval `[t_in, t_out]` inside `(0, t_max)`, with
/// `false` for the entry and `true` for the exit (a ray starting inside leaves through the exit).
#[inline]
pub(crate) fn first_of_interval(t_in: f32, t_out: f32, t_max: f32) -> Option<(f32, bool)> {
    if t_in > 0.0 {
        (t_in < t_max).then_some((t_in, false))
    } else if t_out > 0.0 && t_out < t_max {
        Some((t_out, true))
    } else {
        None
    }
}
