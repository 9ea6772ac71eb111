//! Translucent stones (issue 17): the physics of a `body` — a smooth or rough dielectric
//! boundary around a clear, absorbing or scattering homogeneous interior — end to end through the
//! path tracer. Eight claims (1–8), in five modules:
//!
//! 1. [`furnace`] — white furnace: non-absorbing spheres (smooth; rough m 10° and α 0.5;
//!    isotropic and HG g 0.7 chromatic scattering) at η 1.3, 1.55, 2.4 under a constant sky of 1
//!    render 1 on every 8 × 8-pixel block of a 32 × 32 image and in total, per channel. Two
//!    findings are documented there: a medium leak at the boundary (fixed in
//!    src/render/integrator.rs) and the noise of the rough boundary's compensation tables (not
//!    fixed; an `--ignored` test fails on it by design).
//! 2. [`beer`] — Beer–Lambert through an absorbing slab, `T = (1−R)² τ / (1 − R² τ²)` per
//!    channel; the `colour` + `distance` form equals its coefficients; the stage scale keeps the
//!    look. (8) Free flight: the unscattered fraction through an index-matched scattering slab
//!    is `exp(−σt d)` per channel (path-level spectral MIS, `medium_depth: 0`).
//! 3. [`sphere`] — a clear glass sphere under a gradient sky: per camera ray, the mean over paths
//!    equals an independent f64 branch sum (Snell + Fresnel, all internal reflections). (4) The
//!    camera inside the stone: η² radiance in a clear sphere (exact per path), and the closed
//!    form `η² (1−F₀) τ / (1 − F₀ τ²)` from the centre of an absorbing one.
//! 5. [`hard`] — no non-finite or negative radiance over a deterministic sweep of extreme bodies
//!    and grazing rays. (6) Renders are bit-identical for 1 and 2 threads.
//! 7. [`interface`] — chi-square (both transport modes, grazing and total internal reflection),
//!    reciprocity and energy of the compensated rough boundary bodies use (GGX, Smith,
//!    `with_energy_tables`) at η 1.55 and 2.4, which tests/dielectric.rs (η 1.5, 2.4, 1/1.5,
//!    uncompensated) and tests/interface_energy.rs (η 1.5, 2.4, 1/1.5; GGX only at α 0.3) do not
//!    cover.
//!
//! Statistics: means are tested with `z = (mean − expected)/SE` (SE from the sample variance of
//! independent paths: the independent sampler), families Šidák-corrected to the stated overall
//! significance; expected values with zero variance (every path exact) must match to rounding.
//! Statistical tests have negative controls that a wrong model fails. Seeds are fixed, so CI is
//! repeatable. Sample counts and significance are in each test's doc comment.
//!
//! Runtime (release, two cores): ≈ 10 s for the file (`cargo test --release --test
//! translucent`). Heavier versions, ≈ 1.5 min: `cargo test --release --test translucent --
//! --ignored --nocapture` (`furnace_default_tables_full` is the rough furnace with the tables a
//! recipe builds; see [`furnace`], finding 2).

mod common;

#[allow(dead_code)]
#[path = "dielectric/checks.rs"]
mod checks;
#[allow(dead_code)]
#[path = "dielectric/chi.rs"]
mod chi;
#[allow(dead_code)]
#[path = "dielectric/energy.rs"]
mod energy;
#[allow(dead_code)]
#[path = "interface_energy/measure.rs"]
mod measure;

#[path = "translucent/beer.rs"]
mod beer;
#[path = "translucent/furnace.rs"]
mod furnace;
#[path = "translucent/hard.rs"]
mod hard;
#[path = "translucent/interface.rs"]
mod interface;
#[path = "translucent/sphere.rs"]
mod sphere;

use glam::Vec3;
use lapidary::geometry::Ray;
use lapidary::image::stats::{normal_quantile_two_sided, sidak};
use lapidary::recipe::GemRecipe;
use lapidary::render::{PathSample, PixelSums, Strategy, World, trace};
use lapidary::sampler::{PixelSampler, SamplerKind, hash_words, slots};
use lapidary::scene::Scene;
use lapidary::spectrum::RgbSample;

/// Compiles recipe text (panics with the recipe error).
pub fn scene(text: &str) -> Scene {
    GemRecipe::parse("translucent.ron", text)
        .unwrap_or_else(|e| panic!("{e}\n{text}"))
        .compile()
        .unwrap_or_else(|e| panic!("{e}\n{text}"))
}

/// The scene and its world.
pub fn build(text: &str) -> (Scene, World) {
    let s = scene(text);
    let w = World::new(&s).unwrap_or_else(|e| panic!("{e}\n{text}"));
    (s, w)
}

/// A recipe whose whole surface is the translucent `body` (RON tuple) on `stage` (RON tuple).
pub fn gem(body: &str, stage: &str) -> String {
    format!("(body: {body}, surface: Body, stage: {stage})")
}

