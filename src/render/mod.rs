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
pub mod path;
mod polarised;
mod prefilter;
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

use crate::bsdf::{Bsdf, Scatter};
use crate::sampler::PixelSampler;
use crate::scene::stage::{Camera, RenderSettings};
use crate::spectrum::{HeroSample, RgbSample, Spectral};
use glam::Vec2;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
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

/// One tile row's pixel sums after the samples `samples` of each pixel, traced by the lane loop
/// in packets of [`lanes::simd::L`] adjacent pixels, sample by sample (each pixel's samples are
/// added in order, as the scalar loop adds them).
fn lane_row(
    world: &World,
    setup: &lanes::trace::Setup,
    row: &[PixelSums],
    x0: u32,
    y: u32,
    samples: std::ops::Range<u32>,
) -> Vec<PixelSums> {
    let mut sums = row.to_vec();
    for (k, chunk) in sums.chunks_mut(lanes::simd::L).enumerate() {
        let (x, count) = (x0 + (k * lanes::simd::L) as u32, chunk.len() as u32);
        let packet = |sample| lanes::trace::Packet {
            x0: x,
            y,
            count,
            sample,
        };
        let mut samplers = lanes::trace::packet_samplers(setup, packet(samples.start));
        for s in samples.clone() {
            let out = lanes::dispatch(world, setup, packet(s), &mut samplers);
            for (p, o) in chunk.iter_mut().zip(&out) {
                p.add(o);
            }
        }
    }
    sums
}

