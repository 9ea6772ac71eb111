//! The path loop's polarised vertex ([`crate::polarisation::transport`]): what a BSDF-sampled
//! vertex does to the camera's Stokes row, and a doubly refractive boundary's sample.

use super::facet::facet_event;
use super::path::PathState;
use super::shading::SurfaceBsdf;
use super::world::CrystalOptics;
use crate::bsdf::{Bsdf, BsdfSample, Lobe, LobeKind, Scatter};
use crate::color::Rgb;
use crate::polarisation::Mueller;
use crate::polarisation::boundary::{Boundary, Mode};
use crate::polarisation::crystal;
use crate::polarisation::optics::Optics;
use crate::polarisation::stokes::{ROWS, StokesRows};
use crate::polarisation::transport::{InterfaceEvent, MAX_CHANNELS, PathPolarisation};
use crate::polarisation::uniaxial::Uniaxial;
use crate::spectrum::Spectral;
use glam::Vec3;
use num_complex::Complex64 as C;

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
    rows: Option<&mut StokesRows>,
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
    let mut rows = rows;
    let channels = (!outside && pol.mode.is_none() && !pol.is_unpolarised())
        .then(|| take_wave(&b.crystal, pol, rows.as_deref_mut(), -wo, f64::from(u.0)));
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

/// Inside a crystal, a polarised camera row `pol` that carries no wave (after a platelet's
/// reflection) takes one of the crystal's two waves along the unit `ray` (the camera path's
/// direction), and the Stokes AOVs' `rows` with it; returns the factor of each channel's
/// throughput. The light along the ray is the incoherent sum of the two waves, `Σₘ Lₘ (1, sₘ)`
/// with `sₘ` wave `m`'s pure linear state (the two opposite: their fields are orthogonal), which
/// the row reads as `Σₘ Lₘ (1 + w·sₘ)`. The path takes wave `m` with probability
/// `(1 + w·sₘ) / 2` of channel 0's ratios (½ each for an unpolarised row) and carries its pure
/// row, which reads `2 Lₘ`: weight 1 for channel 0, `(1 + w_c·sₘ) / (1 + w₀·sₘ)` for channel
/// `c`, and each AOV row's factor changes by its reading over the sensor's. `u ∈ [0, 1)`.
pub(super) fn take_wave(
    optics: &Optics,
    pol: &mut PathPolarisation,
    rows: Option<&mut StokesRows>,
    ray: glam::DVec3,
    u: f64,
) -> [f32; MAX_CHANNELS] {
    let modes = optics.modes();
    let light = (-ray).as_vec3();
    let field = optics.field(ray, modes[0]).as_vec3();
    // Each channel's reading of wave m's pure state: the row turned to the first wave's field
    // (S1 there is the first wave's state, its negative the second's).
    let reading = |p: &PathPolarisation, m: Mode| -> [f32; MAX_CHANNELS] {
        let mut q = *p;
        q.rotate_to(field, light);
        let sign = if m == modes[0] { 1.0 } else { -1.0 };
        std::array::from_fn(|c| (1.0 + sign * q.w[c][0]).max(0.0))
    };
    let mode = if u < 0.5 * f64::from(reading(pol, modes[0])[0]) {
        modes[0]
    } else {
        modes[1]
    };
    let sensor = reading(pol, mode);
    if let Some(r) = rows
        && !r.settled
    {
        for j in 0..ROWS {
            let own = reading(&r.rows[j], mode);
            r.rescale(j, own, sensor);
        }
    }
    let k = std::array::from_fn(|c| {
        if sensor[0] > 0.0 {
            sensor[c] / sensor[0]
        } else {
            0.0
        }
    });
    *pol = crystal::pure_state(optics, ray, mode);
    k
}

