//! `compare` detects a bias, not only noise (issue 14), on the golden scenes: the references in
//! `tests/refs/` against the golden test renders of `tests/golden.rs` (96×96, 256 spp,
//! independent sampler, seed 7), which this module shares rather than rendering them again.
//!
//! - a uniform 2 % shift of every scene fails;
//! - a 5 % shift of one material's pixels (selected by `material.Y`) fails wherever the noise
//!   lets it stand 2 above the limit (every opaque gem's material, some of the translucent ones');
//! - a changed coat IOR (the recipe's text edited) fails;
//! - two independent renders of every scene (seeds 7 and 8, neither the reference) pass (ignored in
//!   CI: a second golden render of every scene; CI runs the 30 short independent pairs below);
//! - over seeded pairs of independent renders, the false-failure rate is at most the stated
//!   α = 0.01: the number of failures `f` of `n` pairs must satisfy `f ≤ k` with `k` the
//!   smallest count for which `P(Bin(n, 0.01) > k) < 0.001`. CI runs 30 pairs at 48×48 and
//!   128 spp; the full 200 pairs at the golden settings are `#[ignore]`d:
//!   `cargo test --release --test golden -- --ignored --nocapture`.

use super::{golden_renders, recipe_of, reference, render_text, scenes};
use lapidary::image::ExrImage;
use lapidary::image::compare::{AGGREGATE_ALPHA, Comparison, compare};

fn render(name: &str, size: u32, spp: u32, seed: u64) -> ExrImage {
    let recipe = recipe_of(name);
    let text = std::fs::read_to_string(&recipe).unwrap();
    render_text(&recipe, &text, size, spp, seed)
}

/// `img` with R, G, B multiplied by `gain` where `select(pixel index)` holds.
fn shifted(img: &ExrImage, gain: f32, select: impl Fn(usize) -> bool) -> ExrImage {
    let mut img = img.clone();
    for c in img
        .channels
        .iter_mut()
        .filter(|c| ["R", "G", "B"].contains(&&*c.name))
    {
        for (i, v) in c.data.iter_mut().enumerate() {
            if select(i) {
                *v *= gain;
            }
        }
    }
    img
}

/// One line about a comparison: pixel test and every scale.
fn summary(c: &Comparison) -> String {
    let z = c.ztest.as_ref().expect("the images carry variance");
    let scales: Vec<String> = z
        .scales
        .iter()
        .map(|s| {
            let mark = if s.passed { "" } else { " FAIL" };
            format!("{} {:.2}/{:.2}{mark}", s.label(), s.max_abs_z, s.z_crit)
        })
        .collect();
    format!(
        "pixels {:.2} %{}, tiles |z|/limit: {}",
        100.0 * z.pass_fraction,
        if z.pixels_passed { "" } else { " FAIL" },
        scales.join(", ")
    )
}

/// Whether the aggregate test failed at some scale.
fn bias_seen(c: &Comparison) -> bool {
    c.ztest
        .as_ref()
        .is_some_and(|z| z.scales.iter().any(|s| !s.passed))
}

#[test]
fn a_uniform_two_percent_shift_fails_on_every_golden_scene() {
    for (name, test) in golden_renders() {
        let reference = reference(name);
        for gain in [1.02, 0.98] {
            let c = compare(&shifted(test, gain, |_| true), &reference).unwrap();
            eprintln!("{name} × {gain}: {}", summary(&c));
            assert!(!c.passed, "{name} × {gain} passed: {}", summary(&c));
            // The aggregate test sees it on its own, even where the pixel test does not.
            assert!(bias_seen(&c), "{name} × {gain}: {}", summary(&c));
        }
    }
}

/// Seed 7 against seed 8 at the golden settings (a second full golden render of every scene, so
/// ignored in CI: `tests/golden.rs` compares seed 7 with each reference, an independent render,
/// and `false_failure_rate_of_independent_pairs_short` runs 30 independent pairs).
#[test]
#[ignore = "a second golden render of every scene: ~2.5 min on 2 cores"]
fn independent_renders_of_every_golden_scene_pass() {
    for (name, a) in golden_renders() {
        let b = &render(name, 96, 256, 8);
        let c = compare(a, b).unwrap();
        eprintln!("{name}, seed 7 vs 8: {}", summary(&c));
        assert!(c.passed, "{name}: seed 7 vs 8 failed: {}", summary(&c));
    }
}

