//! Colorimetry data: the CIE 1931 2° colour-matching functions, CIE illuminant D65 and the
//! linear sRGB ↔ XYZ matrices.
//!
//! | what | source | stored as |
//! | --- | --- | --- |
//! | x̄, ȳ, z̄ (CIE 1931 2° standard observer) | CIE 015:2004 *Colorimetry* and CIE 018:2019, 1 nm, 360–830 nm | `data/cie1931_2deg.csv`, 1 nm |
//! | D65 relative SPD, `S(560 nm) = 100` | CIE S 014-2:2006 / ISO 11664-2:2007, 5 nm | `data/d65.csv`, 5 nm |
//! | linear sRGB ↔ XYZ | IEC 61966-2-1:1999 (Rec.709 primaries, D65 white) | constants below |
//!
//! The tables were written from the colour-science package by `scripts/cie-tables.py`, which
//! also tells how the D65 values from 785 to 830 nm (not shipped by colour-science) were computed
//! from the CIE daylight basis functions; they equal the CIE's published values. The CSV files are
//! embedded with `include_str!` and parsed once, at first use.
//!
//! **Interpolation.** Every lookup interpolates linearly between table entries and returns 0
//! outside `[LAMBDA_MIN, LAMBDA_MAX]` (and for NaN). D65 is kept at the CIE's 5 nm spacing and
//! interpolated at lookup: the CIE's own 1 nm D65 table is defined as the linear interpolation of
//! the 5 nm one (CIE S 014-2), so both give the same values.
//!
//! **Integration.** [`spectrum_to_xyz`] sums at 1 nm over 360–830 nm, the CIE's recommended
//! summation (CIE 015:2004), normalised by [`CIE_Y_INTEGRAL`] so that a constant spectrum of
//! 1 has `Y = 1`.

use glam::{Mat3, Vec3};
use std::sync::OnceLock;

/// Shortest wavelength of the tables, nm.
pub const LAMBDA_MIN: f32 = 360.0;
/// Longest wavelength of the tables, nm.
pub const LAMBDA_MAX: f32 = 830.0;
/// Number of 1 nm samples of the colour-matching functions (360, 361, …, 830 nm).
pub const CMF_SAMPLES: usize = 471;
/// `∫ ȳ(λ) dλ` over 360–830 nm, summed at 1 nm (nm): the sum of the ȳ column of
/// `data/cie1931_2deg.csv`, 106.856917 — the normalisation that makes [`spectrum_to_xyz`] give
/// `Y = 1` for a constant 1 with this table (the 106.856895 found in some renderers differs by
/// 2·10⁻⁷ relative, below `f32` resolution of the sums that use it).
pub const CIE_Y_INTEGRAL: f32 = 106.856_92;

/// D65's table spacing, nm.
const D65_STEP: f32 = 5.0;
/// Number of 5 nm D65 samples (360, 365, …, 830 nm).
const D65_SAMPLES: usize = 95;

/// Linear sRGB → CIE XYZ (rows X, Y, Z; `Y = 1` for RGB white).
///
/// The Rec.709 primaries `R (0.64, 0.33)`, `G (0.30, 0.60)`, `B (0.15, 0.06)` and the D65 white
/// `(0.3127, 0.3290)` of IEC 61966-2-1:1999 (= ITU-R BT.709-6), turned into a matrix by the
/// method of SMPTE RP 177-1993 and kept to nine decimals. It rounds to the standard's printed
/// four-decimal matrix; the standard's printed inverse is the inverse of that rounded matrix and
/// differs from [`XYZ_TO_LINEAR_SRGB`] in the fourth decimal.
pub const LINEAR_SRGB_TO_XYZ: Mat3 = Mat3::from_cols_array(&[
    0.412_390_8,
    0.212_639,
    0.019_330_82,
    0.357_584_34,
    0.715_168_7,
    0.119_194_78,
    0.180_480_8,
    0.072_192_32,
    0.950_532_15,
]);

/// CIE XYZ → linear sRGB: the inverse of [`LINEAR_SRGB_TO_XYZ`] (computed in double precision).
pub const XYZ_TO_LINEAR_SRGB: Mat3 = Mat3::from_cols_array(&[
    3.240_97,
    -0.969_243_6,
    0.055_630_08,
    -1.537_383_2,
    1.875_967_5,
    -0.203_976_96,
    -0.498_610_76,
    0.041_555_06,
    1.056_971_5,
]);

