//! The wavelengths a spectral path carries (issue 19): four per camera path, the first drawn from
//! a density over the visible range and three stratified after it.
//!
//! **The density.** `p(λ) ∝ sech²(a (λ − μ))` on `[360, 830]` nm — the form Radziszewski, Boryczko
//! & Alda fitted to the luminous efficiency curve ("An improved technique for full spectral
//! rendering", Journal of WSCG 17, 2009), with `a = 0.0072` nm⁻¹ and `μ = 538` nm as pbrt-v4 uses
//! (Pharr, Jakob & Humphreys, *Physically Based Rendering*, 4th ed., §4.6.5). Its CDF has the
//! closed form `(T(λ) − T(360)) / (T(830) − T(360))` with `T(λ) = tanh(a (λ − μ))`. The constants
//! are derived here from `a` and `μ`, not copied.
//!
//! **Tabulated at 1 nm.** A path draws four wavelengths, and inverting the closed form costs a
//! logarithm and a division each; with the film's colour-matching lookups that made a spectral
//! path's bookkeeping a tenth of an opaque gem's spectral render (callgrind, sunstone). So the
//! density used is `p` averaged over each 1 nm bin: bin `j` (`360 + j ..= 361 + j` nm) has exactly
//! the mass the closed-form CDF gives it, and within it the density is flat. That is `p` to 0.75 %
//! (the change of `sech²` across half a nanometre at 830 nm, and the CDF's rounding to `f32`), and,
//! being the density actually sampled and divided by, it is exact: no bias, only the variance of a
//! 0.75 % different importance function. Any integral over whole nanometres (the chi-square test's
//! 10 nm bins) sees the closed form's masses exactly. It is inverted by the guide-table method
//! (Chen & Asau, "On generating random variates from an empirical distribution", AIIE Transactions
//! 6(2), 1974): `u` indexes one of [`GUIDE`] cells, which names the first bin that can hold it, and
//! a short forward scan finds the bin (at most three steps: the narrowest bin, at 830 nm, holds
//! 2.3·10⁻⁴ of the mass and a cell 4.9·10⁻⁴; tested); `λ` is then linear in `u` within it.
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
/// Bins of the tabulated density, one per nm.
const BINS: usize = (LAMBDA_MAX - LAMBDA_MIN) as usize;
/// Cells of the guide table (module docs); a power of two, so that `u · GUIDE` is exact.
pub const GUIDE: usize = 2048;

/// One nanometre of the tabulated density (module docs) and of the unit-luminance D65.
#[derive(Clone, Copy)]
struct Bin {
    /// The CDF at the bin's start, `P(λ < 360 + j)`.
    cdf: f32,
    /// The density in the bin, per nm: the next bin's `cdf` minus this one's.
    pdf: f32,
    /// `1 / pdf`.
    inv_pdf: f32,
    /// [`super::rgb2spec::d65_normalised`] at the bin's start and its change over the bin (the
    /// unit-luminance D65 is linear between its 1 nm values, as the CIE's 1 nm D65 is itself
    /// interpolated from 5 nm).
    d65: f32,
    d65_step: f32,
}

/// What [`HeroWavelengths::sample`] reads (fixed-size, so that indices clamped to the sizes need
/// no bounds checks).
struct Constants {
    bins: [Bin; BINS],
    /// Cell `g`: the last bin whose `cdf ≤ g / GUIDE`.
    guide: [u16; GUIDE],
}

/// `x` truncated to an index in `0 ..= max` (NaN to 0). Through `i32`, whose saturating conversion
/// takes fewer instructions than `usize`'s; `x` is at most a few thousand here.
#[inline(always)]
pub(crate) fn index(x: f32, max: usize) -> usize {
    (x as i32).clamp(0, max as i32) as usize
}

/// The closed-form CDF of the module docs, in `f64`.
fn closed_form_cdf(lambda: f64) -> f64 {
    let t = |l: f64| (A * (l - MU)).tanh();
    let t0 = t(f64::from(LAMBDA_MIN));
    (t(lambda) - t0) / (t(f64::from(LAMBDA_MAX)) - t0)
}

fn constants() -> &'static Constants {
    static C: LazyLock<Box<Constants>> = LazyLock::new(|| {
        // The CDF at every whole nanometre, rounded once to f32 (0 and 1 exactly at the ends);
        // the densities are the differences of those rounded values, so that the density a
        // sample reports is the slope of the CDF it was drawn from.
        let cdf: Vec<f32> = (0..=BINS)
            .map(|j| match j {
                0 => 0.0,
                BINS => 1.0,
                _ => closed_form_cdf(f64::from(LAMBDA_MIN) + j as f64) as f32,
            })
            .collect();
        let d65 = |j: usize| super::rgb2spec::d65_normalised(LAMBDA_MIN + j as f32);
        let bins: [Bin; BINS] = std::array::from_fn(|j| {
            let pdf = (f64::from(cdf[j + 1]) - f64::from(cdf[j])) as f32;
            Bin {
                cdf: cdf[j],
                pdf,
                inv_pdf: 1.0 / pdf,
                d65: d65(j),
                d65_step: d65(j + 1) - d65(j),
            }
        });
        let guide = std::array::from_fn(|g| {
            let u = g as f32 / GUIDE as f32;
            (bins.partition_point(|b| b.cdf <= u) - 1) as u16
        });
        Box::new(Constants { bins, guide })
    });
    &C
}

