//! Claim 7a, modulated density, explicit form: a population whose density is modulated by a field
//! (`body.platelets[k].modulation`) is its unmodulated self thinned — platelet `i` of cell `c` kept
//! iff its own uniform number is below `m(centre)` — so its platelets per region follow
//! `density × ∫ m`. Chi-square and z-tests; the family of [`counts_per_region_follow_density_times_modulation`]
//! is Šidák-corrected to an overall significance of 0.01 ([`ALPHA`]); sample counts are in each
//! test's doc comment. Each has a negative control that must be rejected at the same level.

use super::common::{chi_square_pooled, sidak_alpha};
use super::{gem, scene, z_limit};
use glam::{DVec3, Vec3};
use lapidary::platelet::modulation::thinning_uniform;
use lapidary::platelet::{Modulation, Platelet, Population};
use lapidary::recipe::GemRecipe;
use std::f64::consts::TAU;
use std::path::Path;

/// Overall significance of each family.
const ALPHA: f64 = 0.01;
/// Cells per axis of the sampled block (27 000 cells around the origin).
const SIDE: i32 = 30;

/// The first population of a recipe's body.
fn population(text: &str) -> Population {
    let s = scene(text);
    s.surface.body.expect("a body").platelets[0].clone()
}

/// A population of 3000 platelets per unit³ (radius 0.01–0.03, 2 per cell of 0.087) whose density
/// is modulated by `modulation` (RON field).
fn modulated(modulation: &str) -> Population {
    population(&gem(
        &format!(
            "(ior: 1.5, platelets: [(density: 3000.0, radius: (0.01, 0.03), orientation: Uniform, \
             entries: [(1.0, \"copper\")], seed: 5, modulation: {modulation})])"
        ),
        "",
    ))
}

/// The patterned sunstone's population (its density follows the course's three Perlin functions).
fn patterned() -> Population {
    let g = GemRecipe::load(Path::new("gems/sunstone-patterned.ron")).expect("the gem");
    let s = g.compile().expect("it compiles");
    let pop = s.surface.body.expect("a body").platelets[0].clone();
    assert!(
        pop.modulation.is_some(),
        "the patterned sunstone's density is modulated"
    );
    pop
}

/// Every cell of the block, x fastest.
fn cells() -> impl Iterator<Item = [i32; 3]> {
    let h = SIDE / 2;
    (-h..SIDE - h)
        .flat_map(move |z| (-h..SIDE - h).flat_map(move |y| (-h..SIDE - h).map(move |x| [x, y, z])))
}

/// Kept platelets per cell of the block, in [`cells`] order.
fn counts(pop: &Population) -> Vec<u64> {
    cells()
        .map(|c| {
            let mut n = 0;
            pop.each_in_cell(c, |_, _| {
                n += 1;
                false
            });
            n
        })
        .collect()
}

/// `∫ m` over the cube of side `side` at `lo` (object units³) by the midpoint rule on `k³` points.
fn integral(m: &Modulation, lo: DVec3, side: f64, k: usize) -> f64 {
    let h = side / k as f64;
    let mut sum = 0.0;
    for i in 0..k {
        for j in 0..k {
            for l in 0..k {
                let p = lo + DVec3::new(i as f64 + 0.5, j as f64 + 0.5, l as f64 + 0.5) * h;
                sum += f64::from(m.at(p.as_vec3()));
            }
        }
    }
    sum * h * h * h
}