/// The parsed tables.
struct Tables {
    /// x̄, ȳ, z̄ at 360 + i nm.
    cmf: Vec<Vec3>,
    /// D65 at 360 + 5 i nm.
    d65: Vec<f32>,
    /// `XYZ_TO_LINEAR_SRGB · (x̄, ȳ, z̄) / ∫ȳ` at 360 + i nm ([`rgb_bar_table`]).
    rgb_bar: Box<[[f32; 3]; CMF_SAMPLES]>,
}

fn tables() -> &'static Tables {
    static TABLES: OnceLock<Tables> = OnceLock::new();
    TABLES.get_or_init(|| {
        let cmf = parse(include_str!("data/cie1931_2deg.csv"), 3, CMF_SAMPLES, 1.0)
            .expect("data/cie1931_2deg.csv is well formed (checked by the tests)");
        let d65 = parse(include_str!("data/d65.csv"), 1, D65_SAMPLES, D65_STEP)
            .expect("data/d65.csv is well formed (checked by the tests)");
        let m = glam::DMat3::from_cols_array(&XYZ_TO_LINEAR_SRGB.to_cols_array().map(f64::from));
        let rgb_bar = Box::new(std::array::from_fn(|i| {
            let r = &cmf[i];
            let xyz = glam::DVec3::new(r[0].into(), r[1].into(), r[2].into());
            (m * xyz / f64::from(CIE_Y_INTEGRAL)).as_vec3().to_array()
        }));
        Tables {
            cmf: cmf.iter().map(|r| Vec3::new(r[0], r[1], r[2])).collect(),
            d65: d65.iter().map(|r| r[0]).collect(),
            rgb_bar,
        }
    })
}

/// Parses a CSV table: `#` comment lines, one header line, then rows `lambda,v1,…,v_columns`
/// whose wavelengths must be `LAMBDA_MIN + i·step` for `i < rows`. `None` on any deviation.
fn parse(text: &str, columns: usize, rows: usize, step: f32) -> Option<Vec<Vec<f32>>> {
    let mut lines = text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'));
    lines.next()?.starts_with("lambda_nm").then_some(())?;
    let mut out = Vec::with_capacity(rows);
    for (i, line) in lines.enumerate() {
        let fields: Vec<f32> = line
            .split(',')
            .map(|f| f.trim().parse().ok())
            .collect::<Option<_>>()?;
        let lambda = LAMBDA_MIN + i as f32 * step;
        if fields.len() != columns + 1 || fields[0] != lambda {
            return None;
        }
        out.push(fields[1..].to_vec());
    }
    (out.len() == rows).then_some(out)
}

/// Position of `lambda_nm` in a table of `len` samples spaced `step` nm from [`LAMBDA_MIN`]:
/// `(i, t)` with the value `(1 − t)·v[i] + t·v[i + 1]`; `None` outside the range or for NaN.
#[inline]
fn locate(lambda_nm: f32, step: f32, len: usize) -> Option<(usize, f32)> {
    if !(LAMBDA_MIN..=LAMBDA_MAX).contains(&lambda_nm) {
        return None;
    }
    let x = (lambda_nm - LAMBDA_MIN) / step;
    let i = (x as usize).min(len - 2);
    Some((i, (x - i as f32).clamp(0.0, 1.0)))
}

/// The CIE 1931 2° colour-matching functions `(x̄, ȳ, z̄)` at `lambda_nm` (nm), interpolated
/// linearly in the 1 nm table; `Vec3::ZERO` outside 360–830 nm or for NaN. Dimensionless,
/// `ȳ(555 nm) = 1`.
pub fn xyz_bar(lambda_nm: f32) -> Vec3 {
    let cmf = &tables().cmf;
    match locate(lambda_nm, 1.0, CMF_SAMPLES) {
        Some((i, t)) => cmf[i].lerp(cmf[i + 1], t),
        None => Vec3::ZERO,
    }
}

/// The 1 nm table of the colour-matching functions: entry `i` is `(x̄, ȳ, z̄)` at `360 + i` nm.
pub fn xyz_bar_table() -> &'static [Vec3] {
    &tables().cmf
}

/// The colour-matching functions in linear sRGB per unit `∫ȳ`: entry `i` is
/// `XYZ_TO_LINEAR_SRGB · (x̄, ȳ, z̄)(360 + i nm) / CIE_Y_INTEGRAL` (computed in double precision), so
/// that `Σ_λ f(λ) · rgb_bar(λ)` at 1 nm is [`xyz_to_linear_srgb`] of [`spectrum_to_xyz`]`(f)`.
/// The spectral film's conversion reads it: one lookup per wavelength instead of the XYZ lookup
/// and a matrix per path.
pub fn rgb_bar_table() -> &'static [[f32; 3]; CMF_SAMPLES] {
    &tables().rgb_bar
}

