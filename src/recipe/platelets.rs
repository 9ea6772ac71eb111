//! Serde description of a body's platelet populations (issue 18): metal inclusions suspended in a
//! translucent stone. Compiled into [`crate::platelet::Population`]s.
//!
//! ```ron
//! body: (
//!     ior: 1.52,
//!     platelets: [(
//!         density: 400.0,                 // platelets per cubic object unit, 0 <.. 1e7
//!         radius: (0.01, 0.03),           // smallest and largest radius, object units
//!         orientation: Uniform,           // or Aligned(axis: (0.0, 1.0, 0.0), spread: 5.0)
//!         entries: [(1.0, "copper_flake"), (0.5, "copper_rough")],  // weights and materials
//!         seed: 3,                        // optional (default: from the recipe seed)
//!         modulation: Remap(field: Perlin(scale: 0.5), from: (-0.5, 0.5), to: (0.0, 1.0)),
//!                                         // optional: density × field, clamped to 0 ..= 1
//!     )],
//! )
//! ```
//!
//! A platelet's faces are the named layered materials, evaluated under the body's IOR (their
//! outside medium is the stone: metal in glass reflects with the relative index `(n + ik)/n_host`).
//!
//! `modulation` is a field of the kind a map's `Switch` compares (`Perlin`, `Turbulence`,
//! `Marble`, `Constant`, `Sum`, `Product`, `Remap`; see [`super::surface::FieldDesc`]) over
//! object space; its value, clamped to `0 ..= 1`, multiplies `density` at each point
//! ([`crate::platelet::modulation`]). Its numbers are range-checked as a Switch's are; a field that
//! cannot exceed 0 anywhere (an empty population) is an error.

use super::ranged::refuse;
use super::surface::FieldDesc;
use serde::{Deserialize, Deserializer, Serialize};

/// Most populations a body may hold.
pub const MAX_POPULATIONS: usize = 8;
/// Most entries one population may list.
pub const MAX_ENTRIES: usize = 64;

ranged!(density_range, "platelets.density", open 0.0, 1e7);
ranged!(spread_range, "spread", 0.0, 90.0);
ranged!(weight_range, "entry weight", open 0.0, 1e6);

fn radius_range<'de, D: Deserializer<'de>>(d: D) -> Result<(f32, f32), D::Error> {
    let v = <(f32, f32)>::deserialize(d)?;
    if v.0 > 0.0 && v.1 >= v.0 && v.1 <= 1e3 && v.0.is_finite() && v.1.is_finite() {
        Ok(v)
    } else {
        // Stand-in: each radius within 0 <.. 1000 (0.01 for one at or below 0), in order.
        let f = |r: f32| {
            if r > 1e3 {
                1e3
            } else if r > 0.0 {
                r
            } else {
                0.01
            }
        };
        let (a, b) = (f(v.0), f(v.1));
        refuse(
            format!(
                "platelets.radius = {v:?}: needs 0 < smallest <= largest <= 1000 (object units)"
            ),
            (a.min(b), a.max(b)),
        )
    }
}

fn entry_list<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<EntryDesc>, D::Error> {
    super::ranged::bounded_list(d, "platelets.entries", MAX_ENTRIES, true)
}

pub(crate) fn population_list<'de, D: Deserializer<'de>>(
    d: D,
) -> Result<Vec<PlateletsDesc>, D::Error> {
    super::ranged::bounded_list(d, "platelets", MAX_POPULATIONS, false)
}

/// One weighted entry: a layered material of the recipe.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EntryDesc(
    #[serde(deserialize_with = "weight_range")] pub f32,
    pub String,
);

/// How the platelets' normals are distributed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum OrientationDesc {
    /// Random: uniform over the sphere (goldstone).
    Uniform,
    /// Parallel to one plane: normals uniform in a cone of half-angle `spread` (degrees,
    /// 0 ..= 90) about `axis` (object space; Oregon sunstone's schiller).
    Aligned {
        /// The common normal.
        #[serde(deserialize_with = "super::surface::axis_check")]
        axis: (f32, f32, f32),
        /// Half-angle of the cone, degrees.
        #[serde(default, deserialize_with = "spread_range")]
        spread: f32,
    },
}

/// A platelet population.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlateletsDesc {
    /// Mean platelets per cubic object unit, 0 <.. 1e7.
    #[serde(deserialize_with = "density_range")]
    pub density: f32,
    /// Smallest and largest radius, object units (uniform between them).
    #[serde(deserialize_with = "radius_range")]
    pub radius: (f32, f32),
    /// Normal distribution.
    pub orientation: OrientationDesc,
    /// Weighted materials of the faces (1 ..= 64 entries).
    #[serde(deserialize_with = "entry_list")]
    pub entries: Vec<EntryDesc>,
    /// Seed of the point process (default: derived from the recipe seed and the population's
    /// position).
    #[serde(default, deserialize_with = "super::ranged::seed_range")]
    pub seed: Option<u64>,
    /// Density modulation: a field over object space whose value, clamped to `0 ..= 1`
    /// (dimensionless), multiplies `density` at each point (default: none, uniform density).
    #[serde(default)]
    pub modulation: Option<FieldDesc>,
}
