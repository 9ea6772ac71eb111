//! The path loop's polarised vertex ([`crate::polarisation::transport`]): what a BSDF-sampled
//! vertex does to the camera's Stokes row, and a doubly refractive boundary's sample.

use super::path::PathState;
use super::shading::SurfaceBsdf;
use super::world::CrystalOptics;
use crate::bsdf::{Bsdf, BsdfSample, Lobe, LobeKind, Scatter};
use crate::polarisation::boundary::{Boundary, Mode};
use crate::polarisation::crystal;
use crate::polarisation::transport::PathPolarisation;
use crate::polarisation::uniaxial::Uniaxial;
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
    bs: &BsdfSample<S>,
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

/// The BSDF sample of a camera path meeting a doubly refractive body's smooth boundary
/// ([`crate::polarisation::crystal`]): the boundary solved at the wavelength of channel 0 (a
/// spectral path keeps only its hero from here, as after a dispersive refraction), the row `pol`
/// updated (every channel alike).
///
/// # Arguments
/// * `wo` – the direction toward the previous vertex (world, unit).
/// * `outside` – whether the path arrives from outside the stone.
/// * `u` – two numbers in `[0, 1)`.
pub(super) fn crystal_sample<S: Spectral>(
    crystal: &CrystalOptics,
    pol: &mut PathPolarisation,
    sb: &SurfaceBsdf<'_>,
    wo: Vec3,
    outside: bool,
    lambda: &S::Wavelengths,
    u: (f32, f32),
) -> Option<BsdfSample<S>>
where
    Bsdf: Scatter<S>,
{
    let no = f64::from(sb.interface_eta::<S>(0, lambda)?);
    let n = sb.frame.n.as_dvec3();
    let wo = wo.as_dvec3();
    // The normal pointing out of the stone.
    let facing = if n.dot(wo) > 0.0 { n } else { -n };
    let normal = if outside { facing } else { -facing };
    let b = Boundary {
        crystal: Uniaxial {
            no,
            ne: no + f64::from(crystal.birefringence),
            axis: crystal.axis.as_dvec3(),
        },
        n1: 1.0,
        normal,
    };
    let step = if outside {
        crystal::from_outside(&b, wo, pol, f64::from(u.0))?
    } else {
        crystal::from_inside(&b, -wo, pol, (f64::from(u.0), f64::from(u.1)))?
    };
    pol.w = [pol.w[0]; crate::polarisation::transport::MAX_CHANNELS];
    let wi = step.wi.as_vec3().try_normalize()?;
    let kind = if step.crossed {
        LobeKind::SpecularTransmission
    } else {
        LobeKind::SpecularReflection
    };
    let spectral = S::WAVELENGTH_DIMENSIONS > 0;
    let w = step.weight as f32;
    let weight = S::from_channels(|c| if c == 0 || !spectral { w } else { 0.0 });
    let cos = wi.dot(sb.frame.n).abs();
    let pdf = step.prob as f32;
    if !(w.is_finite() && w >= 0.0 && pdf > 0.0 && cos > 0.0) {
        return None;
    }
    Some(BsdfSample {
        wi,
        f: weight * (pdf / cos),
        pdf,
        weight,
        lobe: Lobe { kind, layer: 0 },
        flags: kind.flags(),
        eta: step.eta as f32,
        pdf_is_proportional: false,
        terminate_secondary: spectral,
    })
}

/// The transmittance over distance `t` of a pleochroic crystal for the wave the path's segment
/// carries, the camera ray travelling along `dir` (unit): `exp(−σ t)` with `σ = σ_ω` for the
/// ordinary wave and `σ_ω cos² θ + σ_ε sin² θ` for the extraordinary, `θ` between its wave normal
/// and the axis. A segment that has no wave yet (after a depolarising vertex) takes one, each
/// with probability ½ and weight 1 (the unpolarised row is the mean of the two orthogonal waves'),
/// with `u ∈ [0, 1)`.
pub(super) fn pleochroic_transmittance<S: Spectral>(
    crystal: &CrystalOptics,
    pol: &mut PathPolarisation,
    dir: Vec3,
    t: f32,
    u: f32,
    lambda: &S::Wavelengths,
) -> S {
    let optics = Uniaxial {
        no: f64::from(crystal.no),
        ne: f64::from(crystal.no + crystal.birefringence),
        axis: crystal.axis.as_dvec3(),
    };
    let ray = dir.as_dvec3();
    let mode = match pol.mode {
        Some(m) => m,
        None => {
            let m = if u < 0.5 { Mode::O } else { Mode::E };
            *pol = crystal::pure_state(&optics, ray, m);
            m
        }
    };
    let sigma = match mode {
        Mode::O => crystal.sigma[0],
        _ => {
            let k = crystal::wave_direction(&optics, ray, mode);
            let c2 = k.dot(optics.axis).powi(2) as f32;
            crystal.sigma[0] * c2 + crystal.sigma[1] * (1.0 - c2)
        }
    };
    S::from_unbounded(sigma, lambda).map(|s| (-s * t).exp())
}

/// The pleochroic crystal a segment in `medium` crosses, with the number that picks its wave
/// where it has none yet (drawn on every segment inside a pleochroic crystal; other scenes draw
/// nothing).
pub(super) fn pleochroic_segment<'w>(
    world: &'w super::world::World,
    medium: crate::geometry::MediumId,
    sampler: &mut crate::sampler::PixelSampler,
) -> Option<(&'w CrystalOptics, f32)> {
    let c = world.crystal.as_ref().filter(|c| c.pleochroic())?;
    (medium == world.interior).then(|| (c, sampler.get1d()))
}

/// The crystal whose boundary `hit` is: the stone's smooth dielectric boundary of a doubly
/// refractive body.
pub(super) fn crystal_boundary<'w, S: Spectral>(
    world: &'w super::world::World,
    hit: &super::world::Hit,
    sb: &SurfaceBsdf<'_>,
    lambda: &S::Wavelengths,
) -> Option<&'w CrystalOptics>
where
    Bsdf: Scatter<S>,
{
    let c = world.crystal.as_ref()?;
    (matches!(hit, super::world::Hit::Stone(_)) && sb.interface_eta::<S>(0, lambda).is_some())
        .then_some(c)
}