/// Material indices of `img` (`material.Y`) with their pixel counts, largest first.
fn materials(img: &ExrImage) -> Vec<(i32, usize)> {
    let mut counts = std::collections::BTreeMap::<i32, usize>::new();
    for &m in img.channel("material.Y").unwrap() {
        *counts.entry(m as i32).or_default() += 1;
    }
    let mut v: Vec<(i32, usize)> = counts.into_iter().filter(|(m, _)| *m >= 0).collect();
    v.sort_by_key(|&(m, n)| (std::cmp::Reverse(n), m));
    v
}

/// The |z| a 5 % shift of material `m`'s pixels (by the reference's labels) would score at the
/// material scale if the renders had no noise: per channel `0.05 Σ t / √Σ (var_t + var_r)` over
/// the material's pixels, the largest channel.
fn expected_z(test: &ExrImage, reference: &ExrImage, m: i32) -> f64 {
    let labels = reference.channel("material.Y").unwrap();
    ["R", "G", "B"]
        .iter()
        .map(|c| {
            let t = test.channel(c).unwrap();
            let vt = test.channel(&format!("variance.{c}")).unwrap();
            let vr = reference.channel(&format!("variance.{c}")).unwrap();
            let (mut sum, mut var) = (0.0f64, 0.0f64);
            for i in (0..labels.len()).filter(|&i| labels[i] as i32 == m) {
                sum += f64::from(t[i]);
                var += f64::from(vt[i]) + f64::from(vr[i]);
            }
            0.05 * sum / var.sqrt()
        })
        .fold(0.0, f64::max)
}

#[test]
fn a_five_percent_shift_of_one_material_fails() {
    // On every gem with more than one material, each material covering ≥ 2 % of the image
    // (184 pixels) is brightened by 5 % on its own where the reference's `material.Y` names it
    // (the labels the aggregate test groups by). The cells of an aventurine's materials are
    // scattered over the stone, so no tile sees such a shift; the per-material groups do.
    // (The test render's own labels agree with the reference's on only about half of an
    // aventurine's stone pixels — the first sample's material is itself random there — so a
    // shift selected by them is diluted; it is printed, not asserted.)
    //
    // The failure is required wherever the renders' noise lets the shift stand out: where its
    // noise-free |z| at the material scale is at least 2 above the scale's limit (a miss then has
    // probability < 2.3 %; the renders are seeded, so the outcome is fixed). That holds for every
    // material of the opaque gems (expected |z| 7.0–34.7). On the translucent gems (issue 17)
    // light found only by BSDF sampling through the body makes the pixels several times noisier:
    // at 256 spp the pink Sunstone's three glitter materials (5.0–5.6 against 5.8) and the
    // Aventurine glass's body (5.5 against 6.0) are printed, not asserted.
    let mut tried = 0;
    for (name, test) in golden_renders() {
        let reference = reference(name);
        let list = materials(&reference);
        if list.len() < 2 {
            continue;
        }
        let limit = compare(test, &reference)
            .unwrap()
            .ztest
            .expect("the images carry variance")
            .scales
            .iter()
            .find(|s| s.label() == "material")
            .expect("a material scale")
            .z_crit;
        let by_ref = reference.channel("material.Y").unwrap();
        let by_test = test.channel("material.Y").unwrap();
        for &(m, count) in list.iter().filter(|(_, n)| *n >= 184) {
            let c = compare(&shifted(test, 1.05, |i| by_ref[i] as i32 == m), &reference).unwrap();
            let own =
                compare(&shifted(test, 1.05, |i| by_test[i] as i32 == m), &reference).unwrap();
            let expected = expected_z(test, &reference, m);
            let required = expected >= limit + 2.0;
            eprintln!(
                "{name}, material {m} ({count} px) × 1.05: expected |z| {expected:.2} (limit \
                 {limit:.2}{}): {}; selected by the test's labels: {}",
                if required { "" } else { ", not required" },
                summary(&c),
                if own.passed { "pass" } else { "FAIL" }
            );
            if required {
                assert!(
                    !c.passed,
                    "{name}: material {m} × 1.05 passed: {}",
                    summary(&c)
                );
                tried += 1;
            }
        }
    }
    assert!(tried >= 15, "only {tried} materials tried");
}

