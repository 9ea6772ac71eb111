//! `ln`, `exp`, `ln_1p` and `exp_m1` in `f64` as inline polynomial kernels, for the micro-facet
//! exponent `cos^e θh = exp(e/2 · ln(1 − sin²θh))` ([`super::microfacet`]) and its sampler.
//!
//! These are accurate replacements, not approximations: each agrees with the standard library's
//! `f64` function to ~1e-14 relative (`tests` below, over the ranges the micro-facet code uses),
//! so a result rounded to `f32` is the correctly rounded value except in rare ties — more
//! accurate than the `f32` `log1pf`/`expf`/`expm1f` chain they replace, whose three roundings
//! an exponent of 6.6e7 (m = 0.01°) amplifies. Inlined, they avoid three library calls per `D`
//! and leave the loop around them free to vectorise.
//!
//! - `ln`: `x = 2^k m`, `m ∈ [√½, √2)`, `ln m = 2 atanh s`, `s = (m − 1)/(m + 1)`, `|s| ≤ 0.172`,
//!   odd series to `s^17` (truncation < 4e-14 relative).
//! - `exp`: `x = k ln 2 + r`, `|r| ≤ ln 2 / 2`, `ln 2` split in two parts (Cody–Waite), Taylor
//!   series to `r^11` (truncation < 2e-14), then `2^k` by the exponent bits (two steps, so that
//!   results in the subnormal range of `f64` are formed without overflow of the scale).

/// `ln 2` split (fdlibm's constants): the high part has its low 32 bits zero, so `k · LN2_HI` is
/// exact for `|k| < 2²¹`; the low part carries `ln 2 − LN2_HI` to full `f64` precision.
const LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000);
const LN2_LO: f64 = f64::from_bits(0x3dea_39ef_3579_3c76);

/// Natural logarithm of `x`: `−∞` at 0, NaN below 0, `+∞` at `+∞`; subnormal inputs included.
#[inline]
pub fn ln(x: f64) -> f64 {
    if !(x > 0.0 && x < f64::INFINITY) {
        return if x == 0.0 {
            f64::NEG_INFINITY
        } else if x == f64::INFINITY {
            x
        } else {
            f64::NAN
        };
    }
    let mut bits = x.to_bits();
    let mut k: i64 = 0;
    if bits < (1u64 << 52) {
        // Subnormal: scale into the normal range first.
        bits = (x * f64::from_bits(0x4350_0000_0000_0000)).to_bits(); // × 2⁵⁴
        k = -54;
    }
    k += ((bits >> 52) as i64) - 1023;
    let mut m = f64::from_bits((bits & ((1u64 << 52) - 1)) | (1023u64 << 52));
    if m > std::f64::consts::SQRT_2 {
        m *= 0.5;
        k += 1;
    }
    let s = (m - 1.0) / (m + 1.0);
    let s2 = s * s;
    // 2 (s + s³/3 + … + s¹⁷/17), Horner in s².
    let p = 1.0 / 17.0;
    let p = p * s2 + 1.0 / 15.0;
    let p = p * s2 + 1.0 / 13.0;
    let p = p * s2 + 1.0 / 11.0;
    let p = p * s2 + 1.0 / 9.0;
    let p = p * s2 + 1.0 / 7.0;
    let p = p * s2 + 1.0 / 5.0;
    let p = p * s2 + 1.0 / 3.0;
    let p = p * s2 + 1.0;
    let kf = k as f64;
    kf * LN2_HI + (2.0 * s * p + kf * LN2_LO)
}

