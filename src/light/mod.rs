//! Light sources: area lights and environments, with sampling for next-event estimation.
//!
//! Every light offers `sample` (a direction toward it with its solid-angle density, as a
//! [`LightSample`]) and `pdf` (the density `sample` would give a direction found some other way,
//! e.g. by BSDF sampling), which agree exactly so the integrator can weight the two strategies by
//! multiple importance sampling (Veach 1997, ch. 9). `power` estimates emitted flux for choosing
//! among lights.
//!
//! - [`Area`]: planar rectangles and discs ([`area`]).
//! - [`EnvironmentLight`]: light from infinitely far away, constant, a sky gradient or a lat-long
//!   map ([`environment`]).
//! - [`Distribution1D`], [`Distribution2D`]: the piecewise-constant densities behind map sampling
//!   ([`distribution`]).

pub mod area;
pub mod distribution;
pub mod environment;
mod outline;
mod spherical_rect;

pub use area::Area;
pub use distribution::{Distribution1D, Distribution2D};
pub use environment::EnvironmentLight;

use crate::color::Rgb;
use glam::Vec3;

/// A light sample for next-event estimation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// Unit direction from the shading point toward the light (world space).
    pub wi: Vec3,
    /// Distance to the sampled point in world units (`f32::INFINITY` for environments).
    pub dist: f32,
    /// Emitted radiance arriving at the shading point along `−wi` (zero if the sampled face does
    /// not emit).
    pub radiance: Rgb,
    /// Density of `wi` per steradian (> 0, finite).
    pub pdf: f32,
}

/// `x` if it is positive and finite, else 0: how densities leave this module.
#[inline]
fn positive_or_zero(x: f32) -> f32 {
    if x.is_finite() && x > 0.0 { x } else { 0.0 }
}
