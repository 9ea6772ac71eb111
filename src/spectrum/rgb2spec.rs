//! RGB → spectrum: the sigmoid-polynomial spectra of Wenzel Jakob and Johannes Hanika, "A
//! Low-Dimensional Function Space for Efficient Spectral Upsampling", Computer Graphics Forum
//! 38(2), Eurographics 2019 — "the paper" below.
//!
//! **The model.** A reflectance is `s(λ) = S(c0 t² + c1 t + c2)` with the paper's sigmoid
//! `S(x) = 1/2 + x / (2 √(1 + x²))`, always inside (0, 1), so an albedo stays ≤ 1 at every
//! wavelength. Here `t = (λ − 360 nm) / 470 nm ∈ [0, 1]` is the wavelength normalised over the
//! tables of [`super::cie`] (better conditioned than coefficients in nm); [`Sigmoid::coeffs`] are
//! in that variable.
//!
//! **The fit** ([`fit`]). For a target linear sRGB colour, Gauss–Newton on the three coefficients
//! minimises, as the paper does, the CIELAB distance ΔE76 between the target and the colour of `s`
//! under D65 ([`reflectance_to_rgb`]: the XYZ of `s·D65` in 1 nm sums, to linear sRGB, relative to
//! the perfect reflector, which is therefore exactly white), with an analytic Jacobian, a step
//! limit and step halving.
//!
//! **The table.** The paper's layout: for each choice of the largest channel, a `RES³` grid over
//! the two other channels divided by the largest (`x`, `y ∈ [0, 1]`, uniform) and the largest
//! value `z` on a smoothstep scale, here `z_k = Z_DARK + (1 − Z_DARK) · smoothstep(k / (RES − 1))`
//! (denser near both ends). It is computed by [`fit`] at first use, in parallel with rayon, by the
//! paper's continuation: the middle brightness slice is walked from its grey corner (whose
//! solution is exact), its top row then every column, each fit starting from its neighbour's
//! solution; then every `(x, y)` is continued from the middle brightness out to both ends of the
//! `z` scale. A fit that does not converge from its neighbour retries through intermediate
//! targets. The table is kept on disk between runs ([`cache`]: `$LAPIDARY_CACHE_DIR`, else the
//! user's cache folder; keyed by a hash of these sources and data). Every entry converges to ΔE76 < 10⁻⁶ ([`max_fit_error`]). A lookup interpolates the
//! coefficients trilinearly ([`reflectance`]).
//!
//! **Black, white, dark** (the pitfalls of pbrt-v4 pull request #62 and issue #82). Greys are
//! exactly flat; 0 and 1, which the sigmoid only approaches, are flat 0 and flat 1 exactly (the
//! coefficient `c2 = ±∞`, which [`sigmoid`] maps to 0 and 1). Near black, the sigmoid model cannot
//! keep a saturated colour dark: a dark red or magenta needs a polynomial that is very negative in
//! the green and rises towards long wavelengths, where the colour-matching functions vanish and
//! nothing stops `S` from reaching 1 (measured: over a grid of colours of brightness `z`, the
//! worst fitted spectrum — a dark red-magenta such as `(z, 0, z/4)` — reaches `s = 1` near
//! 830 nm for every `z` from 0.02 to 0.5, so `max s / z = 1/z`). So the table stops at
//! `z = Z_DARK`, and a colour darker than that is the spectrum of `rgb · Z_DARK / max(rgb)` scaled
//! by `max(rgb) / Z_DARK` ([`Sigmoid::scale`]) — exact, since colour is linear in the spectrum.
//! Hence, for every colour, `s(λ) ≤ max(rgb) / Z_DARK = 4 · max(rgb)` on 360–830 nm
//! (`near_black_stays_dark`): issue #82's colour `(1.07·10⁻⁴, 0, 1.05·10⁻⁵)` stays below
//! 4.3·10⁻⁴, where a fit at its own brightness rises towards 1 in the far red, as the issue
//! reports.
//!
//! **Resolution, measured**: see [`RES`].

