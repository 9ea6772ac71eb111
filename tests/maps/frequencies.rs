use crate::common::chi_square_pooled;
use crate::support::{
    BACKGROUND, CUMULATIVE, ENTRY_MATERIALS, WEIGHTED_NODE, vnode, voronoi_node, weighted_map,
};
use crate::{alpha_i, binomial_p, block_ids, p_below, pick_probabilities, random_point};
use lapidary::sampler::Rng;
use std::collections::HashMap;

// ------------------------------------------------------------------------------------------------
// 1. Entry frequencies match the weights
// ------------------------------------------------------------------------------------------------

/// Lattice cells in the default (CI) frequency and fill tests: a 64 × 64 × 25 block.
const N_CELLS: usize = 102_400;
/// Points looked up in the default end-to-end frequency test (≥ 1e5 distinct cells).
const N_LOOKUP: usize = 300_000;

/// `pick` over the ids of `n` distinct cells of a fill-1 node (weights 1 : 2 : 3 : 4) against
/// `n · wₖ`: Pearson chi-square, 3 degrees of freedom, per-test significance `α_i`.
fn entry_frequencies_by_cell(n: usize) {
    let map = weighted_map(0x1a, 1.0, 1.0);
    let node = voronoi_node(&map, WEIGHTED_NODE);
    let mut observed = [0u64; 4];
    for id in block_ids(&node.basis, n) {
        assert!(node.filled(id));
        let k = node.pick(id, &map.entries);
        assert!(k < 4, "pick {k} out of range");
        observed[k] += 1;
    }
    let expected: Vec<f64> = pick_probabilities(&CUMULATIVE)
        .iter()
        .map(|p| p * n as f64)
        .collect();
    let chi = chi_square_pooled(&observed, &expected, 5.0);
    println!(
        "entry frequencies by cell id: {n} cells, observed {observed:?}, expected {expected:.0?}, \
         chi² {:.2} dof {} p {:.3e} (α_i {:.2e})",
        chi.chi2,
        chi.dof,
        chi.p_value,
        alpha_i()
    );
    assert_eq!(chi.dof, 3);
    assert!(chi.passes(alpha_i()), "{chi:?}");
}

/// Entry frequencies over the ids of 102 400 distinct lattice cells; significance `α_i`.
#[test]
fn entry_frequencies_match_weights_by_cell() {
    entry_frequencies_by_cell(N_CELLS);
}

/// Full strength, 1 024 000 cells: `cargo test --release --test maps -- --ignored`.
#[test]
#[ignore = "slow: cargo test --release --test maps -- --ignored"]
fn entry_frequencies_match_weights_by_cell_full() {
    entry_frequencies_by_cell(10 * N_CELLS);
}

/// End to end: `n_points` uniform points of a box of `0.67 · n_points` cells looked up in a sparse
/// (fill ½) weighted Voronoi over a background; the outcomes of the *distinct* cells (deduplicated
/// by the trail's id) — background, or entry 0 … 3 — against `m · (½, ½ wₖ)`, `m` the number of
/// distinct cells. Chi-square, 4 degrees of freedom, significance `α_i`. Also checks that a cell's
/// outcome is the same at every point of it and is the one `filled`/`pick` give for its id.
fn entry_frequencies_end_to_end(n_points: usize) {
    let inv_scale = 20.0;
    let map = weighted_map(0x2b, 0.5, inv_scale);
    let node = voronoi_node(&map, WEIGHTED_NODE);
    let side = (n_points as f32 / 1.5).cbrt() / inv_scale;
    let mut rng = Rng::new(0x2b2b);
    let mut seen: HashMap<u64, usize> = HashMap::with_capacity(n_points);
    for _ in 0..n_points {
        let p = random_point(&mut rng, -0.5 * side, 0.5 * side);
        let hit = map.lookup(p, rng.uniform());
        let ids = hit.trail.ids();
        assert_eq!(ids.len(), 1, "{hit:?}");
        let id = ids[0];
        let outcome = match ENTRY_MATERIALS.iter().position(|&m| m == hit.material) {
            Some(k) => {
                assert_eq!(hit.trail.glitter_cell(), Some(id));
                k
            }
            None => {
                assert_eq!(hit.material, BACKGROUND);
                assert_eq!(hit.trail.glitter_cell(), None);
                4
            }
        };
        assert!(hit.facet.is_none());
        let want = if node.filled(id) {
            node.pick(id, &map.entries)
        } else {
            4
        };
        assert_eq!(outcome, want, "cell {id:#x} at {p:?}");
        let prev = *seen.entry(id).or_insert(outcome);
        assert_eq!(prev, outcome, "cell {id:#x} changes outcome inside");
    }
    let m = seen.len();
    assert!(m >= n_points / 3, "only {m} distinct cells");
    let mut observed = [0u64; 5];
    for &k in seen.values() {
        observed[k] += 1;
    }
    let fill = p_below(0.5);
    let mut expected: Vec<f64> = pick_probabilities(&CUMULATIVE)
        .iter()
        .map(|p| p * fill * m as f64)
        .collect();
    expected.push((1.0 - fill) * m as f64);
    let chi = chi_square_pooled(&observed, &expected, 5.0);
    println!(
        "entry frequencies end to end: {n_points} lookups, {m} distinct cells, observed \
         {observed:?}, expected {expected:.0?}, chi² {:.2} dof {} p {:.3e}",
        chi.chi2, chi.dof, chi.p_value
    );
    assert_eq!(chi.dof, 4);
    assert!(chi.passes(alpha_i()), "{chi:?}");
}

/// 300 000 lookups (≈ 155 000 distinct cells); significance `α_i`.
#[test]
fn entry_frequencies_match_weights_end_to_end() {
    entry_frequencies_end_to_end(N_LOOKUP);
}

/// Full strength, 3 000 000 lookups: `cargo test --release --test maps -- --ignored`.
#[test]
#[ignore = "slow: cargo test --release --test maps -- --ignored"]
fn entry_frequencies_match_weights_end_to_end_full() {
    entry_frequencies_end_to_end(10 * N_LOOKUP);
}

// ------------------------------------------------------------------------------------------------
// 2. Fill fractions
// ------------------------------------------------------------------------------------------------

/// For `fill ∈ {0.02, 0.25, 0.9}`: the number of filled cells among `n` distinct cells against
/// Binomial(`n`, `fill`) (the exact probability of `to_unit_f32 < fill`), exact two-sided test at
/// `α_i` each.
fn fill_fractions(n: usize) {
    let fills = [(0.02f32, 0x21u64), (0.25, 0x22), (0.9, 0x23)];
    for (fill, seed) in fills {
        let node = vnode(seed, 1.0, (0, 1), fill);
        let filled = block_ids(&node.basis, n)
            .into_iter()
            .filter(|&id| node.filled(id))
            .count() as u64;
        let p = binomial_p(filled, n as u64, p_below(fill));
        println!(
            "fill {fill}: {filled} of {n} cells filled ({:.5}), two-sided binomial p {p:.3e}",
            filled as f64 / n as f64
        );
        assert!(
            p >= alpha_i(),
            "fill {fill}: {filled} of {n} filled, p = {p:e}"
        );
    }
}

/// 102 400 cells per fill value; significance `α_i` each (three tests).
#[test]
fn fill_fraction_is_binomial() {
    fill_fractions(N_CELLS);
}

/// Full strength, 1 024 000 cells per fill value: `cargo test --release --test maps -- --ignored`.
#[test]
#[ignore = "slow: cargo test --release --test maps -- --ignored"]
fn fill_fraction_is_binomial_full() {
    fill_fractions(10 * N_CELLS);
}