/// The two-sided critical `|z|` of one test in a family of `k` at overall significance `alpha`.
pub fn z_limit(alpha: f64, k: usize) -> f64 {
    normal_quantile_two_sided(sidak(alpha, k))
}

/// Per-channel sums of path radiance.
#[derive(Clone, Copy, Debug, Default)]
pub struct Acc {
    /// Paths.
    pub n: u64,
    /// Σ radiance.
    pub sum: [f64; 3],
    /// Σ radiance².
    pub sq: [f64; 3],
    /// Largest radiance of any path and channel.
    pub max: f64,
}

impl Acc {
    /// Adds one path.
    pub fn add(&mut self, rgb: [f32; 3]) {
        self.n += 1;
        for (c, &v) in rgb.iter().enumerate() {
            let v = f64::from(v);
            self.sum[c] += v;
            self.sq[c] += v * v;
            self.max = self.max.max(v);
        }
    }

    /// Adds a film pixel's sums.
    pub fn add_pixel(&mut self, p: &PixelSums) {
        self.n += u64::from(p.n);
        let (sum, sq) = (p.radiance_sum(), p.radiance_sq_sum());
        for c in 0..3 {
            self.sum[c] += sum[c];
            self.sq[c] += sq[c];
        }
    }

    /// Adds another accumulator.
    pub fn merge(&mut self, o: &Acc) {
        self.n += o.n;
        for c in 0..3 {
            self.sum[c] += o.sum[c];
            self.sq[c] += o.sq[c];
        }
        self.max = self.max.max(o.max);
    }

    /// Mean of channel `c`.
    pub fn mean(&self, c: usize) -> f64 {
        self.sum[c] / self.n.max(1) as f64
    }

    /// Standard error of the mean of channel `c` (unbiased sample variance over `n`).
    pub fn se(&self, c: usize) -> f64 {
        if self.n < 2 {
            return 0.0;
        }
        let n = self.n as f64;
        let var = (self.sq[c] - self.sum[c] * self.sum[c] / n) / (n - 1.0);
        (var.max(0.0) / n).sqrt()
    }

    /// `(mean − expected)/SE` of channel `c`; a zero-variance mean (every path the same) must be
    /// `expected` to [`EXACT`] relative, else the score is infinite.
    pub fn z(&self, c: usize, expected: f64) -> f64 {
        let d = self.mean(c) - expected;
        let se = self.se(c);
        if se > EXACT * expected.abs().max(1e-3) {
            d / se
        } else if d.abs() <= EXACT * expected.abs().max(1.0) {
            0.0
        } else {
            f64::INFINITY.copysign(d)
        }
    }
}

/// Relative agreement required of a mean whose paths all carry the same value.
pub const EXACT: f64 = 1e-5;

/// Traces `n` independent paths along the fixed camera ray `ray` (the sampler positioned as the
/// renderer leaves it after the camera's slots) and accumulates their radiance. Every path's
/// radiance must be finite and non-negative (checked here).
pub fn trace_ray(
    world: &World,
    ray: Ray,
    n: u32,
    key: &[u64],
    max_depth: u32,
    strategy: Strategy,
) -> Acc {
    let pixel = hash_words(key);
    let mut acc = Acc::default();
    for i in 0..n {
        let p = trace_one(world, ray, pixel, i, max_depth, strategy);
        assert_valid(&p, || format!("ray {ray:?}, path {i}"));
        acc.add(p.radiance.0);
    }
    acc
}

/// One path along `ray`, sample `index` of pseudo-pixel `pixel`.
pub fn trace_one(
    world: &World,
    ray: Ray,
    pixel: u64,
    index: u32,
    max_depth: u32,
    strategy: Strategy,
) -> PathSample {
    let mut s = PixelSampler::new(SamplerKind::Independent, 0x7a5c, pixel, index);
    s.skip_to(slots::bounce(0));
    trace::<RgbSample>(world, ray, &mut s, max_depth, strategy)
}

/// Panics unless every channel of the path's radiance is finite and `≥ 0`.
pub fn assert_valid(p: &PathSample, what: impl Fn() -> String) {
    assert!(
        p.radiance.0.iter().all(|v| v.is_finite() && *v >= 0.0),
        "{}: radiance {:?}",
        what(),
        p.radiance
    );
}

/// Exact unpolarised Fresnel reflectance (Born & Wolf §1.5.2) in f64 for light arriving at
/// cosine `cos_i > 0` onto a medium of relative index `eta` (transmitted over incident side); 1
/// under total internal reflection. Written independently of `lapidary::bsdf::fresnel`.
pub fn fresnel(cos_i: f64, eta: f64) -> f64 {
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// A ray with origin `o` and the normalised direction of `d`.
pub fn ray(o: Vec3, d: Vec3) -> Ray {
    Ray::new(o, d.normalize())
}
