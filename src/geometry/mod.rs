//! Geometry shared by the maps and the renderer: orthonormal shading frames.
//!
//! Directions follow the conventions of [`crate::bsdf`]: a frame's `n` is the local `z`, and a
//! vector in local coordinates has `z = cos θ` to the normal.

pub mod frame;

pub use frame::Frame;
