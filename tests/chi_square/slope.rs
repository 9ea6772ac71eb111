//! Chi-square of a micro-facet distribution's `sample_h` against `pdf_h` in **slope space**, so
//! that near-mirror lobes (m = 0.01°, a lobe 1e-4 rad wide) are resolved as well as rough ones.
//!
//! A micro-normal `h` at polar angle `θh` has slope `t = tan θh`; with `α = tan m` (the RMS slope
//! for Beckmann, and the Walter et al. 2007 equivalent for Blinn) the scaled slope `r = t / α` is
//! O(1) for every roughness. The histogram variable is `x = r / (1 + r) ∈ [0, 1)` (the whole
//! hemisphere, no overflow bin) and the azimuth `φ`. The density of `(x, φ)` follows from
//! `dω = sin θ dθ dφ` with `θ = atan(α r)`: `dθ = α dr / (1 + t²)` and `sin θ = t / √(1 + t²)`, so
//! `dω = α² r / (1 + t²)^{3/2} dr dφ`, and `dr = dx / (1 − x)²`.

use super::common::{ChiSquare, Grid2, chi_square_pooled};
use glam::Vec3;
use lapidary::bsdf::{Distribution, MicrofacetDistribution};
use lapidary::sampler::{Rng, hash_words};
use std::f64::consts::PI;

/// Roughnesses (degrees) of the issue, from near-mirror to very rough.
pub const ROUGHNESS: [f32; 5] = [0.01, 0.1, 1.0, 10.0, 45.0];

/// Both distributions.
pub const KINDS: [Distribution; 3] = [
    Distribution::Blinn,
    Distribution::Beckmann,
    Distribution::Ggx,
];

/// Number of configurations.
pub fn count() -> usize {
    ROUGHNESS.len() * KINDS.len()
}

/// The slope-space grid: 64 bins in `x`, 16 in `φ`.
pub const GRID: Grid2 = Grid2 {
    nu: 64,
    nv: 16,
    u: (0.0, 1.0),
    v: (0.0, 2.0 * PI),
};

/// The outcome of one distribution's test.
pub struct SlopeResult {
    /// Samples drawn.
    pub samples: u64,
    /// `sample_h` returned `None`.
    pub failed: u64,
    /// Samples that were not a finite upper-hemisphere direction.
    pub invalid: u64,
    /// `∫ pdf_h dω` over the hemisphere by the per-bin quadrature.
    pub integral: f64,
    /// The test.
    pub chi: ChiSquare,
}

/// `(x, φ)` of a micro-normal for slope scale `alpha`, `None` unless it is a finite upward
/// direction.
pub fn slope_coords(h: Vec3, alpha: f64) -> Option<(f64, f64)> {
    if !h.is_finite() || h.z <= 0.0 {
        return None;
    }
    let (x, y, z) = (f64::from(h.x), f64::from(h.y), f64::from(h.z));
    let r = (x * x + y * y).sqrt() / z / alpha;
    let mut phi = y.atan2(x);
    if phi < 0.0 {
        phi += 2.0 * PI;
    }
    Some((r / (1.0 + r), phi))
}

/// Draws `n` micro-normals and tests them against `pdf_h`.
pub fn run(kind: Distribution, m: f32, n: u64, seed: u64) -> SlopeResult {
    let d = MicrofacetDistribution::new(kind, m);
    let alpha = f64::from(m).to_radians().tan();
    let cells = GRID.len();
    let mut observed = vec![0u64; cells + 1];
    let (mut failed, mut invalid) = (0u64, 0u64);
    let mut rng = Rng::new(hash_words(&[seed, kind as u64, u64::from(m.to_bits())]));
    for _ in 0..n {
        match d.sample_h(rng.uniform2()) {
            None => failed += 1,
            Some(h) => match slope_coords(h, alpha).and_then(|(x, p)| GRID.bin(x, p)) {
                Some(b) => observed[b] += 1,
                None => invalid += 1,
            },
        }
    }
    observed[cells] = failed;
    let mass = GRID.integrate_adaptive(4, 1e-8, 6, |x, phi| {
        let r = x / (1.0 - x);
        let t = alpha * r;
        let cos_t = 1.0 / (1.0 + t * t).sqrt();
        let sin_t = t * cos_t;
        let h = Vec3::new(
            (sin_t * phi.cos()) as f32,
            (sin_t * phi.sin()) as f32,
            cos_t as f32,
        );
        let jacobian = alpha * alpha * r * cos_t.powi(3) / ((1.0 - x) * (1.0 - x));
        f64::from(d.pdf_h(h)) * jacobian
    });
    let integral: f64 = mass.iter().sum();
    let mut expected: Vec<f64> = mass.iter().map(|p| p * n as f64).collect();
    expected.push((1.0 - integral).max(0.0) * n as f64);
    SlopeResult {
        samples: n,
        failed,
        invalid,
        integral,
        chi: chi_square_pooled(&observed, &expected, 5.0),
    }
}
