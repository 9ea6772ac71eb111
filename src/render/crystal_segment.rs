//! A camera path's segment inside a doubly refractive body (polarised transport): the wave it
//! carries — taken by its row after a platelet ([`take_wave`]) —, a pleochroic crystal's
//! absorption of that wave ([`pleochroic_transmittance`]), and a thin section's coherent pair of
//! waves ([`thin_section`]).

use super::world::CrystalOptics;
use crate::polarisation::Mueller;
use crate::polarisation::boundary::Mode;
use crate::polarisation::crystal;
use crate::polarisation::optics::Optics;
use crate::polarisation::stokes::{ROWS, StokesRows};
use crate::polarisation::transport::{MAX_CHANNELS, PathPolarisation};
use crate::polarisation::uniaxial::Uniaxial;
use crate::spectrum::Spectral;
use glam::Vec3;
use num_complex::Complex64 as C;

/// Inside a crystal, a polarised camera row `pol` that carries no wave (after a platelet's
/// reflection) takes one of the crystal's two waves along the unit `ray` (the camera path's
/// direction), and the Stokes AOVs' `rows` with it; returns the wave and the factor of each
/// channel's throughput. The light along the ray is the incoherent sum of the two waves,
/// `Σₘ Lₘ (1, sₘ)` with `sₘ` wave `m`'s pure linear state (the two opposite: their fields are
/// orthogonal), which the row reads as `Σₘ Lₘ (1 + w·sₘ)`. The path takes wave `m` with probability
/// `(1 + w·sₘ) / 2` of channel 0's ratios (½ each for an unpolarised row) and carries its pure
/// row, which reads `2 Lₘ`: weight 1 for channel 0, `(1 + w_c·sₘ) / (1 + w₀·sₘ)` for channel
/// `c`, and each AOV row's factor changes by its reading over the sensor's. `u ∈ [0, 1)`.
pub(super) fn take_wave(
    optics: &Optics,
    pol: &mut PathPolarisation,
    rows: Option<&mut StokesRows>,
    ray: glam::DVec3,
    u: f64,
) -> TakenWave {
    let modes = optics.modes();
    let (light, field) = ((-ray).as_vec3(), optics.field(ray, modes[0]).as_vec3());
    // Each channel's S1 ratio in the first wave's field frame: the first wave's state reads
    // `1 + S1`, the second's `1 − S1`.
    let s1 = |p: &PathPolarisation| -> [f32; MAX_CHANNELS] {
        let mut q = *p;
        q.rotate_to(field, light);
        q.w.map(|w| w[0])
    };
    let sensor_s1 = s1(pol);
    let first = f64::from(1.0 + sensor_s1[0]);
    let (mode, sign) = if u < 0.5 * first {
        (modes[0], 1.0)
    } else {
        (modes[1], -1.0)
    };
    let reading = |s1: [f32; MAX_CHANNELS]| s1.map(|v| (1.0 + sign * v).max(0.0));
    let sensor = reading(sensor_s1);
    if let Some(r) = rows
        && !r.settled
    {
        for j in 0..ROWS {
            let own = reading(s1(&r.rows[j]));
            r.rescale(j, own, sensor);
        }
    }
    let channels = sensor.map(|v| if sensor[0] > 0.0 { v / sensor[0] } else { 0.0 });
    *pol = crystal::pure_state(optics, ray, mode);
    TakenWave { mode, channels }
}

/// The wave a row took ([`take_wave`]) and the factor of each channel's throughput.
#[derive(Clone, Copy, Debug)]
pub(super) struct TakenWave {
    /// The crystal's wave.
    pub mode: Mode,
    /// Per channel, the factor of its throughput.
    pub channels: [f32; MAX_CHANNELS],
}

/// The transmittance over distance `t` of a pleochroic crystal for the wave the path's segment
/// carries, the camera ray travelling along `dir` (unit). Uniaxial: `exp(−σ t)` with `σ = σ_ω`
/// for the ordinary wave and `σ_ω cos² θ + σ_ε sin² θ` for the extraordinary, `θ` between its
/// wave normal and the axis; biaxial: `σ = Σ (D̂·aᵢ)² σᵢ` over the principal axes, `D̂` the
/// wave's unit displacement ([`crate::polarisation::optics::Optics::absorption_weights`]),
/// each principal coefficient's spectrum where the recipe gave one ([`absorption`]). A segment
/// that has no wave yet takes one with `u ∈ [0, 1)`: after a depolarising vertex each with
/// probability ½ and weight 1 (the unpolarised row is the mean of the two orthogonal waves'),
/// after a platelet's conductor by the row it carries ([`take_wave`]).
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
            let taken = take_wave(&optics, pol, rows.as_deref_mut(), ray, f64::from(u));
            channels = Some(taken.channels);
            taken.mode
        }
    };
    // The principal coefficients' shares.
    let w = match (mode, &optics) {
        (Mode::O, _) => [1.0, 0.0, 0.0],
        (_, Optics::Uniaxial(x)) => {
            let k = optics.wave_of_ray(ray, mode);
            let c2 = k.dot(x.axis).powi(2) as f32;
            [c2, 1.0 - c2, 0.0]
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
            w.map(|w| w as f32)
        }
    };
    if let Some(r) = rows {
        r.follow(pol);
    }
    let sigma = absorption::<S>(crystal, w, lambda);
    let tr = sigma.map(|s| (-s * t).exp());
    match channels {
        Some(k) => tr * S::from_channels(|c| k[c]),
        None => tr,
    }
}

/// A crystal's absorption coefficient for a wave that takes the principal coefficients with
/// shares `w`: their spectra mixed per wavelength in spectral transport where the recipe gave
/// spectra (absorption is linear in them), else the mixed colour's spectrum.
fn absorption<S: Spectral>(crystal: &CrystalOptics, w: [f32; 3], lambda: &S::Wavelengths) -> S {
    if S::WAVELENGTH_DIMENSIONS > 0 && crystal.sigma_measured.iter().any(Option::is_some) {
        let mut sum = S::ZERO;
        for ((&w, c), m) in w.iter().zip(crystal.sigma).zip(crystal.sigma_measured) {
            if w != 0.0 {
                sum += m.map_or_else(
                    || S::from_unbounded(c, lambda),
                    |m| S::from_measured(m, c, lambda),
                ) * w;
            }
        }
        sum
    } else {
        let [a, b, c] = crystal.sigma;
        S::from_unbounded(a * w[0] + b * w[1] + c * w[2], lambda)
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
    let shares = match &optics {
        // The ordinary wave absorbs σ_ω, the extraordinary σ_ω cos² θ + σ_ε sin² θ (its wave
        // normal is the ray here).
        Optics::Uniaxial(x) => {
            let c2 = ray.dot(x.axis).powi(2) as f32;
            [[1.0, 0.0, 0.0], [c2, 1.0 - c2, 0.0]]
        }
        Optics::Biaxial(_) => [m1, m2].map(|m| {
            let w = optics.absorption_weights(ray, m).unwrap_or([1.0 / 3.0; 3]);
            w.map(|w| w as f32)
        }),
    };
    let [s1, s2] = shares.map(|w| absorption::<S>(crystal, w, lambda));
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
