//! A fluorescent colorant's re-radiation (issue 20; course §5.2.2): what fraction of the light
//! arriving at wavelength `λi` comes back at `λo`, how a path going from the camera picks the
//! `λi` that fed its `λo`, and the 3 × 3 matrix an RGB render uses instead.
//!
//! **The model** (the diffuse fluorescent BBRRDF of J. Jung, J. Hanika, S. Marschner and C.
//! Dachsbacher, "A Simple Diffuse Fluorescent BBRRDF Model", MAM 2018; the re-radiation of A.
//! Wilkie, A. Weidlich, C. Larboulette and W. Purgathofer, "A Reflectance Model for Diffuse
//! Fluorescent Surfaces", GRAPHITE 2006). The colorant absorbs the fraction `a(λi) ∈ [0, 1]` of
//! the photons arriving at `λi` (its *excitation* spectrum) and re-emits, with quantum yield
//! `Q ∈ [0, 1]`, photons distributed over `λo` by its *emission* spectrum `e(λo)` (normalised:
//! `∫ e dλ = 1`, per nm). Photons only lose energy (Stokes): emission at `λo < λi` is dropped,
//! not redistributed. In radiometric (energy) units a photon at `λ` carries `hc/λ`, so the
//! re-radiated spectral radiance per unit incident radiance is, per nm of `λo`,
//!
//! `K(λi → λo) = Q · a(λi) · e(λo) · (λi / λo) · [λo ≥ λi]`,
//!
//! and a fluorescent Lambertian base is `f = ρ(λo)/π · δ(λi − λo) + K(λi → λo)/π`. The energy it
//! re-emits per unit absorbed at `λi` is `Q ∫_{λi} e(λo) λi/λo dλo ≤ Q`, and the photons
//! `Q ∫_{λi} e ≤ Q` (tested below).
//!
//! **Sampling** ([`Fluorescence::sample_excitation`]). A camera path carries `λo` and asks which
//! `λi` fed it: `λi` is drawn from `a(λi)` restricted to `λi ≤ λo`, with density
//! `p(λi) = a(λi) / A(λo)`, `A(λo) = ∫_{360}^{λo} a`, so the estimator's weight is
//! `K / p = Q · e(λo) · (λi / λo) · A(λo)` — independent of `λi` but for the energy ratio.
//! `a` is read as piecewise constant over 1 nm cells (its value at each cell's centre), which
//! the kernel uses too, so the density is exact (chi-square tested).
//!
//! **RGB** ([`Fluorescence::rgb_matrix`]). An RGB render cannot move light between
//! wavelengths; it moves it between channels. Column `k` of the matrix is the linear sRGB colour
//! (through CIE XYZ) of the spectrum re-emitted under the illuminant spectrum of the `k`-th unit
//! primary ([`super::rgb2spec::illuminant`]); for light whose spectrum is that upsampling of its
//! RGB colour the matrix is exact (linearity), for any other it is the approximation whose cost
//! `lapidary tradeoff` measures — the reduced re-radiation of A. Fichet, L. Belcour and P. Barla,
//! "Non-Orthogonal Reduction for Rendering Fluorescent Materials in Non-Spectral Engines",
//! CGF 43(4), 2024, with the primaries' spectra as the reduction's basis.

use super::cie::{self, CMF_SAMPLES, LAMBDA_MAX, LAMBDA_MIN};
use super::line::Line;
use super::measured::Measured;
use super::rgb2spec;
use super::wavelengths::LINE_SHARE;

/// 1 nm cells over 360–830 nm.
const CELLS: usize = CMF_SAMPLES - 1;

/// A fluorescent colorant: excitation, emission and quantum yield, tabulated per 1 nm.
#[derive(Clone, Debug, PartialEq)]
pub struct Fluorescence {
    /// `a` per 1 nm cell (cell `j` spans `360 + j … 361 + j` nm), 0 ..= 1.
    excitation: Vec<f32>,
    /// `∫_{360}^{360 + j} a`, `j = 0 … CELLS` (non-decreasing).
    excitation_cdf: Vec<f64>,
    /// `e` per 1 nm cell, normalised so that the cells sum to 1.
    emission: Vec<f32>,
    /// `Q`.
    quantum_yield: f32,
    /// [`Fluorescence::rgb_matrix`], computed once.
    matrix: [[f32; 3]; 3],
}

