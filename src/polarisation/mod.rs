//! Polarised light and crystal optics: Stokes vectors, Mueller matrices, the Fresnel matrices of
//! dielectric and conductor interfaces, refraction into a uniaxial or biaxial crystal, and the polarised
//! transport the path loop runs when a scene calls for it ([`transport`]: the camera's Stokes
//! row carried per channel). Tested against closed forms (Malus's law, Brewster's angle, the
//! retardance of total internal reflection and Fresnel's rhomb, energy balance, the scalar
//! Fresnel equations of [`crate::bsdf::fresnel`], Snell's law for the ordinary wave and the index
//! ellipsoid's walk-off for the extraordinary one); renders in `tests/polarisation.rs`.
//!
//! # Conventions
//!
//! Written once here, after Wilkie & Weidlich, "Polarised Light in Computer Graphics" (SIGGRAPH
//! Asia 2012 course) and Collett, *Field Guide to Polarization* (SPIE, 2005):
//!
//! - A Stokes vector `(S0, S1, S2, S3)` is measured in a **reference frame**: a unit `x` axis
//!   orthogonal to the direction of propagation `d` (the frame's `y` is `d × x`). `S0` is the
//!   intensity, `S1 = I(x) − I(y)`, `S2 = I(+45°) − I(−45°)` (45° from `x` toward `y`),
//!   `S3 = I(right) − I(left)` circular. A physical vector has `S0 ≥ |(S1, S2, S3)|`.
//! - A Mueller matrix maps the Stokes vector of light entering an element, in the element's input
//!   frame, to the light leaving it, in its output frame. At an interface both frames have `x`
//!   along the **s** direction (perpendicular to the plane of incidence) and `y` along **p**.
//! - Angles of polarisers and frame rotations are measured from `x` toward `y`.
//! - Jones amplitudes use the time dependence `e^{−iωt}` (Born & Wolf); `S3 > 0` is then the
//!   polarisation whose `y` component lags.

pub mod biaxial;
mod biaxial_boundary;
pub mod boundary;
pub mod crystal;
pub mod cvec;
pub mod etendue;
pub mod event;
pub mod fresnel;
pub mod interference;
pub mod mueller;
pub mod optics;
pub mod quartic;
pub mod stokes;
pub mod transport;
pub mod uniaxial;
mod uniaxial_boundary;

pub use mueller::Mueller;

/// A Stokes vector `(S0, S1, S2, S3)` in some reference frame (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stokes(pub [f64; 4]);

impl Stokes {
    /// Unpolarised light of intensity `i`.
    pub fn unpolarised(i: f64) -> Stokes {
        Stokes([i, 0.0, 0.0, 0.0])
    }

    /// Light of intensity `i` linearly polarised at `angle` radians from the frame's `x` axis.
    pub fn linear(i: f64, angle: f64) -> Stokes {
        Stokes([i, i * (2.0 * angle).cos(), i * (2.0 * angle).sin(), 0.0])
    }

    /// The intensity `S0`.
    pub fn intensity(self) -> f64 {
        self.0[0]
    }

    /// Degree of polarisation `|(S1, S2, S3)| / S0` (0 for black light).
    pub fn degree(self) -> f64 {
        let [s0, s1, s2, s3] = self.0;
        if s0 > 0.0 {
            (s1 * s1 + s2 * s2 + s3 * s3).sqrt() / s0
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_light_is_fully_polarised_and_unpolarised_light_not() {
        for a in [0.0, 0.3, 1.0, 2.5] {
            let s = Stokes::linear(2.0, a);
            assert!((s.degree() - 1.0).abs() < 1e-12 && s.intensity() == 2.0);
        }
        assert_eq!(Stokes::unpolarised(1.0).degree(), 0.0);
        assert_eq!(Stokes::unpolarised(0.0).degree(), 0.0);
        // Horizontal is +S1, vertical −S1, +45° is +S2.
        assert!((Stokes::linear(1.0, 0.0).0[1] - 1.0).abs() < 1e-12);
        assert!((Stokes::linear(1.0, std::f64::consts::FRAC_PI_2).0[1] + 1.0).abs() < 1e-12);
        assert!((Stokes::linear(1.0, std::f64::consts::FRAC_PI_4).0[2] - 1.0).abs() < 1e-12);
    }
}
