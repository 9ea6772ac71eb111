//! The path loop's polarised vertex ([`crate::polarisation::transport`]): what a BSDF-sampled
//! vertex does to the camera's Stokes row, and a doubly refractive boundary's sample.

use super::crystal_segment::take_wave;
use super::facet::facet_event;
use super::path::PathState;
use super::shading::SurfaceBsdf;
use super::world::CrystalOptics;
use crate::bsdf::{Bsdf, BsdfSample, Lobe, LobeKind, Scatter};
use crate::color::Rgb;
use crate::polarisation::boundary::Boundary;
use crate::polarisation::crystal;
use crate::polarisation::optics::Optics;
use crate::polarisation::stokes::{ROWS, StokesRows};
use crate::polarisation::transport::{InterfaceEvent, MAX_CHANNELS, PathPolarisation};
use crate::spectrum::Spectral;
use glam::Vec3;

/// The Stokes AOVs of a camera path ([`crate::polarisation::stokes`]): its four rows and what
/// each has measured so far, in the path's channels.
pub(super) struct StokesAov<S> {
    /// The rows.
    pub rows: StokesRows,
    sum: [S; ROWS],
}

impl<S: Spectral> StokesAov<S> {
    /// The rows of a camera ray along `dir` (unit) in a world that measures the Stokes AOVs.
    pub fn new(world: &super::world::World, dir: Vec3) -> Option<StokesAov<S>> {
        let right = world.stokes?;
        let scale = if world.analyser.is_some() {
            1.0 / crate::polarisation::transport::ANALYSER_TRANSMITTANCE
        } else {
            1.0
        };
        Some(StokesAov {
            rows: StokesRows::new(right, dir, scale),
            sum: [S::ZERO; ROWS],
        })
    }

    /// Records a contribution `added` to the path's radiance: each row reads it times its factor.
    #[inline]
    pub fn add(&mut self, added: S) {
        for (sum, f) in self.sum.iter_mut().zip(&self.rows.f) {
            *sum += added * S::from_channels(|c| f[c]);
        }
    }

    /// Records an emission that the rows read with their own corrections `kf` (a polarised
    /// light: [`StokesRows::polarised_emission`]); `c` is the contribution before any row's
    /// correction, as [`PathState::gathered`] gives it.
    pub fn add_read(&mut self, c: S, kf: [[f32; MAX_CHANNELS]; ROWS]) {
        for (sum, k) in self.sum.iter_mut().zip(&kf) {
            *sum += c * S::from_channels(|ch| k[ch]);
        }
    }

    /// The Stokes vector the path measured, linear Rec.709 per component.
    pub fn finish(&self, film: &S::Wavelengths) -> [Rgb; 4] {
        let m = self.sum.map(|s| s.to_rgb(film));
        // S₀ = R₀, Sⱼ = Rⱼ − R₀ ([`StokesRows::components`]) per colour channel.
        std::array::from_fn(|j| {
            if j == 0 {
                m[0]
            } else {
                Rgb(std::array::from_fn(|c| m[j][c] - m[0][c]))
            }
        })
    }
}

/// [`StokesAov::add`] when the path has the AOVs.
#[inline]
pub(super) fn stokes_add<S: Spectral>(aov: &mut Option<StokesAov<S>>, added: S) {
    if let Some(a) = aov {
        a.add(added);
    }
}

/// The Stokes row's update at a BSDF-sampled vertex: Fresnel's Mueller matrix at a smooth
/// dielectric interface and at a bare conductor's or rough dielectric's facet (the throughput
/// corrected per channel), depolarisation anywhere else; the Stokes AOVs' rows alike.
///
/// # Arguments
/// * `wo` – the direction the light leaves toward the previous vertex (world, unit).
/// * `above` – whether `wo` lies above the interface's frame (`z > 0`).
/// * `facets` – whether a micro-facet surface polarises here (inside a crystal only a
///   platelet's conductor; the path then carries no wave until [`take_wave`]).
#[allow(clippy::too_many_arguments)]
#[inline]
pub(super) fn polarise<S: Spectral>(
    pol: &mut PathPolarisation,
    rows: Option<&mut StokesRows>,
    path: &mut PathState<S>,
    sb: &SurfaceBsdf<'_>,
    bs: &BsdfSample<S>,
    wo: Vec3,
    above: bool,
    facets: bool,
) where
    Bsdf: Scatter<S>,
{
    use crate::polarisation::transport::Interface;
    let event = if facets {
        facet_event::<S>(sb, (wo, bs.wi), &path.lambda, pol.x)
    } else {
        None
    };
    let event = event.or_else(|| {
        if !bs.flags.is_specular() {
            return None;
        }
        sb.interface_eta::<S>(0, &path.lambda)?;
        let refraction = bs.flags.is_transmission();
        // Relative index of the side the light did not arrive from over the side it did: the
        // light arrives along `wi`, from `wo`'s side for a reflection and the other side for a
        // refraction.
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
        Some(InterfaceEvent::new(sb.frame.n, wo, bs.wi, eta, kind, pol.x))
    });
    let Some(event) = event else {
        pol.depolarise();
        if let Some(r) = rows {
            r.depolarise();
        }
        return;
    };
    let k = pol.take(&event);
    // A crystal's wave does not survive a platelet's conductor (which only reflects: the path
    // stays in the crystal, carrying the row until it takes a wave again).
    pol.mode = None;
    pol.normal = Vec3::ZERO;
    if let Some(r) = rows {
        r.take(&event, k);
    }
    path.beta *= S::from_channels(|c| k[c]);
}

