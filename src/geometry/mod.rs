//! Geometry: rays, the stone's shapes and their intersection, shading frames.
//!
//! Directions follow the conventions of [`crate::bsdf`]: a frame's `n` is the local `z`, and a
//! vector in local coordinates has `z = cos θ` to the normal.

pub mod frame;
pub mod ray;

pub use frame::Frame;
pub use ray::{Ray, offset_origin};
