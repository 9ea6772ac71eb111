//! Serde description of a gem's surface: the map tree and its fields (docs/design.md §6), separate from the
//! runtime [`crate::texture::Map`] it compiles into.
//!
//! ```ron
//! surface: Overlay(
//!     under: Switch(
//!         by: Marble(scale: 0.8, turbulence: 1.5, octaves: 5),
//!         stops: [(0.0, Map("tiles")), (0.85, Material("vein"))],
//!         blend: 0.05,
//!     ),
//!     over: Voronoi(
//!         scale: 0.06, fill: 0.03,
//!         entries: [(1.0, Material("glitter_a")), (2.0, Material("glitter_b"))],
//!         bump: Cone(half_angle: 15.0),
//!     ),
//! )
//! ```
//!
//! Every number is range-checked while it is read, so an error points at the number itself
//! (`file:line:col`); the allowed ranges are listed in `docs/recipes.md`.

use super::ranged::{finite, refuse};
use serde::{Deserialize, Deserializer, Serialize};

ranged!(scale_range, "scale", 1e-4, 1e4);
ranged!(jitter_range, "jitter", 0.0, 1.0);
// Stand-in 1 (the default): a nearest value below 1 would make the surface transparent.
ranged!(fill_range, "fill", 0.0, 1.0, else |_| 1.0);
ranged!(gain_range, "gain", 0.0, 1.0);
ranged!(lacunarity_range, "lacunarity", open 1.0, 8.0);
ranged!(turbulence_range, "turbulence", 0.0, 100.0);
ranged!(half_angle_range, "half_angle", 0.0, 89.0);
ranged!(rms_range, "rms", 0.0, 60.0);

fn octaves_range<'de, D: Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    let v = u32::deserialize(d)?;
    if (1..=16).contains(&v) {
        Ok(v)
    } else {
        refuse(
            format!("octaves = {v} is out of range: allowed 1 ..= 16"),
            v.clamp(1, 16),
        )
    }
}

pub(super) fn axis_check<'de, D: Deserializer<'de>>(d: D) -> Result<(f32, f32, f32), D::Error> {
    let v = <(f32, f32, f32)>::deserialize(d)?;
    let len = (v.0 * v.0 + v.1 * v.1 + v.2 * v.2).sqrt();
    if len.is_finite() && len > 1e-6 {
        Ok(v)
    } else {
        refuse(
            format!("axis = {v:?} must be a finite, non-zero direction"),
            x_axis(),
        )
    }
}

fn choices<'de, D, T>(d: D) -> Result<Vec<T>, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    super::ranged::bounded_list(d, "entries", super::ranged::MAX_CHOICES, true)
}

fn stop_list<'de, D, T>(d: D) -> Result<Vec<T>, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    super::ranged::bounded_list(d, "stops", super::ranged::MAX_CHOICES, false)
}

fn inputs<'de, D, T>(d: D) -> Result<Vec<T>, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    super::ranged::bounded_list(d, "inputs", super::ranged::MAX_FIELD_INPUTS, true)
}

fn interval<'de, D: Deserializer<'de>>(d: D) -> Result<(f32, f32), D::Error> {
    let v = <(f32, f32)>::deserialize(d)?;
    if v.0.is_finite() && v.1.is_finite() && v.0 != v.1 {
        Ok(v)
    } else {
        refuse(
            format!("{v:?} must be two finite, different numbers"),
            (0.0, 1.0),
        )
    }
}

fn finite_pair<'de, D: Deserializer<'de>>(d: D) -> Result<(f32, f32), D::Error> {
    let v = <(f32, f32)>::deserialize(d)?;
    if v.0.is_finite() && v.1.is_finite() {
        Ok(v)
    } else {
        refuse(format!("{v:?} must be finite"), (0.0, 1.0))
    }
}

fn one() -> f32 {
    1.0
}
fn half() -> f32 {
    0.5
}
fn two() -> f32 {
    2.0
}
fn one_octave() -> u32 {
    1
}
fn four_octaves() -> u32 {
    4
}
fn x_axis() -> (f32, f32, f32) {
    (1.0, 0.0, 0.0)
}

/// A Voronoi entry's weight: finite and `0 <.. 1e6`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(into = "f32")]
pub struct Weight(pub f32);

impl<'de> Deserialize<'de> for Weight {
    /// Reads the weight; one out of range is refused (stand-in 1; see
    /// [`crate::recipe::source::recover`]).
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        Weight::try_from(f32::deserialize(d)?).or_else(|m| refuse(m, Weight(1.0)))
    }
}

impl TryFrom<f32> for Weight {
    type Error = String;
    fn try_from(v: f32) -> Result<Self, String> {
        if v > 0.0 && v <= 1e6 {
            Ok(Weight(v))
        } else {
            Err(format!(
                "entry weight = {v} is out of range: allowed 0 <.. 1e6"
            ))
        }
    }
}

