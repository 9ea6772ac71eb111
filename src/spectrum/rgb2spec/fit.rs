//! The fit of a sigmoid-polynomial spectrum to a linear sRGB colour (Jakob & Hanika 2019) and the
//! coefficient table built from it ([`super`] describes both). Double precision throughout.
//!
//! The colour of coefficients `c` is `rgb(c) = Σ_n S(p_c(t_n)) w_n` over the nodes of a
//! quadrature: normalised wavelengths `t_n` and weights `w_n`, the white-balanced linear sRGB
//! of a unit reflectance at `t_n` under D65. The residual is the CIELAB difference
//! `Lab(rgb(c)) − Lab(target)` (CIE 015:2004, reference white = sRGB white), as in the
//! paper, with an analytic Jacobian: `S'(x) = 1 / (2 (1 + x²)^{3/2})`, `∂p/∂c = (t², t, 1)`.
//! Gauss–Newton solves the 3 × 3 system per step (Levenberg–Marquardt damping if it is singular),
//! limits the step to 20 per coefficient and halves it until the error decreases. Each
//! fit iterates first on 5 nm nodes (cheap, within ΔE ≈ 0.3 of the 1 nm sums) and then on the
//! 1 nm sums that define [`super::reflectance_to_rgb`], to ΔE < 10⁻⁶.

use super::super::cie::{self, CMF_SAMPLES, LAMBDA_MIN};
use super::sigmoid_inverse;
use glam::{DMat3, DVec3};
use rayon::prelude::*;
use std::sync::OnceLock;

/// Converged when ΔE76 is below this.
const TOL: f64 = 1e-6;
/// A fit worse than this (ΔE76) is retried through intermediate targets.
const RETRY: f64 = 1e-3;
/// Iteration limit of one Gauss–Newton solve.
const MAX_ITER: usize = 60;
/// Largest change of one coefficient per step (normalised-wavelength units).
const STEP_MAX: f64 = 20.0;
/// Node spacing of the coarse quadrature, nm.
const COARSE_STEP: usize = 5;
/// Halvings of the intermediate-target retry.
const RETRY_DEPTH: u32 = 6;
/// The grey column's value at `z = 1` (flat 1 has an infinite coefficient, not interpolable).
const WHITE_CAP: f64 = 0.999;

/// A quadrature over 360–830 nm: node `n` is `[t, w_r, w_g, w_b]`, the normalised wavelength and
/// the white-balanced linear sRGB weight of a unit reflectance there under D65 (so the weights sum
/// to exactly (1, 1, 1)); padded with zero-weight nodes to a multiple of [`LANES`].
pub(super) struct Quadrature {
    nodes: Vec<[f64; 4]>,
}

/// Nodes evaluated together (independent accumulators, which the compiler can vectorise).
const LANES: usize = 4;

impl Quadrature {
    /// Nodes every `step` nm (a divisor of 470), each 1 nm sample's weight shared between its two
    /// nodes linearly: exact for spectra linear between nodes, and the 1 nm sums for `step = 1`.
    fn new(step: usize) -> Quadrature {
        let to_rgb = cie::XYZ_TO_LINEAR_SRGB.as_dmat3();
        let raw: Vec<DVec3> = (0..CMF_SAMPLES)
            .map(|i| {
                let lambda = LAMBDA_MIN + i as f32;
                to_rgb * (cie::xyz_bar(lambda) * cie::d65(lambda)).as_dvec3()
            })
            .collect();
        let white: DVec3 = raw.iter().sum();
        let last = (CMF_SAMPLES - 1) / step;
        let mut w = vec![DVec3::ZERO; last + 1];
        for (i, v) in raw.iter().enumerate() {
            let (n, f) = (i / step, (i % step) as f64 / step as f64);
            w[n] += (1.0 - f) * *v / white;
            if f > 0.0 {
                w[n + 1] += f * *v / white;
            }
        }
        let mut nodes: Vec<[f64; 4]> = (0..=last)
            .map(|n| [n as f64 / last as f64, w[n].x, w[n].y, w[n].z])
            .collect();
        nodes.resize(nodes.len().next_multiple_of(LANES), [0.0; 4]);
        Quadrature { nodes }
    }

    /// The 1 nm sums ([`super::reflectance_to_rgb`], and the last iterations of every fit).
    pub(super) fn fine() -> &'static Quadrature {
        static Q: OnceLock<Quadrature> = OnceLock::new();
        Q.get_or_init(|| Quadrature::new(1))
    }

    /// Nodes every 5 nm, for the first iterations of a fit.
    fn coarse() -> &'static Quadrature {
        static Q: OnceLock<Quadrature> = OnceLock::new();
        Q.get_or_init(|| Quadrature::new(COARSE_STEP))
    }

    /// The nodes as `[t, w_r, w_g, w_b]` (including zero-weight padding).
    pub(super) fn nodes(&self) -> &[[f64; 4]] {
        &self.nodes
    }
}

