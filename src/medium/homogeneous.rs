//! A homogeneous medium: constant absorption and scattering coefficients per channel and one
//! Henyey–Greenstein phase function. Free flight is sampled as described in [`super`]; a medium
//! that does not scatter (`σs = 0`, or scattering turned off by the `medium-scattering` knob) is
//! not sampled at all: its transmittance `exp(−σa t)` (Beer–Lambert) multiplies the throughput.

use super::{FreeFlight, HenyeyGreenstein};
use crate::color::Rgb;
use crate::spectrum::Spectral;
use crate::spectrum::measured::Measured;

/// A coefficient at the wavelengths: the measured spectrum where there is one, else the RGB
/// value's spectrum.
#[inline]
fn coefficient<S: Spectral>(rgb: Rgb, measured: Option<&Measured>, lambda: &S::Wavelengths) -> S {
    match measured {
        Some(m) => S::from_measured(m, rgb, lambda),
        None => S::from_unbounded(rgb, lambda),
    }
}

/// Constant coefficients, per world unit of length, and a phase function.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Homogeneous {
    /// Absorption coefficient `σa` per channel, per world unit, ≥ 0.
    pub sigma_a: Rgb,
    /// Scattering coefficient `σs` per channel, per world unit, ≥ 0.
    pub sigma_s: Rgb,
    /// The phase function at scattering points.
    pub phase: HenyeyGreenstein,
    /// A measured absorption spectrum, per world unit (`sigma_a` is then its RGB projection):
    /// spectral paths read it at their wavelengths. Interned ([`Measured::intern`]): a reference
    /// keeps the medium small (an inline spectrum made it 400 bytes larger and RGB renders
    /// through media measurably slower).
    pub sigma_a_measured: Option<&'static Measured>,
    /// A measured scattering spectrum, per world unit (`sigma_s` is its RGB projection).
    pub sigma_s_measured: Option<&'static Measured>,
}

/// `exp(−σ t)` per channel, exactly 1 where `σ = 0` (also for `t = ∞`).
#[inline]
fn transmittance<S: Spectral>(sigma_t: S, t: f32) -> S {
    sigma_t.map(|s| if s > 0.0 { (-s * t).exp() } else { 1.0 })
}

impl Homogeneous {
    /// Whether the medium scatters in any channel.
    #[inline]
    pub fn scatters(&self) -> bool {
        self.sigma_s.0.iter().any(|&s| s > 0.0)
            || self.sigma_s_measured.is_some_and(|m| m.max() > 0.0)
    }

    /// The same medium without scattering: light that would scatter continues straight on, so
    /// only absorption remains (`σt = σa`); the `medium-scattering=off` approximation.
    pub fn without_scattering(self) -> Self {
        Homogeneous {
            sigma_s: Rgb::ZERO,
            sigma_s_measured: None,
            ..self
        }
    }

    /// The single-scattering albedo `σs / σt` per channel (0 where `σt = 0`).
    pub fn albedo(&self) -> Rgb {
        let t = self.sigma_a + self.sigma_s;
        Rgb(std::array::from_fn(|c| {
            if t.0[c] > 0.0 {
                self.sigma_s.0[c] / t.0[c]
            } else {
                0.0
            }
        }))
    }

    /// See [`super::Medium::transmittance`].
    #[inline]
    pub fn transmittance<S: Spectral>(&self, t: f32, lambda: &S::Wavelengths) -> S {
        let sigma_t = coefficient::<S>(self.sigma_a, self.sigma_a_measured, lambda)
            + coefficient::<S>(self.sigma_s, self.sigma_s_measured, lambda);
        transmittance(sigma_t, t)
    }

    /// See [`super::Medium::collision`].
    #[inline]
    pub fn collision<S: Spectral>(&self, hero: usize, u: f32, lambda: &S::Wavelengths) -> f32 {
        if !self.scatters() {
            return f32::INFINITY;
        }
        let sigma_t = coefficient::<S>(self.sigma_a, self.sigma_a_measured, lambda)
            + coefficient::<S>(self.sigma_s, self.sigma_s_measured, lambda);
        distance(sigma_t.channel(hero), u)
    }

