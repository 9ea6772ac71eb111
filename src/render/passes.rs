//! The pass loop: every pass adds a run of samples to every pixel, tile by tile in parallel.
//!
//! Each tile keeps its pixels' sums for the whole render ([`TileSums`], the tile's rows one after
//! another) and a pass adds its samples to them in place; the film is assembled from the tiles
//! after the last pass (and after each pass for [`Control::on_pass`]). A part render
//! ([`Control::samples`]) keeps a copy of the sums from before each pass so that a pass stopped part
//! way is dropped whole.

use super::film::{self, Film, PixelSums};
use super::{CameraRays, Control, FilterSampler, TILE, World, lanes, trace, trace_with};
use crate::bsdf::{Bsdf, Scatter};
use crate::sampler::PixelSampler;
use crate::scene::stage::{Camera, RenderSettings};
use crate::spectrum::Spectral;
use glam::Vec2;
use rayon::prelude::*;
use std::sync::atomic::Ordering;
use std::time::Instant;

/// Samples per pass. A render that nothing stops early runs long passes (each pass waits for its
/// slowest tile, and a part copies its sums before each pass); a render with a time limit, a
/// sample range (a farm part keeps its completed passes when stopped) or a report after each pass
/// keeps them short, so a stopped render has most pixels at the same count. The sums are exact:
/// the pass size changes no pixel.
fn pass_size(spp: u32, short: bool) -> u32 {
    spp.clamp(1, if short { 4 } else { 16 })
}

/// One tile's sums, row after row (and its Stokes sums when the render measures them).
#[derive(Clone)]
struct TileSums {
    /// The tile's lowest corner, pixels.
    x0: u32,
    y0: u32,
    /// Its pixels, row-major over its own width.
    pixels: Vec<PixelSums>,
    /// Its pixels' Stokes sums (empty unless the render measures them).
    stokes: Vec<film::StokesSums>,
}

impl TileSums {
    /// Copies the tile's sums into their places in `film`.
    fn write(&self, film: &mut Film) {
        let w = film.width;
        let x1 = (self.x0 + TILE).min(w);
        let tw = (x1 - self.x0) as usize;
        for (r, row) in self.pixels.chunks(tw).enumerate() {
            let at = ((self.y0 + r as u32) * w + self.x0) as usize;
            film.pixels[at..at + tw].copy_from_slice(row);
        }
        for (r, row) in self.stokes.chunks(tw).enumerate() {
            let at = ((self.y0 + r as u32) * w + self.x0) as usize;
            film.stokes[at..at + tw].copy_from_slice(row);
        }
    }
}

/// The film assembled from the tiles' sums.
fn assemble(w: u32, h: u32, stokes: bool, tiles: &[TileSums]) -> Film {
    let mut film = Film::new(w, h);
    if stokes {
        film.stokes = vec![film::StokesSums::default(); film.pixels.len()];
    }
    for t in tiles {
        t.write(&mut film);
    }
    film
}