use super::cie::{self, CMF_SAMPLES, LAMBDA_MIN};
use std::sync::OnceLock;

pub(crate) mod cache;
pub mod fit;
mod sigmoid;

pub use sigmoid::{Sigmoid, sigmoid, sigmoid_inverse};

/// Grid resolution per axis of the coefficient table (3 · RES³ entries).
///
/// Measured in a release build on this project's machine (2 cores, the other one busy with another
/// job), first use = building the table; round trip = the 17³ grid of sRGB colours `k/16`
/// through [`reflectance`] and [`reflectance_to_rgb`]:
///
/// | RES | first use | max ΔE76 | mean ΔE76 | max abs. linear error |
/// | --- | --- | --- | --- | --- |
/// | 32 | 0.9 s | 0.43 | 0.045 | 2.5·10⁻³ |
/// | 48 | 3.1 s | 0.21 | 0.022 | 1.2·10⁻³ |
/// | 64 | 7.0 s | 0.13 | 0.012 | 6.4·10⁻⁴ |
///
/// 32 keeps first use under 2 s with errors well below a just-noticeable difference (ΔE76 ≈ 2.3);
/// the largest are saturated colours with a small second channel (`(0.81, 0.06, 0.06)`), where
/// the coefficients curve most between grid points. The table holds 3 · 32³ · 3 `f32` (1.2 MB).
pub const RES: usize = 32;

/// The darkest brightness (largest channel) the table holds; darker colours are scaled down from
/// it, so that `s(λ) ≤ max(rgb) / Z_DARK` for every colour (module docs).
pub const Z_DARK: f32 = 0.25;

/// The coefficient table.
struct Table {
    /// Brightness slices `z_k`, increasing, `z_0 = Z_DARK`, `z_{RES−1} = 1`.
    z: Vec<f32>,
    /// Entry `((l·RES + k)·RES + j)·RES + i`: largest channel `l`, brightness `z_k`,
    /// `y = j / (RES − 1)`, `x = i / (RES − 1)`.
    coeffs: Vec<[f32; 3]>,
    /// Largest CIELAB ΔE76 of any entry's fit.
    max_fit_error: f32,
}

fn table() -> &'static Table {
    static TABLE: OnceLock<Table> = OnceLock::new();
    TABLE.get_or_init(|| {
        let z = fit::z_scale(RES, f64::from(Z_DARK));
        // Read from the on-disk cache when a valid one is there ([`cache`]), else built and
        // stored for the next run.
        let (coeffs, max_fit_error) = cache::load(3 * RES * RES * RES).unwrap_or_else(|| {
            let (coeffs, err) = fit::build_table(RES, &z);
            cache::store(&coeffs, err);
            (coeffs, err)
        });
        Table {
            z: z.iter().map(|&v| v as f32).collect(),
            coeffs,
            max_fit_error,
        }
    })
}

/// Builds the coefficient table now (about a second, [`RES`]) instead of at the first lookup.
pub fn warm_up() {
    table();
}

/// The largest CIELAB ΔE76 between a table entry's target colour and its fitted spectrum's colour
/// (builds the table if needed).
pub fn max_fit_error() -> f32 {
    table().max_fit_error
}

/// Clamps a channel to [0, 1] (NaN to 0).
fn unit(v: f32) -> f32 {
    if v > 0.0 { v.min(1.0) } else { 0.0 }
}

