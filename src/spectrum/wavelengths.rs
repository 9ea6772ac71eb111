//! The wavelengths a spectral path carries (issue 19): four per camera path, the first drawn from
//! a density over the visible range and three stratified after it.
//!
//! **The density.** `p(λ) ∝ sech²(a (λ − μ))` on `[360, 830]` nm — the form Radziszewski, Boryczko
//! & Alda fitted to the luminous efficiency curve ("An improved technique for full spectral
//! rendering", Journal of WSCG 17, 2009), with `a = 0.0072` nm⁻¹ and `μ = 538` nm as pbrt-v4 uses
//! (Pharr, Jakob & Humphreys, *Physically Based Rendering*, 4th ed., §4.6.5). It is inverted in
//! closed form: with `T(λ) = tanh(a (λ − μ))`, the CDF is `(T(λ) − T(360)) / (T(830) − T(360))`,
//! so `λ = μ + atanh(T(360) + u (T(830) − T(360))) / a`, and the normalised density is
//! `p(λ) = a sech²(a (λ − μ)) / (T(830) − T(360))`. The constants are derived here from `a` and
//! `μ`, not copied.
//!
//! **Stratification.** Wavelength `i` uses `u_i = (u + i/4) mod 1`: the four fall in the four
//! quarters of the CDF (Wilkie et al., "Hero Wavelength Spectral Sampling", EGSR 2014, rotate
//! the hero wavelength by equal steps; here the steps are taken in the CDF so that every
//! wavelength keeps the same density `p`). Each carries its own `p(λ_i)`; a radiance estimate
//! averages `L(λ_i) w(λ_i) / p(λ_i)` over the four.
//!
//! **Termination.** A smooth dispersive refraction sends each wavelength a different way: the
//! path keeps the first (the hero) and drops the others, whose densities become 0, and the hero's
//! density is divided by 4 so that its estimate stands for the four it replaces (pbrt-v4's
//! `TerminateSecondary`; the dropped channels are not accumulated).

use std::sync::LazyLock;

/// Shortest wavelength carried, nm.
pub const LAMBDA_MIN: f32 = 360.0;
/// Longest wavelength carried, nm.
pub const LAMBDA_MAX: f32 = 830.0;
/// Wavelengths per path.
pub const N: usize = 4;
/// Steepness `a` of the visible-range density, nm⁻¹ (module docs).
const A: f64 = 0.0072;
/// Centre `μ` of the visible-range density, nm.
const MU: f64 = 538.0;

/// `T(360)` and `T(830) − T(360)` (module docs), in `f64`, computed once (four `tanh` per
/// wavelength were a tenth of a spectral path's time).
#[inline]
fn range() -> (f64, f64) {
    static RANGE: LazyLock<(f64, f64)> = LazyLock::new(|| {
        let t0 = (A * (f64::from(LAMBDA_MIN) - MU)).tanh();
        let t1 = (A * (f64::from(LAMBDA_MAX) - MU)).tanh();
        (t0, t1 - t0)
    });
    *RANGE
}

/// What [`HeroWavelengths::sample`] reads: the CDF's constants in `f32` and the unit-luminance
/// D65 ([`super::rgb2spec::d65_normalised`]) at 1 nm, 360–830 nm (linear between its 1 nm
/// values, as the CIE's 1 nm D65 is itself interpolated from 5 nm).
struct Constants {
    t0: f32,
    span: f32,
    /// `a / span`: the density is `(1 − y²) · a / span`.
    pdf_scale: f32,
    /// `1 / (2a)`: `λ = μ + ln((1 + y)/(1 − y)) / (2a)`.
    half_inv_a: f32,
    illuminant: Vec<f32>,
}

impl Constants {
    /// The unit-luminance D65 at `l` nm (within 360 ..= 830), linear between the 1 nm values.
    #[inline]
    fn illuminant_at(&self, l: f32) -> f32 {
        let x = l - LAMBDA_MIN;
        let j = (x as usize).min(self.illuminant.len() - 2);
        let f = x - j as f32;
        self.illuminant[j] + f * (self.illuminant[j + 1] - self.illuminant[j])
    }
}

fn constants() -> &'static Constants {
    static C: LazyLock<Constants> = LazyLock::new(|| {
        let (t0, span) = range();
        Constants {
            t0: t0 as f32,
            span: span as f32,
            pdf_scale: (A / span) as f32,
            half_inv_a: (0.5 / A) as f32,
            illuminant: (0..=(LAMBDA_MAX - LAMBDA_MIN) as usize)
                .map(|i| super::rgb2spec::d65_normalised(LAMBDA_MIN + i as f32))
                .collect(),
        }
    });
    &C
}