/// The transmittance over distance `t` of a pleochroic crystal for the wave the path's segment
/// carries, the camera ray travelling along `dir` (unit). Uniaxial: `exp(−σ t)` with `σ = σ_ω`
/// for the ordinary wave and `σ_ω cos² θ + σ_ε sin² θ` for the extraordinary, `θ` between its
/// wave normal and the axis; biaxial: `σ = Σ (D̂·aᵢ)² σᵢ` over the principal axes, `D̂` the
/// wave's unit displacement ([`crate::polarisation::optics::Optics::absorption_weights`]). A
/// segment that has no wave yet (after a depolarising vertex) takes one, each with probability ½
/// and weight 1 (the unpolarised row is the mean of the two orthogonal waves'), with
/// `u ∈ [0, 1)`.
///
/// A thin section ([`CrystalOptics::thin_nm`]) is [`thin_section`] instead. The Stokes AOVs'
/// `rows` follow.
pub(super) fn pleochroic_transmittance<S: Spectral>(
    crystal: &CrystalOptics,
    pol: &mut PathPolarisation,
    mut rows: Option<&mut StokesRows>,
    dir: Vec3,
    t: f32,
    u: f32,
    lambda: &S::Wavelengths,
) -> S {
    if let Some(nm) = crystal.thin_nm {
        return thin_section::<S>(crystal, nm, pol, rows, dir, t, lambda);
    }
    let optics = crystal.at(f64::from(crystal.no), None);
    let optics = match (crystal.biaxial, optics) {
        // The uniaxial extraordinary index as the d line's f32 sum (as it always was).
        (None, Optics::Uniaxial(x)) => Optics::Uniaxial(Uniaxial {
            ne: f64::from(crystal.no + crystal.birefringence),
            ..x
        }),
        (_, o) => o,
    };
    let ray = dir.as_dvec3();
    let modes = optics.modes();
    // A segment after a platelet's reflection takes a wave by the row's polarisation.
    let mut channels = None;
    let mode = match pol.mode {
        Some(m) => m,
        None if pol.is_unpolarised() => {
            let m = if u < 0.5 { modes[0] } else { modes[1] };
            *pol = crystal::pure_state(&optics, ray, m);
            m
        }
        None => {
            let r = rows.as_deref_mut();
            channels = Some(take_wave(&optics, pol, r, ray, f64::from(u)));
            pol.mode.unwrap_or(modes[0])
        }
    };
    let sigma = match (mode, &optics) {
        (Mode::O, _) => crystal.sigma[0],
        (_, Optics::Uniaxial(x)) => {
            let k = optics.wave_of_ray(ray, mode);
            let c2 = k.dot(x.axis).powi(2) as f32;
            crystal.sigma[0] * c2 + crystal.sigma[1] * (1.0 - c2)
        }
        (_, Optics::Biaxial(_)) => {
            // The wave normal its boundary made, where the path knows it.
            let s = if pol.normal.as_dvec3().dot(ray) > 0.0 {
                pol.normal.as_dvec3().normalize()
            } else {
                optics.wave_of_ray(ray, mode)
            };
            let w = optics
                .absorption_weights_of(s, ray, mode)
                .unwrap_or([1.0 / 3.0; 3]);
            crystal.sigma[0] * (w[0] as f32)
                + crystal.sigma[1] * (w[1] as f32)
                + crystal.sigma[2] * (w[2] as f32)
        }
    };
    if let Some(r) = rows {
        r.follow(pol);
    }
    let tr = S::from_unbounded(sigma, lambda).map(|s| (-s * t).exp());
    match channels {
        Some(k) => tr * S::from_channels(|c| k[c]),
        None => tr,
    }
}

/// Wavelengths (nm) a thin section's retardance is evaluated at in RGB transport, per channel:
/// about the dominant wavelengths of the sRGB primaries (a thin section turns spectral transport
/// on; these serve a render forced to RGB).
const RGB_NM: [f32; MAX_CHANNELS] = [610.0, 550.0, 465.0, 550.0];