/// The reflectance spectrum of a linear sRGB albedo, each channel clamped to [0, 1] (NaN to 0):
/// trilinear interpolation of the table's coefficients. Greys (`r = g = b`) are exactly flat
/// (`c0 = c1 = 0`, `c2 = S⁻¹(g)`, flat 0 and flat 1 included); a colour darker than [`Z_DARK`]
/// is the spectrum of `rgb · Z_DARK / max(rgb)` with `scale = max(rgb) / Z_DARK` (module docs).
/// Values are in [0, 1] at every wavelength, and at most `max(rgb) / Z_DARK`.
pub fn reflectance(rgb: [f32; 3]) -> Sigmoid {
    let rgb = rgb.map(unit);
    if rgb[0] == rgb[1] && rgb[1] == rgb[2] {
        return Sigmoid::flat(rgb[0]);
    }
    // A renderer asks for the same few colours (a light's, an albedo, a medium's coefficients)
    // again and again: a small per-thread memo saves the table's eight scattered reads (the
    // table is 1.2 MB, beyond the core's cache). The key is the colour's bits, so a hit returns
    // exactly what the lookup would.
    let key = rgb.map(f32::to_bits);
    let slot = (key[0]
        .wrapping_mul(0x9e37_79b9)
        .wrapping_add(key[1].wrapping_mul(0x85eb_ca6b))
        .wrapping_add(key[2].wrapping_mul(0xc2b2_ae35))
        >> (32 - MEMO_BITS)) as usize;
    if let Some(s) = MEMO.with(|m| {
        let (k, s) = m.borrow()[slot];
        (k == key).then_some(s)
    }) {
        return s;
    }
    let s = lookup(rgb);
    MEMO.with(|m| m.borrow_mut()[slot] = (key, s));
    s
}

/// log2 of the per-thread memo's entries.
const MEMO_BITS: u32 = 6;

thread_local! {
    /// Recent colours and their spectra, direct-mapped by a hash of the colour's bits (the key
    /// `[u32::MAX; 3]` is a NaN colour, which [`unit`] never produces, so empty slots never hit).
    static MEMO: std::cell::RefCell<[([u32; 3], Sigmoid); 1 << MEMO_BITS]> =
        const { std::cell::RefCell::new([([u32::MAX; 3], Sigmoid::ZERO); 1 << MEMO_BITS]) };
}

/// [`reflectance`] without the memo, for a non-grey colour in `[0, 1]³`.
fn lookup(rgb: [f32; 3]) -> Sigmoid {
    let l = if rgb[0] >= rgb[1] && rgb[0] >= rgb[2] {
        0
    } else if rgb[1] >= rgb[2] {
        1
    } else {
        2
    };
    let z = rgb[l];
    let x = rgb[(l + 1) % 3] / z;
    let y = rgb[(l + 2) % 3] / z;
    let t = table();
    let (zk, zf, scale) = if z < t.z[0] {
        (0, 0.0, z / t.z[0])
    } else {
        let k = t.z.partition_point(|&v| v <= z).clamp(1, RES - 1) - 1;
        let f = ((z - t.z[k]) / (t.z[k + 1] - t.z[k])).clamp(0.0, 1.0);
        (k, f, 1.0)
    };
    let cell = |v: f32| {
        let g = v * (RES - 1) as f32;
        let i = (g as usize).min(RES - 2);
        (i, (g - i as f32).clamp(0.0, 1.0))
    };
    let ((xi, xf), (yj, yf)) = (cell(x), cell(y));
    let mut c = [0.0f32; 3];
    for (dk, wk) in [(0, 1.0 - zf), (1, zf)] {
        if wk == 0.0 {
            continue;
        }
        for (dj, wj) in [(0, 1.0 - yf), (1, yf)] {
            for (di, wi) in [(0, 1.0 - xf), (1, xf)] {
                let w = wk * wj * wi;
                let e = t.coeffs[((l * RES + zk + dk) * RES + yj + dj) * RES + xi + di];
                for (a, b) in c.iter_mut().zip(e) {
                    *a += w * b;
                }
            }
        }
    }
    Sigmoid { coeffs: c, scale }
}