/// Renders the passes of `settings` (or of `control.samples`) over tiles; returns the film,
/// whether it is partial, and the samples per pixel every pixel has.
pub(super) fn render_passes<S: Spectral>(
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
    let stokes = world.stokes.is_some();
    // A dichroscope's image is two views side by side, each the camera's whole view: the rays
    // of a half-width image, the right half's pixels shifted onto it.
    let half = world.dichroscope.map(|_| (w / 2).max(1));
    let rays = CameraRays::new(camera, half.unwrap_or(w), h, depth_of_field);
    let filter = FilterSampler::new(settings.filter);
    let mut tiles: Vec<TileSums> = (0..h.div_ceil(TILE))
        .flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| (tx * TILE, ty * TILE)))
        .map(|(x0, y0)| {
            let n = (((x0 + TILE).min(w) - x0) * ((y0 + TILE).min(h) - y0)) as usize;
            TileSums {
                x0,
                y0,
                pixels: vec![PixelSums::EMPTY; n],
                stokes: if stokes {
                    vec![film::StokesSums::default(); n]
                } else {
                    Vec::new()
                },
            }
        })
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
        // A part must hold exactly the samples its range says: a pass stopped part way is
        // dropped whole, so its sums from before the pass are kept. A whole render keeps the
        // finished tiles (the samples AOV counts them).
        let before = control.samples.is_some().then(|| tiles.clone());
        let finished: Vec<bool> = tiles
            .par_iter_mut()
            .map(|tile| {
                if stop() {
                    return false;
                }
                let (x0, y0) = (tile.x0, tile.y0);
                let (x1, y1) = ((x0 + TILE).min(w), (y0 + TILE).min(h));
                let tw = (x1 - x0) as usize;
                for (r, y) in (y0..y1).enumerate() {
                    let row = &mut tile.pixels[r * tw..(r + 1) * tw];
                    if let Some(setup) = &lane_setup {
                        lane_row(world, setup, row, x0, y, done..end);
                        continue;
                    }
                    for (k, (x, p)) in (x0..x1).zip(row.iter_mut()).enumerate() {
                        let mut ps = tile.stokes.get_mut(r * tw + k);
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
                            let film_pt = Vec2::new(column as f32 + 0.5, y as f32 + 0.5) + offset;
                            let ray = rays.ray(film_pt, lens);
                            let (depth, strategy) = (settings.max_depth, control.strategy);
                            if plain {
                                p.add(&trace::<S>(world, ray, &mut sampler, depth, strategy));
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
                    }
                }
                if let Some(progress) = control.progress {
                    progress(tile.pixels.len() as u64 * u64::from(end - done));
                }
                true
            })
            .collect();
        if finished.iter().any(|f| !f) {
            partial = true;
            if let Some(before) = before {
                tiles = before;
            }
            break;
        }
        done = end;
        if let Some(on_pass) = control.on_pass {
            on_pass(&assemble(w, h, stokes, &tiles), done - first);
        }
    }
    (assemble(w, h, stokes, &tiles), partial, done - first)
}

/// Adds the samples `samples` of each pixel of one tile row (`row`, starting at column `x0`) by
/// the lane loop, in packets of [`lanes::simd::L`] adjacent pixels, sample by sample (each
/// pixel's samples are added in order, as the scalar loop adds them).
fn lane_row(
    world: &World,
    setup: &lanes::trace::Setup,
    row: &mut [PixelSums],
    x0: u32,
    y: u32,
    samples: std::ops::Range<u32>,
) {
    for (k, chunk) in row.chunks_mut(lanes::simd::L).enumerate() {
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
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Tiles of an image that is not a multiple of the tile size, each pixel marked with its
    /// index in the film: the assembled film holds every mark in its place, Stokes sums too.
    #[test]
    fn tiles_assemble_into_their_places() {
        let (w, h) = (37u32, 21u32);
        let mut tiles = Vec::new();
        for y0 in (0..h).step_by(TILE as usize) {
            for x0 in (0..w).step_by(TILE as usize) {
                let (x1, y1) = ((x0 + TILE).min(w), (y0 + TILE).min(h));
                let mut t = TileSums {
                    x0,
                    y0,
                    pixels: Vec::new(),
                    stokes: Vec::new(),
                };
                for y in y0..y1 {
                    for x in x0..x1 {
                        let i = u64::from(y * w + x);
                        t.pixels.push(PixelSums {
                            rays: i,
                            ..PixelSums::EMPTY
                        });
                        let mut s = film::StokesSums::default();
                        s.0[0][0] = i128::from(i);
                        t.stokes.push(s);
                    }
                }
                tiles.push(t);
            }
        }
        let film = assemble(w, h, true, &tiles);
        for (i, (p, s)) in film.pixels.iter().zip(&film.stokes).enumerate() {
            assert_eq!(p.rays, i as u64);
            assert_eq!(s.0[0][0], i as i128);
        }
    }

    #[test]
    fn passes_are_short_only_where_a_render_may_stop_early() {
        assert_eq!(pass_size(64, false), 16);
        assert_eq!(pass_size(64, true), 4);
        assert_eq!(pass_size(3, false), 3);
        assert_eq!(pass_size(0, true), 1);
    }
}
