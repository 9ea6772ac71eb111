//! Serde description of the stone's shape (`stage.shape`): the analytic shapes, a mesh, a
//! parametric cut or a GemCad design, each size range-checked as it is read.

use super::ranged::{positive2, refuse, sizes_ok};
use serde::{Deserialize, Deserializer, Serialize};

/// Three coordinates as a recipe writes them.
type V3 = (f32, f32, f32);

ranged!(length_range, "length", open 0.0, 1e4);
ranged!(factor_range, "scale", open 0.0, 1e4);

fn one() -> f32 {
    1.0
}

fn two() -> f32 {
    2.0
}

/// The stone's shape, in object space: a cabochon and a slab rest on the plane y = 0, centred on
/// the y axis; a sphere is centred at the origin (lift it with `transform`); a mesh keeps its file's
/// coordinates.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum ShapeDesc {
    /// A sphere centred at the origin.
    Sphere {
        /// Radius, 0 <.. 1e4.
        #[serde(deserialize_with = "length_range")]
        radius: f32,
    },
    /// An elliptical dome (half-ellipsoid of semi-axes `radius.0`, `height`, `radius.1` along x, y,
    /// z) over a flat base (`base = 0`) or a shallower dome below (depth `base`).
    Cabochon {
        /// Semi-axes of the outline along x and z.
        #[serde(deserialize_with = "positive2")]
        radius: (f32, f32),
        /// Dome height above the girdle.
        #[serde(deserialize_with = "length_range")]
        height: f32,
        /// Depth of the lower dome; 0 (default) is a flat base.
        #[serde(default, deserialize_with = "base_range")]
        base: f32,
    },
    /// A polished plate (a box) for swatches: full sizes along x, y, z, centred above the origin.
    Slab {
        /// Full sizes.
        #[serde(deserialize_with = "positive3")]
        size: V3,
    },
    /// A faceted stone of a parametric cut (`recipe::cut`).
    Cut(super::cut::CutDesc),
    /// A faceted stone from a GemCad `.asc` design (relative to the recipe), scaled to a girdle
    /// width (the smaller of its extents along x and z).
    Design {
        /// The `.asc` file.
        file: String,
        /// Girdle width in object units, 0 <.. 1e4 (default 2).
        #[serde(default = "two", deserialize_with = "length_range")]
        width: f32,
    },
    /// A triangle mesh from a Wavefront OBJ file (relative to the recipe).
    Mesh {
        /// The OBJ file.
        file: String,
        /// Uniform scale applied to the file's coordinates, 0 <.. 1e4 (default 1).
        #[serde(default = "one", deserialize_with = "factor_range")]
        scale: f32,
    },
}

fn positive3<'de, D: Deserializer<'de>>(d: D) -> Result<V3, D::Error> {
    let v = V3::deserialize(d)?;
    let mut s = [v.0, v.1, v.2];
    sizes_ok(&mut s, v).map(|()| (s[0], s[1], s[2]))
}

fn base_range<'de, D: Deserializer<'de>>(d: D) -> Result<f32, D::Error> {
    let v = f32::deserialize(d)?;
    if (0.0..=1e4).contains(&v) {
        Ok(v)
    } else {
        refuse(
            format!("base = {v} is out of range: allowed 0 ..= 1e4 (0: a flat base)"),
            if v > 1e4 { 1e4 } else { 0.0 },
        )
    }
}