/// The density per nm of [`sample_visible`] at `lambda` (0 outside `[LAMBDA_MIN, LAMBDA_MAX]`).
pub fn visible_pdf(lambda: f32) -> f32 {
    if !(LAMBDA_MIN..=LAMBDA_MAX).contains(&lambda) {
        return 0.0;
    }
    // In f32 (a path draws four): `cosh` from one `exp`, relative error ~1e-7.
    let x = (A as f32) * (lambda - MU as f32);
    let e = x.exp();
    let c = 0.5 * (e + 1.0 / e);
    (A as f32) / (c * c * range().1 as f32)
}

/// A wavelength (nm) from the visible-range density, by inverting its CDF at `u ∈ [0, 1)` (values
/// outside are clamped).
pub fn sample_visible(u: f32) -> f32 {
    let (t0, span) = range();
    let u = u.clamp(0.0, 1.0);
    // The argument stays in (−1, 1): T(360) > −1 and T(830) < 1. In f32 (a path draws four):
    // atanh y = ½ ln((1 + y)/(1 − y)), within 0.01 nm of the f64 inverse.
    let y = t0 as f32 + u * span as f32;
    let lambda = MU as f32 + 0.5 * ((1.0 + y) / (1.0 - y)).ln() / A as f32;
    lambda.clamp(LAMBDA_MIN, LAMBDA_MAX)
}

/// The share of camera paths whose wavelengths are drawn from the scene's emission lines when it
/// has any ([`HeroWavelengths::sample_with_lines`]).
pub const LINE_SHARE: f32 = 0.5;

/// The density per nm of [`HeroWavelengths::sample_with_lines`] at `lambda`.
pub fn line_mixture_pdf(lambda: f32, lines: &[super::line::Line]) -> f32 {
    let mut boxes = 0.0;
    for l in lines {
        let (lo, hi) = l.support();
        if lambda >= lo && lambda <= hi && hi > lo {
            boxes += 1.0 / (hi - lo);
        }
    }
    (1.0 - LINE_SHARE) * visible_pdf(lambda) + LINE_SHARE * boxes / lines.len().max(1) as f32
}

/// The four wavelengths of a path and their densities.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeroWavelengths {
    /// Wavelengths, nm; `lambda[0]` is the hero.
    pub lambda: [f32; N],
    /// Density per nm each was drawn with; 0 once terminated.
    pub pdf: [f32; N],
    /// The unit-luminance D65 illuminant at each wavelength
    /// ([`super::rgb2spec::d65_normalised`]), looked up once per path for every emitted colour
    /// the path meets.
    pub illuminant: [f32; N],
}

impl Default for HeroWavelengths {
    /// The wavelengths of `u = 0`.
    fn default() -> Self {
        HeroWavelengths::sample(0.0)
    }
}

impl HeroWavelengths {
    /// The four wavelengths of the number `u ∈ [0, 1)` (module docs: `u_i = (u + i/4) mod 1`).
    pub fn sample(u: f32) -> Self {
        let c = constants();
        let mut w = HeroWavelengths {
            lambda: [0.0; N],
            pdf: [0.0; N],
            illuminant: [0.0; N],
        };
        for i in 0..N {
            let mut ui = u + i as f32 / N as f32;
            if ui >= 1.0 {
                ui -= 1.0;
            }
            let ui = ui.clamp(0.0, 1.0);
            // As `sample_visible`; the density from `y = tanh(a (λ − μ))` directly, since
            // sech² = 1 − tanh² (no `cosh`): the same as `visible_pdf(λ)` to rounding.
            let y = c.t0 + ui * c.span;
            let l = (MU as f32 + ((1.0 + y) / (1.0 - y)).ln() * c.half_inv_a)
                .clamp(LAMBDA_MIN, LAMBDA_MAX);
            w.lambda[i] = l;
            w.pdf[i] = (1.0 - y * y) * c.pdf_scale;
            w.illuminant[i] = c.illuminant_at(l);
        }
        w
    }

    /// The four wavelengths of `u` when the scene has narrow emission lines (issue 20): with
    /// probability [`LINE_SHARE`] (`u.y` decides) all four are drawn from one line's support
    /// ([`super::line::Line::support`], uniformly, stratified as in [`HeroWavelengths::sample`]),
    /// else from the visible density; each wavelength's density is the mixture's,
    /// `(1 − c) p_vis(λ) + (c/n) Σ_j [λ ∈ support_j] / width_j`, so every channel is an unbiased
    /// one-sample mixture estimate. Without lines this is [`HeroWavelengths::sample`] exactly.
    pub fn sample_with_lines(u: f32, u_select: f32, lines: &[super::line::Line]) -> Self {
        let mut w = HeroWavelengths::sample(u);
        if lines.is_empty() {
            return w;
        }
        let n = lines.len();
        let pick = (u_select < LINE_SHARE)
            .then(|| ((u_select / LINE_SHARE * n as f32) as usize).min(n - 1));
        for i in 0..N {
            if let Some(j) = pick {
                let mut ui = u + i as f32 / N as f32;
                if ui >= 1.0 {
                    ui -= 1.0;
                }
                let (lo, hi) = lines[j].support();
                w.set(i, lo + ui * (hi - lo));
            }
            w.pdf[i] = line_mixture_pdf(w.lambda[i], lines);
        }
        w
    }