/// A sampled excitation wavelength.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExcitationSample {
    /// `λi`, nm (≤ the `λo` asked for).
    pub lambda: f32,
    /// Its density per nm, `a(λi) / A(λo)`.
    pub pdf: f32,
    /// `K(λi → λo) / pdf`: the estimator's weight (π and the cosine excluded).
    pub weight: f32,
}

impl Fluorescence {
    /// A colorant from its excitation `a(λ)` (values 0 ..= 1: the fraction of photons absorbed by
    /// the fluorophore), emission shape (any scale: normalised here) and quantum yield (0 ..= 1),
    /// or what is wrong.
    pub fn new(
        excitation: &Measured,
        emission: &Measured,
        quantum_yield: f32,
    ) -> Result<Fluorescence, String> {
        if !(0.0..=1.0).contains(&quantum_yield) {
            return Err(format!(
                "quantum_yield = {quantum_yield} is out of range: allowed 0 ..= 1"
            ));
        }
        let centre = |j: usize| LAMBDA_MIN + j as f32 + 0.5;
        let a: Vec<f32> = (0..CELLS).map(|j| excitation.at(centre(j))).collect();
        if a.iter().any(|v| !(0.0..=1.0).contains(v)) {
            return Err("the excitation spectrum must stay within 0 ..= 1".into());
        }
        let e: Vec<f64> = (0..CELLS)
            .map(|j| f64::from(emission.at(centre(j)).max(0.0)))
            .collect();
        let total: f64 = e.iter().sum();
        if !(total > 0.0) {
            return Err(
                "the emission spectrum is zero over 360 ..= 830 nm: it must be positive \
                 somewhere in that range"
                    .into(),
            );
        }
        let mut cdf = Vec::with_capacity(CELLS + 1);
        let mut acc = 0.0f64;
        cdf.push(0.0);
        for &v in &a {
            acc += f64::from(v);
            cdf.push(acc);
        }
        let mut f = Fluorescence {
            excitation: a,
            excitation_cdf: cdf,
            emission: e.iter().map(|v| (v / total) as f32).collect(),
            quantum_yield,
            matrix: [[0.0; 3]; 3],
        };
        f.matrix = f.compute_rgb_matrix();
        Ok(f)
    }

    /// The cell of `lambda` (clamped to the range).
    fn cell(lambda: f32) -> usize {
        ((lambda - LAMBDA_MIN).max(0.0) as usize).min(CELLS - 1)
    }

    /// `a(λ)`.
    pub fn excitation(&self, lambda: f32) -> f32 {
        self.excitation[Self::cell(lambda)]
    }

    /// `e(λ)`, per nm.
    pub fn emission(&self, lambda: f32) -> f32 {
        self.emission[Self::cell(lambda)]
    }

    /// `Q`.
    pub fn quantum_yield(&self) -> f32 {
        self.quantum_yield
    }

    /// `K(λi → λo)`, per nm of `λo` (module docs).
    pub fn kernel(&self, lambda_i: f32, lambda_o: f32) -> f32 {
        if !(lambda_o >= lambda_i) {
            return 0.0;
        }
        self.quantum_yield
            * self.excitation(lambda_i)
            * self.emission(lambda_o)
            * (lambda_i / lambda_o)
    }

    /// `A(λ) = ∫_{360}^{λ} a`, nm.
    fn excitation_below(&self, lambda: f32) -> f64 {
        let x = f64::from((lambda - LAMBDA_MIN).clamp(0.0, CELLS as f32));
        let j = (x as usize).min(CELLS - 1);
        self.excitation_cdf[j] + (x - j as f64) * f64::from(self.excitation[j])
    }