/// The counts per region follow `density × ∫ m`. Two populations of 27 000 cells:
///
/// - **Sine along x**: `Marble(scale: 1, turbulence: 0)`, `m = ½ + ½ sin(2π x)`, 3000 per unit³;
///   regions are the 30 slabs one cell thick across x (≈ 27 000 platelets kept of ≈ 54 000; a slab
///   expects 1 800 · m̄), expectations in closed form
///   `D A (Δ/2 − (cos 2πx₁ − cos 2πx₀)/4π)`.
/// - **The patterned sunstone** (`gems/sunstone-patterned.ron`: three Perlin functions summed,
///   remapped and clamped): regions are the 216 blocks of 5³ cells, expectations by the midpoint
///   rule on 24³ points per block (checked on four blocks against 12³: the two agree within 5 % of
///   the block's Poisson SE).
///
/// Per population: Pearson's chi-square of the region counts (29 and 215 dof) and a z-test of the
/// total against `D ∫ m` over the block: 4 tests at overall 0.01 (Šidák: 2.5e-3 each, |z| ≤ 3.02).
/// Negative controls, each rejected by the chi-square: the sine a twentieth of a period later, and
/// the sunstone's population with its counts compared to the unmodulated density.
#[test]
fn counts_per_region_follow_density_times_modulation() {
    let family = 4;
    let a = sidak_alpha(ALPHA, family);
    let zl = z_limit(ALPHA, family);
    let h = SIDE / 2;

    // Sine along x.
    let pop = modulated("Marble(scale: 1.0, axis: (1.0, 0.0, 0.0), turbulence: 0.0)");
    let cell = f64::from(pop.cell);
    let area = (f64::from(SIDE) * cell).powi(2);
    let d = f64::from(pop.density);
    let mut slabs = vec![0u64; SIDE as usize];
    for (c, n) in cells().zip(counts(&pop)) {
        slabs[(c[0] + h) as usize] += n;
    }
    let slab = |shift: f64| -> Vec<f64> {
        (0..SIDE)
            .map(|i| {
                let x0 = f64::from(i - h) * cell + shift;
                let x1 = x0 + cell;
                d * area * (cell / 2.0 - ((TAU * x1).cos() - (TAU * x0).cos()) / (2.0 * TAU))
            })
            .collect()
    };
    let expected = slab(0.0);
    let chi = chi_square_pooled(&slabs, &expected, 5.0);
    let total: u64 = slabs.iter().sum();
    let mean: f64 = expected.iter().sum();
    let z = (total as f64 - mean) / mean.sqrt();
    eprintln!(
        "sine along x: {total} kept (expected {mean:.0}), chi² {:.1} / {} dof (p {:.3}), z {z:.2}",
        chi.chi2, chi.dof, chi.p_value
    );
    assert!(chi.passes(a), "sine: {chi:?}");
    assert!(z.abs() <= zl, "sine: total z {z:.2}");
    let shifted = chi_square_pooled(&slabs, &slab(0.05), 5.0);
    assert!(
        !shifted.passes(a),
        "a shifted sine is not rejected: {shifted:?}"
    );

    // The patterned sunstone.
    let pop = patterned();
    let m = pop.modulation.as_ref().expect("modulated");
    let cell = f64::from(pop.cell);
    let d = f64::from(pop.density);
    let (blocks, per) = (6usize, 5i32);
    let mut observed = vec![0u64; blocks * blocks * blocks];
    let region = |c: [i32; 3]| {
        let b = |v: i32| ((v + h) / per) as usize;
        b(c[0]) + blocks * (b(c[1]) + blocks * b(c[2]))
    };
    for (c, n) in cells().zip(counts(&pop)) {
        observed[region(c)] += n;
    }
    let side = f64::from(per) * cell;
    let corner = |r: usize| {
        let (i, j, k) = (r % blocks, (r / blocks) % blocks, r / (blocks * blocks));
        DVec3::new(i as f64, j as f64, k as f64) * side - DVec3::splat(f64::from(h) * cell)
    };
    let expected: Vec<f64> = (0..observed.len())
        .map(|r| d * integral(m, corner(r), side, 24))
        .collect();
    for r in [0, 77, 130, 215] {
        let coarse = d * integral(m, corner(r), side, 12);
        assert!(
            (coarse - expected[r]).abs() <= 0.05 * expected[r].sqrt() + 1e-9,
            "quadrature: block {r}: {coarse} (12³) vs {} (24³)",
            expected[r]
        );
    }
    let chi = chi_square_pooled(&observed, &expected, 5.0);
    let total: u64 = observed.iter().sum();
    let mean: f64 = expected.iter().sum();
    let z = (total as f64 - mean) / mean.sqrt();
    eprintln!(
        "patterned sunstone: {total} kept (expected {mean:.0}, {:.0} unmodulated), chi² {:.1} / {} \
         dof (p {:.3}), z {z:.2}",
        d * (f64::from(SIDE) * cell).powi(3),
        chi.chi2,
        chi.dof,
        chi.p_value
    );
    assert!(chi.passes(a), "patterned: {chi:?}");
    assert!(z.abs() <= zl, "patterned: total z {z:.2}");
    let flat: Vec<f64> = vec![mean / observed.len() as f64; observed.len()];
    let uniform = chi_square_pooled(&observed, &flat, 5.0);
    assert!(
        !uniform.passes(a),
        "a uniform density is not rejected: {uniform:?}"
    );
}