/// A thin section's interior over distance `t` along the camera ray's `dir` (unit): its two
/// waves travel together (walk-off neglected) and leave coherently, so the segment is one linear
/// retarder and diattenuator — the Jones matrix `diag(a₁, a₂ e^{iδ})` in the frame of the first
/// wave's field, `δ = 2π t d_nm (n₂ − n₁) / λ` per channel's wavelength and `aⱼ = exp(−σⱼ t / 2)`
/// each wave's amplitude transmittance (Born & Wolf §15.4.4) — applied to the path's row and
/// the Stokes AOVs' `rows`. Returns the throughput factor per channel.
fn thin_section<S: Spectral>(
    crystal: &CrystalOptics,
    nm_per_unit: f32,
    pol: &mut PathPolarisation,
    rows: Option<&mut StokesRows>,
    dir: Vec3,
    t: f32,
    lambda: &S::Wavelengths,
) -> S {
    let optics = crystal.at(f64::from(crystal.no), None);
    let ray = dir.as_dvec3();
    let [m1, m2] = optics.modes();
    let x1 = optics.field(ray, m1).as_vec3();
    // The retardation `d (n₂ − n₁)` at the d line, and at each channel's wavelength where an
    // index has its own law (the body's index there from its law, if dispersive).
    let path_nm = f64::from(t) * f64::from(nm_per_unit);
    let retardation_d = path_nm * (optics.index(ray, m2) - optics.index(ray, m1));
    let own_laws = crystal.laws.iter().any(Option::is_some);
    let retardation = |nm: Option<f32>| match nm {
        Some(l) if own_laws => {
            let n = crystal.body_law.map_or(crystal.no, |b| b.at(l));
            let o = crystal.at(f64::from(n), Some(l));
            path_nm * (o.index(ray, m2) - o.index(ray, m1))
        }
        _ => retardation_d,
    };
    let sigma = match &optics {
        // The ordinary wave absorbs σ_ω, the extraordinary σ_ω cos² θ + σ_ε sin² θ (its wave
        // normal is the ray here).
        Optics::Uniaxial(x) => {
            let c2 = ray.dot(x.axis).powi(2) as f32;
            [
                crystal.sigma[0],
                crystal.sigma[0] * c2 + crystal.sigma[1] * (1.0 - c2),
            ]
        }
        Optics::Biaxial(_) => [m1, m2].map(|m| {
            let w = optics.absorption_weights(ray, m).unwrap_or([1.0 / 3.0; 3]);
            crystal.sigma[0] * (w[0] as f32)
                + crystal.sigma[1] * (w[1] as f32)
                + crystal.sigma[2] * (w[2] as f32)
        }),
    };
    let [s1, s2] = sigma.map(|s| S::from_unbounded(s, lambda));
    let m: [Mueller; MAX_CHANNELS] = std::array::from_fn(|c| {
        let (a1, a2) = if c < S::CHANNELS {
            (s1.channel(c), s2.channel(c))
        } else {
            (0.0, 0.0)
        };
        let own = S::wavelength_nm(lambda, c);
        let nm = own.unwrap_or(RGB_NM[c]);
        let delta = std::f64::consts::TAU * retardation(own) / f64::from(nm);
        Mueller::diagonal_jones(
            C::from(f64::from((-0.5 * a1 * t).exp())),
            C::from_polar(f64::from((-0.5 * a2 * t).exp()), delta),
        )
    });
    let d = -dir;
    let k = pol.element(x1, d, &m);
    if let Some(r) = rows
        && !r.settled
    {
        for j in 0..ROWS {
            let kj = r.rows[j].element(x1, d, &m);
            r.rescale(j, kj, k);
        }
    }
    S::from_channels(|c| m[c].0[0][0] as f32 * k[c])
}

/// The pleochroic crystal a segment in `medium` crosses, with the number that picks its wave
/// where it has none yet (drawn on every segment inside a pleochroic crystal; other scenes draw
/// nothing).
pub(super) fn pleochroic_segment<'w>(
    world: &'w super::world::World,
    medium: crate::geometry::MediumId,
    sampler: &mut crate::sampler::PixelSampler,
) -> Option<(&'w CrystalOptics, f32)> {
    let c = world
        .crystal
        .as_ref()
        .filter(|c| c.pleochroic() || c.thin_nm.is_some())?;
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
    // A thin section's boundary refracts as an isotropic one (its waves leave together).
    let c = world.crystal.as_ref().filter(|c| c.thin_nm.is_none())?;
    (matches!(hit, super::world::Hit::Stone(_)) && sb.interface_eta::<S>(0, lambda).is_some())
        .then_some(c)
}