    /// A `λi ≤ λo` drawn from `a` (module docs) with `u ∈ [0, 1)`; `None` when nothing below
    /// `λo` excites the colorant.
    pub fn sample_excitation(&self, lambda_o: f32, u: f32) -> Option<ExcitationSample> {
        let lambda_o = lambda_o.clamp(LAMBDA_MIN, LAMBDA_MAX);
        let total = self.excitation_below(lambda_o);
        if !(total > 0.0) {
            return None;
        }
        let target = f64::from(u.clamp(0.0, 1.0)) * total;
        // The last cell whose start is at or below the target, and of positive weight.
        let mut j = self
            .excitation_cdf
            .partition_point(|&c| c <= target)
            .saturating_sub(1)
            .min(CELLS - 1);
        while self.excitation[j] == 0.0 && j > 0 {
            j -= 1;
        }
        let a = self.excitation[j];
        if a == 0.0 {
            return None;
        }
        // Strictly inside cell `j` (its end belongs to the next cell, whose `a` may differ).
        let offset = ((target - self.excitation_cdf[j]) / f64::from(a)).clamp(0.0, 0.9999);
        let lambda = (LAMBDA_MIN + j as f32 + offset as f32).min(lambda_o);
        if Self::cell(lambda) != j {
            return None; // λo at a cell's start: a zero-width remainder (probability 0)
        }
        let pdf = (f64::from(a) / total) as f32;
        let weight =
            self.quantum_yield * self.emission(lambda_o) * (lambda / lambda_o) * total as f32;
        Some(ExcitationSample {
            lambda,
            pdf,
            weight,
        })
    }

    /// [`Fluorescence::sample_excitation`] mixed with the scene's narrow emission lines (a
    /// laser's): with probability [`LINE_SHARE`] (when some line's support starts below `λo`;
    /// `u_select` decides) `λi` is drawn uniformly from one such line's support clipped at `λo`,
    /// else from `a`; the density is the mixture's, `(1 − c) a(λi)/A(λo) + (c/m) Σ_j
    /// [λi ∈ S_j]/|S_j|`, and the weight `K/p` (module docs). A narrow line far inside a broad
    /// excitation band is otherwise found by one path in hundreds. Without usable lines this is
    /// [`Fluorescence::sample_excitation`] exactly.
    pub fn sample_excitation_mixed(
        &self,
        lambda_o: f32,
        lines: &[Line],
        u_select: f32,
        u: f32,
    ) -> Option<ExcitationSample> {
        let lambda_o = lambda_o.clamp(LAMBDA_MIN, LAMBDA_MAX);
        let clipped = |l: &Line| {
            let (lo, hi) = l.support();
            let hi = hi.min(lambda_o);
            (hi > lo).then_some((lo, hi))
        };
        let m = lines.iter().filter_map(clipped).count();
        if m == 0 {
            return self.sample_excitation(lambda_o, u);
        }
        let total = self.excitation_below(lambda_o);
        let c = if total > 0.0 { LINE_SHARE } else { 1.0 };
        let lambda = if u_select < c {
            let j = ((u_select / c * m as f32) as usize).min(m - 1);
            let (lo, hi) = lines.iter().filter_map(clipped).nth(j)?;
            (lo + u.clamp(0.0, 1.0) * (hi - lo)).min(hi)
        } else {
            self.sample_excitation(lambda_o, u)?.lambda
        };
        let mut boxes = 0.0f32;
        for (lo, hi) in lines.iter().filter_map(clipped) {
            if lambda >= lo && lambda <= hi {
                boxes += 1.0 / (hi - lo);
            }
        }
        let p_a = if total > 0.0 {
            (f64::from(self.excitation(lambda)) / total) as f32
        } else {
            0.0
        };
        let pdf = (1.0 - c) * p_a + c * boxes / m as f32;
        let k = self.kernel(lambda, lambda_o);
        (pdf > 0.0 && k > 0.0).then(|| ExcitationSample {
            lambda,
            pdf,
            weight: k / pdf,
        })
    }

    /// The energy re-emitted per unit energy absorbed-and-arriving at `λi`: `∫ K(λi → λo) dλo`
    /// (1 nm sums), at most `Q a(λi)`.
    pub fn reemitted_energy(&self, lambda_i: f32) -> f32 {
        (0..CELLS)
            .map(|j| self.kernel(lambda_i, LAMBDA_MIN + j as f32 + 0.5))
            .sum()
    }

    /// The photons re-emitted per photon arriving at `λi`: `Q a(λi) ∫_{λo ≥ λi} e`.
    pub fn reemitted_photons(&self, lambda_i: f32) -> f32 {
        let from = Self::cell(lambda_i);
        let tail: f32 = self.emission[from..].iter().sum();
        self.quantum_yield * self.excitation(lambda_i) * tail
    }

