use crate::common::chi_square_pooled;
use crate::{alpha_i, binomial_p, random_point};
use glam::Vec3;
use lapidary::sampler::Rng;
use lapidary::texture::{FieldNode, FieldTable, Map, MapNode, Stop};

// ------------------------------------------------------------------------------------------------
// 8. Switch blend bands
// ------------------------------------------------------------------------------------------------

/// Lookups per band value in the default switch test.
const N_SWITCH: u64 = 20_000;

/// A switch over `Remap(Constant(10 v), [0, 10] → [0, 1])` with stops at `thresholds` (materials
/// 0, 1, …) and blend `blend`; returns the map and the field's value.
fn switch_map(v: f32, thresholds: &[f32], blend: f32) -> (Map, f32) {
    let mut f = FieldTable::default();
    let c = f.add(FieldNode::Constant(10.0 * v)).unwrap();
    let field = f
        .add(FieldNode::Remap {
            input: c,
            from: [0.0, 10.0],
            to: [0.0, 1.0],
            clamp: false,
        })
        .unwrap();
    let value = f.eval(field, Vec3::ZERO);
    let mut nodes: Vec<MapNode> = (0..thresholds.len() as u32)
        .map(MapNode::Material)
        .collect();
    let stops = thresholds
        .iter()
        .enumerate()
        .map(|(k, &threshold)| Stop {
            threshold,
            node: k as u32,
        })
        .collect();
    nodes.push(MapNode::Switch {
        field,
        first: 0,
        count: thresholds.len() as u32,
        blend,
    });
    let root = thresholds.len() as u32;
    (Map::new(nodes, vec![], stops, f, root).unwrap(), value)
}

/// Inside a band of width `b = 0.2` around a threshold `t` the fraction of lookups taking the
/// upper stop follows `P = (v − (t − b/2)) / b`: with `u` from `Rng`, an exact two-sided binomial
/// test at `α_i` for each of the seven band values (five around `t = 0.5` in a two-stop switch,
/// two around `t = 0.8` in a three-stop switch); with stratified `u = (i + ½)/n` the fraction is
/// `P` to within `1/n`. Outside the bands the stop is the same for every `u`.
fn switch_bands(n: u64) {
    let blend = 0.2f32;
    let cases: [(&[f32], f32, u32); 7] = [
        (&[0.0, 0.5], 0.41, 1),
        (&[0.0, 0.5], 0.45, 1),
        (&[0.0, 0.5], 0.5, 1),
        (&[0.0, 0.5], 0.55, 1),
        (&[0.0, 0.5], 0.59, 1),
        (&[0.0, 0.5, 0.8], 0.72, 2),
        (&[0.0, 0.5, 0.8], 0.85, 2),
    ];
    let mut rng = Rng::new(0x88);
    for (thresholds, target, upper) in cases {
        let (map, v) = switch_map(target, thresholds, blend);
        let t = thresholds[upper as usize];
        let want = (f64::from(v) - f64::from(t - 0.5 * blend)) / f64::from(blend);
        let (mut hits, mut strat) = (0u64, 0u64);
        for i in 0..n {
            let p = random_point(&mut rng, -2.0, 2.0);
            let m = map.lookup(p, rng.uniform()).material;
            assert!(m == upper || m == upper - 1, "v {v}: material {m}");
            hits += u64::from(m == upper);
            let us = ((i as f64 + 0.5) / n as f64) as f32;
            strat += u64::from(map.lookup(p, us).material == upper);
        }
        let p = binomial_p(hits, n, want);
        let frac = strat as f64 / n as f64;
        println!(
            "switch t {t} v {v:.4}: P(upper) {want:.4}, random u {:.4} (p {p:.3e}), \
             stratified u {frac:.5}",
            hits as f64 / n as f64
        );
        assert!(
            p >= alpha_i(),
            "v {v}: {hits} of {n} upper, want {want}: p {p:e}"
        );
        assert!(
            (frac - want).abs() <= 1.0 / n as f64 + 1e-5,
            "v {v}: stratified fraction {frac}, want {want}"
        );
    }
    // Outside the bands: deterministic, for every u (including the edges and invalid values).
    let us = [
        0.0f32,
        1e-7,
        0.25,
        0.5,
        0.75,
        1.0 - f32::EPSILON / 2.0,
        1.0,
        f32::NAN,
    ];
    let outside: [(&[f32], f32, u32); 9] = [
        (&[0.0, 0.5], -5.0, 0),
        (&[0.0, 0.5], 0.05, 0),
        (&[0.0, 0.5], 0.39, 0),
        (&[0.0, 0.5], 0.61, 1),
        (&[0.0, 0.5], 7.0, 1),
        (&[0.0, 0.5, 0.8], 0.3, 0),
        (&[0.0, 0.5, 0.8], 0.65, 1),
        (&[0.0, 0.5, 0.8], 0.69, 1),
        (&[0.0, 0.5, 0.8], 0.91, 2),
    ];
    for (thresholds, target, stop) in outside {
        let (map, v) = switch_map(target, thresholds, blend);
        for u in us {
            for p in [Vec3::ZERO, Vec3::new(0.3, -7.0, 2.5)] {
                assert_eq!(map.lookup(p, u).material, stop, "v {v} u {u}");
            }
        }
    }
}