/// One wavelength drawn from the tabulated density.
struct Drawn {
    /// Wavelength, nm.
    lambda: f32,
    /// Density per nm it was drawn with.
    pdf: f32,
    /// The unit-luminance D65 at `lambda`.
    d65: f32,
}

/// The wavelength drawn at `u ∈ [0, 1)` (values outside are clamped).
#[inline(always)]
fn draw(c: &Constants, u: f32) -> Drawn {
    let u = u.clamp(0.0, 1.0);
    let g = index(u * GUIDE as f32, GUIDE - 1);
    let mut j = usize::from(c.guide[g]);
    while j + 1 < BINS && c.bins[j + 1].cdf <= u {
        j += 1;
    }
    let b = c.bins[j];
    let f = ((u - b.cdf) * b.inv_pdf).clamp(0.0, 1.0);
    Drawn {
        lambda: LAMBDA_MIN + j as f32 + f,
        pdf: b.pdf,
        d65: b.d65 + f * b.d65_step,
    }
}

/// The unit-luminance D65 at `l` nm (within 360 ..= 830), linear between the 1 nm values.
#[inline]
fn illuminant_at(c: &Constants, l: f32) -> f32 {
    let x = l - LAMBDA_MIN;
    let j = index(x, BINS - 1);
    let b = c.bins[j];
    b.d65 + (x - j as f32) * b.d65_step
}

/// The density per nm of [`sample_visible`] at `lambda` (0 outside `[LAMBDA_MIN, LAMBDA_MAX]`):
/// the closed form's average over the nanometre `lambda` lies in (module docs).
pub fn visible_pdf(lambda: f32) -> f32 {
    if !(LAMBDA_MIN..=LAMBDA_MAX).contains(&lambda) {
        return 0.0;
    }
    let j = index(lambda - LAMBDA_MIN, BINS - 1);
    constants().bins[j].pdf
}

/// A wavelength (nm) from the visible-range density, by inverting its CDF at `u ∈ [0, 1)` (values
/// outside are clamped).
pub fn sample_visible(u: f32) -> f32 {
    draw(constants(), u).lambda
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
            let d = draw(c, ui);
            (w.lambda[i], w.pdf[i], w.illuminant[i]) = (d.lambda, d.pdf, d.d65);
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
        self.illuminant[i] = illuminant_at(constants(), l);
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
    fn bins_hold_the_closed_form_masses() {
        let c = constants();
        for (j, b) in c.bins.iter().enumerate() {
            let lo = f64::from(LAMBDA_MIN) + j as f64;
            let mass = closed_form_cdf(lo + 1.0) - closed_form_cdf(lo);
            assert!(
                (f64::from(b.pdf) - mass).abs() < 1e-7,
                "bin {j}: {} vs {mass}",
                b.pdf
            );
            // Within 0.75 % of sech² anywhere in the bin: 0.702 % at the ends of the last bins,
            // plus the CDF's rounding to f32 (up to 0.03 % of the smallest bins).
            for t in [0.0, 0.5, 1.0] {
                let x = A * (lo + t - MU);
                let exact = A / (x.cosh().powi(2) * span());
                let r = f64::from(b.pdf) / exact;
                assert!((r - 1.0).abs() < 0.0075, "bin {j} at +{t}: ratio {r}");
            }
        }
        // The guide table: every cell starts at or before its bin and needs at most 3 steps.
        for g in 0..GUIDE {
            let (lo, hi) = (g as f32 / GUIDE as f32, (g + 1) as f32 / GUIDE as f32);
            let first = usize::from(c.guide[g]);
            assert!(c.bins[first].cdf <= lo);
            let last = c.bins.partition_point(|b| b.cdf < hi) - 1;
            assert!(last - first <= 3, "cell {g}: bins {first}..={last}");
        }
    }

    /// `T(830) − T(360)` (module docs), in `f64`.
    fn span() -> f64 {
        let t = |l: f64| (A * (l - MU)).tanh();
        t(f64::from(LAMBDA_MAX)) - t(f64::from(LAMBDA_MIN))
    }

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
                // The density the table reports for the wavelength (a wavelength on a bin's
                // upper edge may round into the next bin, whose density differs by < 1.5 %).
                let p = visible_pdf(w.lambda[i]);
                assert!((w.pdf[i] - p).abs() <= 0.015 * p, "{} vs {p}", w.pdf[i]);
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
