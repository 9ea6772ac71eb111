//! Fixed-point sample sums: the film adds integers, so its sums are exact and associative.
//!
//! Floating-point addition is not associative: the sum of samples `0..N` in one pass and the sum
//! of two sums over `0..k` and `k..N` differ in their last bits. A render split into sample
//! ranges on several machines (`lapidary render --samples`, `lapidary merge`) must equal the
//! one-machine render bit for bit, so each sample is converted to an integer count of a small
//! unit (truncated toward zero, a deterministic function of the sample alone) and the film adds
//! integers. Integer addition is exact, so any split and any merge order give the same sums.
//! Wrapping addition is exact modulo 2¹²⁸ (or 2⁶⁴) and therefore also associative: the sums are
//! right whenever the true total fits, which the limits below guarantee for every sample count a
//! render accepts (at most 2²⁰ per pixel per part, and per merged image). The sum of squares is
//! non-negative and saturates instead, which is associative for non-negative terms as well.
//!
//! Resolution: radiance to 2⁻⁴⁰ ≈ 9·10⁻¹³ (an `f32` sample ≥ 2⁻¹⁷ ≈ 7.6·10⁻⁶ converts exactly;
//! below that the truncation error is under 10⁻¹² per sample), squared radiance to 2⁻³², AOVs to
//! 2⁻³⁰, depth to 2⁻³².
//!
//! The conversions take an `i64` fast path when the value fits: Rust's `f64 as i128` is a
//! library call, `f64 as i64` one instruction, and both truncate identically.

/// Units of radiance per unit of [`PixelSums::sum`](super::PixelSums) (2⁴⁰).
pub const RADIANCE_SCALE: f64 = (1u64 << 40) as f64;
/// The radiance of one unit of a fixed-point sum (2⁻⁴⁰).
pub const RADIANCE_UNIT: f64 = 1.0 / RADIANCE_SCALE;
/// Largest |radiance| a sample may have (2⁶⁰ ≈ 1.2·10¹⁸); a sample beyond it is dropped like a
/// non-finite one. At the limit a sum of 2²⁶ samples still fits in an `i128`.
pub const RADIANCE_LIMIT: f32 = (1u64 << 60) as f32;
/// Units of squared radiance per unit of [`PixelSums::sum_sq`](super::PixelSums) (2³²).
pub const SQUARE_SCALE: f64 = (1u64 << 32) as f64;
/// The squared radiance of one unit of a sum of squares (2⁻³²).
pub const SQUARE_UNIT: f64 = 1.0 / SQUARE_SCALE;
/// Units per unit of an albedo or normal AOV (2³⁰).
pub const AOV_SCALE: f64 = (1u64 << 30) as f64;
/// One unit of an AOV sum (2⁻³⁰).
pub const AOV_UNIT: f64 = 1.0 / AOV_SCALE;
/// AOV values are clamped to ±this (256: albedos lie in [0, 1] and normals are unit).
pub const AOV_LIMIT: f32 = 256.0;
/// Units per unit of distance in the depth AOV (2³²).
pub const DEPTH_SCALE: f64 = (1u64 << 32) as f64;
/// One unit of the depth sum (2⁻³²).
pub const DEPTH_UNIT: f64 = 1.0 / DEPTH_SCALE;
/// Depths are clamped to [0, 2⁶⁰] scene units.
pub const DEPTH_LIMIT: f32 = (1u64 << 60) as f32;

/// 2⁶² as `f64`: values below it in magnitude convert through `i64` exactly.
const FAST: f64 = (1u64 << 62) as f64;

/// `x` truncated toward zero to an `i128`.
#[inline(always)]
fn trunc_i128(x: f64) -> i128 {
    if x.abs() < FAST {
        i128::from(x as i64)
    } else {
        x as i128
    }
}

/// A sample's radiance as a count of [`RADIANCE_UNIT`] (truncated toward zero). The caller
/// drops samples beyond [`RADIANCE_LIMIT`] first.
#[inline(always)]
pub fn radiance(v: f32) -> i128 {
    trunc_i128(f64::from(v) * RADIANCE_SCALE)
}

/// A sample's squared radiance as a count of [`SQUARE_UNIT`], saturating at `u128::MAX` (a
/// single sample saturates beyond 2⁴⁸ ≈ 2.8·10¹⁴; a pixel's sum beyond 2⁹⁶ ≈ 7.9·10²⁸, and its
/// variance then reads `f32::MAX`). The square of an `f32` is exact in `f64` (48 significant
/// bits), and so is the scaling.
#[inline(always)]
pub fn square(v: f32) -> u128 {
    let v = f64::from(v);
    let q = v * v * SQUARE_SCALE;
    if q < FAST {
        // Through `i64`: x86-64 converts to a signed integer in one instruction, to an unsigned
        // one in several (callgrind: 16 instructions a conversion through `u64`).
        (q as i64) as u128
    } else {
        q as u128
    }
}