/// 20 000 lookups per band value; significance `α_i` each (seven tests).
#[test]
fn switch_band_follows_the_linear_ramp() {
    switch_bands(N_SWITCH);
}

/// Full strength, 200 000 lookups per band value: `cargo test --release --test maps -- --ignored`.
#[test]
#[ignore = "slow: cargo test --release --test maps -- --ignored"]
fn switch_band_follows_the_linear_ramp_full() {
    switch_bands(10 * N_SWITCH);
}

/// A switch nested in another switch's band: the outer field (0.46, `P_o = 0.3`) and the inner
/// fields (0.55, `P_i = 0.75`) are in their bands; since the outer switch rescales `u` to stay
/// uniform, the four materials come out with the product probabilities
/// `(1−P_o)(1−P_i), (1−P_o)P_i, P_o(1−P_i), P_o P_i`. `n` lookups with random `u`: chi-square,
/// 3 degrees of freedom, at `α_i`; with stratified `u` the counts are exact to ±2.
fn nested_switches(n: u64) {
    let mut f = FieldTable::default();
    let outer = f.add(FieldNode::Constant(0.46)).unwrap();
    let inner = f.add(FieldNode::Constant(0.55)).unwrap();
    let stop = |threshold: f32, node: u32| Stop { threshold, node };
    let stops = vec![
        stop(0.0, 0),
        stop(0.5, 1),
        stop(0.0, 2),
        stop(0.5, 3),
        stop(0.0, 4),
        stop(0.5, 5),
    ];
    let switch = |field, first| MapNode::Switch {
        field,
        first,
        count: 2,
        blend: 0.2,
    };
    let nodes = vec![
        MapNode::Material(0),
        MapNode::Material(1),
        MapNode::Material(2),
        MapNode::Material(3),
        switch(inner, 0),
        switch(inner, 2),
        switch(outer, 4),
    ];
    let map = Map::new(nodes, vec![], stops, f, 6).unwrap();
    let po = (0.46 - 0.4) / 0.2;
    let pi = (0.55 - 0.4) / 0.2;
    let probs = [
        (1.0 - po) * (1.0 - pi),
        (1.0 - po) * pi,
        po * (1.0 - pi),
        po * pi,
    ];
    let mut rng = Rng::new(0x89);
    let (mut random, mut strat) = ([0u64; 4], [0u64; 4]);
    for i in 0..n {
        random[map.lookup(Vec3::ZERO, rng.uniform()).material as usize] += 1;
        let u = ((i as f64 + 0.5) / n as f64) as f32;
        strat[map.lookup(Vec3::ZERO, u).material as usize] += 1;
    }
    let expected: Vec<f64> = probs.iter().map(|p| p * n as f64).collect();
    let chi = chi_square_pooled(&random, &expected, 5.0);
    println!(
        "nested switches: {n} lookups, random u {random:?}, stratified {strat:?}, expected \
         {expected:.0?}, chi² {:.2} p {:.3e}",
        chi.chi2, chi.p_value
    );
    assert!(chi.passes(alpha_i()), "{chi:?}");
    for (k, (&s, e)) in strat.iter().zip(&expected).enumerate() {
        assert!((s as f64 - e).abs() <= 2.0, "material {k}: {s} vs {e}");
    }
}

/// 40 000 lookups; significance `α_i`.
#[test]
fn nested_switch_bands_stay_independent() {
    nested_switches(2 * N_SWITCH);
}

/// Full strength, 400 000 lookups: `cargo test --release --test maps -- --ignored`.
#[test]
#[ignore = "slow: cargo test --release --test maps -- --ignored"]
fn nested_switch_bands_stay_independent_full() {
    nested_switches(20 * N_SWITCH);
}