/// The BSDF sample of a camera path meeting a doubly refractive body's smooth boundary
/// ([`crate::polarisation::crystal`]): the boundary solved at the wavelength of channel 0 (a
/// spectral path keeps only its hero from here, as after a dispersive refraction), the row `pol`
/// updated (every channel alike), and the Stokes AOVs' `rows` with it (the same choice, each
/// row's own weight).
///
/// # Arguments
/// * `wo` – the direction toward the previous vertex (world, unit).
/// * `outside` – whether the path arrives from outside the stone.
/// * `u` – two numbers in `[0, 1)`.
#[allow(clippy::too_many_arguments)]
pub(super) fn crystal_sample<S: Spectral>(
    crystal: &CrystalOptics,
    pol: &mut PathPolarisation,
    mut rows: Option<&mut StokesRows>,
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
    let crystal_optics = crystal.at(no, S::wavelength_nm(lambda, 0));
    // A biaxial boundary's normal made unit in f64 (an f32 normal is unit to 6e-8 only): the
    // quartic of the waves' normal components takes a unit normal; the uniaxial closed forms
    // keep theirs.
    let normal = match crystal_optics {
        Optics::Biaxial(_) => normal.normalize(),
        Optics::Uniaxial(_) => normal,
    };
    let b = Boundary {
        crystal: crystal_optics,
        n1: 1.0,
        normal,
    };
    // Inside, a polarised row without a wave (after a platelet) takes one first.
    let channels = (!outside && pol.mode.is_none() && !pol.is_unpolarised())
        .then(|| take_wave(&b.crystal, pol, rows.as_deref_mut(), -wo, f64::from(u.0)).channels);
    let step = if outside {
        crystal::from_outside(&b, wo, pol, f64::from(u.0))?
    } else {
        crystal::from_inside(&b, -wo, pol, (f64::from(u.0), f64::from(u.1)))?
    };
    pol.w = [pol.w[0]; MAX_CHANNELS];
    if let Some(r) = rows
        && !r.settled
    {
        if outside {
            // The same number picks the same wave for every row (the shares are the adjoint's);
            // each row's weight is its own.
            for j in 0..ROWS {
                let w = crystal::from_outside(&b, wo, &mut r.rows[j], f64::from(u.0))
                    .map_or(0.0, |s| s.weight);
                r.rows[j].w = [r.rows[j].w[0]; MAX_CHANNELS];
                let ratio = if step.weight > 0.0 {
                    (w / step.weight) as f32
                } else {
                    0.0
                };
                r.rescale(j, [ratio; MAX_CHANNELS], [1.0; MAX_CHANNELS]);
            }
        } else {
            // Inside, every row is the path's wave's pure state: they step alike.
            r.follow(pol);
        }
    }
    let wi = step.wi.as_vec3().try_normalize()?;
    let kind = if step.crossed {
        LobeKind::SpecularTransmission
    } else {
        LobeKind::SpecularReflection
    };
    let spectral = S::WAVELENGTH_DIMENSIONS > 0;
    let w = step.weight as f32;
    let k = channels.unwrap_or([1.0; MAX_CHANNELS]);
    let weight = S::from_channels(|c| if c == 0 || !spectral { w * k[c] } else { 0.0 });
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
    // A thin section's boundary refracts as an isotropic one (its waves leave together).
    let c = world.crystal.as_ref().filter(|c| c.thin_nm.is_none())?;
    (matches!(hit, super::world::Hit::Stone(_)) && sb.interface_eta::<S>(0, lambda).is_some())
        .then_some(c)
}
