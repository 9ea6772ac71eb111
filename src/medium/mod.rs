//! Participating media: what fills a translucent stone's body (issue 17).
//!
//! A path travelling through a medium meets, per unit length (world units), absorption `σa` and
//! scattering `σs` (extinction `σt = σa + σs`), per channel of the transported light; where it
//! scatters, a [`phase`] function picks the new direction. Only homogeneous media exist today
//! ([`Homogeneous`]); [`Medium::Vacuum`] is the outside of every stone and the inside of a clear one.
//!
//! **Directions.** As for BSDFs (`src/bsdf/mod.rs`), `wo` points from the scattering point back
//! toward the previous vertex (toward the camera) and `wi` away from it toward the next vertex;
//! the phase function's angle is the one between the propagation directions `−wo` and `wi`, so a
//! forward-scattering medium (`g > 0`) continues roughly straight on.
//!
//! **Free flight with chromatic coefficients.** Each path picks one *hero* channel uniformly at its
//! first medium segment and samples every distance from that channel's exponential,
//! `p_h(t) = σt,h e^(−σt,h t)` (and reaches the surface with probability `T_h`). Every free flight
//! reports the value (`T σs` or `T`) and the density **each** channel would have had; the path
//! keeps the product of the densities' ratios to the hero's, `r_c = Π p_c/p_h`, and its
//! contributions are divided by `mean_c r_c`. That is the one-sample MIS (balance heuristic) over
//! the channels applied to the whole path, as in pbrt-v4's volumetric path tracer (its `r_u`) and
//! Miller, Georgiev & Jarosz, "A Null-Scattering Path Integral Formulation of Light Transport",
//! SIGGRAPH 2019 (§5, spectral MIS), restricted to homogeneous media (no null collisions). Weighting
//! each event on its own instead lets per-channel factors up to `N` multiply along a path of many
//! scattering events into fireflies; the path-level weight stays bounded by `N` times the largest
//! channel's own estimate.

pub mod homogeneous;
pub mod phase;

pub use homogeneous::Homogeneous;
pub use phase::{HenyeyGreenstein, PhaseSample};

use crate::spectrum::Spectral;

/// A medium a ray can travel through.
// `Homogeneous` carries its measured spectra inline (two 48-value grids): media live in one small
// per-world `Vec` read by reference, and inline grids keep the free-flight code free of a pointer
// chase; the size difference to `Vacuum` costs a few hundred bytes per world.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Medium {
    /// Nothing: no absorption, no scattering.
    Vacuum,
    /// Constant coefficients and phase function.
    Homogeneous(Homogeneous),
}

/// What happened along a ray segment of length `t_max` in a medium: the value of the event per
/// channel and the density each channel's sampling would have given it (the path divides by
/// the hero channel's and keeps the ratios, see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FreeFlight<S> {
    /// The path reached the end of the segment (the next surface, or nothing).
    Pass {
        /// The transmittance `T(t_max)` (1 in a vacuum, exactly).
        value: S,
        /// Probability of passing per channel (`T(t_max)`; 1 where nothing was sampled).
        pdf: S,
    },
    /// The path scattered at distance `t`; the new direction comes from the phase function.
    Scatter {
        /// Distance along the ray, world units, `0 < t < t_max`.
        t: f32,
        /// `T(t) σs` per channel.
        value: S,
        /// The distance's density per channel, `σt T(t)`.
        pdf: S,
    },
}

impl Medium {
    /// Samples the free flight along a segment of length `t_max` (`f32::INFINITY` if the ray meets
    /// nothing).
    ///
    /// # Arguments
    /// * `hero` – the channel whose extinction the distance is sampled from (`< S::CHANNELS`).
    /// * `u` – a uniform number for the distance.
    /// * `lambda` – the path's wavelengths.
    #[inline]
    pub fn free_flight<S: Spectral>(
        &self,
        t_max: f32,
        hero: usize,
        u: f32,
        lambda: &S::Wavelengths,
    ) -> FreeFlight<S> {
        match self {
            Medium::Vacuum => FreeFlight::Pass {
                value: S::ONE,
                pdf: S::ONE,
            },
            Medium::Homogeneous(h) => h.free_flight(t_max, hero, u, lambda),
        }
    }

    /// The distance (world units) at which [`free_flight`](Self::free_flight) with the same `hero`,
    /// `u` and `lambda` scatters when the segment is longer; `f32::INFINITY` where the medium
    /// cannot scatter. A surface beyond it is never met first.
    #[inline]
    pub fn collision<S: Spectral>(&self, hero: usize, u: f32, lambda: &S::Wavelengths) -> f32 {
        match self {
            Medium::Vacuum => f32::INFINITY,
            Medium::Homogeneous(h) => h.collision::<S>(hero, u, lambda),
        }
    }

    /// The transmittance `e^(−σt t)` per channel over `t` world units (a shadow segment; 1 in a
    /// vacuum).
    #[inline]
    pub fn transmittance<S: Spectral>(&self, t: f32, lambda: &S::Wavelengths) -> S {
        match self {
            Medium::Vacuum => S::ONE,
            Medium::Homogeneous(h) => h.transmittance(t, lambda),
        }
    }

    /// The smallest extinction `σt` over the RGB channels, per world unit (0 in a vacuum).
    #[inline]
    pub fn min_extinction(&self) -> f32 {
        match self {
            Medium::Vacuum => 0.0,
            Medium::Homogeneous(h) => {
                let t = h.sigma_a + h.sigma_s;
                t.0[0].min(t.0[1]).min(t.0[2])
            }
        }
    }

    /// The phase function at a scattering point (`None` in a vacuum, which never scatters).
    #[inline]
    pub fn phase(&self) -> Option<HenyeyGreenstein> {
        match self {
            Medium::Vacuum => None,
            Medium::Homogeneous(h) => Some(h.phase),
        }
    }

    /// Whether the medium can scatter light (a scattering event is possible).
    #[inline]
    pub fn scatters(&self) -> bool {
        match self {
            Medium::Vacuum => false,
            Medium::Homogeneous(h) => h.scatters(),
        }
    }
}