    /// The light re-emitted under an incident spectrum given as quadrature nodes `(λi, L(λi)
    /// dλi)` (nm, radiance per node, any order): `R(λo) = Σ_{λi ≤ λo} K(λi → λo) L(λi) dλi` at
    /// `λo = 360, 361, …, 830` nm (the grid of [`cie::spectrum_to_xyz`]). A line's fine nodes
    /// ([`Line::nodes`]) keep its exact position against the Stokes bound and `a`.
    pub fn reemitted_spectrum(&self, nodes: &[(f32, f32)]) -> Vec<f32> {
        let mut nodes = nodes.to_vec();
        nodes.sort_by(|a, b| a.0.total_cmp(&b.0));
        // `K` separates, `K = Q e(λo)/λo · a(λi) λi [λi ≤ λo]`: a running sum as `λo` rises.
        let mut acc = 0.0f64;
        let mut next = 0;
        (0..CMF_SAMPLES)
            .map(|i| {
                let lo = LAMBDA_MIN + i as f32;
                while next < nodes.len() && nodes[next].0 <= lo {
                    let (l, w) = nodes[next];
                    acc += f64::from(self.excitation(l)) * f64::from(l) * f64::from(w);
                    next += 1;
                }
                (f64::from(self.quantum_yield * self.emission(lo) / lo) * acc) as f32
            })
            .collect()
    }

    /// CIE XYZ (normalised like [`cie::spectrum_to_xyz`]) of [`Fluorescence::reemitted_spectrum`].
    pub fn reemitted_xyz(&self, nodes: &[(f32, f32)]) -> glam::Vec3 {
        let out = self.reemitted_spectrum(nodes);
        cie::spectrum_to_xyz(|l| out[((l - LAMBDA_MIN) as usize).min(CMF_SAMPLES - 1)])
    }

    /// The same colorant with the RGB matrix `matrix` in place of [`Fluorescence::rgb_matrix`]'s
    /// (a matrix reduced under the scene's own light: [`super::prefilter`]).
    pub fn with_rgb_matrix(&self, matrix: [[f32; 3]; 3]) -> Fluorescence {
        Fluorescence {
            matrix,
            ..self.clone()
        }
    }

    /// The linear sRGB colour re-emitted under each unit primary's illuminant spectrum: column `k`
    /// for primary `k` (module docs). Multiply an incident RGB radiance by it for the RGB render.
    #[inline]
    pub fn rgb_matrix(&self) -> &[[f32; 3]; 3] {
        &self.matrix
    }