/// An AOV value (albedo or normal component) as a count of [`AOV_UNIT`], clamped to
/// ±[`AOV_LIMIT`] (NaN counts as 0: `clamp` keeps a NaN and `as` turns it into 0).
#[inline(always)]
pub fn aov(v: f32) -> i64 {
    (f64::from(v.clamp(-AOV_LIMIT, AOV_LIMIT)) * AOV_SCALE) as i64
}

/// A first-hit distance as a count of [`DEPTH_UNIT`], clamped to [0, [`DEPTH_LIMIT`]] (NaN
/// counts as 0).
#[inline(always)]
pub fn depth(t: f32) -> i128 {
    trunc_i128(f64::from(t.clamp(0.0, DEPTH_LIMIT)) * DEPTH_SCALE)
}

/// A radiance sum as a real number (the `i128 → f64` conversion rounds to nearest).
pub fn radiance_value(sum: i128) -> f64 {
    sum as f64 * RADIANCE_UNIT
}

/// A sum of squared radiance as a real number.
pub fn radiance_value_sq(sum: u128) -> f64 {
    sum as f64 * SQUARE_UNIT
}

/// An AOV sum as a real number.
pub fn aov_value(sum: i64) -> f64 {
    sum as f64 * AOV_UNIT
}

/// A depth sum as a real number.
pub fn depth_value(sum: i128) -> f64 {
    sum as f64 * DEPTH_UNIT
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conversions_round_trip_representable_values() {
        for v in [0.0f32, 1.0, 0.1, 3.5e-5, 1234.567, 7.0e6, 1.0e12, 1.0e17] {
            let back = radiance_value(radiance(v));
            assert!((back - f64::from(v)).abs() <= RADIANCE_UNIT, "{v}: {back}");
        }
        for v in [0.0f32, 1.0, 0.1, 3.5e-5, 1234.567, 7.0e6, 1.0e12, 2.0e14] {
            let sq = radiance_value_sq(square(v));
            let want = f64::from(v) * f64::from(v);
            assert!(
                (sq - want).abs() <= SQUARE_UNIT + want * 1e-15,
                "{v}²: {sq}"
            );
        }
        assert_eq!(radiance(-2.5), -(5 * (1i128 << 39)));
        assert_eq!(square(3.0e14), u128::MAX);
        assert_eq!(square(RADIANCE_LIMIT), u128::MAX);
        assert!((aov_value(aov(-0.75)) + 0.75).abs() < 1e-9);
        assert_eq!(aov(f32::NAN), 0);
        assert_eq!(aov(1e9), aov(AOV_LIMIT));
        assert!((depth_value(depth(12.25)) - 12.25).abs() < 1e-9);
        assert_eq!(depth(-1.0), 0);
    }

    /// Both conversion paths truncate alike around the i64 fast-path boundary.
    #[test]
    fn fast_path_agrees_with_the_wide_path() {
        for x in [
            FAST * 0.999_999,
            FAST,
            FAST * 1.000_001,
            -FAST * 0.5,
            -FAST * 3.0,
        ] {
            assert_eq!(trunc_i128(x), x as i128, "{x}");
        }
    }

    /// Summing in any order or grouping gives the same integers, where `f64` sums do not.
    #[test]
    fn sums_are_associative() {
        let values: Vec<f32> = (0..1000)
            .map(|i| ((i * 7919 % 1000) as f32 * 0.37).powf(1.7) + 1e-4)
            .collect();
        let whole: i128 = values.iter().map(|&v| radiance(v)).sum();
        for split in [1, 17, 500, 999] {
            let a: i128 = values[..split].iter().map(|&v| radiance(v)).sum();
            let b: i128 = values[split..].iter().rev().map(|&v| radiance(v)).sum();
            assert_eq!(a + b, whole);
        }
        let whole_sq: u128 = values.iter().map(|&v| square(v)).sum();
        let a: u128 = values[..300].iter().map(|&v| square(v)).sum();
        let b: u128 = values[300..].iter().rev().map(|&v| square(v)).sum();
        assert_eq!(a + b, whole_sq);
        // The `f64` sums of squares this replaces (48 significant bits a term) disagree for some
        // split: a control, so the test can fail.
        let sq = |v: &f32| f64::from(*v) * f64::from(*v);
        let fwhole: f64 = values.iter().map(sq).sum();
        let differs = (1..values.len()).any(|k| {
            let a: f64 = values[..k].iter().map(sq).sum();
            let b: f64 = values[k..].iter().map(sq).sum();
            a + b != fwhole
        });
        assert!(differs);
    }
}