/// CIELAB `f` and its derivative (CIE 015:2004 eq. 8.9).
fn lab_f(v: f64) -> (f64, f64) {
    const D: f64 = 6.0 / 29.0;
    if v > D * D * D {
        let c = v.cbrt();
        (c, 1.0 / (3.0 * c * c))
    } else {
        let k = 1.0 / (3.0 * D * D);
        (v * k + 4.0 / 29.0, k)
    }
}

/// CIELAB of a linear sRGB colour (reference white: sRGB white) and `∂Lab/∂rgb`.
pub(super) fn lab(rgb: DVec3) -> (DVec3, DMat3) {
    let m = cie::LINEAR_SRGB_TO_XYZ.as_dmat3();
    let white = m * DVec3::ONE;
    let a = DMat3::from_diagonal(white.recip()) * m;
    let v = a * rgb;
    let ((fx, dx), (fy, dy), (fz, dz)) = (lab_f(v.x), lab_f(v.y), lab_f(v.z));
    let value = DVec3::new(116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz));
    let d = DMat3::from_cols(
        DVec3::new(0.0, 500.0 * dx, 0.0),
        DVec3::new(116.0 * dy, -500.0 * dy, 200.0 * dy),
        DVec3::new(0.0, 0.0, -200.0 * dz),
    );
    (value, d * a)
}

/// The colour of coefficients `c` under the quadrature `q`, and its Jacobian `∂rgb/∂c` (columns
/// `c0`, `c1`, `c2`). `S(p) = 1/2 + p/(2r)` and `S'(p) = 1/(2r³)`, `r = √(1 + p²)`; in double
/// precision the direct form of `S` keeps ample relative precision down to the table's darkest
/// values.
fn colour(q: &Quadrature, c: DVec3) -> (DVec3, DMat3) {
    // sums[m][lane]: m = 0..3 rgb, 3..6 ∂/∂c0, 6..9 ∂/∂c1, 9..12 ∂/∂c2.
    let mut sums = [[0.0f64; LANES]; 12];
    for chunk in q.nodes.chunks_exact(LANES) {
        for (lane, &[t, wr, wg, wb]) in chunk.iter().enumerate() {
            let p = (c.x * t + c.y) * t + c.z;
            let inv_r = 1.0 / (1.0 + p * p).sqrt();
            let s = 0.5 + 0.5 * p * inv_r;
            let ds = 0.5 * inv_r * inv_r * inv_r;
            for (m, f) in [s, ds * t * t, ds * t, ds].into_iter().enumerate() {
                sums[3 * m][lane] += f * wr;
                sums[3 * m + 1][lane] += f * wg;
                sums[3 * m + 2][lane] += f * wb;
            }
        }
    }
    let v = |m: usize| {
        DVec3::new(
            sums[m].iter().sum(),
            sums[m + 1].iter().sum(),
            sums[m + 2].iter().sum(),
        )
    };
    (v(0), DMat3::from_cols(v(3), v(6), v(9)))
}

/// Residual `Lab(rgb(c)) − target_lab` and its Jacobian.
fn residual(q: &Quadrature, c: DVec3, target_lab: DVec3) -> (DVec3, DMat3) {
    let (rgb, d_rgb) = colour(q, c);
    let (l, d_lab) = lab(rgb);
    (l - target_lab, d_lab * d_rgb)
}

/// Gauss–Newton from `c` towards the colour `target`, on the 5 nm quadrature and then on the 1 nm
/// one: the coefficients and their ΔE76 (1 nm).
fn solve(target: DVec3, c: DVec3) -> (DVec3, f64) {
    let target_lab = lab(target).0;
    let (c, _) = gauss_newton(Quadrature::coarse(), target_lab, c);
    gauss_newton(Quadrature::fine(), target_lab, c)
}

