//! The path loop's polarised vertex ([`crate::polarisation::transport`]): what a BSDF-sampled
//! vertex does to the camera's Stokes row.

use super::path::PathState;
use super::shading::SurfaceBsdf;
use crate::bsdf::{Bsdf, Scatter};
use crate::polarisation::transport::PathPolarisation;
use crate::spectrum::Spectral;
use glam::Vec3;

/// The Stokes row's update at a BSDF-sampled vertex: Fresnel's Mueller matrix at a smooth
/// dielectric interface (the throughput corrected per channel), depolarisation anywhere else.
///
/// # Arguments
/// * `wo` – the direction the light leaves toward the previous vertex (world, unit).
/// * `above` – whether `wo` lies above the interface's frame (`z > 0`).
#[inline]
pub(super) fn polarise<S: Spectral>(
    pol: &mut PathPolarisation,
    path: &mut PathState<S>,
    sb: &SurfaceBsdf<'_>,
    bs: &crate::bsdf::BsdfSample<S>,
    wo: Vec3,
    above: bool,
) where
    Bsdf: Scatter<S>,
{
    use crate::polarisation::transport::{Interface, MAX_CHANNELS};
    if !bs.flags.is_specular() || sb.interface_eta::<S>(0, &path.lambda).is_none() {
        pol.depolarise();
        return;
    }
    let refraction = bs.flags.is_transmission();
    // Relative index of the side the light did not arrive from over the side it did: the light
    // arrives along `wi`, from `wo`'s side for a reflection and the other side for a refraction.
    let arrives_from_below = above == refraction;
    let eta: [Option<f32>; MAX_CHANNELS] = std::array::from_fn(|c| {
        (c < S::CHANNELS)
            .then(|| sb.interface_eta::<S>(c, &path.lambda))
            .flatten()
            .map(|e| if arrives_from_below { 1.0 / e } else { e })
    });
    let kind = if refraction {
        Interface::Refraction
    } else {
        Interface::Reflection
    };
    let k = pol.interface(sb.frame.n, wo, bs.wi, eta, kind);
    path.beta *= S::from_channels(|c| k[c]);
}
