//! FLIP and HDR-FLIP: perceptual per-pixel difference maps between a test and a reference image.
//!
//! An own implementation of
//! - **LDR-FLIP**: P. Andersson, J. Nilsson, T. Akenine-Möller, M. Oskarsson, K. Åström,
//!   M. D. Fairchild, "FLIP: A Difference Evaluator for Alternating Images", Proc. ACM Comput.
//!   Graph. Interact. Tech. 3(2) (HPG 2020) — cited below as **\[F\]**;
//! - **HDR-FLIP**: P. Andersson, J. Nilsson, P. Shirley, T. Akenine-Möller, "Visualizing Errors
//!   in Rendered High Dynamic Range Images", Eurographics 2021 short papers — cited as **\[H\]**.
//!
//! Values that the papers leave implicit were checked against the authors' public reference
//! implementation (NVlabs/flip, `python/flip_api.py`) — cited as **\[R\]**; no code was taken.
//!
//! **LDR pipeline \[F\]** for sRGB-encoded images with values in `[0, 1]`: decode sRGB → linear
//! Rec.709 RGB → CIE XYZ (D65) → YCxCz (CIELAB without the cube root). Colour: filter each YCxCz
//! channel with its contrast sensitivity filter, convert back to linear RGB, clamp to `[0, 1]³`,
//! convert to CIELAB, apply the Hunt adjustment `(L, 0.01·L·a, 0.01·L·b)`, take the HyAB distance
//! `|ΔL| + √(Δa² + Δb²)`, raise it to `qc`, and remap with `pc`, `pt` so that the Hunt-adjusted
//! green–blue distance (also raised to `qc`) maps to 1. Features: on the normalised achromatic
//! channel `(Y + 16) / 116 = Y/Y_w` of the *unfiltered* images, edge (first Gaussian derivative)
//! and point (second derivative) detectors in x and y; the feature error is
//! `(max(|‖e_r‖ − ‖e_t‖|, |‖p_r‖ − ‖p_t‖|) / √2)^qf`. Final error: `ΔE_c^(1 − ΔE_f)`.
//!
//! **HDR pipeline \[H\]** for linear-radiance Rec.709 images: exposures `c` from `c_start =
//! log₂(x_t / Y_max)` to `c_stop = log₂(x_t / Y_median)` of the reference luminance, where
//! `x_t` solves `tone(x_t) = 0.85`; `max(2, ⌈c_stop − c_start⌉)` evenly spaced exposures (one if
//! `c_start = c_stop`, both 0 if the reference is black). Each exposure scales both images by
//! `2^c`, tone-maps per channel with ACES (Narkowicz's fit, pre-scaled by 0.6 \[R\]), clamps to
//! `[0, 1]` and runs the LDR pipeline on those linear values; the HDR error is the per-pixel
//! maximum over exposures.
//!
//! | constant | value | source |
//! |---|---|---|
//! | CSF achromatic `(a1, b1, a2, b2)` | `(1, 0.0047, 0, 10⁻⁵)` | \[F\] §4.1, \[R\] |
//! | CSF red–green (Cx) | `(1, 0.0053, 0, 10⁻⁵)` | \[F\] §4.1, \[R\] |
//! | CSF blue–yellow (Cz) | `(34.1, 0.04, 13.5, 0.025)` | \[F\] §4.1, \[R\] |
//! | CSF kernel `a1√(π/b1)e^(−π²r²/b1) + a2√(π/b2)e^(−π²r²/b2)`, `r` in degrees, normalised to sum 1 | | \[F\] eq. 3, \[R\] |
//! | CSF radius `⌈3√(b_max/(2π²))·ppd⌉`, `b_max = 0.04` (all channels) | | \[R\] |
//! | `gw` (edge detector peak-to-trough, degrees), `σ = 0.5·gw·ppd`, radius `⌈3σ⌉` | 0.082 | \[F\] §4.2, \[R\] |
//! | detector weights: positive ones sum to 1, negative ones to −1 | | \[F\] §4.2, \[R\] |
//! | `qc`, `qf`, `pc`, `pt` | 0.7, 0.5, 0.4, 0.95 | \[F\] §4.1–4.3 |
//! | Hunt factor | 0.01 | \[F\] §4.1 |
//! | sRGB↔XYZ matrix (D65, rational form), white = XYZ of RGB (1,1,1) | | \[R\], IEC 61966-2-1 |
//! | sRGB transfer (0.04045, 12.92, 0.055, 1.055, 2.4) | | IEC 61966-2-1 |
//! | CIELAB `δ = 6/29` | | CIE 15 |
//! | ACES `(k0..k5) = (0.6²·2.51, 0.6·0.03, 0, 0.6²·2.43, 0.6·0.59, 0.14)` | | \[H\] §3, \[R\] |
//! | exposure target `t = 0.85`, luminance `(0.2126, 0.7152, 0.0722)` | | \[H\] §3, \[R\] |
//! | [`DEFAULT_PPD`] | 67 | \[F\] §5 (0.7 m wide 4K display at 0.7 m: 67.02) |
//!
//! **Deviations and conventions.** Filters replicate edge pixels at borders (as \[R\]). Input
//! sanitising: LDR NaN → 0, other values clamped to `[0, 1]`; HDR NaN, ±∞ and negatives → 0. If
//! the reference's median luminance is 0, the smallest positive luminance replaces it (the
//! paper's formula would give `+∞`). A non-finite or non-positive `ppd` is replaced by
//! [`DEFAULT_PPD`]; `ppd` is clamped to `[10⁻³, 10⁴]`. Final values are clamped to `[0, 1]`.
//! Zero-sized images give an empty map with mean 0.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