/// Gauss–Newton from `c` towards `target_lab` under the quadrature `q`.
fn gauss_newton(q: &Quadrature, target_lab: DVec3, mut c: DVec3) -> (DVec3, f64) {
    let (mut r, mut j) = residual(q, c, target_lab);
    for _ in 0..MAX_ITER {
        let err = r.length();
        if err < TOL {
            break;
        }
        let det = j.determinant();
        let mut step = if det.is_finite() && det.abs() > 1e-300 {
            -(j.inverse() * r)
        } else {
            // Levenberg–Marquardt: (JᵀJ + μI) δ = −Jᵀr.
            let jt = j.transpose();
            let jtj = jt * j;
            let mu = 1e-6 * (jtj.x_axis.x + jtj.y_axis.y + jtj.z_axis.z).max(1e-300);
            -((jtj + DMat3::from_diagonal(DVec3::splat(mu))).inverse() * (jt * r))
        };
        if !step.is_finite() {
            break;
        }
        let m = step.abs().max_element();
        if m > STEP_MAX {
            step *= STEP_MAX / m;
        }
        let mut accepted = false;
        for _ in 0..30 {
            let (rn, jn) = residual(q, c + step, target_lab);
            if rn.length() < err {
                (c, r, j, accepted) = (c + step, rn, jn, true);
                break;
            }
            step *= 0.5;
        }
        if !accepted {
            break;
        }
    }
    (c, r.length())
}

/// [`solve`] from the solution `c_from` of the colour `from`; when that does not reach [`RETRY`],
/// through the midpoint of the straight line in RGB, recursively (`depth` halvings).
fn solve_from(from: DVec3, c_from: DVec3, to: DVec3, depth: u32) -> (DVec3, f64) {
    let (c, e) = solve(to, c_from);
    if e <= RETRY || depth == 0 {
        return (c, e);
    }
    let mid = (from + to) * 0.5;
    let (cm, _) = solve_from(from, c_from, mid, depth - 1);
    let (c2, e2) = solve_from(mid, cm, to, depth - 1);
    if e2 < e { (c2, e2) } else { (c, e) }
}

/// The flat spectrum `v ∈ (0, 1)` as coefficients.
fn flat(v: f64) -> DVec3 {
    DVec3::new(0.0, 0.0, f64::from(sigmoid_inverse(v as f32)))
}

/// Fits coefficients to a linear sRGB colour (channels clamped to [0, 1], NaN to 0), continuing
/// from the flat 1/2 along the straight line to it: `(c, ΔE76)`, `c` as in
/// [`super::Sigmoid::coeffs`]. Black and white are not reachable (the fit approaches them with
/// growing coefficients); [`super::reflectance`] treats greys exactly.
pub fn fit_rgb(rgb: [f32; 3]) -> ([f32; 3], f32) {
    let target = DVec3::from_array(rgb.map(|v| f64::from(super::unit(v))));
    let (c, e) = solve_from(DVec3::splat(0.5), flat(0.5), target, RETRY_DEPTH);
    (c.as_vec3().to_array(), e as f32)
}

/// The brightness slices `z_k = z_dark + (1 − z_dark) · smoothstep(k / (res − 1))`, `k < res`.
pub(super) fn z_scale(res: usize, z_dark: f64) -> Vec<f64> {
    (0..res)
        .map(|k| {
            let u = k as f64 / (res - 1) as f64;
            z_dark + (1.0 - z_dark) * u * u * (3.0 - 2.0 * u)
        })
        .collect()
}

