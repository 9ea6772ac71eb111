//! The cabochon placed in the world ([`PlacedCabochon`]): the work of the stone's intersection
//! that depends only on the placement, done once per stone (the rays from one origin that use
//! it are [`super::fan`]'s).
//!
//! A cabochon's ellipsoids are met in their normalised frames, where each is the unit sphere. The
//! placement and the scaling to the upper dome's frame fold into one affine map from world space
//! (so a world ray reaches the frame in one transform instead of two), and the map from a
//! unit-sphere point to the world normal into one matrix.

use super::cabochon::Cabochon;
use super::solid::Solid;
use glam::{Affine3A, Mat3A, Vec3};

/// A cabochon placed in the world (module docs).
#[derive(Clone, Debug)]
pub(crate) struct PlacedCabochon {
    /// The shape, object space.
    pub(crate) shape: Cabochon,
    /// World space to the upper dome's normalised frame: `diag(1/axes) · to_object`.
    pub(crate) to_frame: Affine3A,
    /// A unit-sphere point of the upper frame to a world normal (not unit):
    /// `normal_to_world · diag(1/axes)`, the object gradient carried to the world.
    pub(crate) upper_normal: Mat3A,
    /// The same for the lower dome (unused for a flat base).
    pub(crate) lower_normal: Mat3A,
    /// The flat base's unit world normal.
    pub(crate) base_normal: Vec3,
    /// The upper dome's normal field differentiated along the world: `upper_normal · L`, with
    /// `L` the linear part of `to_frame`. At a hit whose unnormalised normal is `g`, the unit
    /// normal changes by `(I − n nᵀ) · upper_shape · δx / |g|` for a displacement `δx` along the
    /// surface (the shape operator; [`super::Fan::intersect_curved`]).
    pub(crate) upper_shape: Mat3A,
    /// The same for the lower dome: `lower_normal · diag(1, h/base, 1) · L` (zero for a flat
    /// base).
    pub(crate) lower_shape: Mat3A,
}

impl PlacedCabochon {
    /// The cabochon placed by `to_object` (world → object) with normals carried by
    /// `normal_to_world` (the inverse transpose of the object → world linear map).
    pub(crate) fn new(shape: Cabochon, to_object: Affine3A, normal_to_world: Mat3A) -> Self {
        let (inv_upper, inv_lower) = shape.inv_axes();
        let scale = Mat3A::from_diagonal;
        let to_frame = Affine3A::from_scale(inv_upper) * to_object;
        let lower_normal = if shape.flat_base() {
            Mat3A::ZERO
        } else {
            normal_to_world * scale(inv_lower)
        };
        let upper_normal = normal_to_world * scale(inv_upper);
        let lower_shape =
            lower_normal * scale(Vec3::new(1.0, shape.lower_y(), 1.0)) * to_frame.matrix3;
        PlacedCabochon {
            shape,
            to_frame,
            upper_normal,
            lower_normal,
            base_normal: (normal_to_world * Vec3::NEG_Y).normalize_or_zero(),
            upper_shape: upper_normal * to_frame.matrix3,
            lower_shape,
        }
    }
}

/// Whether `solid` is met through a [`PlacedCabochon`].
pub(crate) fn placed(solid: &Solid, to_object: Affine3A, nw: Mat3A) -> Option<PlacedCabochon> {
    match solid {
        Solid::Cabochon(c) => Some(PlacedCabochon::new(*c, to_object, nw)),
        _ => None,
    }
}
