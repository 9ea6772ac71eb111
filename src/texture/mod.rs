//! Procedural solid textures over object-space positions (course §5.2.1; docs/design.md §6).
//!
//! - [`voronoi`]: the exact, seedable cellular basis (F1, F2, edge distance, 64-bit cell ids).
//! - [`perlin`](mod@perlin): hashed-lattice gradient noise, fBm and turbulence.
//! - [`field`]: scalar fields (Perlin, turbulence, marble, sums, products, remaps) in a flat table.
//! - [`bump`]: the crystal-facet bump map (tilt distributions, the rule for facets seen from behind).
//! - [`simplify`]: the same tree with the glitter overlay, switch bands or facet bump left out.
//! - [`explain`]: a lookup that records why it chose its material (the pixel inspector).
//! - [`map`]: the runtime map tree — Voronoi surface and glitter maps, overlays, switches, material
//!   leaves — and its allocation-free lookup.
//!
//! Everything here is a pure function of the position, the seeds and (for stochastic switch bands)
//! one random number, and every type is `Send + Sync`: lookups agree bit for bit on any thread.

pub mod bump;
pub mod explain;
pub mod field;
#[cfg(test)]
pub(crate) mod fixtures;
pub mod map;
pub mod perlin;
pub mod simplify;
pub mod voronoi;

/// The instruction set the texture kernels (the Voronoi block, the octave lanes) are compiled for,
/// detected once.
pub(crate) static SIMD: std::sync::LazyLock<pulp::Arch> = std::sync::LazyLock::new(pulp::Arch::new);

pub use bump::{FacetBump, Tilt};
pub use explain::{MapDecision, MapExplanation, MapStep};
pub use field::{FieldId, FieldNode, FieldTable};
pub use map::{CellTrail, Entry, Map, MapError, MapHit, MapNode, NodeId, Stop, VoronoiNode};
pub use perlin::{Octaves, perlin};
pub use simplify::MapEffects;
pub use voronoi::{Voronoi, VoronoiNearest, VoronoiSample};