    /// Carries wavelength `i` at `lambda` nm from here on (a fluorescent re-radiation's excitation
    /// wavelength): its D65 value follows; its density (the film's) is left as drawn.
    pub fn set(&mut self, i: usize, lambda: f32) {
        let l = lambda.clamp(LAMBDA_MIN, LAMBDA_MAX);
        self.lambda[i] = l;
        self.illuminant[i] = constants().illuminant_at(l);
    }

    /// Keeps only the hero wavelength (module docs); does nothing if already done.
    pub fn terminate_secondary(&mut self) {
        if self.secondary_terminated() {
            return;
        }
        for p in &mut self.pdf[1..] {
            *p = 0.0;
        }
        self.pdf[0] /= N as f32;
    }

    /// Whether only the hero wavelength is left.
    pub fn secondary_terminated(&self) -> bool {
        self.pdf[1..].iter().all(|&p| p == 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn density_integrates_to_one() {
        // Midpoint rule at 0.01 nm.
        let n = 47_000;
        let h = (LAMBDA_MAX - LAMBDA_MIN) as f64 / n as f64;
        let sum: f64 = (0..n)
            .map(|i| f64::from(visible_pdf(LAMBDA_MIN + ((i as f64 + 0.5) * h) as f32)) * h)
            .sum();
        assert!((sum - 1.0).abs() < 1e-5, "{sum}");
        assert_eq!(visible_pdf(359.9), 0.0);
        assert_eq!(visible_pdf(830.1), 0.0);
    }

    #[test]
    fn sampling_inverts_the_cdf() {
        assert!((sample_visible(0.0) - LAMBDA_MIN).abs() < 1e-3);
        assert!((sample_visible(1.0) - LAMBDA_MAX).abs() < 1e-2);
        // The CDF at the sampled wavelength returns u (numerical CDF by the midpoint rule).
        for &u in &[0.1f32, 0.25, 0.5, 0.75, 0.9] {
            let l = sample_visible(u);
            let n = 20_000;
            let h = (l - LAMBDA_MIN) as f64 / n as f64;
            let cdf: f64 = (0..n)
                .map(|i| f64::from(visible_pdf(LAMBDA_MIN + ((i as f64 + 0.5) * h) as f32)) * h)
                .sum();
            assert!((cdf - f64::from(u)).abs() < 1e-4, "u {u}: λ {l}, cdf {cdf}");
        }
        // Monotone.
        let mut last = 0.0;
        for i in 0..1000 {
            let l = sample_visible(i as f32 / 1000.0);
            assert!(l >= last);
            last = l;
        }
    }

    #[test]
    fn the_four_fall_in_the_four_quarters() {
        let q = |l: f32| {
            // Which quarter of the CDF λ lies in.
            (0..4)
                .rev()
                .find(|&k| l >= sample_visible(k as f32 / 4.0))
                .unwrap()
        };
        for &u in &[0.0f32, 0.13, 0.49, 0.77, 0.999] {
            let w = HeroWavelengths::sample(u);
            let mut quarters: Vec<usize> = w.lambda.iter().map(|&l| q(l)).collect();
            quarters.sort_unstable();
            assert_eq!(quarters, vec![0, 1, 2, 3], "u {u}: {:?}", w.lambda);
            for i in 0..N {
                // The density from tanh directly (sech² = 1 − tanh²), to rounding.
                let p = visible_pdf(w.lambda[i]);
                assert!((w.pdf[i] - p).abs() <= 2e-5 * p, "{} vs {p}", w.pdf[i]);
                // D65 is linear between its 5 nm values, so the 1 nm table is exact to rounding.
                let d = crate::spectrum::rgb2spec::d65_normalised(w.lambda[i]);
                assert!(
                    (w.illuminant[i] - d).abs() <= 1e-5 * d,
                    "{} vs {d}",
                    w.illuminant[i]
                );
            }
        }
    }

    #[test]
    fn termination_keeps_the_hero_for_all_four() {
        let mut w = HeroWavelengths::sample(0.3);
        let p0 = w.pdf[0];
        assert!(!w.secondary_terminated());
        w.terminate_secondary();
        assert!(w.secondary_terminated());
        assert_eq!(w.pdf, [p0 / 4.0, 0.0, 0.0, 0.0]);
        w.terminate_secondary();
        assert_eq!(w.pdf[0], p0 / 4.0, "a second termination changes nothing");
    }
}