/// Thinning keeps a platelet iff its own uniform number is below the modulation at its centre,
/// and keeps the numbering: the patterned sunstone's platelets over the 27 000-cell block
/// (≈ 55 000 drawn) are exactly the unmodulated population's platelets (same seed, same index,
/// same attributes) that pass `thinning_uniform(seed, cell, index) < m(centre)`. And the kept
/// fraction follows `m`: the drawn platelets with `0 < m < 1` grouped in 10 bins of `m`, the kept
/// count of each bin against `Σ m` (variance `Σ m(1 − m)`), `Σ z²` against chi-square with 10 dof
/// at 0.01; where `m` is 0 or 1 the decision is certain and checked exactly.
#[test]
fn thinning_keeps_each_platelet_with_probability_m_and_keeps_indices() {
    let pop = patterned();
    let m = pop.modulation.clone().expect("modulated");
    let full = pop.clone().with_modulation(None);
    let (mut kept, mut drawn) = (vec![], vec![]);
    let (mut e, mut v, mut k) = ([0.0f64; 10], [0.0f64; 10], [0u64; 10]);
    let (mut certain, mut certain_kept) = (0u64, 0u64);
    for c in cells() {
        kept.clear();
        pop.each_in_cell(c, |i, p| {
            kept.push((i, p));
            false
        });
        drawn.clear();
        full.each_in_cell(c, |i, p| {
            drawn.push((i, p));
            false
        });
        let mut want: Vec<(u32, Platelet)> = vec![];
        for &(i, p) in &drawn {
            let mi = m.at(p.center);
            let survives = thinning_uniform(pop.seed, c, i) < mi;
            if survives {
                want.push((i, p));
            }
            if mi <= 0.0 || mi >= 1.0 {
                certain += u64::from(mi >= 1.0);
                certain_kept += u64::from(survives && mi >= 1.0);
                assert_eq!(survives, mi >= 1.0);
                continue;
            }
            let b = ((mi * 10.0) as usize).min(9);
            e[b] += f64::from(mi);
            v[b] += f64::from(mi) * (1.0 - f64::from(mi));
            k[b] += u64::from(survives);
        }
        assert_eq!(kept, want, "cell {c:?}");
    }
    assert_eq!(certain, certain_kept);
    let chi2: f64 = (0..10)
        .filter(|&b| v[b] > 0.0)
        .map(|b| (k[b] as f64 - e[b]).powi(2) / v[b])
        .sum();
    let bins = (0..10).filter(|&b| v[b] > 0.0).count();
    let p = super::common::chi2_p_value(chi2, bins);
    eprintln!(
        "kept fraction per m bin: chi² {chi2:.1} / {bins} dof (p {p:.3}); {} platelets at m = 1",
        certain
    );
    assert!(
        p >= ALPHA,
        "kept fractions: chi² {chi2:.1} / {bins}: {k:?} vs {e:?}"
    );
}

/// The kept set is a pure function of `(seed, cell)`: generated backwards, interleaved with
/// another population, or by a clone, each cell holds the same platelets (1 000 cells).
#[test]
fn thinned_cells_are_the_same_in_any_order() {
    let pop = patterned();
    let other = modulated("Perlin(scale: 0.3, seed: 4)");
    let list: Vec<[i32; 3]> = cells().take(1000).collect();
    let mut buf = vec![];
    let forward: Vec<Vec<Platelet>> = list
        .iter()
        .map(|&c| {
            pop.cell_platelets(c, &mut buf);
            buf.clone()
        })
        .collect();
    let clone = pop.clone();
    for (k, &c) in list.iter().enumerate().rev() {
        other.cell_platelets(c, &mut buf);
        clone.cell_platelets(c, &mut buf);
        assert_eq!(buf, forward[k], "cell {c:?}");
    }
    // A modulated population's walk meets only kept discs: every hit's platelet is in its cell's
    // kept list.
    let mut hits = 0;
    for i in 0..400 {
        let o = Vec3::new(-1.2, 0.01 * i as f32 - 2.0, 0.3);
        let d = Vec3::new(1.0, 0.05, -0.02);
        if let Some(hit) =
            lapidary::platelet::grid::intersect(std::slice::from_ref(&pop), o, d, 0.0, 2.4, None)
        {
            let mut found = false;
            pop.each_in_cell(hit.id.cell, |j, _| {
                found |= j == hit.id.index;
                false
            });
            assert!(found, "hit on a dropped platelet {:?}", hit.id);
            hits += 1;
        }
    }
    assert!(hits > 20, "the check needs hits: {hits}");
}
