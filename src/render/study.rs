//! Convergence studies for `lapidary tradeoff` (docs/design.md §9). One render per setting runs until a
//! time budget; the film is captured after every pass of samples ([`Control::on_pass`]), and a
//! capture after `n` spp equals a render of `n` spp bit for bit. So one run gives the error at
//! every power-of-two spp (equal-spp comparisons and the error-against-time curve) and at the
//! budget (the equal-time comparison).
//!
//! Errors are measured against a converged [`Reference`]: relMSE as in `lapidary compare`
//! (`mean((t − r)² / (r² + 0.01))` over pixels and channels), HDR-FLIP
//! ([`crate::image::flip`]), and the stone's mean luminance relative to the reference's, which
//! shows a model's energy gain or loss apart from noise.

use super::{Control, RenderStats, World, render_scene};
use crate::image::ExrImage;
use crate::image::compare::REL_MSE_EPSILON;
use crate::image::flip::{DEFAULT_PPD, hdr_flip};
use crate::scene::Scene;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// The film after some passes.
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    /// Samples per pixel every pixel has.
    pub spp: u32,
    /// Render time until this capture, seconds (captures excluded).
    pub seconds: f64,
    /// Pixel means, row-major.
    pub rgb: Vec<[f32; 3]>,
}

/// What one budgeted render produced.
#[derive(Clone, Debug)]
pub struct Convergence {
    /// Captures at 4, 8, 16, … spp, in order.
    pub snapshots: Vec<Snapshot>,
    /// The capture after the last complete pass inside the budget (the equal-time image).
    pub last: Option<Snapshot>,
    /// Figures of the whole render.
    pub stats: RenderStats,
}

impl Convergence {
    /// The capture at exactly `spp` samples, if the render got that far.
    pub fn at(&self, spp: u32) -> Option<&Snapshot> {
        self.snapshots.iter().find(|s| s.spp == spp)
    }
}

/// Renders `scene`'s `world` for at most `budget` (and at most `max_spp`), capturing the film at
/// every power-of-two spp from 4 and after the last complete pass.
///
/// # Arguments
/// * `world`, `scene` – what to render; `scene.stage.render` gives size, depth, sampler and seed.
/// * `budget` – wall-clock time for the render (setup not included).
/// * `max_spp` – stop here if the budget allows more.
/// * `threads` – worker threads (`None`: one per core).
pub fn converge(
    world: &World,
    scene: &Scene,
    budget: Duration,
    max_spp: u32,
    threads: Option<usize>,
) -> Convergence {
    struct State {
        overhead: Duration,
        snapshots: Vec<Snapshot>,
        last: Option<Snapshot>,
    }
    let state = Mutex::new(State {
        overhead: Duration::ZERO,
        snapshots: vec![],
        last: None,
    });
    let start = Instant::now();
    let capture = |film: &super::Film, spp: u32| {
        let t = Instant::now();
        let mut st = state.lock().unwrap_or_else(|e| e.into_inner());
        let seconds = (t - start).saturating_sub(st.overhead).as_secs_f64();
        let snap = Snapshot {
            spp,
            seconds,
            rgb: film.rgb(),
        };
        if spp >= 4 && spp.is_power_of_two() {
            st.snapshots.push(snap.clone());
        }
        st.last = Some(snap);
        st.overhead += t.elapsed();
    };
    let mut scene = scene.clone();
    scene.stage.render.spp = max_spp;
    let control = Control {
        threads,
        deadline: Some(start + budget),
        on_pass: Some(&capture),
        ..Control::default()
    };
    let rendered = render_scene(world, &scene, &control);
    let st = state.into_inner().unwrap_or_else(|e| e.into_inner());
    let mut stats = rendered.stats;
    stats.elapsed = stats.elapsed.saturating_sub(st.overhead);
    Convergence {
        snapshots: st.snapshots,
        last: st.last,
        stats,
    }
}

/// A converged image to measure errors against.
#[derive(Clone, Debug, PartialEq)]
pub struct Reference {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Pixel means.
    pub rgb: Vec<[f32; 3]>,
    /// Variance of each pixel mean (the reference's own noise).
    pub variance: Vec<[f32; 3]>,
    /// Pixels whose first hit is the stone (`material.Y ≥ 0`).
    pub stone: Vec<bool>,
}

/// Errors of one image against the [`Reference`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Errors {
    /// relMSE against the true image, estimated: `mean(((t − r)² − var_r) / (r² + 0.01))` over
    /// pixels and channels. The reference's noise is independent of the test's, so
    /// `E[(t − r)²] = E[(t − μ)²] + var_r` and subtracting its (honest, independent-sampler)
    /// variance leaves an unbiased estimate of the test's own error; it can dip below 0 when that
    /// error is far below the reference's noise.
    pub rel_mse: f64,
    /// The plain `mean((t − r)² / (r² + 0.01))`, as `lapidary compare` prints it.
    pub rel_mse_raw: f64,
    /// Mean HDR-FLIP.
    pub flip: f64,
    /// The stone pixels' summed luminance over the reference's (1 = same energy).
    pub stone_ratio: f64,
}