impl From<Weight> for f32 {
    fn from(w: Weight) -> f32 {
        w.0
    }
}

/// A node of the map tree.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum MapDesc {
    /// A material of the recipe's `materials`, by name.
    Material(String),
    /// The bare boundary of the recipe's translucent `body`: light refracts into the stone.
    Body,
    /// A map of the recipe's `maps`, by name.
    Map(String),
    /// A Voronoi surface or glitter map.
    Voronoi {
        /// Mean cell spacing in object units, 1e-4 ..= 1e4.
        #[serde(deserialize_with = "scale_range")]
        scale: f32,
        /// Feature-point jitter, 0 (cubic grid) ..= 1 (default).
        #[serde(default = "one", deserialize_with = "jitter_range")]
        jitter: f32,
        /// Seed; default: derived from the recipe seed and the node's position in the file.
        #[serde(default, deserialize_with = "super::ranged::seed_range")]
        seed: Option<u64>,
        /// `(weight, node)` pairs (1 ..= 100 000); each filled cell picks one with probability ∝
        /// weight.
        #[serde(deserialize_with = "choices")]
        entries: Vec<(Weight, MapDesc)>,
        /// Fraction of filled cells, 0 ..= 1 (default 1); the rest are transparent.
        #[serde(default = "one", deserialize_with = "fill_range")]
        fill: f32,
        /// Crystal-facet bump of the filled cells.
        #[serde(default)]
        bump: Option<BumpDesc>,
    },
    /// `over` where opaque, `under` where `over` is transparent.
    Overlay {
        /// The map seen through transparent cells.
        under: Box<MapDesc>,
        /// The (usually sparse) map on top.
        over: Box<MapDesc>,
    },
    /// A field picks one of several maps.
    Switch(SwitchDesc),
}

/// Facet tilt distribution of a bump (see [`crate::texture::bump`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum BumpDesc {
    /// Uniform in solid angle inside a cone; `half_angle` in degrees, 0 ..= 89.
    Cone {
        /// Cone half-angle in degrees.
        #[serde(deserialize_with = "half_angle_range")]
        half_angle: f32,
    },
    /// Beckmann normals with RMS slope angle `rms` in degrees, 0 ..= 60.
    Beckmann {
        /// RMS slope angle in degrees.
        #[serde(deserialize_with = "rms_range")]
        rms: f32,
    },
}

/// A switch as written (checked by [`SwitchDesc`]'s conversion).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SwitchRaw {
    /// The field compared with the thresholds.
    pub by: FieldDesc,
    /// `(threshold, node)`, thresholds strictly ascending (at most 100 000).
    #[serde(deserialize_with = "stop_list")]
    pub stops: Vec<(f32, MapDesc)>,
    /// Width of the stochastic band around each threshold (field units), default 0.
    #[serde(default)]
    pub blend: f32,
}

/// A checked switch: at least one stop, finite ascending thresholds, a blend band no wider than
/// the narrowest gap between thresholds.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(into = "SwitchRaw")]
pub struct SwitchDesc(pub SwitchRaw);

impl<'de> Deserialize<'de> for SwitchDesc {
    /// Reads and checks the switch. Empty `stops` stop the parser; bad thresholds or blend are
    /// refused ([`crate::recipe::source::recover`]) with a stand-in: thresholds 0, 1, 2, … and no
    /// blend.
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let mut raw = SwitchRaw::deserialize(d)?;
        match switch_problem(&raw) {
            None => Ok(SwitchDesc(raw)),
            Some(m) if raw.stops.is_empty() => Err(serde::de::Error::custom(m)),
            Some(m) => {
                for (i, (t, _)) in raw.stops.iter_mut().enumerate() {
                    *t = i as f32;
                }
                raw.blend = 0.0;
                refuse(m, SwitchDesc(raw))
            }
        }
    }
}

impl TryFrom<SwitchRaw> for SwitchDesc {
    type Error = String;
    fn try_from(s: SwitchRaw) -> Result<Self, String> {
        match switch_problem(&s) {
            None => Ok(SwitchDesc(s)),
            Some(m) => Err(m),
        }
    }
}

/// What is wrong with a switch, if anything (see [`SwitchDesc`]).
fn switch_problem(s: &SwitchRaw) -> Option<String> {
    if s.stops.is_empty() {
        return Some("Switch: `stops` is empty; give at least one (threshold, node)".into());
    }
    let t: Vec<f32> = s.stops.iter().map(|(t, _)| *t).collect();
    if let Some(i) = t.iter().position(|v| !v.is_finite()) {
        return Some(format!(
            "Switch: stops[{i}] threshold {} is not finite",
            t[i]
        ));
    }
    if let Some(i) = t.windows(2).position(|w| w[0] >= w[1]) {
        return Some(format!(
            "Switch: thresholds must be strictly ascending, but stops[{}] = {} ≥ stops[{}] = {}",
            i,
            t[i],
            i + 1,
            t[i + 1]
        ));
    }
    let gap = t
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold(f32::INFINITY, f32::min);
    if !(s.blend >= 0.0 && s.blend.is_finite() && s.blend <= gap) {
        return Some(if gap.is_finite() {
            format!(
                "Switch: blend = {} is out of range: allowed 0 ..= {gap} (the narrowest gap \
                 between thresholds)",
                s.blend
            )
        } else {
            format!(
                "Switch: blend = {} is out of range: allowed any finite value ≥ 0 (one stop: no \
                 gap between thresholds)",
                s.blend
            )
        });
    }
    None
}