/// `e^x`: 0 below −746 (below the smallest `f64`), `+∞` above 710, NaN for NaN.
#[inline]
pub fn exp(x: f64) -> f64 {
    if !(x > -746.0) {
        return if x.is_nan() { x } else { 0.0 };
    }
    if x > 710.0 {
        return f64::INFINITY;
    }
    let k = (x * std::f64::consts::LOG2_E).round();
    let r = (x - k * LN2_HI) - k * LN2_LO;
    // Taylor to r¹¹.
    let p = 1.0 / 39_916_800.0;
    let p = p * r + 1.0 / 3_628_800.0;
    let p = p * r + 1.0 / 362_880.0;
    let p = p * r + 1.0 / 40_320.0;
    let p = p * r + 1.0 / 5_040.0;
    let p = p * r + 1.0 / 720.0;
    let p = p * r + 1.0 / 120.0;
    let p = p * r + 1.0 / 24.0;
    let p = p * r + 1.0 / 6.0;
    let p = p * r + 0.5;
    let p = p * r + 1.0;
    let p = p * r + 1.0;
    // 2^k in two factors, each a normal f64 (k ∈ [−1077, 1025]).
    let k = k as i64;
    let k1 = k / 2;
    let k2 = k - k1;
    let pow2 = |e: i64| f64::from_bits(((e + 1023) as u64) << 52);
    p * pow2(k1) * pow2(k2)
}

/// `ln(1 + x)`, accurate for small `|x|` (series below 1e-2, where `1 + x` would round).
#[inline]
pub fn ln_1p(x: f64) -> f64 {
    if x.abs() < 1e-2 {
        // Σ (−1)^(n+1) xⁿ/n to x⁹; the next term is below 1e-19 relative.
        let p = 1.0 / 9.0;
        let p = 1.0 / 8.0 - x * p;
        let p = 1.0 / 7.0 - x * p;
        let p = 1.0 / 6.0 - x * p;
        let p = 0.2 - x * p;
        let p = 0.25 - x * p;
        let p = 1.0 / 3.0 - x * p;
        let p = 0.5 - x * p;
        x * (1.0 - x * p)
    } else {
        ln(1.0 + x)
    }
}

/// `e^x − 1`, accurate for small `|x|` (series below 1e-2, where `e^x − 1` would cancel).
#[inline]
pub fn exp_m1(x: f64) -> f64 {
    if x.abs() < 1e-2 {
        // Σ xⁿ/n! to x⁸; the next term is below 1e-20 relative.
        let p = 1.0 / 40_320.0;
        let p = 1.0 / 5_040.0 + x * p;
        let p = 1.0 / 720.0 + x * p;
        let p = 1.0 / 120.0 + x * p;
        let p = 1.0 / 24.0 + x * p;
        let p = 1.0 / 6.0 + x * p;
        let p = 0.5 + x * p;
        x * (1.0 + x * p)
    } else {
        exp(x) - 1.0
    }
}