/// An unbounded linear sRGB quantity (radiance, absorption coefficient, …; channels clamped to
/// `[0, f32::MAX / 4]`, NaN to 0) as `scale · s(λ)`: `scale = 2 · max(rgb)` and `s` the
/// [`reflectance`] of `rgb / scale` (so its largest channel is 1/2, mid-table). A grey stays flat;
/// black is `(0, Sigmoid::ZERO)`.
pub fn unbounded(rgb: [f32; 3]) -> (f32, Sigmoid) {
    let rgb = rgb.map(|v| if v > 0.0 { v.min(f32::MAX / 4.0) } else { 0.0 });
    let m = rgb[0].max(rgb[1]).max(rgb[2]);
    if m == 0.0 {
        return (0.0, Sigmoid::ZERO);
    }
    let scale = 2.0 * m;
    (scale, reflectance(rgb.map(|v| v / scale)))
}

/// Relative spectral power of D65 normalised to unit luminance: `d65(λ) / N` with
/// `N = Σ d65 ȳ / Σ ȳ` (1 nm sums), so that [`cie::spectrum_to_xyz`] gives it `Y = 1` and
/// chromaticity D65.
pub fn d65_normalised(lambda_nm: f32) -> f32 {
    static NORM: OnceLock<f32> = OnceLock::new();
    let n = *NORM.get_or_init(|| cie::spectrum_to_xyz(cie::d65).y);
    cie::d65(lambda_nm) / n
}

/// An emitted linear sRGB colour (clamped as in [`unbounded`]) as the spectral radiance
/// `L(λ) = scale · s(λ) · d65_normalised(λ)`: `(scale, s)` from [`unbounded`], so a grey light is
/// D65-shaped and `L` has the light's sRGB colour through [`cie::spectrum_to_xyz`] and
/// [`cie::xyz_to_linear_srgb`] (to 2.4·10⁻⁴: the sRGB matrix's white (0.3127, 0.3290) and the
/// tabulated D65's (0.31273, 0.32902) differ that much).
pub fn illuminant(rgb: [f32; 3]) -> (f32, Sigmoid) {
    unbounded(rgb)
}