    /// See [`super::Medium::free_flight`].
    #[inline]
    pub fn free_flight<S: Spectral>(
        &self,
        t_max: f32,
        hero: usize,
        u: f32,
        lambda: &S::Wavelengths,
    ) -> FreeFlight<S> {
        let sigma_a = coefficient::<S>(self.sigma_a, self.sigma_a_measured, lambda);
        if !self.scatters() {
            // Nothing is sampled: the same (deterministic) event for every channel.
            return FreeFlight::Pass {
                value: transmittance(sigma_a, t_max),
                pdf: S::ONE,
            };
        }
        let sigma_s = coefficient::<S>(self.sigma_s, self.sigma_s_measured, lambda);
        let sigma_t = sigma_a + sigma_s;
        let t = distance(sigma_t.channel(hero), u);
        if t < t_max {
            let tr = transmittance(sigma_t, t);
            FreeFlight::Scatter {
                t,
                value: tr * sigma_s,
                pdf: sigma_t * tr,
            }
        } else {
            let tr = transmittance(sigma_t, t_max);
            FreeFlight::Pass { value: tr, pdf: tr }
        }
    }
}

/// The free-flight distance `−ln(1 − u) / σt` (world units) for the hero channel's extinction
/// `st` (endless where `st ≤ 0`): inversion of the exponential distribution (pbrt-v4 §11.2.2).
#[inline]
fn distance(st: f32, u: f32) -> f32 {
    if st > 0.0 {
        -(1.0 - u).ln() / st
    } else {
        f32::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::{RgbSample, RgbWavelengths};

    fn medium(a: [f32; 3], s: [f32; 3]) -> Homogeneous {
        Homogeneous {
            sigma_a: Rgb(a),
            sigma_s: Rgb(s),
            phase: HenyeyGreenstein::new(0.0),
            sigma_a_measured: None,
            sigma_s_measured: None,
        }
    }

    /// The expected pass weight is the transmittance and the expected scatter weight integrates
    /// `T(t) σs` over the segment, per channel — for chromatic σt (one-sample MIS over channels).
    #[test]
    fn estimator_is_unbiased_per_channel() {
        let m = medium([0.2, 1.0, 3.0], [2.0, 0.5, 0.0]);
        let d = 0.8f32;
        let n = 400_000;
        let (mut pass, mut scat) = ([0.0f64; 3], [0.0f64; 3]);
        // The path-level weight of one event: value / mean over channels of the densities
        // (the hero's density cancels between the throughput and the ratios).
        let w = |value: RgbSample, pdf: RgbSample| value * (1.0 / pdf.average());
        for i in 0..n {
            let hero = i % 3;
            let u = (i / 3) as f32 / (n / 3) as f32 + 0.5 / n as f32;
            match m.free_flight::<RgbSample>(d, hero, u, &RgbWavelengths) {
                FreeFlight::Pass { value, pdf } => {
                    let weight = w(value, pdf);
                    (0..3).for_each(|c| pass[c] += weight[c] as f64)
                }
                FreeFlight::Scatter { t, value, pdf } => {
                    assert!(t > 0.0 && t < d);
                    let weight = w(value, pdf);
                    (0..3).for_each(|c| scat[c] += weight[c] as f64)
                }
            }
        }
        for c in 0..3 {
            let st = f64::from(m.sigma_a.0[c] + m.sigma_s.0[c]);
            let tr = (-st * f64::from(d)).exp();
            let sc = f64::from(m.sigma_s.0[c]) / st * (1.0 - tr);
            let (p, s) = (pass[c] / n as f64, scat[c] / n as f64);
            assert!((p - tr).abs() < 2e-3, "channel {c}: pass {p} vs {tr}");
            assert!((s - sc).abs() < 2e-3, "channel {c}: scatter {s} vs {sc}");
        }
    }

    /// Absorption only: the exact Beer–Lambert factor, no sampling; a zero channel stays 1 even
    /// for an infinite segment.
    #[test]
    fn absorption_only_is_beer_lambert() {
        let m = medium([0.5, 0.0, 2.0], [0.0; 3]);
        let FreeFlight::Pass { value, pdf } =
            m.free_flight::<RgbSample>(f32::INFINITY, 0, 0.5, &RgbWavelengths)
        else {
            panic!("no scattering")
        };
        assert_eq!((value.0, pdf), ([0.0, 1.0, 0.0], RgbSample::ONE));
        let FreeFlight::Pass { value, .. } =
            m.free_flight::<RgbSample>(2.0, 2, 0.5, &RgbWavelengths)
        else {
            panic!("no scattering")
        };
        assert!((value[0] - (-1.0f32).exp()).abs() < 1e-6);
        assert_eq!(
            m.without_scattering(),
            medium([0.5, 0.0, 2.0], [0.0; 3]),
            "idempotent"
        );
    }

    /// A vacuum-like homogeneous medium (σ = 0) passes with weight exactly 1.
    #[test]
    fn clear_medium_passes_exactly() {
        let m = medium([0.0; 3], [0.0; 3]);
        let FreeFlight::Pass { value, pdf } =
            m.free_flight::<RgbSample>(3.0, 1, 0.3, &RgbWavelengths)
        else {
            panic!()
        };
        assert_eq!((value, pdf), (RgbSample::ONE, RgbSample::ONE));
    }

    /// A measured absorption spectrum: spectral paths see `exp(−σa(λ) t)` at each wavelength;
    /// the RGB variant its projection.
    #[test]
    fn measured_absorption_is_read_per_wavelength() {
        use crate::spectrum::HeroSample;
        use crate::spectrum::wavelengths::HeroWavelengths;
        let m = Measured::from_points(
            &[(360.0, 0.2), (550.0, 0.2), (560.0, 3.0), (830.0, 3.0)],
            1e4,
        )
        .unwrap();
        let h = Homogeneous {
            sigma_a: m.to_rgb(),
            sigma_a_measured: Some(m.intern()),
            ..medium([0.0; 3], [0.0; 3])
        };
        let lambda = HeroWavelengths::sample(0.41);
        let t = 0.7;
        let tr = h.transmittance::<HeroSample>(t, &lambda);
        for i in 0..4 {
            let want = (-m.at(lambda.lambda[i]) * t).exp();
            assert!((tr.0[i] - want).abs() < 1e-6, "{} nm", lambda.lambda[i]);
        }
        let rgb = h.transmittance::<RgbSample>(t, &RgbWavelengths);
        for c in 0..3 {
            assert!((rgb.0[c] - (-m.to_rgb()[c] * t).exp()).abs() < 1e-6);
        }
    }

    /// `collision` is the distance at which `free_flight` scatters: the same bits for a segment
    /// longer than it, a pass for one that ends at or before it, and endless without scattering.
    #[test]
    fn the_collision_is_where_the_free_flight_scatters() {
        let m = medium([0.3, 0.5, 0.9], [2.0, 1.5, 0.7]);
        let lambda = RgbWavelengths;
        let mut scattered = 0;
        for i in 0..3000 {
            let u = (i as f32 + 0.5) / 3000.0;
            let hero = i % 3;
            let t = m.collision::<RgbSample>(hero, u, &lambda);
            assert!(t.is_finite() && t > 0.0, "{u}: {t}");
            for t_max in [t * 0.5, t, f32::INFINITY, 1.0] {
                match m.free_flight::<RgbSample>(t_max, hero, u, &lambda) {
                    FreeFlight::Scatter { t: s, .. } => {
                        assert_eq!(s.to_bits(), t.to_bits());
                        assert!(t < t_max);
                        scattered += 1;
                    }
                    FreeFlight::Pass { .. } => assert!(t >= t_max, "{u}: {t} < {t_max}"),
                }
            }
        }
        assert!(scattered > 3000, "{scattered}");
        let clear = medium([0.3, 0.5, 0.9], [0.0; 3]);
        assert_eq!(clear.collision::<RgbSample>(0, 0.5, &lambda), f32::INFINITY);
    }
}