#[test]
fn a_changed_ior_fails() {
    // Sunstone's coats at IOR 1.58 → 1.55 (every coat), rendered as the golden test renders.
    let recipe = recipe_of("sunstone");
    let text = std::fs::read_to_string(&recipe).unwrap();
    assert!(text.contains("ior: 1.58"));
    let changed = render_text(&recipe, &text.replace("ior: 1.58", "ior: 1.55"), 96, 256, 7);
    let c = compare(&changed, &reference("sunstone")).unwrap();
    eprintln!("sunstone, IOR 1.55: {}", summary(&c));
    assert!(!c.passed, "IOR 1.55 passed: {}", summary(&c));
    assert!(bias_seen(&c), "{}", summary(&c));
}

/// The largest failure count `k` allowed of `n` trials at false-failure rate `alpha`: the
/// smallest `k` with `P(Bin(n, alpha) > k) < 0.001`.
fn failure_bound(n: usize, alpha: f64) -> usize {
    let mut pmf = (1.0 - alpha).powi(n as i32); // P(X = 0)
    let mut cdf = pmf;
    for k in 0..n {
        if 1.0 - cdf < 1e-3 {
            return k;
        }
        pmf *= (n - k) as f64 / (k + 1) as f64 * alpha / (1.0 - alpha);
        cdf += pmf;
    }
    n
}

/// Compares `pairs` pairs of independent renders (scene `k mod 10`, seeds `100 + 2k` and
/// `101 + 2k`) and checks the failure count against [`failure_bound`].
fn false_failure_rate(pairs: usize, size: u32, spp: u32) {
    let names = scenes();
    let alpha = AGGREGATE_ALPHA;
    let mut failures = Vec::new();
    for k in 0..pairs {
        let name = &names[k % names.len()];
        let seed = 100 + 2 * k as u64;
        let a = render(name, size, spp, seed);
        let b = render(name, size, spp, seed + 1);
        let c = compare(&a, &b).unwrap();
        if !c.passed {
            eprintln!(
                "pair {k}: {name}, seeds {seed}/{}: {}",
                seed + 1,
                summary(&c)
            );
            failures.push(k);
        }
    }
    let bound = failure_bound(pairs, alpha);
    eprintln!(
        "false failures: {} of {pairs} pairs ({:.2} %) at {size}×{size}, {spp} spp; stated α {alpha}; \
         allowed ≤ {bound} (P(Bin({pairs}, {alpha}) > {bound}) < 0.001)",
        failures.len(),
        100.0 * failures.len() as f64 / pairs as f64
    );
    assert!(failures.len() <= bound, "failed pairs: {failures:?}");
}

#[test]
fn failure_bound_is_the_binomial_tail() {
    // P(Bin(200, 0.01) > 6) = 0.0043, > 7 = 0.0010 (just above), > 8 = 0.00024.
    assert_eq!(failure_bound(200, 0.01), 8);
    // P(Bin(30, 0.01) > 2) = 0.0033, > 3 = 0.00022.
    assert_eq!(failure_bound(30, 0.01), 3);
    assert_eq!(failure_bound(10, 0.0), 0);
}

#[test]
fn false_failure_rate_of_independent_pairs_short() {
    false_failure_rate(30, 48, 128);
}

#[test]
#[ignore = "200 pairs at the golden settings: ~20 min on 2 cores"]
fn false_failure_rate_of_independent_pairs() {
    false_failure_rate(200, 96, 256);
}