/// Samples per pass. A pass copies every pixel's sums into its tile and back (most of a pass's
/// overhead: 16 passes of 4 samples cost a 640×480 Lepidolite 8 % of its time), so long passes
/// are cheaper; a render with a time limit, a sample range (a farm part keeps its completed
/// passes when stopped) or a report after each pass keeps them short, so a stopped render has
/// most pixels at the same count. The sums are exact: the pass size changes no pixel.
fn pass_size(spp: u32, short: bool) -> u32 {
    spp.clamp(1, if short { 4 } else { 16 })
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
            render_passes::<HeroSample>(world, camera, depth_of_field, settings, control)
        } else {
            render_passes::<RgbSample>(world, camera, depth_of_field, settings, control)
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

fn render_passes<S: Spectral>(
    world: &World,
    camera: &Camera,
    depth_of_field: bool,
    settings: &RenderSettings,
    control: &Control,
) -> (Film, bool, u32)
where
    Bsdf: Scatter<S>,
{
    let (w, h) = (settings.width, settings.height);
    let mut film = Film::new(w, h);
    let stokes = world.stokes.is_some();
    if stokes {
        film.stokes = vec![film::StokesSums::default(); film.pixels.len()];
    }
    // A dichroscope's image is two views side by side, each the camera's whole view: the rays
    // of a half-width image, the right half's pixels shifted onto it.
    let half = world.dichroscope.map(|_| (w / 2).max(1));
    let rays = CameraRays::new(camera, half.unwrap_or(w), h, depth_of_field);
    let filter = FilterSampler::new(settings.filter);
    let tiles: Vec<(u32, u32)> = (0..h.div_ceil(TILE))
        .flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| (tx * TILE, ty * TILE)))
        .collect();
    let stop = || {
        control.cancel.is_some_and(|c| c.load(Ordering::Relaxed))
            || control.deadline.is_some_and(|d| Instant::now() >= d)
    };
    // The lane loop where it applies (docs/design.md §13): the same samples, bit for bit.
    let lane_setup =
        (S::WAVELENGTH_DIMENSIONS == 0 && control.lanes && lanes::unsupported(world).is_none())
            .then_some(lanes::trace::Setup {
                rays: &rays,
                filter: &filter,
                sampler: settings.sampler,
                seed: settings.seed,
                width: w,
                max_depth: settings.max_depth,
                strategy: control.strategy,
                leading_field: world.map.leading_field(),
            });
    let step = pass_size(
        settings.spp,
        control.deadline.is_some() || control.samples.is_some() || control.on_pass.is_some(),
    );
    let last = control
        .samples
        .as_ref()
        .map_or(settings.spp, |r| r.end.min(settings.spp));
    let first = control.samples.as_ref().map_or(0, |r| r.start.min(last));
    let mut done = first;
    let mut partial = false;
    while done < last {
        let end = (done + step).min(last);
        type TileSums = (Vec<PixelSums>, Vec<film::StokesSums>);
        let results: Vec<Option<TileSums>> = tiles
            .par_iter()
            .map(|&(x0, y0)| {
                if stop() {
                    return None;
                }
                let (x1, y1) = ((x0 + TILE).min(w), (y0 + TILE).min(h));
                let mut sums = Vec::with_capacity(((x1 - x0) * (y1 - y0)) as usize);
                let mut stokes_sums = Vec::new();
                for y in y0..y1 {
                    let row = &film.pixels[(y * w + x0) as usize..(y * w + x1) as usize];
                    match &lane_setup {
                        Some(setup) => {
                            sums.extend_from_slice(&lane_row(world, setup, row, x0, y, done..end));
                        }
                        None => {
                            for (x, &pixel_sums) in (x0..x1).zip(row) {
                                let mut p = pixel_sums;
                                let mut ps = film.stokes.get((y * w + x) as usize).copied();
                                // A dichroscope's right window: the same view, the other analyser.
                                let right = half.filter(|&h| x >= h);
                                let column = x - right.unwrap_or(0);
                                let plain = half.is_none() && ps.is_none();
                                let pixel = u64::from(y) * u64::from(w) + u64::from(x);
                                let mut sampler =
                                    PixelSampler::new(settings.sampler, settings.seed, pixel, done);
                                for s in done..end {
                                    sampler.restart(s);
                                    let offset = filter.sample(sampler.get2d());
                                    let lens = sampler.get2d();
                                    let film_pt =
                                        Vec2::new(column as f32 + 0.5, y as f32 + 0.5) + offset;
                                    let ray = rays.ray(film_pt, lens);
                                    let (depth, strategy) = (settings.max_depth, control.strategy);
                                    if plain {
                                        p.add(&trace::<S>(
                                            world,
                                            ray,
                                            &mut sampler,
                                            depth,
                                            strategy,
                                        ));
                                        continue;
                                    }
                                    let mut st = [crate::color::Rgb::ZERO; 4];
                                    let sample = trace_with::<S>(
                                        world,
                                        ray,
                                        &mut sampler,
                                        depth,
                                        strategy,
                                        right.is_some(),
                                        ps.is_some().then_some(&mut st),
                                    );
                                    if p.add(&sample)
                                        && let Some(ps) = &mut ps
                                    {
                                        ps.add(&st);
                                    }
                                }
                                sums.push(p);
                                stokes_sums.extend(ps);
                            }
                        }
                    }
                }
                if let Some(progress) = control.progress {
                    progress(sums.len() as u64 * u64::from(end - done));
                }
                Some((sums, stokes_sums))
            })
            .collect();
        // A part (a sample range) must hold exactly the samples its range says: a pass stopped
        // part way is dropped whole. A whole render keeps the finished tiles (the samples AOV
        // counts them).
        if control.samples.is_some() && results.iter().any(Option::is_none) {
            partial = true;
            break;
        }
        for (&(x0, y0), sums) in tiles.iter().zip(results) {
            let Some((sums, stokes_sums)) = sums else {
                partial = true;
                continue;
            };
            let x1 = (x0 + TILE).min(w);
            let mut it = sums.into_iter();
            let mut st = stokes_sums.into_iter();
            for y in y0..(y0 + TILE).min(h) {
                for x in x0..x1 {
                    let i = (y * w + x) as usize;
                    if let Some(p) = it.next() {
                        film.pixels[i] = p;
                    }
                    if let Some(p) = st.next() {
                        film.stokes[i] = p;
                    }
                }
            }
        }
        if partial {
            break;
        }
        done = end;
        if let Some(on_pass) = control.on_pass {
            on_pass(&film, done - first);
        }
    }
    (film, partial, done - first)
}