/// CIE standard illuminant D65, relative spectral power at `lambda_nm` (nm), normalised to 100 at
/// 560 nm; linear interpolation of the CIE's 5 nm table, 0 outside 360–830 nm or for NaN.
pub fn d65(lambda_nm: f32) -> f32 {
    let d65 = &tables().d65;
    match locate(lambda_nm, D65_STEP, D65_SAMPLES) {
        Some((i, t)) => d65[i] + t * (d65[i + 1] - d65[i]),
        None => 0.0,
    }
}

/// CIE XYZ of the spectrum `f` (a function of the wavelength in nm): `Σ f(λ) (x̄, ȳ, z̄)(λ) / Σ ȳ(λ)`
/// over λ = 360, 361, …, 830 nm, so that `f ≡ 1` gives `Y = 1`. Accumulated in double precision.
/// `f` is called 471 times; a non-finite value of `f` gives a non-finite result.
pub fn spectrum_to_xyz(f: impl Fn(f32) -> f32) -> Vec3 {
    let mut sum = [0.0f64; 3];
    for (i, bar) in xyz_bar_table().iter().enumerate() {
        let v = f64::from(f(LAMBDA_MIN + i as f32));
        for (s, b) in sum.iter_mut().zip(bar.to_array()) {
            *s += v * f64::from(b);
        }
    }
    let norm = f64::from(CIE_Y_INTEGRAL);
    Vec3::new(
        (sum[0] / norm) as f32,
        (sum[1] / norm) as f32,
        (sum[2] / norm) as f32,
    )
}

/// XYZ of D65 normalised to `Y = 1`, from the tables: `spectrum_to_xyz(d65)` divided by its `Y`.
/// Its chromaticity is (0.31273, 0.32902), the CIE's tabulated D65 white point.
pub fn d65_white_xyz() -> Vec3 {
    static WHITE: OnceLock<Vec3> = OnceLock::new();
    *WHITE.get_or_init(|| {
        let xyz = spectrum_to_xyz(d65);
        xyz / xyz.y
    })
}

/// Chromaticity `(x, y) = (X, Y) / (X + Y + Z)`; `(0, 0)` for a zero sum.
pub fn xyz_to_xy(xyz: Vec3) -> (f32, f32) {
    let sum = xyz.x + xyz.y + xyz.z;
    if sum == 0.0 {
        (0.0, 0.0)
    } else {
        (xyz.x / sum, xyz.y / sum)
    }
}

/// CIE XYZ → linear sRGB (Rec.709 primaries, D65 white, IEC 61966-2-1), by
/// [`XYZ_TO_LINEAR_SRGB`]. Not clamped: colours outside the gamut get negative channels.
#[inline]
pub fn xyz_to_linear_srgb(xyz: Vec3) -> Vec3 {
    XYZ_TO_LINEAR_SRGB * xyz
}