/// True when the Blinn lobe's `cos^e θh` is certain to round to 0 in `f32`, so that
/// [`super::microfacet::MicrofacetDistribution::d`] is 0 without its logarithm and exponential (a near-mirror lobe,
/// e ~ 10⁴–10⁸, evaluated away from its peak: most light samples of a smooth coat).
///
/// The exponent `e ln cos θh` is bounded above by `−e s2 / 2` (`ln(1 − x) ≤ −x`) on the branch
/// that reads `s2 = sin²θh`, and by `−e (1 − z)` (`ln z ≤ z − 1`) on the branch that reads `z`;
/// either below −128 puts `e^…` under 2⁻¹⁵⁰ (`ln 2⁻¹⁵⁰ ≈ −103.97`), which rounds to 0 in `f32`,
/// with a margin far beyond the kernels' 10⁻¹⁴ relative error. So the skip returns the same 0 the
/// full evaluation gives, bit for bit. Only for `e > 0` (for `e ≤ 0` the lobe does not vanish).
#[inline(always)]
pub fn cos_power_underflows(e: f32, s2: f32, z: f32) -> bool {
    let e = f64::from(e);
    if !(e > 0.0) {
        return false;
    }
    let bound = if s2 < 0.5 {
        0.5 * f64::from(s2)
    } else {
        1.0 - f64::from(z)
    };
    e * bound > 128.0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel(a: f64, b: f64) -> f64 {
        if a == b { 0.0 } else { ((a - b) / b).abs() }
    }

    /// Points spread over `[lo, hi]` logarithmically or linearly, plus the ends.
    fn points(lo: f64, hi: f64, n: usize) -> impl Iterator<Item = f64> {
        (0..=n).map(move |i| lo + (hi - lo) * i as f64 / n as f64)
    }

    #[test]
    fn ln_matches_std() {
        // sin²θh from 1e-30 to 1 (log-spaced), and cos θh down to f32's subnormals.
        for i in 0..=20_000 {
            let x = 10f64.powf(-320.0 + 320.0 * i as f64 / 20_000.0);
            assert!(
                rel(ln(x), x.ln()) < 1e-14,
                "ln {x}: {} vs {}",
                ln(x),
                x.ln()
            );
        }
        for x in points(0.5, 2.0, 10_000) {
            // Near 1 the error is absolute (the result crosses 0).
            assert!((ln(x) - x.ln()).abs() < 1e-16 + 1e-14 * x.ln().abs(), "{x}");
        }
        assert_eq!(ln(1.0), 0.0);
        assert_eq!(ln(0.0), f64::NEG_INFINITY);
        assert_eq!(ln(f64::INFINITY), f64::INFINITY);
        assert!(ln(-1.0).is_nan() && ln(f64::NAN).is_nan());
        assert!(rel(ln(f64::from_bits(1)), f64::from_bits(1).ln()) < 1e-14);
    }

    #[test]
    fn exp_matches_std() {
        for x in points(-745.0, 709.0, 200_000) {
            let (a, b) = (exp(x), x.exp());
            // Below 2^-1022 the result is subnormal and has fewer significant bits.
            let tol = 2e-14 * b + f64::from_bits(8);
            assert!((a - b).abs() <= tol, "exp {x}: {a:e} vs {b:e}");
        }
        for x in points(-1.0, 1.0, 20_000) {
            assert!(
                rel(exp(x), x.exp()) < 1e-14,
                "{x}: {}",
                rel(exp(x), x.exp())
            );
        }
        assert_eq!(exp(0.0), 1.0);
        assert_eq!(exp(-1000.0), 0.0);
        assert_eq!(exp(f64::NEG_INFINITY), 0.0);
        assert_eq!(exp(1000.0), f64::INFINITY);
        assert!(exp(f64::NAN).is_nan());
    }

    #[test]
    fn ln_1p_and_exp_m1_match_std_near_zero() {
        for i in 0..=4000 {
            let m = 10f64.powf(-40.0 + 40.0 * i as f64 / 4000.0);
            for x in [m, -m.min(0.999_999)] {
                assert!(rel(ln_1p(x), x.ln_1p()) < 2e-14, "ln_1p {x}");
                assert!(rel(exp_m1(x), x.exp_m1()) < 5e-14, "exp_m1 {x}");
            }
        }
        assert_eq!(ln_1p(-1.0), f64::NEG_INFINITY);
        assert_eq!(exp_m1(f64::NEG_INFINITY), -1.0);
        assert_eq!(ln_1p(0.0), 0.0);
        assert_eq!(exp_m1(0.0), 0.0);
    }

    /// Wherever the underflow bound fires, the full evaluation — `cos^e θh` from the same
    /// kernels, rounded to `f32` — is 0 (so the skip changes no bit), over exponents from 1 to
    /// 6.6·10⁷ (m = 0.01°) and θh on a geometric ladder from 10⁻⁶ rad to the horizon; and it
    /// fires (on 18 % of these directions, most of them the near-mirror lobes' far from their
    /// peaks; else the test would prove nothing).
    #[test]
    fn the_underflow_bound_is_sound() {
        let mut fired = 0;
        let mut total = 0;
        for e in [1.0f32, 30.0, 300.0, 3e3, 3e4, 3e5, 3e6, 6.6e7] {
            for i in 0..4000 {
                let t = 1e-6f64 * (std::f64::consts::FRAC_PI_2 / 1e-6).powf(f64::from(i) / 3999.0);
                let (s, c) = (t.sin() as f32, t.cos() as f32);
                let s2 = (s * s).min(1.0);
                if c <= 0.0 {
                    continue; // D is 0 below the horizon before any exponent.
                }
                total += 1;
                if !cos_power_underflows(e, s2, c) {
                    continue;
                }
                fired += 1;
                let log_cos = if s2 < 0.5 {
                    0.5 * ln(1.0 - f64::from(s2))
                } else {
                    ln(f64::from(c))
                };
                let full = exp(f64::from(e) * log_cos) as f32;
                assert_eq!(full, 0.0, "e {e} θ {t}");
            }
        }
        assert!(fired > total / 10, "{fired} of {total}");
    }
}