    /// [`Fluorescence::rgb_matrix`] from the spectra (3 × 470² kernel evaluations).
    fn compute_rgb_matrix(&self) -> [[f32; 3]; 3] {
        let mut m = [[0.0f32; 3]; 3];
        for k in 0..3 {
            let mut primary = [0.0f32; 3];
            primary[k] = 1.0;
            let (scale, s) = rgb2spec::illuminant(primary);
            // The kernel separates, `K = Q e(λo)/λo · a(λi) λi [λi ≤ λo]`: the re-emitted
            // spectrum is `Q e(λo)/λo` times a prefix sum over the excitation cells (1 nm sums
            // over λi), so each column costs one pass instead of one per output wavelength.
            let mut prefix = Vec::with_capacity(CELLS + 1);
            let mut acc = 0.0f64;
            prefix.push(0.0);
            for j in 0..CELLS {
                let l = LAMBDA_MIN + j as f32 + 0.5;
                let li = scale * s.eval(l) * rgb2spec::d65_normalised(l);
                acc += f64::from(li) * f64::from(self.excitation[j]) * f64::from(l);
                prefix.push(acc);
            }
            let out = |lo: f32| -> f32 {
                // Cells whose centre is at or below λo.
                let n = ((lo - LAMBDA_MIN - 0.5).floor() + 1.0).clamp(0.0, CELLS as f32) as usize;
                (f64::from(self.quantum_yield * self.emission(lo) / lo) * prefix[n]) as f32
            };
            let rgb = cie::xyz_to_linear_srgb(cie::spectrum_to_xyz(out));
            // An RGB render carries non-negative channels: a re-emission outside the sRGB gamut
            // (an orange dye's emission has a slightly negative blue) is clamped, as measured
            // emission is ([`super::measured::Measured::to_rgb_emission`]).
            for (c, v) in rgb.to_array().into_iter().enumerate() {
                m[c][k] = v.max(0.0);
            }
        }
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rhodamine-like colorant for the tests: excitation a Gaussian at 530 nm (σ 25 nm, peak
    /// 0.9), emission a Gaussian at 590 nm (σ 20 nm), yield 0.8.
    fn dye() -> Fluorescence {
        let gauss = |mu: f32, sigma: f32, peak: f32| {
            let pts: Vec<(f32, f32)> = (0..=470)
                .step_by(2)
                .map(|i| {
                    let l = 360.0 + i as f32;
                    (l, peak * (-0.5 * ((l - mu) / sigma).powi(2)).exp())
                })
                .collect();
            Measured::from_points(&pts, 1.0).unwrap()
        };
        Fluorescence::new(&gauss(530.0, 25.0, 0.9), &gauss(590.0, 20.0, 1.0), 0.8).unwrap()
    }

    #[test]
    fn energy_and_photons_never_exceed_the_yield_of_what_is_absorbed() {
        let f = dye();
        for i in 0..=94 {
            let l = 360.0 + 5.0 * i as f32;
            let q_abs = f.quantum_yield() * f.excitation(l);
            let energy = f.reemitted_energy(l);
            let photons = f.reemitted_photons(l);
            assert!(energy >= 0.0 && photons >= 0.0);
            assert!(
                energy <= q_abs * (1.0 + 1e-5) + 1e-9,
                "{l}: {energy} > {q_abs}"
            );
            assert!(
                photons <= q_abs * (1.0 + 1e-5) + 1e-9,
                "{l}: {photons} > {q_abs}"
            );
            // Energy is lost to the Stokes shift: strictly less wherever anything is emitted.
            if photons > 1e-6 {
                assert!(energy < photons, "{l}: {energy} vs {photons}");
            }
        }
        // Only longer wavelengths: nothing re-emitted at or below 500 nm from 520 nm.
        assert_eq!(f.kernel(520.0, 500.0), 0.0);
        assert!(f.kernel(520.0, 590.0) > 0.0);
        // Bad inputs are refused.
        let flat = Measured::from_points(&[(360.0, 0.5), (830.0, 0.5)], 1.0).unwrap();
        let zero = Measured::from_points(&[(360.0, 0.0), (830.0, 0.0)], 1.0).unwrap();
        assert!(Fluorescence::new(&flat, &flat, 1.5).is_err());
        assert!(Fluorescence::new(&flat, &zero, 0.5).is_err());
        let high = Measured::from_points(&[(360.0, 1.5), (830.0, 1.5)], 2.0).unwrap();
        assert!(Fluorescence::new(&high, &flat, 0.5).is_err());
    }

    /// Pearson's χ² (cells expecting fewer than 5 pooled) and its critical value at 0.0025 (α
    /// 0.01 Šidák over 4 tests; Wilson–Hilferty). Panics if a sample fell where nothing was
    /// expected.
    fn chi_square(observed: &[f64], expected: &[f64]) -> (f64, f64) {
        let (mut stat, mut dof, mut pool_o, mut pool_e) = (0.0, 0usize, 0.0, 0.0);
        for (o, e) in observed.iter().zip(expected) {
            if *e < 5.0 {
                assert!(*e > 0.0 || *o == 0.0, "a sample where the density is 0");
                pool_o += o;
                pool_e += e;
            } else {
                stat += (o - e) * (o - e) / e;
                dof += 1;
            }
        }
        if pool_e > 0.0 {
            stat += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
            dof += 1;
        }
        let k = (dof - 1) as f64;
        let z = 2.807_033_768; // upper 0.25 % point of the standard normal
        let a = 2.0 / (9.0 * k);
        (stat, k * (1.0 - a + z * a.sqrt()).powi(3))
    }

    /// Chi-square of the excitation sampling against its density (integrated per 2 nm bin) for
    /// several `λo`, 200 000 samples each, α = 0.01 per test (Šidák over 4: 0.0025 each, with the
    /// Wilson–Hilferty critical value); the weight equals `K / pdf` for every sample.
    #[test]
    fn excitation_sampling_matches_its_density() {
        let f = dye();
        for lambda_o in [480.0f32, 540.0, 600.0, 830.0] {
            let bins = ((lambda_o - LAMBDA_MIN) / 2.0).ceil() as usize;
            let mut observed = vec![0.0f64; bins];
            let n = 200_000u32;
            let mut state = 0x9e37_79b9_7f4a_7c15u64 ^ lambda_o.to_bits() as u64;
            for _ in 0..n {
                state = state
                    .wrapping_mul(6_364_136_223_846_793_005)
                    .wrapping_add(1_442_695_040_888_963_407);
                let u = (state >> 40) as f32 / (1u64 << 24) as f32;
                let s = f.sample_excitation(lambda_o, u).expect("excited below λo");
                assert!(s.lambda <= lambda_o && s.lambda >= LAMBDA_MIN);
                let want = f.kernel(s.lambda, lambda_o) / s.pdf;
                assert!(
                    (s.weight - want).abs() <= 1e-4 * want.max(1e-6),
                    "{s:?} vs {want}"
                );
                assert!(
                    (s.pdf - f.excitation(s.lambda) / f.excitation_below(lambda_o) as f32).abs()
                        < 1e-6
                );
                let b = (((s.lambda - LAMBDA_MIN) / 2.0) as usize).min(bins - 1);
                observed[b] += 1.0;
            }
            let total = f.excitation_below(lambda_o);
            let expected: Vec<f64> = (0..bins)
                .map(|b| {
                    let lo = LAMBDA_MIN + 2.0 * b as f32;
                    let hi = (lo + 2.0).min(lambda_o);
                    f64::from(n) * (f.excitation_below(hi) - f.excitation_below(lo)) / total
                })
                .collect();
            let (stat, critical) = chi_square(&observed, &expected);
            assert!(
                stat < critical,
                "λo {lambda_o}: χ² {stat:.1} ≥ {critical:.1}"
            );
            // Negative control: the same samples against a uniform density are rejected.
            let uniform = vec![f64::from(n) / bins as f64; bins];
            let (bad, critical) = chi_square(&observed, &uniform);
            assert!(bad > critical, "λo {lambda_o}: uniform χ² {bad:.1} passed");
        }
        // A colorant excited only above 500 nm has no excitation sample for λo below that.
        let above = Measured::from_points(
            &[(360.0, 0.0), (500.0, 0.0), (510.0, 0.5), (830.0, 0.5)],
            1.0,
        )
        .unwrap();
        let g = Fluorescence::new(&above, &above, 1.0).unwrap();
        assert_eq!(g.sample_excitation(450.0, 0.5), None);
        assert!(g.sample_excitation(600.0, 0.5).is_some());
    }

    /// The matrix moves green light to red (the dye absorbs green and emits orange), and agrees
    /// with integrating the kernel over a green illuminant's spectrum.
    #[test]
    fn the_rgb_matrix_moves_green_to_red() {
        let f = dye();
        let m = *f.rgb_matrix();
        // Red in, little out: the dye barely absorbs beyond 600 nm.
        assert!(m[0][0] < 0.05, "{m:?}");
        // Green in: mostly red out (orange emission), more than any other column sends to red.
        assert!(m[0][1] > 0.1 && m[0][1] > m[0][0], "{m:?}");
        // Every entry finite; the blue column (the dye's excitation tail) re-emits less red than
        // the green one.
        assert!(m.iter().flatten().all(|v| v.is_finite()), "{m:?}");
        assert!(m[0][2] < m[0][1], "{m:?}");
        // Each column against the kernel integrated directly (a double sum over 1 nm cells of
        // λi and the CMF grid of λo), independent of the prefix sums the matrix uses.
        for k in 0..3 {
            let mut primary = [0.0f32; 3];
            primary[k] = 1.0;
            let (scale, s) = rgb2spec::illuminant(primary);
            let out = |lo: f32| -> f32 {
                (0..CELLS)
                    .map(|j| {
                        let l = LAMBDA_MIN + j as f32 + 0.5;
                        scale * s.eval(l) * rgb2spec::d65_normalised(l) * f.kernel(l, lo)
                    })
                    .sum()
            };
            let rgb = cie::xyz_to_linear_srgb(cie::spectrum_to_xyz(out)).to_array();
            for c in 0..3 {
                let want = rgb[c].max(0.0);
                assert!(
                    (m[c][k] - want).abs() <= 1e-4 * want.abs().max(1e-3),
                    "M[{c}][{k}] = {} vs {want}",
                    m[c][k]
                );
            }
        }
    }
}
