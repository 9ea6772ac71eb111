//! The sigmoid-polynomial spectrum of Jakob & Hanika 2019 ([`super`]): the sigmoid, its inverse
//! and the spectrum type.

use crate::spectrum::cie::{LAMBDA_MAX, LAMBDA_MIN};

/// The wavelength span of the normalised variable `t`, nm.
const SPAN: f32 = LAMBDA_MAX - LAMBDA_MIN;

/// The sigmoid `S(x) = 1/2 + x / (2 √(1 + x²))` of the paper, in (0, 1); `S(−∞) = 0`,
/// `S(+∞) = 1`. For `x < 0` it is evaluated as `1 / (2 r (r − x))`, `r = √(1 + x²)` (the same
/// value without cancellation), so dark values keep their relative precision; the result never
/// exceeds 1 despite rounding. NaN gives NaN.
#[inline]
pub fn sigmoid(x: f32) -> f32 {
    if x.abs() > 1e18 {
        // x² would overflow; S(x) is 1/(4x²) below zero (0 in f32 here) and 1 above.
        return if x > 0.0 { 1.0 } else { 0.0 };
    }
    let r = (1.0 + x * x).sqrt();
    if x < 0.0 {
        0.5 / (r * (r - x))
    } else {
        (0.5 + 0.5 * x / r).min(1.0)
    }
}

/// The inverse of [`sigmoid`]: `S⁻¹(y) = (y − 1/2) / √(y (1 − y))`; `−∞` for `y ≤ 0` and `+∞`
/// for `y ≥ 1` (and NaN), which [`sigmoid`] maps back to 0 and 1 exactly.
pub fn sigmoid_inverse(y: f32) -> f32 {
    if y.is_nan() || y >= 1.0 {
        f32::INFINITY
    } else if y <= 0.0 {
        f32::NEG_INFINITY
    } else {
        let y = f64::from(y);
        ((y - 0.5) / (y * (1.0 - y)).sqrt()) as f32
    }
}

/// A sigmoid-polynomial spectrum `scale · S(c0 t² + c1 t + c2)`, `t = (λ − 360 nm) / 470 nm`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sigmoid {
    /// `[c0, c1, c2]`, the polynomial in the normalised wavelength `t ∈ [0, 1]` over 360–830 nm.
    /// `c2` may be ±∞ (with `c0 = c1 = 0`): a flat 0 or 1.
    pub coeffs: [f32; 3],
    /// A factor in `[0, 1]`: 1, except for a reflectance darker than [`super::Z_DARK`], which is the
    /// spectrum of a colour of brightness `Z_DARK` scaled down (module docs).
    pub scale: f32,
}

impl Sigmoid {
    /// The flat spectrum 0.
    pub const ZERO: Sigmoid = Sigmoid::flat_raw(f32::NEG_INFINITY);
    /// The flat spectrum 1.
    pub const ONE: Sigmoid = Sigmoid::flat_raw(f32::INFINITY);

    const fn flat_raw(c2: f32) -> Sigmoid {
        Sigmoid {
            coeffs: [0.0, 0.0, c2],
            scale: 1.0,
        }
    }

    /// The flat spectrum `v` (clamped to [0, 1]; NaN gives 0): `c0 = c1 = 0`, `c2 = S⁻¹(v)`.
    pub fn flat(v: f32) -> Sigmoid {
        if v.is_nan() || v <= 0.0 {
            Sigmoid::ZERO
        } else {
            Sigmoid::flat_raw(sigmoid_inverse(v))
        }
    }

    /// True when the spectrum is constant (`c0 = c1 = 0`).
    pub fn is_flat(&self) -> bool {
        self.coeffs[0] == 0.0 && self.coeffs[1] == 0.0
    }

    /// The polynomial at `lambda_nm` (clamped to 360–830 nm; NaN is taken as 360 nm).
    #[inline]
    fn poly(&self, lambda_nm: f32) -> f32 {
        let [c0, c1, c2] = self.coeffs;
        if c0 == 0.0 && c1 == 0.0 {
            return c2; // flat, possibly ±∞
        }
        let lambda = if lambda_nm >= LAMBDA_MIN {
            lambda_nm.min(LAMBDA_MAX)
        } else {
            LAMBDA_MIN // also NaN
        };
        let t = (lambda - LAMBDA_MIN) / SPAN;
        (c0 * t + c1) * t + c2
    }

    /// The spectrum at `lambda_nm` (nm), in `[0, scale]`. Defined on 360–830 nm; a wavelength
    /// outside is clamped to that range (NaN is taken as 360 nm).
    #[inline]
    pub fn eval(&self, lambda_nm: f32) -> f32 {
        self.scale * sigmoid(self.poly(lambda_nm))
    }

    /// The largest value over 360–830 nm (exact: `S` is increasing, so it is `S` at the
    /// polynomial's maximum, at an end or at the vertex).
    pub fn max_value(&self) -> f32 {
        let [c0, c1, _] = self.coeffs;
        let mut best = self.poly(LAMBDA_MIN).max(self.poly(LAMBDA_MAX));
        if c0 < 0.0 {
            let t = -c1 / (2.0 * c0);
            if (0.0..=1.0).contains(&t) {
                best = best.max(self.poly(LAMBDA_MIN + t * SPAN));
            }
        }
        self.scale * sigmoid(best)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sigmoid_and_inverse() {
        assert_eq!(sigmoid(0.0), 0.5);
        assert_eq!(sigmoid(f32::INFINITY), 1.0);
        assert_eq!(sigmoid(f32::NEG_INFINITY), 0.0);
        assert!((sigmoid(-1e4) - 2.5e-9).abs() < 1e-13, "{}", sigmoid(-1e4));
        assert!((sigmoid(3.0) - (0.5 + 1.5 / 10f32.sqrt())).abs() < 1e-7);
        for y in [1e-6, 0.01, 0.3, 0.5, 0.77, 0.999] {
            assert!(
                (sigmoid(sigmoid_inverse(y)) - y).abs() < 1e-6 * y.max(1e-2),
                "{y}"
            );
        }
        assert_eq!(sigmoid_inverse(0.0), f32::NEG_INFINITY);
        assert_eq!(sigmoid_inverse(1.0), f32::INFINITY);
    }

    #[test]
    fn max_value_is_the_largest_sample() {
        for coeffs in [
            [-40.0, 30.0, -4.0],
            [25.0, -20.0, 1.0],
            [3.0, 2.0, -1.0],
            [-5.0, 1.0, 0.5],
        ] {
            let s = Sigmoid { coeffs, scale: 0.8 };
            let brute = (0..=4700)
                .map(|i| s.eval(360.0 + i as f32 * 0.1))
                .fold(0.0, f32::max);
            assert!(
                (s.max_value() - brute).abs() < 1e-5,
                "{coeffs:?}: {} vs {brute}",
                s.max_value()
            );
        }
        assert_eq!(
            Sigmoid::flat(0.25).max_value(),
            Sigmoid::flat(0.25).eval(400.0)
        );
    }

    #[test]
    fn wavelengths_outside_the_range_are_clamped() {
        let s = Sigmoid {
            coeffs: [10.0, -3.0, -2.0],
            scale: 1.0,
        };
        assert_eq!(s.eval(300.0), s.eval(360.0));
        assert_eq!(s.eval(f32::NAN), s.eval(360.0));
        assert_eq!(s.eval(1e9), s.eval(830.0));
        assert_ne!(s.eval(360.0), s.eval(830.0));
    }
}
