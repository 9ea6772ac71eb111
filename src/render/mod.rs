//! The path tracer (docs/design.md §8): camera rays, pixel filters, the integrator, the film, and the
//! loop that renders a compiled [`Scene`](crate::scene::Scene) in passes of samples over tiles, in parallel.
//!
//! **Determinism.** Every random number is `hash(seed, pixel, sample, slot)` ([`PixelSampler`]);
//! each pixel's samples are added in sample order by the one task that owns its tile in a pass,
//! and passes run one after another. A render is therefore bit-identical for any thread count and
//! any tile order. The film's sums are fixed-point integers ([`fixed`]), exact and associative,
//! so a render may also be split into sample ranges ([`Control::samples`]) rendered anywhere and
//! merged ([`part`]) into the same film, bit for bit.
//!
//! **Stopping early.** A cancel flag or a deadline is checked before each tile; tiles not started
//! are skipped, the render returns what was accumulated and says it is partial. Each pixel's
//! sample count is kept (the `samples` AOV), so a partial image is still an unbiased mean. A part
//! render ([`Control::samples`]) keeps only complete passes, so it holds exactly the range it
//! reports.

pub mod camera;
pub mod camera_path;
mod crystal_segment;
pub mod direct;
mod facet;
pub mod film;
pub mod filter;
pub mod fixed;
pub mod integrator;
pub mod lanes;
pub mod manifold;
pub mod memory;
pub mod output;
pub mod part;
mod passes;
pub mod path;
mod polarised;
mod prefilter;
mod segment;
pub mod setup;
pub mod shading;
pub mod study;
pub mod world;

pub use camera::CameraRays;
pub use camera_path::{trace, trace_at, trace_with};
pub use direct::Strategy;
pub use film::{Film, PixelSums};
pub use filter::FilterSampler;
pub use output::{Metadata, exr_image, film_channels};
pub use path::{PathSample, PathState};
pub use shading::{ShadingContext, SurfaceBsdf};
pub use world::{World, WorldError};

use crate::scene::stage::{Camera, RenderSettings};
use crate::spectrum::{HeroSample, RgbSample};
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

/// Tile edge in pixels.
pub const TILE: u32 = 16;

/// A callback after each complete pass: the film and the spp every pixel has.
pub type PassCallback<'a> = &'a (dyn Fn(&Film, u32) + Sync);

/// How a render is run (not what it renders).
#[derive(Default)]
pub struct Control<'a> {
    /// Worker threads (`None`: rayon's global pool, one per core).
    pub threads: Option<usize>,
    /// Direct-light estimators.
    pub strategy: Strategy,
    /// Stop starting tiles after this instant.
    pub deadline: Option<Instant>,
    /// Stop starting tiles once this is set (Ctrl-C).
    pub cancel: Option<&'a AtomicBool>,
    /// Called after each tile with the number of pixel samples it added.
    pub progress: Option<&'a (dyn Fn(u64) + Sync)>,
    /// Called after each complete pass with the film and the samples every pixel now has: the
    /// film then equals a render with that many spp, bit for bit (`lapidary tradeoff` takes its
    /// convergence curves this way).
    pub on_pass: Option<PassCallback<'a>>,
    /// Render only these sample indices of every pixel (a part of a render split across
    /// machines; `None`: all of `0..spp`). Sample `s` of a pixel is the same whichever range
    /// renders it, and the film's sums are exact ([`film`]), so parts covering `0..spp` merge
    /// into the one-machine render bit for bit. An empty or out-of-range end is clamped to
    /// `spp`.
    pub samples: Option<std::ops::Range<u32>>,
    /// Trace with the lane loop where it applies ([`lanes`]; both loops give the same image bit
    /// for bit). Off by default: the lane loop is not faster yet (docs/design.md §13 has the
    /// figures); `--lanes on`.
    pub lanes: bool,
}

/// Figures of a finished (or stopped) render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderStats {
    /// Wall-clock time.
    pub elapsed: Duration,
    /// Camera paths traced (samples kept and dropped).
    pub paths: u64,
    /// Rays traced (camera, extension, shadow).
    pub rays: u64,
    /// Samples dropped as non-finite.
    pub dropped: u64,
    /// Whether the render stopped before every pixel had all its samples.
    pub partial: bool,
    /// Samples per pixel every pixel has (equal to the requested count, or the length of the
    /// requested range, unless partial).
    pub spp_complete: u32,
}

/// A rendered film and its figures.
#[derive(Clone, Debug)]
pub struct Rendered {
    /// The accumulated samples.
    pub film: Film,
    /// Time, paths, rays, drops.
    pub stats: RenderStats,
}

/// Renders `world` seen by `camera` with `settings`.
///
/// # Arguments
/// * `world` – the built world ([`World::new`]).
/// * `camera` – the stage's camera; `depth_of_field` says whether its lens is used.
/// * `settings` – size, spp, depth, sampler, filter, seed.
/// * `control` – threads, strategy, early stop, progress.
pub fn render(
    world: &World,
    camera: &Camera,
    depth_of_field: bool,
    settings: &RenderSettings,
    control: &Control,
) -> Rendered {
    let start = Instant::now();
    // The transported-light variant is chosen once per render: each is its own monomorphised
    // renderer (crate::spectrum docs), so an RGB render runs no spectral code at all.
    let run = || {
        if world.spectral {
            passes::render_passes::<HeroSample>(world, camera, depth_of_field, settings, control)
        } else {
            passes::render_passes::<RgbSample>(world, camera, depth_of_field, settings, control)
        }
    };
    let (film, partial, spp_complete) = match control.threads {
        Some(n) => match rayon::ThreadPoolBuilder::new()
            .num_threads(n.max(1))
            .build()
        {
            Ok(pool) => pool.install(run),
            Err(_) => run(),
        },
        None => run(),
    };
    let dropped = film.dropped();
    Rendered {
        stats: RenderStats {
            elapsed: start.elapsed(),
            paths: film.samples() + dropped,
            rays: film.rays(),
            dropped,
            partial,
            spp_complete,
        },
        film,
    }
}

/// Renders a compiled scene with its own camera and render settings, the lens used when depth of
/// field is on (what `lapidary render`, `regress` and `tradeoff` do).
pub fn render_scene(world: &World, scene: &crate::scene::Scene, control: &Control) -> Rendered {
    render(
        world,
        &scene.stage.camera,
        scene.effects.on(crate::scene::Effect::DepthOfField),
        &scene.stage.render,
        control,
    )
}