/// The linear sRGB colour of a reflectance spectrum `f` (a function of λ in nm) under D65: the XYZ
/// of `f · D65` (1 nm sums over 360–830 nm) divided by D65's `Y`, to linear sRGB, each channel
/// divided by that of the perfect reflector `f ≡ 1` (a white balance of at most 2.4·10⁻⁴, which
/// makes `f ≡ 1` exactly white). The colour space [`reflectance`] fits in.
pub fn reflectance_to_rgb(f: impl Fn(f32) -> f32) -> [f32; 3] {
    let nodes = fit::Quadrature::fine().nodes();
    let mut sum = [0.0f64; 3];
    for (i, n) in nodes.iter().enumerate().take(CMF_SAMPLES) {
        let v = f64::from(f(LAMBDA_MIN + i as f32));
        for (s, a) in sum.iter_mut().zip(&n[1..]) {
            *s += v * a;
        }
    }
    sum.map(|v| v as f32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{DVec3, Vec3};

    fn colour_of(s: &Sigmoid) -> [f32; 3] {
        reflectance_to_rgb(|l| s.eval(l))
    }

    fn delta_e(a: [f32; 3], b: [f32; 3]) -> f64 {
        let lab = |v: [f32; 3]| fit::lab(DVec3::from_array(v.map(f64::from))).0;
        (lab(a) - lab(b)).length()
    }

    /// A small deterministic generator (xorshift64*, Vigna 2016) for test colours.
    fn rng(seed: &mut u64) -> f32 {
        *seed ^= *seed >> 12;
        *seed ^= *seed << 25;
        *seed ^= *seed >> 27;
        (seed.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40) as f32 / (1u64 << 24) as f32
    }

    #[test]
    fn greys_are_exactly_flat() {
        for g in [0.0, 1e-7, 1e-3, 0.18, 0.5, 0.999, 1.0, 1.5, -2.0, f32::NAN] {
            let s = reflectance([g; 3]);
            let clamped = unit(g);
            assert!(s.is_flat() && s.scale == 1.0, "{g}: {s:?}");
            assert_eq!(s.coeffs[2], sigmoid_inverse(clamped));
            let v = s.eval(550.0);
            assert!(
                [360.0, 412.5, 700.0, 830.0, 1e4]
                    .iter()
                    .all(|&l| s.eval(l) == v)
            );
            assert!((v - clamped).abs() <= 1e-6 * clamped.max(1e-3), "{g}: {v}");
        }
        assert_eq!(reflectance([0.0; 3]).eval(600.0), 0.0);
        assert_eq!(reflectance([1.0; 3]).eval(600.0), 1.0);
        assert_eq!(reflectance([1.0; 3]).max_value(), 1.0);
    }

    #[test]
    fn inputs_are_clamped() {
        assert_eq!(
            reflectance([2.0, -1.0, f32::NAN]),
            reflectance([1.0, 0.0, 0.0])
        );
        assert_eq!(unbounded([f32::NAN, -3.0, 0.0]), (0.0, Sigmoid::ZERO));
        let (scale, s) = unbounded([f32::INFINITY, 1.0, 0.0]);
        assert!(scale.is_finite() && s.coeffs.iter().all(|c| c.is_finite()));
        assert_eq!(Sigmoid::ZERO.eval(f32::NAN), 0.0);
    }

    #[test]
    fn values_stay_in_the_unit_interval() {
        let mut seed = 0x9e37_79b9_7f4a_7c15;
        for n in 0..10_000 {
            let mut rgb = [rng(&mut seed), rng(&mut seed), rng(&mut seed)];
            if n % 4 == 0 {
                rgb[n % 3] = 0.0; // on a face of the cube
            }
            let s = reflectance(rgb);
            let mut max = 0.0f32;
            for l in 360..=830 {
                let v = s.eval(l as f32);
                assert!(v > 0.0 && v <= 1.0, "{rgb:?} at {l} nm: {v} ({s:?})");
                max = max.max(v);
            }
            assert!((s.max_value() - max).abs() <= 1e-3 * max, "{rgb:?}");
        }
    }

    #[test]
    fn table_fits_converged() {
        let e = max_fit_error();
        assert!(e < 1e-3, "worst table fit ΔE {e}");
    }

    #[test]
    fn round_trip_of_the_srgb_cube() {
        let (mut max_de, mut sum_de, mut max_abs, mut n) = (0.0f64, 0.0, 0.0f32, 0);
        for r in 0..=16 {
            for g in 0..=16 {
                for b in 0..=16 {
                    let rgb = [r, g, b].map(|v| v as f32 / 16.0);
                    let back = colour_of(&reflectance(rgb));
                    let de = delta_e(rgb, back);
                    max_de = max_de.max(de);
                    sum_de += de;
                    n += 1;
                    for (a, b) in back.iter().zip(rgb) {
                        max_abs = max_abs.max((a - b).abs());
                    }
                }
            }
        }
        let mean = sum_de / f64::from(n);
        println!("17³ round trip: max ΔE76 {max_de:.4}, mean {mean:.5}, max |Δrgb| {max_abs:.5}");
        assert!(max_de < 0.5 && mean < 0.05 && max_abs < 3e-3);
    }

    #[test]
    fn near_black_stays_dark() {
        // The pitfall exists: the unscaled fit of a dark magenta rises to 1 at 830 nm.
        let (c, e) = fit::fit_rgb([0.02, 0.0, 0.005]);
        let raw = Sigmoid {
            coeffs: c,
            scale: 1.0,
        };
        assert!(e < 1e-4 && raw.eval(830.0) > 0.9, "{raw:?}");
        // pbrt-v4 issue #82's colour stays dark, in the far red too.
        let issue = [0.000_106_780_71, 0.0, 0.000_010_491_596];
        let s = reflectance(issue);
        assert!((700..=830).all(|l| s.eval(l as f32) <= 4.3e-4), "{s:?}");
        // s(λ) ≤ max(rgb) / Z_DARK for every colour, dark or not, on a face of the cube or inside.
        let mut cases = vec![
            issue,
            [0.001, 0.0, 0.0],
            [0.0, 0.001, 0.0],
            [0.0, 0.0, 1e-3],
        ];
        let mut seed = 7;
        for n in 0..5000 {
            let m = rng(&mut seed).powi(3);
            let mut c = [rng(&mut seed), rng(&mut seed), rng(&mut seed)].map(|v| v * m);
            c[n % 3] = m;
            if n % 2 == 0 {
                c[(n + 1) % 3] = 0.0;
            }
            cases.push(c);
        }
        for rgb in cases {
            let s = reflectance(rgb);
            let m = rgb[0].max(rgb[1]).max(rgb[2]);
            let bound = m / Z_DARK;
            assert!(
                s.max_value() <= bound * 1.000_01,
                "{rgb:?}: max {} ({s:?})",
                s.max_value()
            );
            assert!((360..=830).all(|l| s.eval(l as f32) <= bound * 1.000_01));
        }
    }

    #[test]
    fn dark_colours_scale_the_first_slice() {
        let base = [0.7, 0.2, 1.0].map(|v| v * Z_DARK);
        let s = reflectance(base);
        assert_eq!(s.scale, 1.0);
        let d = reflectance(base.map(|v| v * 0.25));
        assert_eq!((d.coeffs, d.scale), (s.coeffs, 0.25));
        let (a, b) = (colour_of(&s), colour_of(&d));
        assert!((0..3).all(|i| (b[i] - 0.25 * a[i]).abs() < 1e-7));
    }

    #[test]
    fn unbounded_round_trips() {
        for rgb in [
            [3.0, 0.5, 0.1],
            [0.2, 0.4, 0.1],
            [7.0, 7.0, 7.0],
            [0.0, 40.0, 2.0],
        ] {
            let (scale, s) = unbounded(rgb);
            let m = rgb[0].max(rgb[1]).max(rgb[2]);
            assert_eq!(scale, 2.0 * m);
            let back = colour_of(&s).map(|v| v * scale);
            for (a, b) in back.iter().zip(rgb) {
                assert!((a - b).abs() < 2e-3 * m, "{rgb:?} → {back:?}");
            }
            if rgb[0] == rgb[1] && rgb[1] == rgb[2] {
                assert!(s.is_flat() && (s.eval(500.0) - 0.5).abs() < 1e-6);
            }
        }
    }

    #[test]
    fn illuminant_round_trips() {
        for rgb in [
            [1.0, 1.0, 1.0],
            [5.0, 2.0, 0.5],
            [0.1, 0.3, 0.9],
            [2.0, 2.0, 2.0],
        ] {
            let (scale, s) = illuminant(rgb);
            let xyz = cie::spectrum_to_xyz(|l| scale * s.eval(l) * d65_normalised(l));
            let back = cie::xyz_to_linear_srgb(xyz);
            let m = rgb[0].max(rgb[1]).max(rgb[2]);
            let err = (back - Vec3::from_array(rgb)).abs().max_element();
            assert!(err < 2e-3 * m, "{rgb:?} → {back}");
        }
        // A grey light is D65 itself, with Y = the grey value.
        let (scale, s) = illuminant([1.0; 3]);
        assert!(s.is_flat());
        let ratio = scale * s.eval(450.0) * d65_normalised(450.0) / cie::d65(450.0);
        let ratio2 = scale * s.eval(700.0) * d65_normalised(700.0) / cie::d65(700.0);
        assert!((ratio - ratio2).abs() < 1e-6 * ratio);
        let y = cie::spectrum_to_xyz(|l| scale * s.eval(l) * d65_normalised(l)).y;
        assert!((y - 1.0).abs() < 1e-5, "{y}");
    }
}
