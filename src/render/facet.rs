//! A bare conductor's polarising vertex (docs/polarisation.md, "Bare conductors"): each
//! micro-facet reflects by Fresnel's Mueller matrix for the conductor's complex index, in the
//! frame of its own plane of incidence — in BSDF sampling ([`super::polarised::polarise`]) and in
//! light sampling ([`super::direct::direct_light`]).

use super::shading::SurfaceBsdf;
use crate::bsdf::{Bsdf, Scatter};
use crate::polarisation::stokes::{ROWS, StokesRows};
use crate::polarisation::transport::{InterfaceEvent, MAX_CHANNELS, PathPolarisation};
use crate::spectrum::Spectral;
use glam::Vec3;

/// The reflection off a bare conductor at `sb` of light arriving from `wi` and leaving along
/// `wo` (world, unit): its facet's event (the half vector of the two directions) for a row whose
/// axis is `x`; `None` if `sb` is no bare conductor or the directions are opposite.
pub(crate) fn conductor_event<S: Spectral>(
    sb: &SurfaceBsdf<'_>,
    (wo, wi): (Vec3, Vec3),
    lambda: &S::Wavelengths,
    x: Vec3,
) -> Option<InterfaceEvent>
where
    Bsdf: Scatter<S>,
{
    let nk = conductor_nk::<S>(sb, lambda)?;
    let h = (wo + wi).try_normalize()?;
    Some(InterfaceEvent::conductor(h, wo, wi, nk, x))
}

/// A bare conductor's relative complex IOR per channel (`None` for a channel the path no longer
/// carries), or `None` if `sb` is no bare conductor ([`SurfaceBsdf::conductor_ior`]).
fn conductor_nk<S: Spectral>(
    sb: &SurfaceBsdf<'_>,
    lambda: &S::Wavelengths,
) -> Option<[Option<(f32, f32)>; MAX_CHANNELS]>
where
    Bsdf: Scatter<S>,
{
    sb.conductor_ior::<S>(0, lambda)?;
    Some(std::array::from_fn(|c| {
        (c < S::CHANNELS)
            .then(|| sb.conductor_ior::<S>(c, lambda))
            .flatten()
    }))
}

/// The camera path's polarisation at a vertex where a light is sampled: its row and, with the
/// Stokes AOVs, theirs.
pub(crate) struct NeePolarisation<'a> {
    /// The sensor's row.
    pub pol: &'a PathPolarisation,
    /// The Stokes AOVs' rows.
    pub rows: Option<&'a StokesRows>,
}

/// How a polarising vertex changes a light sample's contribution: the sensor row's correction
/// per channel and, with the Stokes AOVs, each row's reading times its factor.
pub(crate) struct NeeRead {
    /// Multiplies the contribution, per channel.
    pub k: [f32; MAX_CHANNELS],
    /// Per row and channel: what the row reads of the uncorrected contribution.
    pub rows: Option<[[f32; MAX_CHANNELS]; ROWS]>,
}

/// A light sample (light arriving from the unit `wi`, leaving toward the camera along the unit
/// `wo`, both world) off a bare conductor at `sb`: its Fresnel matrix read by the rows, and the
/// light's own polarisation when it shines through a `polariser` (axis, world, unit); `None`
/// when `sb` is no bare conductor (the contribution stays the scalar code's).
pub(crate) fn conductor_nee<S: Spectral>(
    polar: &NeePolarisation<'_>,
    sb: &SurfaceBsdf<'_>,
    (wo, wi): (Vec3, Vec3),
    polariser: Option<Vec3>,
    lambda: &S::Wavelengths,
) -> Option<NeeRead>
where
    Bsdf: Scatter<S>,
{
    let event = conductor_event::<S>(sb, (wo, wi), lambda, polar.pol.x)?;
    let mut row = *polar.pol;
    let mut k = row.take(&event);
    if let Some(axis) = polariser {
        // The row, now about the light's segment, reads the light's linear polarisation.
        let p = row.polarised_emission(axis, -wi);
        k = std::array::from_fn(|c| k[c] * p[c]);
    }
    Some(NeeRead {
        k,
        // Settled rows follow the sensor's row: they read the contribution as corrected.
        rows: polar
            .rows
            .filter(|r| !r.settled)
            .map(|r| r.read_light(&event, polariser.map(|a| (a, -wi)))),
    })
}
