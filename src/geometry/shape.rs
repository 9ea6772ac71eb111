//! The plain description of the stone's shape in object space (what a [`super::Solid`] is built
//! from; the runtime stage re-exports it as `scene::stage::Shape`).

use glam::Vec3;
use std::path::PathBuf;

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
    /// A triangle mesh to be loaded from an OBJ file.
    Mesh {
        /// Resolved path of the file.
        path: PathBuf,
        /// Uniform scale of its coordinates.
        scale: f32,
    },
}
