//! Geometry: rays, the stone's shapes and their intersection, shading frames.
//!
//! Directions follow the conventions of [`crate::bsdf`]: a frame's `n` is the local `z`, and a
//! vector in local coordinates has `z = cos θ` to the normal. Shapes live in object space
//! ([`Solid`]); a [`Stone`] places one in the world.

pub mod cabochon;
pub mod clip;
pub mod fan;
pub mod frame;
pub mod hit;
pub mod mesh;
pub mod placed;
pub mod polytope;
pub mod ray;
pub mod shape;
pub mod slab;
pub mod solid;
pub mod sphere;
pub mod stone;

pub use cabochon::Cabochon;
pub use clip::{FacetPlane, Hull};
pub use fan::{Curvature, CurvedHit, Fan};
pub use frame::Frame;
pub use hit::{GeometryError, ShapeHit};
pub use mesh::Mesh;
pub use polytope::Polytope;
pub use ray::{MediumId, Ray, offset_origin};
pub use shape::Shape;
pub use slab::Slab;
pub use solid::Solid;
pub use sphere::Sphere;
pub use stone::{Stone, StoneHit};
