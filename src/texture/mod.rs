//! Procedural solid textures over object-space positions (course §5.2.1; DESIGN §4).
//!
//! Today: the cellular basis ([`voronoi`]). Fields (Perlin, fBm, marble) and the map tree that picks
//! a layered material per cell build on it.

pub mod voronoi;

pub use voronoi::{Voronoi, VoronoiSample};