impl From<SwitchDesc> for SwitchRaw {
    fn from(s: SwitchDesc) -> Self {
        s.0
    }
}

/// A scalar field (see [`crate::texture::field`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum FieldDesc {
    /// A constant.
    Constant(#[serde(deserialize_with = "finite")] f32),
    /// fBm of Perlin noise, ≈ −1 … 1.
    Perlin {
        /// Lattice spacing of the first octave, object units, 1e-4 ..= 1e4.
        #[serde(deserialize_with = "scale_range")]
        scale: f32,
        /// Octaves, 1 ..= 16 (default 1: plain Perlin noise).
        #[serde(default = "one_octave", deserialize_with = "octaves_range")]
        octaves: u32,
        /// Amplitude ratio per octave, 0 ..= 1 (default 0.5).
        #[serde(default = "half", deserialize_with = "gain_range")]
        gain: f32,
        /// Frequency ratio per octave, 1 <.. 8 (default 2).
        #[serde(default = "two", deserialize_with = "lacunarity_range")]
        lacunarity: f32,
        /// Seed; default derived like a Voronoi's.
        #[serde(default, deserialize_with = "super::ranged::seed_range")]
        seed: Option<u64>,
    },
    /// Turbulence `Σ gainᵏ |noise|`, 0 … 1.
    Turbulence {
        /// Lattice spacing of the first octave, object units, 1e-4 ..= 1e4.
        #[serde(deserialize_with = "scale_range")]
        scale: f32,
        /// Octaves, 1 ..= 16 (default 4).
        #[serde(default = "four_octaves", deserialize_with = "octaves_range")]
        octaves: u32,
        /// Amplitude ratio per octave, 0 ..= 1 (default 0.5).
        #[serde(default = "half", deserialize_with = "gain_range")]
        gain: f32,
        /// Frequency ratio per octave, 1 <.. 8 (default 2).
        #[serde(default = "two", deserialize_with = "lacunarity_range")]
        lacunarity: f32,
        /// Seed.
        #[serde(default, deserialize_with = "super::ranged::seed_range")]
        seed: Option<u64>,
    },
    /// Marble veins, 0 … 1: `½ + ½ sin(2π(axis·p/scale + turbulence·turb(p/scale)))`.
    Marble {
        /// Vein spacing along `axis`, object units, 1e-4 ..= 1e4.
        #[serde(deserialize_with = "scale_range")]
        scale: f32,
        /// Direction across the veins (normalised), default `(1, 0, 0)`.
        #[serde(default = "x_axis", deserialize_with = "axis_check")]
        axis: (f32, f32, f32),
        /// Turbulence amplitude in vein periods, 0 ..= 100 (default 1).
        #[serde(default = "one", deserialize_with = "turbulence_range")]
        turbulence: f32,
        /// Octaves of the turbulence, 1 ..= 16 (default 4).
        #[serde(default = "four_octaves", deserialize_with = "octaves_range")]
        octaves: u32,
        /// Amplitude ratio per octave, 0 ..= 1 (default 0.5).
        #[serde(default = "half", deserialize_with = "gain_range")]
        gain: f32,
        /// Frequency ratio per octave, 1 <.. 8 (default 2).
        #[serde(default = "two", deserialize_with = "lacunarity_range")]
        lacunarity: f32,
        /// Seed.
        #[serde(default, deserialize_with = "super::ranged::seed_range")]
        seed: Option<u64>,
    },
    /// Sum of fields (1 ..= 64 inputs).
    Sum(#[serde(deserialize_with = "inputs")] Vec<FieldDesc>),
    /// Product of fields (1 ..= 64 inputs).
    Product(#[serde(deserialize_with = "inputs")] Vec<FieldDesc>),
    /// Linear remap `from → to`, optionally clamped to `to`.
    Remap {
        /// The input.
        field: Box<FieldDesc>,
        /// Source interval; its ends must differ.
        #[serde(deserialize_with = "interval")]
        from: (f32, f32),
        /// Target interval.
        #[serde(deserialize_with = "finite_pair")]
        to: (f32, f32),
        /// Clamp to the target interval (default false).
        #[serde(default)]
        clamp: bool,
    },
}
