//! A micro-facet surface's polarising vertex (docs/polarisation.md, "Bare conductors" and
//! "Rough dielectric boundaries"): each micro-facet reflects (a bare conductor's, by Fresnel's
//! Mueller matrix for its complex index) or reflects and refracts (a rough dielectric's, by the
//! dielectric's matrices) in the frame of its own plane of incidence — in BSDF sampling
//! ([`super::polarised::polarise`]) and in light sampling ([`super::direct::direct_light`]).

use super::shading::SurfaceBsdf;
use crate::bsdf::{Bsdf, Scatter};
use crate::polarisation::stokes::{ROWS, StokesRows};
use crate::polarisation::transport::{InterfaceEvent, MAX_CHANNELS, PathPolarisation};
use crate::spectrum::Spectral;
use glam::Vec3;

/// The scattering at a micro-facet surface `sb` of light arriving from `wi` and leaving along
/// `wo` (world, unit), for a row whose axis is `x`: a bare conductor's reflection off the facet
/// of the half vector, or a bare rough dielectric's reflection or refraction off the facet of
/// the generalised half vector; `None` if `sb` is neither, or where the facet is undefined.
pub(crate) fn facet_event<S: Spectral>(
    sb: &SurfaceBsdf<'_>,
    (wo, wi): (Vec3, Vec3),
    lambda: &S::Wavelengths,
    x: Vec3,
) -> Option<InterfaceEvent>
where
    Bsdf: Scatter<S>,
{
    if let Some(nk) = conductor_nk::<S>(sb, lambda) {
        let h = (wo + wi).try_normalize()?;
        return Some(InterfaceEvent::conductor(h, wo, wi, nk, x));
    }
    sb.rough_interface_eta::<S>(0, lambda)?;
    let eta: [Option<f32>; MAX_CHANNELS] = std::array::from_fn(|c| {
        (c < S::CHANNELS)
            .then(|| sb.rough_interface_eta::<S>(c, lambda))
            .flatten()
    });
    InterfaceEvent::rough_dielectric(sb.frame.n, wo, wi, eta, x)
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
/// `wo`, both world) off a micro-facet surface at `sb` ([`facet_event`]): its Fresnel matrix
/// read by the rows, and the light's own polarisation when it shines through a `polariser`
/// (axis, world, unit); `None` when `sb` is neither a bare conductor nor a bare rough dielectric
/// (the contribution stays the scalar code's).
pub(crate) fn facet_nee<S: Spectral>(
    polar: &NeePolarisation<'_>,
    sb: &SurfaceBsdf<'_>,
    (wo, wi): (Vec3, Vec3),
    polariser: Option<Vec3>,
    lambda: &S::Wavelengths,
) -> Option<NeeRead>
where
    Bsdf: Scatter<S>,
{
    let event = facet_event::<S>(sb, (wo, wi), lambda, polar.pol.x)?;
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
