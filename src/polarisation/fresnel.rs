//! The Fresnel equations as Mueller matrices: reflection and refraction at a dielectric interface
//! (total internal reflection's retardance included) and reflection from a conductor, from the
//! complex s and p amplitude coefficients (Born & Wolf, *Principles of Optics*, 7th ed., §1.5.2;
//! §1.5.4 for total reflection). Frames: `x` along s, `y` along p, on both sides (see [`super`]).

use super::Mueller;
use num_complex::Complex64;

/// The complex amplitude coefficients of one interface at one angle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Amplitudes {
    /// Reflected s amplitude over incident.
    pub rs: Complex64,
    /// Reflected p amplitude over incident.
    pub rp: Complex64,
    /// Transmitted s amplitude over incident.
    pub ts: Complex64,
    /// Transmitted p amplitude over incident.
    pub tp: Complex64,
    /// `η cos θt`: the transmitted wave's normal wave number over the incident medium's (complex
    /// under total internal reflection and for conductors; its real part carries the power).
    pub eta_cos_t: Complex64,
}

/// The amplitude coefficients for light arriving at `cos_i ∈ [0, 1]` to the normal on an interface
/// whose far side has relative index `eta` (far over near; complex `n + ik` for a conductor).
///
/// `η cos θt = √(η² − sin² θi)` on the principal branch: under total internal reflection and in
/// a conductor its imaginary part is positive, the wave decaying into the far side with the
/// time dependence `e^{−iωt}`.
pub fn amplitudes(cos_i: f64, eta: Complex64) -> Amplitudes {
    let c = cos_i.clamp(0.0, 1.0);
    let sin2 = 1.0 - c * c;
    let eta_cos_t = (eta * eta - sin2).sqrt();
    let eta2_c = eta * eta * c;
    // r_s = (cos i − η cos t)/(cos i + η cos t); r_p = (η² cos i − η cos t)/(η² cos i + η cos t),
    // i.e. (η cos i − cos t)/(η cos i + cos t) written without dividing by η.
    let safe = |num: Complex64, den: Complex64| {
        if den.norm_sqr() > 0.0 {
            num / den
        } else {
            // Grazing incidence on an index-matched interface: the limit of both ratios is −1
            // for reflection (every interface reflects everything at grazing), 0 for refraction.
            -num.unscale(num.norm().max(f64::MIN_POSITIVE))
        }
    };
    let rs = safe(c - eta_cos_t, c + eta_cos_t);
    let rp = safe(eta2_c - eta_cos_t, eta2_c + eta_cos_t);
    let two_c = Complex64::new(2.0 * c, 0.0);
    let ts = safe(two_c, c + eta_cos_t);
    let tp = safe(two_c * eta, eta2_c + eta_cos_t);
    Amplitudes {
        rs,
        rp,
        ts,
        tp,
        eta_cos_t,
    }
}

/// Reflection from a dielectric of relative index `eta` (far over near, real) at `cos_i`: total
/// internal reflection (`eta < 1` beyond the critical angle) reflects everything and retards p
/// against s.
pub fn dielectric_reflection(cos_i: f64, eta: f64) -> Mueller {
    let a = amplitudes(cos_i, Complex64::new(eta, 0.0));
    Mueller::diagonal_jones(a.rs, a.rp)
}

/// Refraction into a dielectric of relative index `eta` at `cos_i`, as power (the transmitted
/// intensity over the incident, `Re(η cos θt) / cos θi · |t|²`, so that reflection and refraction
/// add to 1); `None` under total internal reflection or at grazing incidence. Radiance picks up
/// a further `η²` (its compression into the denser medium's solid angle), left to the transport.
pub fn dielectric_transmission(cos_i: f64, eta: f64) -> Option<Mueller> {
    let a = amplitudes(cos_i, Complex64::new(eta, 0.0));
    let power = a.eta_cos_t.re / cos_i;
    if !(a.eta_cos_t.im == 0.0 && a.eta_cos_t.re > 0.0 && cos_i > 0.0) {
        return None;
    }
    let m = Mueller::diagonal_jones(a.ts, a.tp);
    Some(Mueller(m.0.map(|row| row.map(|v| v * power))))
}

/// Reflection from a conductor of complex relative index `n + ik` at `cos_i`.
pub fn conductor_reflection(cos_i: f64, n: f64, k: f64) -> Mueller {
    let a = amplitudes(cos_i, Complex64::new(n, k));
    Mueller::diagonal_jones(a.rs, a.rp)
}

#[cfg(test)]
mod tests {
    use super::super::Stokes;
    use super::*;
    use crate::bsdf::fresnel;

    fn angles() -> impl Iterator<Item = f64> {
        (0..=400).map(|i| (f64::from(i) / 400.0).min(1.0))
    }

