//! The entry points of a camera path: [`trace`] (what a render calls per sample), [`trace_at`]
//! (fixed wavelengths, for tests) and [`trace_with`] (a dichroscope's right window, the Stokes
//! AOVs). Each picks the monomorphised path loop ([`super::integrator`]) the world calls for, so
//! a render that needs neither polarised transport nor the Stokes AOVs runs the loop in which
//! they do not occur.

use super::direct::Strategy;
use super::integrator::trace_path;
use super::path::PathSample;
use super::world::World;
use crate::bsdf::{Bsdf, Scatter};
use crate::color::Rgb;
use crate::geometry::Ray;
use crate::sampler::{PixelSampler, slots};
use crate::spectrum::Spectral;

/// Traces one camera path carrying transported light `S` (`trace::<RgbSample>` for the RGB
/// variant).
///
/// # Arguments
/// * `world` – the scene.
/// * `ray` – the camera ray (unit direction).
/// * `sampler` – positioned after the camera's slots.
/// * `max_depth` – most scattering events.
/// * `strategy` – direct-light estimators.
pub fn trace<S: Spectral>(
    world: &World,
    ray: Ray,
    sampler: &mut PixelSampler,
    max_depth: u32,
    strategy: Strategy,
) -> PathSample
where
    Bsdf: Scatter<S>,
{
    let lambda = wavelengths::<S>(world, sampler);
    trace_at::<S>(world, ray, sampler, max_depth, strategy, lambda).0
}

/// [`trace`] at given wavelengths: the film sample and the path's estimate at each wavelength
/// (for tests that hold the wavelengths fixed, e.g. a furnace at every wavelength). After a
/// dispersive refraction only channel 0 (the hero) of the estimate is meaningful.
///
/// # Arguments
/// As [`trace`], and `lambda` – the wavelengths the path carries.
pub fn trace_at<S: Spectral>(
    world: &World,
    ray: Ray,
    sampler: &mut PixelSampler,
    max_depth: u32,
    strategy: Strategy,
    lambda: S::Wavelengths,
) -> (PathSample, S)
where
    Bsdf: Scatter<S>,
{
    // Polarised transport is its own monomorphised loop, as the variants are: a scene without
    // it runs code in which the Stokes row does not occur.
    let (a, mut none) = (world.analyser, [Rgb::ZERO; 4]);
    if world.polarised {
        trace_path::<S, true, false>(
            world, ray, sampler, max_depth, strategy, lambda, a, &mut none,
        )
    } else {
        trace_path::<S, false, false>(
            world, ray, sampler, max_depth, strategy, lambda, a, &mut none,
        )
    }
}

/// [`trace`] for the pixels a plain render does not have: the right half of a dichroscope's
/// image (`right`: the camera's analyser is [`World::dichroscope`]'s, 90° from the left
/// window's) and renders that measure the Stokes AOVs (`stokes`: receives the path's Stokes
/// vector, [`crate::polarisation::stokes`]; left untouched unless the world is polarised).
pub fn trace_with<S: Spectral>(
    world: &World,
    ray: Ray,
    sampler: &mut PixelSampler,
    max_depth: u32,
    strategy: Strategy,
    right: bool,
    stokes: Option<&mut [Rgb; 4]>,
) -> PathSample
where
    Bsdf: Scatter<S>,
{
    let lambda = wavelengths::<S>(world, sampler);
    let a = if right {
        world.dichroscope.or(world.analyser)
    } else {
        world.analyser
    };
    let mut none = [Rgb::ZERO; 4];
    let (s, m, l) = (sampler, max_depth, lambda);
    match (world.polarised, stokes) {
        (true, Some(out)) => trace_path::<S, true, true>(world, ray, s, m, strategy, l, a, out).0,
        (true, None) => trace_path::<S, true, false>(world, ray, s, m, strategy, l, a, &mut none).0,
        (false, _) => trace_path::<S, false, false>(world, ray, s, m, strategy, l, a, &mut none).0,
    }
}

/// The wavelengths a camera path carries: drawn from the sampler's wavelength slot in a spectral
/// variant, the RGB variant's fixed channels otherwise.
#[inline]
fn wavelengths<S: Spectral>(world: &World, sampler: &mut PixelSampler) -> S::Wavelengths {
    if S::WAVELENGTH_DIMENSIONS > 0 {
        S::sample_wavelengths_with(sampler.get2d_at(slots::WAVELENGTH), &world.lines)
    } else {
        S::sample_wavelengths(0.0)
    }
}
