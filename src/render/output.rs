//! The EXR a render writes: colour, AOVs and metadata (docs/design.md §8).
//!
//! Channels (all 32-bit float, one part):
//!
//! | channels | content |
//! |---|---|
//! | `R`, `G`, `B` | mean linear Rec.709 radiance |
//! | `albedo.R/G/B` | mean first-hit albedo (normal-incidence albedo of the stone's material, the floor's albedo; 0 for the sky and lights) |
//! | `normal.X/Y/Z` | mean first-hit world shading normal (facet normal on glitter), unit; 0 where nothing was hit |
//! | `depth.Z` | mean distance to the first hit along the camera ray, over samples that hit; 0 where none did |
//! | `variance.R/G/B` | variance of the pixel mean (sample variance / n), for z-tests against references |
//! | `samples.Y` | samples kept in the pixel (fewer than `spp` in a partial render or where samples were dropped) |
//! | `material.Y` | material index of the pixel's first sample (see `lapidary.materials`); −1 floor, −2 nothing |
//! | `S0.R/G/B` … `S3.R/G/B` | with `--stokes` only: the mean Stokes vector of the light reaching the camera before any analyser, linear Rec.709 per component, in the image's frame (`S1` horizontal − vertical, `S2` +45° − −45° from right toward up, `S3` right − left circular; [`crate::polarisation::stokes`]) |
//!
//! Attributes (text): `lapidary.version`, `lapidary.recipe`, `lapidary.recipe_hash` (16 hex
//! digits), `lapidary.seed`, `lapidary.spp` (requested), `lapidary.spp_complete`,
//! `lapidary.sampler`, `lapidary.max_depth`, `lapidary.render_time` (seconds),
//! `lapidary.dropped`, `lapidary.partial` (`true`/`false`), `lapidary.materials`
//! (`index=name` pairs separated by `;`), `lapidary.accuracy` (the knobs of
//! [`crate::scene::accuracy`] as `key=value,…`; empty when none), and for a scene with a
//! translucent body `lapidary.medium` (`medium-depth=N,medium-scattering=on|off`; the body is
//! the last entry of `lapidary.materials`, named `Body`).

use super::Rendered;
use crate::image::{Channel, ExrImage};

/// What the EXR's header records about a render.
#[derive(Clone, Debug, PartialEq)]
pub struct Metadata {
    /// Recipe file as given on the command line.
    pub recipe: String,
    /// Hash of the recipe and its includes.
    pub recipe_hash: u64,
    /// Seed of the pixel samples.
    pub seed: u64,
    /// Requested samples per pixel.
    pub spp: u32,
    /// Sampler name.
    pub sampler: String,
    /// Longest path in bounces.
    pub max_depth: u32,
    /// Material names by index.
    pub materials: Vec<String>,
    /// Accuracy knobs applied (`key=value,…`, empty when none).
    pub accuracy: String,
    /// The medium settings of a scene with a body (`None` without one: no attribute).
    pub medium: Option<String>,
}

impl Metadata {
    /// The metadata of rendering `scene` (with its current render settings) from `recipe`.
    pub fn of(recipe: &str, scene: &crate::scene::Scene) -> Metadata {
        let r = &scene.stage.render;
        Metadata {
            recipe: recipe.to_string(),
            recipe_hash: scene.hash,
            seed: r.seed,
            spp: r.spp,
            sampler: r.sampler.name().to_string(),
            max_depth: r.max_depth,
            materials: scene.surface.leaf_names(),
            accuracy: scene.accuracy.to_string(),
            medium: scene.surface.body.as_ref().map(|_| {
                format!(
                    "medium-depth={},medium-scattering={},manifold-continuation={},\
                     manifold-halvings={}",
                    r.medium_depth,
                    if r.medium_scattering { "on" } else { "off" },
                    if r.manifold_continuation { "on" } else { "off" },
                    r.manifold_halvings
                )
            }),
        }
    }
}

/// The EXR image of a render.
pub fn exr_image(r: &Rendered, meta: &Metadata) -> ExrImage {
    let s = &r.stats;
    let materials = meta
        .materials
        .iter()
        .enumerate()
        .map(|(i, n)| format!("{i}={n}"))
        .collect::<Vec<_>>()
        .join(";");
    let attributes = [
        ("lapidary.version", env!("CARGO_PKG_VERSION").to_string()),
        ("lapidary.recipe", meta.recipe.clone()),
        ("lapidary.recipe_hash", format!("{:016x}", meta.recipe_hash)),
        ("lapidary.seed", meta.seed.to_string()),
        ("lapidary.spp", meta.spp.to_string()),
        ("lapidary.spp_complete", s.spp_complete.to_string()),
        ("lapidary.sampler", meta.sampler.clone()),
        ("lapidary.max_depth", meta.max_depth.to_string()),
        (
            "lapidary.render_time",
            format!("{:.3}", s.elapsed.as_secs_f64()),
        ),
        ("lapidary.dropped", s.dropped.to_string()),
        ("lapidary.partial", s.partial.to_string()),
        ("lapidary.materials", materials),
        ("lapidary.accuracy", meta.accuracy.clone()),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v))
    .chain(
        meta.medium
            .iter()
            .map(|m| ("lapidary.medium".to_string(), m.clone())),
    )
    .collect();
    ExrImage {
        width: r.film.width,
        height: r.film.height,
        channels: film_channels(&r.film),
        attributes,
    }
}

/// The colour and AOV channels of a film (the table in the module documentation).
pub fn film_channels(film: &super::Film) -> Vec<Channel> {
    let px = &film.pixels;
    let channel = |name: &str, f: &dyn Fn(&super::PixelSums) -> f32| Channel {
        name: name.to_string(),
        data: px.iter().map(f).collect(),
    };
    let mut channels = Vec::with_capacity(16);
    for (c, name) in ["R", "G", "B"].iter().enumerate() {
        channels.push(channel(name, &|p| p.mean()[c]));
        channels.push(channel(&format!("albedo.{name}"), &|p| p.mean_albedo()[c]));
        channels.push(channel(&format!("variance.{name}"), &|p| {
            p.variance_of_mean()[c]
        }));
    }
    for (c, name) in ["X", "Y", "Z"].iter().enumerate() {
        channels.push(channel(&format!("normal.{name}"), &|p| p.mean_normal()[c]));
    }
    channels.push(channel("depth.Z", &|p| p.mean_depth()));
    channels.push(channel("samples.Y", &|p| p.n as f32));
    channels.push(channel("material.Y", &|p| {
        if p.material == i32::MIN {
            -2.0
        } else {
            p.material as f32
        }
    }));
    if film.stokes.len() == px.len() {
        for k in 0..4 {
            for (c, name) in ["R", "G", "B"].iter().enumerate() {
                channels.push(Channel {
                    name: format!("S{k}.{name}"),
                    data: film
                        .stokes
                        .iter()
                        .zip(px)
                        .map(|(s, p)| s.mean(p.n)[k][c])
                        .collect(),
                });
            }
        }
    }
    channels
}
