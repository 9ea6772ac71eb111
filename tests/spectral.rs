//! Spectral transport (issue 19), statistical claims. (1) The wavelengths of a path follow the
//! visible-range density `p(λ) ∝ sech²(0.0072 (λ − 538))` on 360–830 nm, each of the four (the
//! hero and the three stratified after it): Pearson's chi-square over 47 bins of 10 nm against
//! the closed-form CDF, 400 000 paths, α = 0.01 Šidák over the four; negative control: the same
//! samples against a uniform density are rejected.

mod common;

use common::{chi_square_pooled, sidak_alpha};
use lapidary::sampler::Rng;
use lapidary::spectrum::wavelengths::{HeroWavelengths, LAMBDA_MAX, LAMBDA_MIN, N};

/// The CDF of the visible-range density, from its closed form (written out here independently of
/// the sampler: `(tanh(a(λ − μ)) − tanh(a(360 − μ))) / (tanh(a(830 − μ)) − tanh(a(360 − μ)))`).
fn cdf(lambda: f64) -> f64 {
    let t = |l: f64| (0.0072 * (l - 538.0)).tanh();
    (t(lambda) - t(360.0)) / (t(830.0) - t(360.0))
}

#[test]
fn every_wavelength_of_a_path_follows_the_visible_density() {
    let paths = 400_000u64;
    let bins = 47usize;
    let width = f64::from(LAMBDA_MAX - LAMBDA_MIN) / bins as f64;
    let mut counts = vec![vec![0u64; bins]; N];
    let mut rng = Rng::new(19);
    for _ in 0..paths {
        let w = HeroWavelengths::sample(rng.uniform());
        for (i, &l) in w.lambda.iter().enumerate() {
            let b = (((f64::from(l) - f64::from(LAMBDA_MIN)) / width) as usize).min(bins - 1);
            counts[i][b] += 1;
        }
    }
    let edge = |b: usize| f64::from(LAMBDA_MIN) + b as f64 * width;
    let expected: Vec<f64> = (0..bins)
        .map(|b| paths as f64 * (cdf(edge(b + 1)) - cdf(edge(b))))
        .collect();
    let alpha = sidak_alpha(0.01, N);
    for (i, c) in counts.iter().enumerate() {
        let t = chi_square_pooled(c, &expected, 5.0);
        println!(
            "wavelength {i}: chi² {:.1}, dof {}, p {:.3}",
            t.chi2, t.dof, t.p_value
        );
        assert!(t.passes(alpha), "wavelength {i}: p {} < {alpha}", t.p_value);
    }
    // Negative control: a uniform density over the range is rejected.
    let uniform = vec![paths as f64 / bins as f64; bins];
    let t = chi_square_pooled(&counts[0], &uniform, 5.0);
    assert!(
        !t.passes(alpha),
        "a uniform density is not rejected (p {})",
        t.p_value
    );
}