/// Fills the table (layout of `super::Table::coeffs`) for the slices `z`: the coefficients and the
/// largest ΔE76 of a fit (the grey column, set exactly, excluded).
pub(super) fn build_table(res: usize, z: &[f64]) -> (Vec<[f32; 3]>, f32) {
    let n = res - 1;
    let km = res / 2;
    let target = |l: usize, k: usize, j: usize, i: usize| {
        let mut v = [0.0; 3];
        v[l] = z[k];
        v[(l + 1) % 3] = z[k] * i as f64 / n as f64;
        v[(l + 2) % 3] = z[k] * j as f64 / n as f64;
        DVec3::from_array(v)
    };
    // The middle slice: the row y = 1 from its grey corner, then every column from that row.
    let rows: Vec<Vec<DVec3>> = (0..3)
        .into_par_iter()
        .map(|l| {
            let mut row = vec![flat(z[km]); res];
            for i in (0..n).rev() {
                row[i] = solve_from(
                    target(l, km, n, i + 1),
                    row[i + 1],
                    target(l, km, n, i),
                    RETRY_DEPTH,
                )
                .0;
            }
            row
        })
        .collect();
    let columns: Vec<Vec<DVec3>> = (0..3 * res)
        .into_par_iter()
        .map(|li| {
            let (l, i) = (li / res, li % res);
            let mut col = vec![rows[l][i]; res];
            for j in (0..n).rev() {
                col[j] = solve_from(
                    target(l, km, j + 1, i),
                    col[j + 1],
                    target(l, km, j, i),
                    RETRY_DEPTH,
                )
                .0;
            }
            col
        })
        .collect();
    // Every (x, y): from the middle brightness up to 1 and down to the first slice.
    let chains: Vec<(Vec<[f32; 3]>, f64)> = (0..3 * res * res)
        .into_par_iter()
        .map(|lji| {
            let (l, j, i) = (lji / (res * res), (lji / res) % res, lji % res);
            if i == n && j == n {
                let grey = (0..res).map(|k| flat(z[k].min(WHITE_CAP)).as_vec3().to_array());
                return (grey.collect(), 0.0);
            }
            let mut c = vec![DVec3::ZERO; res];
            let mut worst = 0.0f64;
            let (c0, e0) = solve(target(l, km, j, i), columns[l * res + i][j]);
            c[km] = c0;
            worst = worst.max(e0);
            for k in km + 1..res {
                let (ck, e) = solve_from(
                    target(l, k - 1, j, i),
                    c[k - 1],
                    target(l, k, j, i),
                    RETRY_DEPTH,
                );
                (c[k], worst) = (ck, worst.max(e));
            }
            for k in (0..km).rev() {
                let (ck, e) = solve_from(
                    target(l, k + 1, j, i),
                    c[k + 1],
                    target(l, k, j, i),
                    RETRY_DEPTH,
                );
                (c[k], worst) = (ck, worst.max(e));
            }
            (c.iter().map(|v| v.as_vec3().to_array()).collect(), worst)
        })
        .collect();
    let mut coeffs = vec![[0.0f32; 3]; 3 * res * res * res];
    let mut worst = 0.0f64;
    for (lji, (chain, e)) in chains.into_iter().enumerate() {
        let (l, ji) = (lji / (res * res), lji % (res * res));
        for (k, c) in chain.into_iter().enumerate() {
            coeffs[(l * res + k) * res * res + ji] = c;
        }
        worst = worst.max(e);
    }
    (coeffs, worst as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_make_the_perfect_reflector_white() {
        for q in [Quadrature::fine(), Quadrature::coarse()] {
            let sum = q
                .nodes
                .iter()
                .fold(DVec3::ZERO, |a, n| a + DVec3::new(n[1], n[2], n[3]));
            assert!((sum - DVec3::ONE).abs().max_element() < 1e-12, "{sum}");
            let (white, _) = colour(q, DVec3::new(0.0, 0.0, 1e6));
            assert!((white - DVec3::ONE).abs().max_element() < 1e-9);
        }
        assert_eq!(Quadrature::fine().nodes.len(), 472);
        assert_eq!(Quadrature::coarse().nodes.len(), 96);
    }

    #[test]
    fn lab_of_white_and_its_jacobian() {
        let (l, d) = lab(DVec3::ONE);
        assert!(
            (l - DVec3::new(100.0, 0.0, 0.0)).abs().max_element() < 1e-9,
            "{l}"
        );
        // Finite differences agree with the analytic Jacobian.
        let p = DVec3::new(0.3, 0.02, 0.7);
        let (l0, d0) = lab(p);
        for k in 0..3 {
            let mut e = DVec3::ZERO;
            e[k] = 1e-7;
            let fd = (lab(p + e).0 - l0) / 1e-7;
            assert!((fd - d0.col(k)).abs().max_element() < 1e-3 * (1.0 + fd.abs().max_element()));
        }
        assert!(d.determinant().is_finite());
    }

    #[test]
    fn colour_jacobian_matches_finite_differences() {
        let c = DVec3::new(-30.0, 25.0, -3.0);
        let q = Quadrature::fine();
        let (rgb, d) = colour(q, c);
        for k in 0..3 {
            let mut e = DVec3::ZERO;
            e[k] = 1e-6;
            let fd = (colour(q, c + e).0 - rgb) / 1e-6;
            assert!(
                (fd - d.col(k)).abs().max_element() < 1e-6,
                "{k}: {fd} vs {}",
                d.col(k)
            );
        }
    }

    #[test]
    fn fits_reach_saturated_and_pale_colours() {
        for rgb in [
            [0.8, 0.1, 0.05],
            [0.02, 0.3, 0.9],
            [0.9, 0.85, 0.8],
            [0.05, 0.01, 0.0],
        ] {
            let (c, e) = fit_rgb(rgb);
            assert!(e < 1e-4, "{rgb:?}: ΔE {e}, {c:?}");
            let back = super::super::reflectance_to_rgb(|l| {
                super::super::Sigmoid {
                    coeffs: c,
                    scale: 1.0,
                }
                .eval(l)
            });
            for (a, b) in back.iter().zip(rgb) {
                assert!((a - b).abs() < 1e-4, "{rgb:?} → {back:?}");
            }
        }
    }

    #[test]
    fn z_scale_is_increasing_and_ends_at_one() {
        let z = z_scale(32, 0.25);
        assert!(z[0] == 0.25 && z.windows(2).all(|w| w[0] < w[1]));
        assert_eq!(z[31], 1.0);
    }
}