impl Reference {
    /// Reads a lapidary EXR: `R G B`, `variance.R/G/B` and `material.Y`.
    pub fn from_exr(img: &ExrImage) -> Result<Reference, String> {
        let get = |name: &str| {
            img.channel(name)
                .ok_or_else(|| format!("the reference has no `{name}` channel"))
        };
        let (r, g, b) = (get("R")?, get("G")?, get("B")?);
        let (vr, vg, vb) = (get("variance.R")?, get("variance.G")?, get("variance.B")?);
        let material = get("material.Y")?;
        let n = (img.width * img.height) as usize;
        Ok(Reference {
            width: img.width,
            height: img.height,
            rgb: (0..n).map(|i| [r[i], g[i], b[i]]).collect(),
            variance: (0..n).map(|i| [vr[i], vg[i], vb[i]]).collect(),
            stone: material.iter().map(|&m| m >= 0.0).collect(),
        })
    }

    /// The relMSE a perfect image would show against this reference because of the reference's
    /// own noise: `mean(var / (r² + 0.01))`.
    pub fn noise_floor(&self) -> f64 {
        let mut sum = 0.0;
        for (r, v) in self.rgb.iter().zip(&self.variance) {
            for c in 0..3 {
                let rv = f64::from(r[c]);
                sum += f64::from(v[c]) / (rv * rv + REL_MSE_EPSILON);
            }
        }
        sum / (3 * self.rgb.len().max(1)) as f64
    }

    /// The errors of `test` (same size, row-major means).
    pub fn errors(&self, test: &[[f32; 3]]) -> Errors {
        let (mut rel, mut raw, mut count) = (0.0, 0.0, 0usize);
        let (mut lum_t, mut lum_r) = (0.0f64, 0.0f64);
        let lum = |p: &[f32; 3]| {
            0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2])
        };
        for (i, (t, r)) in test.iter().zip(&self.rgb).enumerate() {
            if !(t.iter().chain(r).all(|v| v.is_finite())) {
                continue;
            }
            for c in 0..3 {
                let (tv, rv) = (f64::from(t[c]), f64::from(r[c]));
                let d2 = (tv - rv) * (tv - rv);
                let w = 1.0 / (rv * rv + REL_MSE_EPSILON);
                raw += d2 * w;
                rel += (d2 - f64::from(self.variance[i][c])) * w;
                count += 1;
            }
            if self.stone[i] {
                lum_t += lum(t);
                lum_r += lum(r);
            }
        }
        let flip = hdr_flip(test, &self.rgb, self.width, self.height, DEFAULT_PPD)
            .flip
            .mean;
        let mean = |x: f64| {
            if count == 0 {
                f64::NAN
            } else {
                x / count as f64
            }
        };
        Errors {
            rel_mse: mean(rel),
            rel_mse_raw: mean(raw),
            flip: f64::from(flip),
            stone_ratio: if lum_r > 0.0 { lum_t / lum_r } else { f64::NAN },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reference() -> Reference {
        Reference {
            width: 4,
            height: 2,
            rgb: vec![[0.5; 3]; 8],
            variance: vec![[0.001; 3]; 8],
            stone: (0..8).map(|i| i < 4).collect(),
        }
    }

    #[test]
    fn errors_of_known_images() {
        let r = reference();
        let e = r.errors(&r.rgb);
        assert_eq!((e.rel_mse_raw, e.flip, e.stone_ratio), (0.0, 0.0, 1.0));
        assert!((e.rel_mse + r.noise_floor()).abs() < 1e-12);
        // Stone pixels 10 % brighter, the rest unchanged.
        let test: Vec<[f32; 3]> = (0..8)
            .map(|i| if i < 4 { [0.55; 3] } else { [0.5; 3] })
            .collect();
        let e = r.errors(&test);
        let expected = 0.5 * 0.05f64.powi(2) / (0.25 + 0.01);
        assert!((e.rel_mse_raw - expected).abs() < 1e-7, "{}", e.rel_mse_raw);
        assert!((e.rel_mse - (expected - r.noise_floor())).abs() < 1e-7);
        assert!((e.stone_ratio - 1.1).abs() < 1e-6);
        assert!(e.flip > 0.0);
        assert!((r.noise_floor() - 0.001 / 0.26).abs() < 1e-9);
    }
}