/// Linear sRGB → CIE XYZ, by [`LINEAR_SRGB_TO_XYZ`]; the inverse of [`xyz_to_linear_srgb`].
#[inline]
pub fn linear_srgb_to_xyz(rgb: Vec3) -> Vec3 {
    LINEAR_SRGB_TO_XYZ * rgb
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tables_parse_with_the_expected_sizes() {
        assert_eq!(xyz_bar_table().len(), CMF_SAMPLES);
        assert_eq!(tables().d65.len(), D65_SAMPLES);
        // A malformed table is refused, not half read.
        assert!(parse("lambda_nm,a\n360,1\n362,2\n", 1, 2, 1.0).is_none());
        assert!(parse("lambda_nm,a\n360,1\n361,x\n", 1, 2, 1.0).is_none());
        assert!(parse("lambda_nm,a\n360,1\n", 1, 2, 1.0).is_none());
        assert!(parse("lambda_nm,a\n360,1\n361,2\n", 1, 2, 1.0).is_some());
    }

    #[test]
    fn y_integral_matches_the_table() {
        let sum: f64 = xyz_bar_table().iter().map(|v| f64::from(v.y)).sum();
        assert!((sum - 106.856_917).abs() < 1e-5, "{sum}");
        assert!((sum as f32 - CIE_Y_INTEGRAL).abs() < 1e-5);
        assert!((spectrum_to_xyz(|_| 1.0).y - 1.0).abs() < 1e-6);
    }

    #[test]
    fn table_values_at_known_wavelengths() {
        // Rows of the CIE table.
        let rows = [
            (360.0, [0.000_129_9, 0.000_003_917, 0.000_606_1]),
            (440.0, [0.348_28, 0.023, 1.747_06]),
            (445.0, [0.348_06, 0.029_8, 1.782_6]),
            (555.0, [0.512_050_1, 1.0, 0.005_75]),
            (600.0, [1.062_2, 0.631, 0.000_8]),
            (700.0, [0.011_359_16, 0.004_102, 0.0]),
        ];
        for (lambda, xyz) in rows {
            let v = xyz_bar(lambda);
            for (a, b) in v.to_array().into_iter().zip(xyz) {
                assert!(
                    (a - b).abs() <= 1e-6 * b.max(1.0),
                    "{lambda}: {v} vs {xyz:?}"
                );
            }
        }
        assert_eq!(xyz_bar(555.0).y, 1.0);
        // Halfway between two samples is their mean.
        let mid = xyz_bar(600.5);
        let expected = (xyz_bar(600.0) + xyz_bar(601.0)) * 0.5;
        assert!((mid - expected).abs().max_element() < 1e-6);
        // D65: 100 at 560 nm, and the 5 nm values are interpolated linearly.
        assert_eq!(d65(560.0), 100.0);
        assert!((d65(830.0) - 60.3125).abs() < 1e-4);
        assert!((d65(362.0) - (46.6383 + 0.4 * (49.3637 - 46.6383))).abs() < 1e-4);
    }

    #[test]
    fn out_of_range_is_zero() {
        for lambda in [
            359.99,
            830.01,
            -1.0,
            1e9,
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ] {
            assert_eq!(xyz_bar(lambda), Vec3::ZERO, "{lambda}");
            assert_eq!(d65(lambda), 0.0, "{lambda}");
        }
        assert!(xyz_bar(LAMBDA_MIN).x > 0.0 && d65(LAMBDA_MAX) > 0.0);
    }

    #[test]
    fn d65_integrates_to_its_white_point() {
        let (x, y) = xyz_to_xy(spectrum_to_xyz(d65));
        assert!(
            (x - 0.3127).abs() < 1e-4 && (y - 0.3290).abs() < 1e-4,
            "{x} {y}"
        );
        let w = d65_white_xyz();
        assert!((w.y - 1.0).abs() < 1e-6);
    }

    /// The pre-multiplied table sums to the same colour as XYZ through the matrix.
    #[test]
    fn rgb_bar_is_the_matrix_times_the_cmfs() {
        let f = |l: f32| 0.2 + 0.6 * ((l - 360.0) / 470.0).powi(2);
        let want = xyz_to_linear_srgb(spectrum_to_xyz(f));
        let mut got = [0.0f64; 3];
        for (i, bar) in rgb_bar_table().iter().enumerate() {
            let v = f64::from(f(LAMBDA_MIN + i as f32));
            for (g, b) in got.iter_mut().zip(bar) {
                *g += v * f64::from(*b);
            }
        }
        for (g, w) in got.iter().zip(want.to_array()) {
            assert!((*g as f32 - w).abs() < 1e-5, "{got:?} vs {want}");
        }
    }

    #[test]
    fn srgb_matrix_maps_d65_to_white_and_round_trips() {
        let rgb = xyz_to_linear_srgb(d65_white_xyz());
        assert!((rgb - Vec3::ONE).abs().max_element() < 1e-3, "{rgb}");
        // The matrix's own white point, (0.3127, 0.3290) at Y = 1, is white to float precision.
        let w = Vec3::new(0.3127 / 0.3290, 1.0, (1.0 - 0.3127 - 0.3290) / 0.3290);
        assert!((xyz_to_linear_srgb(w) - Vec3::ONE).abs().max_element() < 1e-5);
        // Rec.709 luminance weights are the middle row.
        assert!((linear_srgb_to_xyz(Vec3::X).y - 0.2126).abs() < 1e-4);
        for v in [
            Vec3::new(0.2, 0.5, 0.9),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(3.0, -0.5, 0.01),
        ] {
            let back = xyz_to_linear_srgb(linear_srgb_to_xyz(v));
            assert!((back - v).abs().max_element() < 1e-5, "{v} → {back}");
        }
        let id = XYZ_TO_LINEAR_SRGB * LINEAR_SRGB_TO_XYZ;
        assert!(id.abs_diff_eq(Mat3::IDENTITY, 1e-6));
    }

    #[test]
    fn chromaticity_of_zero_is_defined() {
        assert_eq!(xyz_to_xy(Vec3::ZERO), (0.0, 0.0));
    }
}