use std::f64::consts::PI;

/// Default observer: pixels per degree of visual angle for a 0.7 m wide 3840-pixel display
/// viewed from 0.7 m (\[F\] §5; exactly `0.7·3840/0.7·π/180 ≈ 67.02`).
pub const DEFAULT_PPD: f32 = 67.0;

/// Per-pixel FLIP error in `[0, 1]` and its mean.
#[derive(Clone, Debug, PartialEq)]
pub struct Flip {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width × height` errors in `[0, 1]`, row-major, top row first.
    pub map: Vec<f32>,
    /// Mean of `map` (0 for an empty image).
    pub mean: f32,
}

/// HDR-FLIP result: the error map plus the exposure range it was taken over.
#[derive(Clone, Debug, PartialEq)]
pub struct HdrFlip {
    /// Per-pixel maximum of LDR-FLIP over the exposures.
    pub flip: Flip,
    /// First exposure `c_start` (stops; images are scaled by `2^c`).
    pub start_exposure: f32,
    /// Last exposure `c_stop` (stops).
    pub stop_exposure: f32,
    /// Number of evenly spaced exposures evaluated (≥ 1).
    pub exposures: u32,
}

/// CSF terms `(a, b)` per YCxCz channel \[F\] §4.1.
const CSF: [[(f64, f64); 2]; 3] = [
    [(1.0, 0.0047), (0.0, 1e-5)],
    [(1.0, 0.0053), (0.0, 1e-5)],
    [(34.1, 0.04), (13.5, 0.025)],
];
const CSF_B_MAX: f64 = 0.04;
const GW: f64 = 0.082;
const QC: f32 = 0.7;
const QF: f32 = 0.5;
const PC: f32 = 0.4;
const PT: f32 = 0.95;
const ACES: [f64; 6] = [
    0.6 * 0.6 * 2.51,
    0.6 * 0.03,
    0.0,
    0.6 * 0.6 * 2.43,
    0.6 * 0.59,
    0.14,
];
const EXPOSURE_TARGET: f64 = 0.85;
const LUMA: [f64; 3] = [0.2126, 0.7152, 0.0722];

/// Linear Rec.709 RGB → XYZ (D65) as exact fractions `NUM[i][j] / DEN[i]` \[R\].
const NUM: [[f64; 3]; 3] = [
    [10135552.0, 8788810.0, 4435075.0],
    [2613072.0, 8788810.0, 887015.0],
    [1425312.0, 8788810.0, 70074185.0],
];
const DEN: [f64; 3] = [24577794.0, 12288897.0, 73733382.0];
const RGB_TO_XYZ: [[f32; 3]; 3] = to_f32(rgb_to_xyz(), false);
const XYZ_TO_RGB: [[f32; 3]; 3] = to_f32(rgb_to_xyz(), true);
/// XYZ of RGB (1, 1, 1): the reference white.
const WHITE: [f32; 3] = mul(&RGB_TO_XYZ, [1.0; 3]);

const fn rgb_to_xyz() -> [[f64; 3]; 3] {
    let mut m = NUM;
    let mut i = 0;
    while i < 9 {
        m[i / 3][i % 3] /= DEN[i / 3];
        i += 1;
    }
    m
}

/// `m` (or its inverse, by cofactors) rounded to `f32`.
const fn to_f32(m: [[f64; 3]; 3], invert: bool) -> [[f32; 3]; 3] {
    let mut c = [[0.0; 3]; 3];
    let mut i = 0;
    while i < 9 {
        let (r, k) = (i / 3, i % 3);
        let (r1, r2, k1, k2) = ((r + 1) % 3, (r + 2) % 3, (k + 1) % 3, (k + 2) % 3);
        c[k][r] = m[r1][k1] * m[r2][k2] - m[r1][k2] * m[r2][k1];
        i += 1;
    }
    let det = m[0][0] * c[0][0] + m[0][1] * c[1][0] + m[0][2] * c[2][0];
    let mut out = [[0.0; 3]; 3];
    i = 0;
    while i < 9 {
        let v = if invert {
            c[i / 3][i % 3] / det
        } else {
            m[i / 3][i % 3]
        };
        out[i / 3][i % 3] = v as f32;
        i += 1;
    }
    out
}

const fn mul(m: &[[f32; 3]; 3], v: [f32; 3]) -> [f32; 3] {
    let [a, b, c] = *m;
    [
        a[0] * v[0] + a[1] * v[1] + a[2] * v[2],
        b[0] * v[0] + b[1] * v[1] + b[2] * v[2],
        c[0] * v[0] + c[1] * v[1] + c[2] * v[2],
    ]
}

fn srgb_to_linear(c: f32) -> f32 {
    let c = if c.is_nan() { 0.0 } else { c.clamp(0.0, 1.0) };
    if c > 0.04045 {
        ((c + 0.055) / 1.055).powf(2.4)
    } else {
        c / 12.92
    }
}

fn linear_to_ycxcz(rgb: [f32; 3]) -> [f32; 3] {
    let [x, y, z] = mul(&RGB_TO_XYZ, rgb);
    let (x, y, z) = (x / WHITE[0], y / WHITE[1], z / WHITE[2]);
    [116.0 * y - 16.0, 500.0 * (x - y), 200.0 * (y - z)]
}

fn ycxcz_to_linear([l, cx, cz]: [f32; 3]) -> [f32; 3] {
    let y = (l + 16.0) / 116.0;
    mul(
        &XYZ_TO_RGB,
        [
            (y + cx / 500.0) * WHITE[0],
            y * WHITE[1],
            (y - cz / 200.0) * WHITE[2],
        ],
    )
}

/// Hunt-adjusted CIELAB of a linear RGB colour \[F\] §4.1.
fn hunt_lab(rgb: [f32; 3]) -> [f32; 3] {
    const D: f32 = 6.0 / 29.0;
    let f = |t: f32| {
        if t > D * D * D {
            t.cbrt()
        } else {
            t / (3.0 * D * D) + 4.0 / 29.0
        }
    };
    let xyz = mul(&RGB_TO_XYZ, rgb);
    let [fx, fy, fz] = [0, 1, 2].map(|i| f(xyz[i] / WHITE[i]));
    let l = 116.0 * fy - 16.0;
    [
        l,
        0.01 * l * 500.0 * (fx - fy),
        0.01 * l * 200.0 * (fy - fz),
    ]
}

fn hyab(a: [f32; 3], b: [f32; 3]) -> f32 {
    (a[0] - b[0]).abs() + (a[1] - b[1]).hypot(a[2] - b[2])
}

/// ACES tone curve with exposure already applied; `x ≥ 0`.
fn tone(x: f32) -> f32 {
    if x.is_nan() || x >= 1e6 {
        return 1.0; // the curve tends to 2.51/2.43 > 1 and is clamped
    }
    let [k0, k1, k2, k3, k4, k5] = ACES.map(|k| k as f32);
    ((k0 * x * x + k1 * x + k2) / (k3 * x * x + k4 * x + k5)).clamp(0.0, 1.0)
}

/// `(weight, normalised 1-D Gaussian)` terms whose products `g(x)·g(y)` sum to the CSF kernel.
fn csf_terms(ppd: f64, csf: &[(f64, f64); 2]) -> Vec<(f32, Vec<f32>)> {
    let r = (3.0 * (CSF_B_MAX / (2.0 * PI * PI)).sqrt() * ppd).ceil() as i64;
    let mut terms: Vec<(f64, Vec<f64>)> = Vec::new();
    for &(a, b) in csf.iter().filter(|(a, _)| *a != 0.0) {
        let g: Vec<f64> = (-r..=r)
            .map(|j| (-PI * PI * (j as f64 / ppd).powi(2) / b).exp())
            .collect();
        let s: f64 = g.iter().sum();
        terms.push((
            a * (PI / b).sqrt() * s * s,
            g.iter().map(|v| v / s).collect(),
        ));
    }
    let total: f64 = terms.iter().map(|t| t.0).sum();
    terms
        .into_iter()
        .map(|(w, g)| {
            (
                (w / total) as f32,
                g.into_iter().map(|v| v as f32).collect(),
            )
        })
        .collect()
}

/// Feature kernels `[gaussian, first derivative, second derivative]` \[F\] §4.2.
fn feature_kernels(ppd: f64) -> [Vec<f32>; 3] {
    let sd = 0.5 * GW * ppd;
    let r = (3.0 * sd).ceil() as i64;
    let g = |j: i64| (-((j * j) as f64) / (2.0 * sd * sd)).exp();
    let signed = |v: Vec<f64>| {
        let pos: f64 = v.iter().filter(|x| **x > 0.0).sum();
        let neg: f64 = -v.iter().filter(|x| **x < 0.0).sum::<f64>();
        let n = |x: f64, s: f64| if s > 0.0 { (x / s) as f32 } else { 0.0 };
        v.into_iter()
            .map(|x| if x < 0.0 { n(x, neg) } else { n(x, pos) })
            .collect()
    };
    let s: f64 = (-r..=r).map(g).sum();
    [
        (-r..=r).map(|j| (g(j) / s) as f32).collect(),
        signed((-r..=r).map(|j| -(j as f64) * g(j)).collect()),
        signed(
            (-r..=r)
                .map(|j| ((j * j) as f64 / (sd * sd) - 1.0) * g(j))
                .collect(),
        ),
    ]
}

/// Horizontal correlation with `k` (odd length), edge pixels replicated.
fn conv_h(src: &[f32], dst: &mut [f32], w: usize, k: &[f32], line: &mut Vec<f32>) {
    let r = k.len() / 2;
    for (s, d) in src.chunks_exact(w).zip(dst.chunks_exact_mut(w)) {
        line.clear();
        line.extend(std::iter::repeat_n(s[0], r));
        line.extend_from_slice(s);
        line.extend(std::iter::repeat_n(s[w - 1], r));
        for (x, o) in d.iter_mut().enumerate() {
            *o = line[x..x + k.len()].iter().zip(k).map(|(a, b)| a * b).sum();
        }
    }
}

/// Vertical correlation with `k` (odd length), edge rows replicated.
fn conv_v(src: &[f32], dst: &mut [f32], w: usize, k: &[f32]) {
    let (r, h) = (k.len() / 2, src.len() / w);
    for (y, d) in dst.chunks_exact_mut(w).enumerate() {
        d.fill(0.0);
        for (t, &kt) in k.iter().enumerate() {
            let sy = (y + t).saturating_sub(r).min(h - 1);
            for (o, v) in d.iter_mut().zip(&src[sy * w..(sy + 1) * w]) {
                *o += kt * v;
            }
        }
    }
}

/// Per-image quantities compared by FLIP.
#[derive(Default)]
struct Analysis {
    lab: Vec<[f32; 3]>,
    edge: Vec<f32>,
    point: Vec<f32>,
}

/// Kernels and scratch buffers for one image size and ppd, reused across HDR exposures.
struct Evaluator {
    w: usize,
    csf: [Vec<(f32, Vec<f32>)>; 3],
    feat: [Vec<f32>; 3],
    cmax: f32,
    planes: Vec<f32>,
    line: Vec<f32>,
    test: Analysis,
    reference: Analysis,
}

impl Evaluator {
    fn new(w: usize, h: usize, ppd: f32) -> Self {
        let ppd = if ppd.is_finite() && ppd > 0.0 {
            ppd
        } else {
            DEFAULT_PPD
        };
        let ppd = f64::from(ppd.clamp(1e-3, 1e4));
        let cmax = hyab(hunt_lab([0.0, 1.0, 0.0]), hunt_lab([0.0, 0.0, 1.0])).powf(QC);
        Evaluator {
            w,
            csf: CSF.each_ref().map(|c| csf_terms(ppd, c)),
            feat: feature_kernels(ppd),
            cmax,
            planes: vec![0.0; 9 * w * h],
            line: Vec::new(),
            test: Analysis::default(),
            reference: Analysis::default(),
        }
    }

    /// Analyses the image whose linear RGB (in `[0, 1]`) at index `i` is `pixel(i)`.
    fn analyse(&mut self, is_test: bool, pixel: impl Fn(usize) -> [f32; 3]) {
        let (w, n) = (self.w, self.planes.len() / 9);
        let mut it = self.planes.chunks_exact_mut(n);
        let [y, cx, cz, lum, fy, fcx, fcz, t1, t2] = std::array::from_fn(|_| it.next().unwrap());
        for i in 0..n {
            [y[i], cx[i], cz[i]] = linear_to_ycxcz(pixel(i));
            lum[i] = (y[i] + 16.0) / 116.0;
        }
        for (terms, (src, dst)) in self.csf.iter().zip([(&*y, &mut *fy), (cx, fcx), (cz, fcz)]) {
            dst.fill(0.0);
            for (wt, k) in terms {
                conv_h(src, t1, w, k, &mut self.line);
                conv_v(t1, t2, w, k);
                dst.iter_mut()
                    .zip(t2.iter())
                    .for_each(|(d, v)| *d += wt * v);
            }
        }
        let out = if is_test {
            &mut self.test
        } else {
            &mut self.reference
        };
        out.lab.clear();
        out.lab.extend((0..n).map(|i| {
            hunt_lab(ycxcz_to_linear([fy[i], fcx[i], fcz[i]]).map(|c| c.clamp(0.0, 1.0)))
        }));
        let [g, d1, d2] = &self.feat;
        conv_h(lum, y, w, g, &mut self.line);
        conv_h(lum, cx, w, d1, &mut self.line);
        conv_h(lum, cz, w, d2, &mut self.line);
        for (k, h_pass, dst) in [(d1, &*cx, &mut out.edge), (d2, &*cz, &mut out.point)] {
            conv_v(h_pass, t1, w, g);
            conv_v(y, t2, w, k);
            dst.clear();
            dst.extend(t1.iter().zip(t2.iter()).map(|(a, b)| a.hypot(*b)));
        }
    }

    /// FLIP error of pixel `i` after both images were analysed.
    fn error(&self, i: usize) -> f32 {
        let (t, r, cmax) = (&self.test, &self.reference, self.cmax);
        let dc = hyab(t.lab[i], r.lab[i]).powf(QC);
        let pccmax = PC * cmax;
        let ec = if dc < pccmax {
            PT / pccmax * dc
        } else {
            PT + (dc - pccmax) / (cmax - pccmax) * (1.0 - PT)
        };
        let df = (t.edge[i] - r.edge[i])
            .abs()
            .max((t.point[i] - r.point[i]).abs());
        let df = (df * std::f32::consts::FRAC_1_SQRT_2).powf(QF).min(1.0);
        let e = ec.min(1.0).powf(1.0 - df);
        if e.is_nan() { 1.0 } else { e.clamp(0.0, 1.0) }
    }
}

fn check_sizes(test: &[[f32; 3]], reference: &[[f32; 3]], width: u32, height: u32) -> usize {
    let n = width as usize * height as usize;
    assert!(
        test.len() == n && reference.len() == n,
        "FLIP: images have {} and {} pixels, expected {width}×{height}",
        test.len(),
        reference.len()
    );
    n
}

fn finish(width: u32, height: u32, map: Vec<f32>) -> Flip {
    let mean = if map.is_empty() {
        0.0
    } else {
        map.iter().map(|&v| f64::from(v)).sum::<f64>() / map.len() as f64
    };
    Flip {
        width,
        height,
        map,
        mean: mean as f32,
    }
}

/// LDR-FLIP \[F\] of two **sRGB-encoded** display images (values in `[0, 1]`; NaN → 0, others
/// clamped), viewed at `ppd` pixels per degree ([`DEFAULT_PPD`] is the paper's default).
///
/// # Panics
/// If a slice does not hold `width × height` pixels.
pub fn ldr_flip(
    test: &[[f32; 3]],
    reference: &[[f32; 3]],
    width: u32,
    height: u32,
    ppd: f32,
) -> Flip {
    let n = check_sizes(test, reference, width, height);
    if n == 0 {
        return finish(width, height, Vec::new());
    }
    let mut ev = Evaluator::new(width as usize, height as usize, ppd);
    ev.analyse(true, |i| test[i].map(srgb_to_linear));
    ev.analyse(false, |i| reference[i].map(srgb_to_linear));
    finish(width, height, (0..n).map(|i| ev.error(i)).collect())
}

/// HDR-FLIP exposure range `(c_start, c_stop, count)` of a sanitised reference \[H\] §3.
fn exposure_range(reference: &[[f32; 3]]) -> (f32, f32, u32) {
    let mut lum: Vec<f64> = reference
        .iter()
        .map(|p| (0..3).map(|c| LUMA[c] * f64::from(hdr_value(p[c]))).sum())
        .collect();
    let y_max = lum.iter().copied().fold(0.0, f64::max);
    if y_max <= 0.0 {
        return (0.0, 0.0, 1);
    }
    let y_min_pos = lum
        .iter()
        .copied()
        .filter(|&v| v > 0.0)
        .fold(f64::INFINITY, f64::min);
    let m = lum.len() / 2;
    let (_, &mut hi, _) = lum.select_nth_unstable_by(m, f64::total_cmp);
    let lo = if lum.len().is_multiple_of(2) {
        lum[..m].iter().copied().fold(f64::MIN, f64::max)
    } else {
        hi
    };
    let median = 0.5 * (lo + hi);
    let median = if median > 0.0 { median } else { y_min_pos };
    // Positive root of tone(x) = t, i.e. (k0 − t·k3)x² + (k1 − t·k4)x + (k2 − t·k5) = 0.
    let [k0, k1, k2, k3, k4, k5] = ACES;
    let t = EXPOSURE_TARGET;
    let (c0, c1) = ((k1 - k4 * t) / (k0 - k3 * t), (k2 - k5 * t) / (k0 - k3 * t));
    let x_t = -0.5 * c0 + (0.25 * c0 * c0 - c1).sqrt();
    let (start, stop) = ((x_t / y_max).log2() as f32, (x_t / median).log2() as f32);
    let count = if start == stop {
        1
    } else {
        (stop - start).ceil().max(2.0) as u32
    };
    (start, stop, count)
}

/// HDR input sanitising: NaN, ±∞ and negative values become 0.
fn hdr_value(c: f32) -> f32 {
    if c.is_finite() && c > 0.0 { c } else { 0.0 }
}

/// HDR-FLIP \[H\] of two **linear-radiance** Rec.709 RGB images (NaN, ±∞, negatives → 0), viewed
/// at `ppd` pixels per degree; the exposure range is chosen from the reference.
///
/// # Panics
/// If a slice does not hold `width × height` pixels.
pub fn hdr_flip(
    test: &[[f32; 3]],
    reference: &[[f32; 3]],
    width: u32,
    height: u32,
    ppd: f32,
) -> HdrFlip {
    let n = check_sizes(test, reference, width, height);
    let (start, stop, count) = exposure_range(reference);
    let mut map = vec![0.0f32; n];
    if n > 0 {
        let mut ev = Evaluator::new(width as usize, height as usize, ppd);
        let step = (stop - start) / (count.max(2) - 1) as f32;
        for k in 0..count {
            let scale = (start + k as f32 * step).exp2();
            ev.analyse(true, |i| test[i].map(|c| tone(hdr_value(c) * scale)));
            ev.analyse(false, |i| reference[i].map(|c| tone(hdr_value(c) * scale)));
            map.iter_mut()
                .enumerate()
                .for_each(|(i, m)| *m = m.max(ev.error(i)));
        }
    }
    HdrFlip {
        flip: finish(width, height, map),
        start_exposure: start,
        stop_exposure: stop,
        exposures: count,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn random_image(n: usize, seed: u64, hi: f32) -> Vec<[f32; 3]> {
        let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        let mut next = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 24) as f32 * hi
        };
        (0..n).map(|_| [next(), next(), next()]).collect()
    }

    fn assert_valid(f: &Flip) {
        assert_eq!(f.map.len(), (f.width * f.height) as usize);
        assert!(
            f.map
                .iter()
                .all(|v| v.is_finite() && (0.0..=1.0).contains(v)),
            "{:?}",
            f.map
        );
        assert!(f.mean.is_finite() && (0.0..=1.0).contains(&f.mean));
    }

    #[test]
    fn identical_images_give_zero() {
        let img = random_image(40 * 30, 1, 1.0);
        let f = ldr_flip(&img, &img, 40, 30, DEFAULT_PPD);
        assert!(f.map.iter().all(|&v| v == 0.0) && f.mean == 0.0);
        let hdr = random_image(40 * 30, 2, 20.0);
        let h = hdr_flip(&hdr, &hdr, 40, 30, DEFAULT_PPD);
        assert!(h.flip.map.iter().all(|&v| v == 0.0) && h.flip.mean == 0.0);
    }

    #[test]
    fn values_in_unit_range_for_random_and_non_finite_inputs() {
        for (w, h) in [(1, 1), (1, 7), (9, 1), (23, 17)] {
            let n = w as usize * h as usize;
            let (a, b) = (random_image(n, 3, 1.0), random_image(n, 4, 1.0));
            assert_valid(&ldr_flip(&a, &b, w, h, DEFAULT_PPD));
            let (a, b) = (random_image(n, 5, 100.0), random_image(n, 6, 100.0));
            let hf = hdr_flip(&a, &b, w, h, DEFAULT_PPD);
            assert_valid(&hf.flip);
            assert!(hf.exposures >= 1 && hf.start_exposure <= hf.stop_exposure);
        }
        let bad = [
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            -1.0,
            1e38,
            f32::MIN_POSITIVE,
        ];
        let mut a = random_image(64, 7, 5.0);
        for (i, p) in a.iter_mut().enumerate() {
            p[i % 3] = bad[i % bad.len()];
        }
        let b = random_image(64, 8, 5.0);
        for ppd in [DEFAULT_PPD, f32::NAN, -3.0, 0.5, 1e9] {
            assert_valid(&ldr_flip(&a, &b, 8, 8, ppd));
            assert_valid(&hdr_flip(&a, &b, 8, 8, ppd).flip);
            assert_valid(&hdr_flip(&b, &a, 8, 8, ppd).flip);
        }
        assert_valid(
            &hdr_flip(
                &a,
                &a.iter().map(|_| [f32::NAN; 3]).collect::<Vec<_>>(),
                8,
                8,
                67.0,
            )
            .flip,
        );
        assert_eq!(ldr_flip(&[], &[], 0, 5, DEFAULT_PPD).mean, 0.0);
    }

    #[test]
    fn black_versus_white_is_near_one() {
        // Both images are constant, so the features agree (ΔE_f = 0) and ΔE = ΔE_c: HyAB = 100
        // (L* 0 vs 100), 100^0.7 = 25.1 > pc·cmax = 0.4·203.3^0.7 = 16.5, so
        // ΔE_c = 0.95 + (25.1 − 16.5)/(41.3 − 16.5)·0.05 ≈ 0.967.
        let f = ldr_flip(&[[0.0; 3]; 64], &[[1.0; 3]; 64], 8, 8, DEFAULT_PPD);
        assert!((f.mean - 0.967).abs() < 2e-3, "{}", f.mean);
        assert!(f.map.iter().all(|&v| (v - f.mean).abs() < 1e-5));
        // The green–blue distance is the normalisation: it maps to exactly 1.
        let g = ldr_flip(
            &[[0.0, 1.0, 0.0]; 16],
            &[[0.0, 0.0, 1.0]; 16],
            4,
            4,
            DEFAULT_PPD,
        );
        assert!((g.mean - 1.0).abs() < 1e-5, "{}", g.mean);
    }

    #[test]
    fn error_grows_as_grey_is_brightened() {
        let r = vec![[0.3f32; 3]; 100];
        let mut last = 0.0;
        for k in 1..=14 {
            let t = vec![[0.3 + 0.05 * k as f32; 3]; 100];
            let m = ldr_flip(&t, &r, 10, 10, DEFAULT_PPD).mean;
            assert!(m > last, "step {k}: {m} <= {last}");
            last = m;
        }
        assert!(last > 0.5);
    }

    #[test]
    fn single_pixel_change_is_local() {
        let (w, h) = (48usize, 40usize);
        let r = vec![[0.5f32; 3]; w * h];
        let mut t = r.clone();
        t[20 * w + 24] = [1.0, 0.2, 0.1];
        let f = ldr_flip(&t, &r, w as u32, h as u32, DEFAULT_PPD);
        assert!(f.map[20 * w + 24] > 0.1, "{}", f.map[20 * w + 24]);
        for (i, &v) in f.map.iter().enumerate() {
            let (x, y) = ((i % w) as i64, (i / w) as i64);
            if (x - 24).abs().max((y - 20).abs()) > 11 {
                assert_eq!(v, 0.0, "pixel ({x}, {y})");
            }
        }
    }

    #[test]
    fn hdr_scaling() {
        let (w, h) = (96usize, 96usize);
        let r: Vec<[f32; 3]> = random_image(w * h, 9, 1.0)
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let s = 0.05
                    + 8.0 * ((i % w) as f32 / w as f32).powi(3)
                    + 0.3 * ((i / w) as f32 * 0.3).sin().abs();
                p.map(|c| s * (0.5 + c))
            })
            .collect();
        let scaled = |k: f32| r.iter().map(|p| p.map(|c| c * k)).collect::<Vec<_>>();
        let t0 = std::time::Instant::now();
        let double = hdr_flip(&scaled(2.0), &r, w as u32, h as u32, DEFAULT_PPD);
        let elapsed = t0.elapsed();
        let near = hdr_flip(&scaled(1.01), &r, w as u32, h as u32, DEFAULT_PPD);
        println!(
            "96x96 HDR-FLIP: {elapsed:?}, {} exposures [{}, {}]; x2 mean {}, x1.01 mean {}",
            double.exposures,
            double.start_exposure,
            double.stop_exposure,
            double.flip.mean,
            near.flip.mean
        );
        assert!(double.flip.mean > 0.15, "{}", double.flip.mean);
        assert!(
            near.flip.mean < 0.05 && near.flip.mean > 0.0,
            "{}",
            near.flip.mean
        );
        assert!(double.exposures >= 2);
    }

    #[test]
    fn exposure_range_of_simple_images() {
        let f = hdr_flip(&[[2.0; 3]; 9], &[[1.0; 3]; 9], 3, 3, DEFAULT_PPD);
        assert_eq!(f.exposures, 1);
        assert_eq!(f.start_exposure, f.stop_exposure);
        // At the single exposure the reference maps to the target 0.85.
        assert!((tone(f.start_exposure.exp2()) - 0.85).abs() < 1e-4);
        assert!(f.flip.mean > 0.1);
        // Luminances 1, 1, 4: max 4, median 1 → two stops, two exposures.
        let (s, e, n) = exposure_range(&[[1.0; 3], [1.0; 3], [4.0; 3]]);
        assert!(((e - s) - 2.0).abs() < 1e-5 && n == 2, "{s} {e} {n}");
        assert_eq!(exposure_range(&[[0.0; 3]; 4]), (0.0, 0.0, 1));
        // Median 0 falls back to the smallest positive luminance (0.25 → 4 stops).
        let (s, e, n) = exposure_range(&[[0.0; 3], [0.0; 3], [0.0; 3], [0.25; 3], [4.0; 3]]);
        assert!(((e - s) - 4.0).abs() < 1e-5 && n == 4, "{s} {e} {n}");
    }

    #[test]
    fn color_round_trip_is_identity() {
        for p in
            random_image(2000, 10, 1.0)
                .into_iter()
                .chain([[0.0; 3], [1.0; 3], [1.0, 0.0, 0.0]])
        {
            let q = ycxcz_to_linear(linear_to_ycxcz(p));
            assert!((0..3).all(|c| (p[c] - q[c]).abs() < 1e-5), "{p:?} -> {q:?}");
        }
        assert!((linear_to_ycxcz([1.0; 3])[0] - 100.0).abs() < 1e-4);
        assert!(
            linear_to_ycxcz([1.0; 3])[1..]
                .iter()
                .all(|c| c.abs() < 1e-4)
        );
    }
}
