//! The `render` block of a recipe's stage (serde description layer): image size, samples, depths,
//! the medium's and the manifold walks' knobs, the sampler, the filter, exposure, seed and the
//! accuracy overrides ([`RenderDesc`]), resolved into [`crate::scene::stage::RenderSettings`] by
//! `resolve.rs`.

use super::material::ModelDesc;
use super::ranged::{count, seed_range};
use crate::bsdf::{Distribution, FresnelMode, Masking};
use indexmap::IndexMap;
use serde::{Deserialize, Deserializer, Serialize};

ranged!(exposure_range, "exposure", -30.0, 30.0);
ranged!(filter_radius_range, "radius", 0.5, 4.0);

fn size_range<'de, D: Deserializer<'de>>(d: D) -> Result<Option<u32>, D::Error> {
    count(d, "image size", 1, 16384)
}
fn spp_range<'de, D: Deserializer<'de>>(d: D) -> Result<Option<u32>, D::Error> {
    count(d, "spp", 1, 1 << 20)
}
fn depth_range<'de, D: Deserializer<'de>>(d: D) -> Result<Option<u32>, D::Error> {
    count(d, "max_depth", 1, 1024)
}
fn medium_depth_range<'de, D: Deserializer<'de>>(d: D) -> Result<Option<u32>, D::Error> {
    count(d, "medium_depth", 0, crate::scene::stage::MAX_MEDIUM_DEPTH)
}
fn manifold_halvings_range<'de, D: Deserializer<'de>>(d: D) -> Result<Option<u32>, D::Error> {
    count(
        d,
        "manifold_halvings",
        0,
        crate::scene::stage::MAX_MANIFOLD_HALVINGS,
    )
}
fn one_and_a_half() -> f32 {
    1.5
}

/// How platelets are traced.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum PlateletForm {
    /// Disc by disc.
    Explicit,
    /// As a medium of oriented flakes.
    Statistical,
}

/// Which numbers drive the pixel samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum SamplerDesc {
    /// Independent uniform numbers from a hash of (seed, pixel, sample, dimension).
    Independent,
    /// Owen-scrambled Sobol' points (low discrepancy).
    Sobol,
}

/// The pixel reconstruction filter.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum FilterDesc {
    /// Each sample counts for the pixel it falls in.
    Box,
    /// A truncated Gaussian of standard deviation `radius / 3` pixels.
    Gaussian {
        /// Support radius in pixels, 0.5 ..= 4 (default 1.5).
        #[serde(default = "one_and_a_half", deserialize_with = "filter_radius_range")]
        radius: f32,
    },
}

/// Render settings; every field left out keeps the studio's value.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RenderDesc {
    /// Image width in pixels, 1 ..= 16384.
    #[serde(default, deserialize_with = "size_range")]
    pub width: Option<u32>,
    /// Image height in pixels, 1 ..= 16384.
    #[serde(default, deserialize_with = "size_range")]
    pub height: Option<u32>,
    /// Samples per pixel, 1 ..= 2²⁰.
    #[serde(default, deserialize_with = "spp_range")]
    pub spp: Option<u32>,
    /// Longest path in bounces, 1 ..= 1024.
    #[serde(default, deserialize_with = "depth_range")]
    pub max_depth: Option<u32>,
    /// Most scattering events in a body's medium per path, 0 ..= 4096 (default 256).
    #[serde(default, deserialize_with = "medium_depth_range")]
    pub medium_depth: Option<u32>,
    /// Whether a body's medium scatters (default true; false: absorption only).
    #[serde(default)]
    pub medium_scattering: Option<bool>,
    /// Whether a failed manifold walk retries by the continuation in the index (default false).
    #[serde(default)]
    pub manifold_continuation: Option<bool>,
    /// Most halvings of a manifold walk's Newton step, 0 ..= 8 (default 1).
    #[serde(default, deserialize_with = "manifold_halvings_range")]
    pub manifold_halvings: Option<u32>,
    /// How a body's platelets are traced: `Explicit` (default, disc by disc) or `Statistical`
    /// (as a medium of oriented flakes).
    #[serde(default)]
    pub platelets: Option<PlateletForm>,
    /// The sampler.
    #[serde(default)]
    pub sampler: Option<SamplerDesc>,
    /// The pixel filter.
    #[serde(default)]
    pub filter: Option<FilterDesc>,
    /// Exposure of the PNG in stops (EV), −30 ..= 30.
    #[serde(default, deserialize_with = "exposure_opt")]
    pub exposure: Option<f32>,
    /// Seed of the pixel samples, 0 ..= 2⁶⁴ − 1 (not of the maps: that is the recipe's `seed`).
    #[serde(default, deserialize_with = "seed_range")]
    pub seed: Option<u64>,
    /// Accuracy knobs for every material and forced effects (docs/design.md §9).
    #[serde(default)]
    pub accuracy: Option<AccuracyDesc>,
}

/// Accuracy knobs of a recipe (`stage.render.accuracy`): each overrides every material's own
/// choice or forces an effect on or off ([`crate::scene::accuracy`]).
///
/// ```ron
/// render: (accuracy: (model: Course, fresnel: Table, t_term: false, absorption: false,
///                     bump: false, effects: {"depth-of-field": false})),
/// ```
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AccuracyDesc {
    /// Evaluation model for every material.
    #[serde(default)]
    pub model: Option<ModelDesc>,
    /// Fresnel evaluation for every material.
    #[serde(default)]
    pub fresnel: Option<FresnelMode>,
    /// Micro-facet distribution for every material.
    #[serde(default)]
    pub distribution: Option<Distribution>,
    /// Masking–shadowing for every material.
    #[serde(default)]
    pub masking: Option<Masking>,
    /// Multiple-scattering compensation on or off for every material.
    #[serde(default)]
    pub compensation: Option<bool>,
    /// The Corrected model's albedo calibration on or off for every material.
    #[serde(default)]
    pub calibration: Option<bool>,
    /// The course's `t` term on or off for every coated material.
    #[serde(default)]
    pub t_term: Option<bool>,
    /// Coat absorption on or off.
    #[serde(default)]
    pub absorption: Option<bool>,
    /// Facet bump on or off.
    #[serde(default)]
    pub bump: Option<bool>,
    /// Any effect by name (`lapidary info` lists them) forced on (`true`) or off.
    #[serde(default)]
    pub effects: IndexMap<String, bool>,
}

fn exposure_opt<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f32>, D::Error> {
    exposure_range(d).map(Some)
}