    /// The unpolarised element `M00` is the scalar Fresnel reflectance of `bsdf::fresnel`
    /// (written independently, in `f32`), inside and outside, dielectric and conductor.
    #[test]
    fn unpolarised_reflectance_is_the_scalar_fresnel_equations() {
        for eta in [1.33, 1.5, 2.4175, 1.0 / 1.5, 1.0 / 2.4175] {
            for c in angles() {
                let m = dielectric_reflection(c, eta);
                let want = f64::from(fresnel::dielectric(c as f32, eta as f32));
                assert!(
                    (m.0[0][0] - want).abs() < 2e-6,
                    "η {eta} cos {c}: {} vs {want}",
                    m.0[0][0]
                );
            }
        }
        for (n, k) in [(0.27, 3.41), (1.5, 0.0), (0.05, 4.2), (2.9, 3.0)] {
            for c in angles() {
                let m = conductor_reflection(c, n, k);
                let want = f64::from(fresnel::conductor(c as f32, n as f32, k as f32));
                assert!((m.0[0][0] - want).abs() < 2e-6, "{n}+{k}i cos {c}");
            }
        }
    }

    /// At Brewster's angle `tan θB = η` the p amplitude vanishes: unpolarised light reflects fully
    /// s-polarised (`S1 = S0`); on either side it is partly polarised with s dominant (up to the
    /// critical angle from inside).
    #[test]
    fn p_vanishes_at_brewsters_angle() {
        for eta in [1.33f64, 1.5, 2.4175, 1.0 / 1.5] {
            let brewster = eta.atan();
            let a = amplitudes(brewster.cos(), Complex64::new(eta, 0.0));
            assert!(a.rp.norm() < 1e-12, "η {eta}: |rp| {}", a.rp.norm());
            let out = dielectric_reflection(brewster.cos(), eta).apply(Stokes::unpolarised(1.0));
            assert!((out.0[1] / out.0[0] - 1.0).abs() < 1e-9, "{out:?}");
            // Either side, short of total internal reflection (which reflects both alike).
            for off in [-0.2, 0.2]
                .into_iter()
                .filter(|o| (brewster + o).sin() < eta)
            {
                let c = (brewster + off).cos();
                let o = dielectric_reflection(c, eta).apply(Stokes::unpolarised(1.0));
                assert!(o.0[1] > 0.0 && o.0[1] < o.0[0], "{o:?}");
            }
        }
    }

    /// Reflected and refracted power add to 1 for s, p, ±45° and circular light at every angle
    /// outside total internal reflection.
    #[test]
    fn reflection_and_refraction_conserve_energy_per_polarisation() {
        let inputs = [
            Stokes::linear(1.0, 0.0),
            Stokes::linear(1.0, std::f64::consts::FRAC_PI_2),
            Stokes::linear(1.0, 0.7),
            Stokes([1.0, 0.0, 0.0, 1.0]),
        ];
        for eta in [1.5, 2.4175, 1.0 / 1.5] {
            for c in angles().filter(|&c| c > 0.0) {
                let Some(t) = dielectric_transmission(c, eta) else {
                    assert!(
                        eta < 1.0 && (1.0 - c * c) >= eta * eta,
                        "TIR only: η {eta} cos {c}"
                    );
                    continue;
                };
                let r = dielectric_reflection(c, eta);
                for s in inputs {
                    let sum = r.apply(s).intensity() + t.apply(s).intensity();
                    assert!((sum - 1.0).abs() < 1e-12, "η {eta} cos {c} {s:?}: {sum}");
                    // Neither output is over-polarised.
                    assert!(r.apply(s).degree() <= 1.0 + 1e-9 && t.apply(s).degree() <= 1.0 + 1e-9);
                }
            }
        }
    }

    /// Total internal reflection keeps all the light and retards p against s by `δ` with
    /// `tan(δ/2) = cos θ √(sin² θ − η²) / sin² θ` (Born & Wolf §1.5.4, eq. 60); Fresnel's rhomb
    /// (glass n 1.51 at 54.6°) gets 45° from one reflection, which two turn into a quarter wave.
    #[test]
    fn total_internal_reflection_retards_by_its_formula() {
        let eta = 1.0f64 / 1.51;
        let critical = eta.asin();
        for i in 1..200 {
            let theta = critical + (std::f64::consts::FRAC_PI_2 - critical) * f64::from(i) / 200.0;
            let m = dielectric_reflection(theta.cos(), eta);
            assert!((m.0[0][0] - 1.0).abs() < 1e-12 && m.0[0][1].abs() < 1e-12);
            let delta = m.0[2][3].atan2(m.0[2][2]).abs();
            let s2 = theta.sin().powi(2);
            let want = 2.0 * (theta.cos() * (s2 - eta * eta).sqrt() / s2).atan();
            assert!((delta - want).abs() < 1e-9, "θ {theta}: {delta} vs {want}");
        }
        let rhomb = dielectric_reflection(54.6f64.to_radians().cos(), eta);
        let delta = rhomb.0[2][3].atan2(rhomb.0[2][2]).abs().to_degrees();
        assert!((delta - 45.0).abs() < 0.1, "Fresnel's rhomb: {delta}°");
        // Two such reflections turn +45° linear light circular.
        let out = rhomb
            .then_after(&rhomb)
            .apply(Stokes::linear(1.0, std::f64::consts::FRAC_PI_4));
        assert!(out.0[3].abs() > 0.999, "{out:?}");
    }
}
