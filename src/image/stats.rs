//! Statistics for image comparison: the complementary error function, the two-sided normal
//! quantile and Šidák's correction for many simultaneous tests (Šidák, "Rectangular confidence
//! regions for the means of multivariate normal distributions", JASA 62, 1967).

/// Two-sided standard normal quantile: the `z ≥ 0` with `P(|Z| > z) = p` for `Z ~ N(0, 1)`.
/// `p ≥ 1` gives 0, `p ≤ 0` (or NaN) gives +∞.
pub fn normal_quantile_two_sided(p: f64) -> f64 {
    if p >= 1.0 {
        return 0.0;
    }
    if !(p > 0.0) {
        return f64::INFINITY;
    }
    // P(|Z| > z) = erfc(z/√2) decreases in z; bisect it (on the logarithm, for tiny p).
    let target = p.ln();
    let tail = |z: f64| erfc(z * std::f64::consts::FRAC_1_SQRT_2).ln();
    let (mut lo, mut hi) = (0.0f64, 38.0f64);
    if tail(hi) > target {
        return hi;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if tail(mid) > target {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-14 * hi {
            break;
        }
    }
    0.5 * (lo + hi)
}

/// Šidák's per-test significance `1 − (1 − α)^(1/n)` for `n` tests at family-wise `α`.
pub fn sidak(alpha: f64, n: usize) -> f64 {
    // Through ln_1p/exp_m1: exact even when the result is far below machine epsilon.
    -((-alpha).ln_1p() / n.max(1) as f64).exp_m1()
}

/// The complementary error function to about 1e-14 relative accuracy for `x ≥ 0`
/// (`erfc(−x) = 2 − erfc(x)` below 0).
pub fn erfc(x: f64) -> f64 {
    if x.is_nan() {
        return f64::NAN;
    }
    if x < 0.0 {
        return 2.0 - erfc(-x);
    }
    let two_over_sqrt_pi = std::f64::consts::FRAC_2_SQRT_PI;
    if x < 2.5 {
        // erf(x) = 2/√π · e^(−x²) · Σ 2ⁿ x^(2n+1) / (1·3·…·(2n+1)): all terms positive.
        let (x2, mut term, mut sum) = (x * x, x, x);
        for n in 1..200 {
            term *= 2.0 * x2 / (2 * n + 1) as f64;
            sum += term;
            if term < 1e-17 * sum {
                break;
            }
        }
        1.0 - two_over_sqrt_pi * (-x2).exp() * sum
    } else {
        // Continued fraction erfc(x) = e^(−x²)/√π · 1/(x + (1/2)/(x + 1/(x + (3/2)/(x + …)))),
        // evaluated by the modified Lentz method.
        let tiny = 1e-300;
        let mut f = x;
        let (mut c, mut d) = (x, 0.0);
        for k in 1..500 {
            let a = 0.5 * k as f64;
            d = x + a * d;
            d = if d.abs() < tiny { tiny } else { d };
            c = x + a / c;
            c = if c.abs() < tiny { tiny } else { c };
            d = 1.0 / d;
            let delta = c * d;
            f *= delta;
            if (delta - 1.0).abs() < 1e-16 {
                break;
            }
        }
        0.5 * two_over_sqrt_pi * (-x * x).exp() / f
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantile_matches_known_values() {
        for (p, z) in [
            (0.05, 1.959_963_984_540_054),
            (0.01, 2.575_829_303_548_901),
            (1e-6, 4.891_638_475_699_412),
            (1e-9, 6.109_410_204_869_99),
            (0.5, 0.674_489_750_196_082),
        ] {
            let q = normal_quantile_two_sided(p);
            assert!((q - z).abs() < 1e-9, "p {p}: {q} vs {z}");
        }
        assert_eq!(normal_quantile_two_sided(1.0), 0.0);
        assert_eq!(normal_quantile_two_sided(0.0), f64::INFINITY);
        assert_eq!(normal_quantile_two_sided(f64::NAN), f64::INFINITY);
        // erfc across the series / continued-fraction seam and in the far tail.
        assert!((erfc(0.5) - 0.479_500_122_186_953_5).abs() < 1e-15);
        assert!((erfc(2.5) / 4.069_520_174_449_59e-4 - 1.0).abs() < 1e-12);
        assert!((erfc(6.0) / 2.151_973_671_249_891e-17 - 1.0).abs() < 1e-12);
        assert!((erfc(-1.0) - 1.842_700_792_949_715).abs() < 1e-15);
        // Šidák: (1 − α_i)^n = 1 − α, and α_i ≈ α/n for small α.
        let a = sidak(0.01, 2304);
        assert!(((1.0 - a).powi(2304) - 0.99).abs() < 1e-12);
        assert!((a / (0.01 / 2304.0) - 1.0).abs() < 0.01);
        assert_eq!(sidak(0.01, 1), 0.01);
    }
}
