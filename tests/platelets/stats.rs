//! Claim 1, statistics: a [`Population`] holds what its recipe asks for. Every test draws whole
//! cells of a block of 30³ = 27 000 cells around the origin (negative coordinates included) and
//! compares what it finds with the recipe's distributions by Pearson's chi-square
//! (`common::chi_square_pooled`, cells expecting fewer than 5 pooled) or a z-score; each family is
//! Šidák-corrected to an overall significance of 0.01 ([`ALPHA`]). Every test has a negative
//! control: the same samples against a slightly wrong hypothesis must be rejected at the same
//! per-test level.

use super::common::{chi_square_pooled, sidak_alpha};
use super::{build, gem, scene, z_limit};
use glam::{DVec3, Vec3};
use lapidary::platelet::{MAX_PER_CELL, Orientation, Platelet, Population};
use lapidary::scene::Effect;

/// Overall significance of each family.
const ALPHA: f64 = 0.01;
/// Cells per axis of the sampled block (27 000 cells).
const SIDE: i32 = 30;

/// Every cell of the block, x fastest.
fn cells() -> impl Iterator<Item = [i32; 3]> {
    let h = SIDE / 2;
    (-h..SIDE - h)
        .flat_map(move |z| (-h..SIDE - h).flat_map(move |y| (-h..SIDE - h).map(move |x| [x, y, z])))
}

/// Number of cells in the block.
fn n_cells() -> usize {
    (SIDE * SIDE * SIDE) as usize
}

/// Every platelet of the block, with its cell.
fn platelets(pop: &Population) -> Vec<([i32; 3], Platelet)> {
    let mut out = vec![];
    let mut buf = vec![];
    for c in cells() {
        pop.cell_platelets(c, &mut buf);
        out.extend(buf.iter().map(|p| (c, *p)));
    }
    out
}

fn pop(density: f32, radius: (f32, f32), orientation: Orientation, seed: u64) -> Population {
    Population::new(density, radius, orientation, vec![(1.0, 0)], seed)
        .unwrap_or_else(|| panic!("density {density} radius {radius:?} is allowed"))
}

/// The populations of the count tests: mean 2 per cell (small platelets: the cell is sized by the
/// target count), 5.3 and 15.97 (large platelets: the cell is 2.2 × the largest radius; the last
/// is just under the largest mean allowed, 16).
fn count_populations() -> Vec<(&'static str, Population)> {
    vec![
        (
            "D 3000, r 0.01–0.03",
            pop(3000.0, (0.01, 0.03), Orientation::Uniform, 11),
        ),
        (
            "D 500, r 0.05–0.1",
            pop(500.0, (0.05, 0.1), Orientation::Uniform, 12),
        ),
        (
            "D 1500, r 0.1",
            pop(1500.0, (0.1, 0.1), Orientation::Uniform, 13),
        ),
    ]
}

/// Poisson probabilities of `0 ..= MAX_PER_CELL − 1` and of `≥ MAX_PER_CELL` (the generator's cap).
fn poisson_cells(lambda: f64) -> Vec<f64> {
    let mut p = (-lambda).exp();
    let mut v = vec![];
    for k in 0..MAX_PER_CELL {
        v.push(p);
        p *= lambda / f64::from(k + 1);
    }
    let tail = (1.0 - v.iter().sum::<f64>()).max(0.0);
    v.push(tail);
    v
}

/// Counts per cell of the block, histogrammed (`0 ..= MAX_PER_CELL`), and the cells' counts.
fn count_histogram(pop: &Population) -> (Vec<u64>, Vec<u32>) {
    let mut hist = vec![0u64; MAX_PER_CELL as usize + 1];
    let mut counts = vec![];
    for c in cells() {
        let mut n = 0u32;
        pop.each_in_cell(c, |_, _| {
            n += 1;
            false
        });
        hist[(n as usize).min(MAX_PER_CELL as usize)] += 1;
        counts.push(n);
    }
    (hist, counts)
}

/// Pearson correlation of `a` and `b`.
fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len() as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        sab += (x - ma) * (y - mb);
        saa += (x - ma) * (x - ma);
        sbb += (y - mb) * (y - mb);
    }
    sab / (saa * sbb).sqrt()
}

/// Platelets per cell are Poisson with mean `density · cell³`, and a volume holds `density ×
/// volume` of them. Three populations (means 2, 5.3, 15.97 per cell), 27 000 cells each
/// (54 000 – 431 000 platelets). Per population: the cell sizing (`cell ≥ 2.2 r_max` and
/// `≥ (2/density)^⅓`, one of them equal), chi-square of the per-cell counts against Poisson
/// (65 cells pooled to ≥ 5 expected), the total against `density × 27 000 cell³` (z, Poisson SE),
/// and the correlation of each cell's count with its +x, +y and +z neighbours' and with the same
/// cell under another seed (z = r √N): 3 × 6 = 18 tests at overall 0.01 (Šidák: per test
/// 5.6e-4, |z| ≤ 3.45). Negative controls: the same counts against a density 5 % too high
/// (chi-square and total must both be rejected).
#[test]
fn counts_per_cell_are_poisson_with_the_recipe_density() {
    let family = 3 * 6;
    let a = sidak_alpha(ALPHA, family);
    let zl = z_limit(ALPHA, family);
    for (label, pop) in count_populations() {
        // Cell sizing.
        let by_radius = 2.2 * f64::from(pop.radius.1);
        let by_count = (2.0 / f64::from(pop.density)).cbrt();
        let cell = f64::from(pop.cell);
        assert!(
            cell >= by_radius * (1.0 - 1e-6) && cell >= by_count * (1.0 - 1e-6),
            "{label}: cell {cell}"
        );
        assert!(
            (cell / by_radius.max(by_count) - 1.0).abs() < 1e-6,
            "{label}: cell {cell}, 2.2 r_max {by_radius}, (2/D)^⅓ {by_count}"
        );
        let lambda = f64::from(pop.density) * cell.powi(3);
        assert!(
            (f64::from(pop.mean_per_cell) / lambda - 1.0).abs() < 1e-6,
            "{label}"
        );

        let (hist, counts) = count_histogram(&pop);
        let n = n_cells() as f64;
        let expected: Vec<f64> = poisson_cells(lambda).iter().map(|p| p * n).collect();
        let chi = chi_square_pooled(&hist, &expected, 5.0);
        let total: u64 = counts.iter().map(|&c| u64::from(c)).sum();
        let z_total = (total as f64 - lambda * n) / (lambda * n).sqrt();
        println!(
            "{label}: λ {lambda:.3} per cell of {cell:.4}; χ² {:.1} on {} dof (p {:.3}); \
             total {total} vs {:.0} (z {z_total:.2})",
            chi.chi2,
            chi.dof,
            chi.p_value,
            lambda * n
        );
        assert!(
            chi.passes(a),
            "{label}: per-cell counts not Poisson({lambda}): {chi:?}"
        );
        assert!(
            z_total.abs() <= zl,
            "{label}: total {total} vs {} (z {z_total:.2})",
            lambda * n
        );

        // Neighbouring cells and another seed are uncorrelated.
        let counts: Vec<f64> = counts.iter().map(|&c| f64::from(c)).collect();
        let s = SIDE as usize;
        for (axis, stride) in [("x", 1usize), ("y", s), ("z", s * s)] {
            let pairs: Vec<(f64, f64)> = (0..counts.len())
                .filter(|&i| (i / stride) % s + 1 < s)
                .map(|i| (counts[i], counts[i + stride]))
                .collect();
            let (u, v): (Vec<f64>, Vec<f64>) = pairs.iter().copied().unzip();
            let z = correlation(&u, &v) * (u.len() as f64).sqrt();
            assert!(
                z.abs() <= zl,
                "{label}: counts correlate with the +{axis} neighbour (z {z:.2})"
            );
        }
        let other = Population {
            seed: pop.seed ^ 0x5eed,
            ..pop.clone()
        };
        let (_, counts2) = count_histogram(&other);
        let counts2: Vec<f64> = counts2.iter().map(|&c| f64::from(c)).collect();
        let z = correlation(&counts, &counts2) * n.sqrt();
        assert!(z.abs() <= zl, "{label}: two seeds correlate (z {z:.2})");

        // Negative control: a density 5 % too high.
        let wrong: Vec<f64> = poisson_cells(1.05 * lambda).iter().map(|p| p * n).collect();
        let chi_wrong = chi_square_pooled(&hist, &wrong, 5.0);
        let z_wrong = (total as f64 - 1.05 * lambda * n) / (1.05 * lambda * n).sqrt();
        assert!(
            !chi_wrong.passes(a),
            "{label}: 5 % too dense not rejected: {chi_wrong:?}"
        );
        assert!(
            z_wrong.abs() > zl,
            "{label}: 5 % too dense not rejected (z {z_wrong:.2})"
        );
    }
}

/// Radii are uniform in `[min, max]` and centres uniform in their whole cell (a stationary point
/// process: discs reach into the neighbouring cells, which the walk visits). Two populations
/// (D 3000, r 0.01–0.03: 54 000 platelets; D 500, r 0.05–0.1: 144 000): radius chi-square over 20
/// equal bins, centre chi-square over 8³ bins of `(x − cell corner)/cell` per axis (joint, so it
/// also tests the axes' independence), 4 tests at overall 0.01. `min == max` gives exactly that
/// radius. Negative controls: the radii against uniform on `[min, 1.05 max]`, and the centres
/// (large platelets) against uniform in the cell shrunk by the radius (an earlier generator that
/// kept each disc inside its cell, which left platelet-poor slabs at the cell faces).
#[test]
fn radii_and_centres_are_uniform() {
    let family = 4;
    let a = sidak_alpha(ALPHA, family);
    let pops = [
        (
            "D 3000, r 0.01–0.03",
            pop(3000.0, (0.01, 0.03), Orientation::Uniform, 21),
        ),
        (
            "D 500, r 0.05–0.1",
            pop(500.0, (0.05, 0.1), Orientation::Uniform, 22),
        ),
    ];
    for (label, pop) in &pops {
        let all = platelets(pop);
        let n = all.len() as f64;
        let (r0, r1) = (f64::from(pop.radius.0), f64::from(pop.radius.1));
        let cell = f64::from(pop.cell);
        let bins = 20;
        let mut hist = vec![0u64; bins + 1]; // the last: outside [min, max]
        let mut wrong_hist = vec![0u64; bins + 1];
        let nc = 8usize;
        let mut centre_hist = vec![0u64; nc * nc * nc + 1]; // the last: outside the shrunk cell
        let mut whole_hist = vec![0u64; nc * nc * nc + 1];
        for (c, p) in &all {
            let r = f64::from(p.radius);
            let u = (r - r0) / (r1 - r0);
            hist[if (0.0..=1.0).contains(&u) {
                ((u * bins as f64) as usize).min(bins - 1)
            } else {
                bins
            }] += 1;
            let uw = (r - r0) / (1.05 * r1 - r0);
            wrong_hist[((uw * bins as f64) as usize).min(bins)] += 1;
            let lo = DVec3::new(f64::from(c[0]), f64::from(c[1]), f64::from(c[2])) * cell;
            let centre = p.center.as_dvec3();
            let f = (centre - lo) / cell;
            let idx = |f: DVec3| {
                if f.min_element() >= -1e-4 && f.max_element() <= 1.0 + 1e-4 {
                    let b = (f * nc as f64)
                        .floor()
                        .clamp(DVec3::ZERO, DVec3::splat(nc as f64 - 1.0));
                    (b.x as usize * nc + b.y as usize) * nc + b.z as usize
                } else {
                    nc * nc * nc
                }
            };
            centre_hist[idx(f)] += 1;
            whole_hist[idx((centre - lo - r) / (cell - 2.0 * r))] += 1;
        }
        let mut expect = vec![n / bins as f64; bins];
        expect.push(0.0);
        let chi_r = chi_square_pooled(&hist, &expect, 5.0);
        let mut expect_c = vec![n / (nc * nc * nc) as f64; nc * nc * nc];
        expect_c.push(0.0);
        let chi_c = chi_square_pooled(&centre_hist, &expect_c, 5.0);
        println!(
            "{label}: {n} platelets; radius χ² {:.1}/{} (p {:.3}); centre χ² {:.1}/{} (p {:.3})",
            chi_r.chi2, chi_r.dof, chi_r.p_value, chi_c.chi2, chi_c.dof, chi_c.p_value
        );
        assert!(chi_r.passes(a), "{label}: radii not uniform: {chi_r:?}");
        assert!(
            chi_c.passes(a),
            "{label}: centres not uniform in the cell: {chi_c:?}"
        );
        // Negative controls.
        let mut wrong = vec![n / bins as f64; bins];
        wrong.push(0.0);
        assert!(
            !chi_square_pooled(&wrong_hist, &wrong, 5.0).passes(a),
            "{label}: radius range 5 % too wide not rejected"
        );
        if r1 / cell > 0.3 {
            let chi_w = chi_square_pooled(&whole_hist, &expect_c, 5.0);
            assert!(
                !chi_w.passes(a),
                "{label}: centres uniform in the shrunk cell not rejected: {chi_w:?}"
            );
        }
    }
    // min == max: every radius is exactly it.
    let fixed = pop(800.0, (0.04, 0.04), Orientation::Uniform, 23);
    let all = platelets(&fixed);
    assert!(all.len() > 10_000);
    assert!(
        all.iter().all(|(_, p)| p.radius == 0.04),
        "min == max gives other radii"
    );
}

/// Bin of a direction over `nz × nphi` equal-area cells of the sphere (`z` bands × azimuth).
fn sphere_bin(n: DVec3, nz: usize, nphi: usize) -> usize {
    let iz = (((n.z + 1.0) / 2.0 * nz as f64) as usize).min(nz - 1);
    let phi = n.y.atan2(n.x) + std::f64::consts::PI;
    let ip = ((phi / std::f64::consts::TAU * nphi as f64) as usize).min(nphi - 1);
    iz * nphi + ip
}

/// Chi-square of directions `ns` against the uniform cone of half-angle `spread` about `axis`:
/// `(1 − cos θ)/(1 − cos spread)` in 10 equal bins × azimuth about the axis in 16 (a frame built
/// here, not the generator's), and a cell of zero expectation outside the cone (1e-4 of slack).
fn cone_chi(ns: &[DVec3], axis: DVec3, spread: f64) -> super::common::ChiSquare {
    let (nu, nphi) = (10usize, 16usize);
    let a = axis.any_orthonormal_vector();
    let b = axis.cross(a);
    let width = 1.0 - spread.cos();
    let mut hist = vec![0u64; nu * nphi + 1];
    for &n in ns {
        // 1 − cos θ = |n − axis|²/2, accurate near the axis.
        let u = (n - axis).length_squared() / 2.0 / width;
        let k = if u <= 1.0 + 1e-4 {
            let iu = ((u * nu as f64) as usize).min(nu - 1);
            let phi = n.dot(b).atan2(n.dot(a)) + std::f64::consts::PI;
            let ip = ((phi / std::f64::consts::TAU * nphi as f64) as usize).min(nphi - 1);
            iu * nphi + ip
        } else {
            nu * nphi
        };
        hist[k] += 1;
    }
    let mut expected = vec![ns.len() as f64 / (nu * nphi) as f64; nu * nphi];
    expected.push(0.0);
    chi_square_pooled(&hist, &expected, 5.0)
}

/// Normals: `Uniform` over the sphere — the drawn normal over 10 × 20 equal-area cells, and the
/// disc's axis (the normal folded onto z ≥ 0, since a disc is two-sided) over the hemisphere's
/// 5 × 20 — and `Aligned` uniform in the cone (spreads 5°, 30°, 90° about the axis (1, 2, 2)/3:
/// `1 − cos θ` uniform over `[0, 1 − cos spread]`, the azimuth uniform; 10 × 16 cells, nothing
/// outside the cone). 54 000 platelets each (D 3000, r 0.01–0.03, 27 000 cells); 5 tests at overall
/// 0.01. Spread 0: every normal is the axis. Negative controls: the 10° cone against an 10.5°
/// one; a hemisphere (Aligned 90° about z) against the uniform sphere; a 80° cone about z, folded,
/// against uniform axes.
#[test]
fn normals_follow_the_orientation() {
    let family = 5;
    let a = sidak_alpha(ALPHA, family);
    let normals = |o: Orientation, seed: u64| -> Vec<DVec3> {
        platelets(&pop(3000.0, (0.01, 0.03), o, seed))
            .iter()
            .map(|(_, p)| p.normal.as_dvec3())
            .collect()
    };
    for n in normals(Orientation::Uniform, 31) {
        assert!((n.length() - 1.0).abs() < 1e-5, "normal {n} is not unit");
    }
    // Uniform: the normal over the sphere, the axis over the hemisphere.
    let uniform = normals(Orientation::Uniform, 31);
    let sphere = |ns: &[DVec3], fold: bool| {
        let (nz, nphi) = (if fold { 5 } else { 10 }, 20);
        let mut hist = vec![0u64; 2 * nz * nphi];
        for &n in ns {
            let n = if fold && n.z < 0.0 { -n } else { n };
            hist[sphere_bin(n, 2 * nz, nphi)] += 1;
        }
        // Folded, the lower half of the bands expects nothing.
        let cells = if fold { nz * nphi } else { 2 * nz * nphi };
        let expected: Vec<f64> = (0..2 * nz * nphi)
            .map(|k| {
                if fold && k < nz * nphi {
                    0.0
                } else {
                    ns.len() as f64 / cells as f64
                }
            })
            .collect();
        chi_square_pooled(&hist, &expected, 5.0)
    };
    let chi_full = sphere(&uniform, false);
    let chi_axis = sphere(&uniform, true);
    println!(
        "Uniform: {} normals; sphere χ² {:.1}/{} (p {:.3}); axes χ² {:.1}/{} (p {:.3})",
        uniform.len(),
        chi_full.chi2,
        chi_full.dof,
        chi_full.p_value,
        chi_axis.chi2,
        chi_axis.dof,
        chi_axis.p_value
    );
    assert!(chi_full.passes(a), "Uniform normals: {chi_full:?}");
    assert!(chi_axis.passes(a), "Uniform axes: {chi_axis:?}");
    // Aligned cones.
    let axis = Vec3::new(1.0, 2.0, 2.0) / 3.0;
    for deg in [5.0f32, 30.0, 90.0] {
        let spread = deg.to_radians();
        let ns = normals(Orientation::Aligned { axis, spread }, 32 + deg as u64);
        let chi = cone_chi(&ns, axis.as_dvec3(), f64::from(spread));
        println!(
            "Aligned {deg}°: χ² {:.1}/{} (p {:.3})",
            chi.chi2, chi.dof, chi.p_value
        );
        assert!(chi.passes(a), "Aligned {deg}°: {chi:?}");
    }
    // Spread 0: the axis itself.
    for n in normals(Orientation::Aligned { axis, spread: 0.0 }, 33) {
        assert!((n - axis.as_dvec3()).length() < 1e-6, "spread 0 gave {n}");
    }
    // Negative controls.
    let ten = normals(
        Orientation::Aligned {
            axis,
            spread: 10f32.to_radians(),
        },
        34,
    );
    assert!(
        cone_chi(&ten, axis.as_dvec3(), 10f64.to_radians()).passes(a),
        "the 10° cone itself"
    );
    let wrong = cone_chi(&ten, axis.as_dvec3(), 10.5f64.to_radians());
    assert!(!wrong.passes(a), "a 10° cone passed as 10.5°: {wrong:?}");
    let hemi = normals(
        Orientation::Aligned {
            axis: Vec3::Z,
            spread: 90f32.to_radians(),
        },
        35,
    );
    assert!(
        !sphere(&hemi, false).passes(a),
        "a hemisphere passed as the sphere"
    );
    let cone80 = normals(
        Orientation::Aligned {
            axis: Vec3::Z,
            spread: 80f32.to_radians(),
        },
        36,
    );
    assert!(
        !sphere(&cone80, true).passes(a),
        "an 80° cone passed as uniform axes"
    );
}

/// The recipe's fields arrive in the compiled body: density, radius, the orientation (spread in
/// degrees → radians, the axis normalised), the entries as cumulative weights over the platelet
/// materials (indexed after the body; a name listed twice is one material), an explicit seed kept,
/// a default seed that is deterministic, differs between populations and follows the recipe's
/// `seed`; the platelet materials are built under the body's IOR and the `platelets` effect is
/// called for.
#[test]
fn recipe_fields_arrive() {
    let body = |seed: &str| {
        format!(
            "(ior: 1.52, platelets: [
                (density: 3000.0, radius: (0.01, 0.03), orientation: Uniform,
                 entries: [(1.0, \"mirror\"), (3.0, \"copper\"), (0.5, \"mirror\"), (1.5, \"copper_smooth\")]),
                (density: 200.0, radius: (0.05, 0.05), orientation: Aligned(axis: (0.0, 3.0, 4.0), spread: 12.5),
                 entries: [(2.0, \"copper\")]{seed}),
                (density: 10.0, radius: (0.02, 0.04), orientation: Aligned(axis: (0.0, 0.0, -2.0)),
                 entries: [(1.0, \"mirror_rough\")]),
            ])"
        )
    };
    let text = gem(&body(", seed: 99"), "");
    let s = scene(&text);
    assert!(s.effects.called(Effect::Platelets));
    let b = s.surface.body.as_ref().expect("a body");
    let bi = s.surface.body_index();
    assert_eq!(b.platelets.len(), 3);
    let names: Vec<&str> = b
        .platelet_materials
        .iter()
        .map(|(n, _)| n.as_str())
        .collect();
    assert_eq!(names, ["mirror", "copper", "copper_smooth", "mirror_rough"]);
    for (n, m) in &b.platelet_materials {
        assert_eq!(m.outside_ior, 1.52, "{n} is not under the body's IOR");
    }
    let (p0, p1, p2) = (&b.platelets[0], &b.platelets[1], &b.platelets[2]);
    assert_eq!(
        (p0.density, p0.radius, p0.orientation),
        (3000.0, (0.01, 0.03), Orientation::Uniform)
    );
    let cumulative: Vec<f32> = p0.entries.iter().map(|e| e.0).collect();
    let want = [1.0 / 6.0, 4.0 / 6.0, 4.5 / 6.0, 1.0];
    assert!(
        cumulative
            .iter()
            .zip(want)
            .all(|(a, b)| (a - b).abs() < 1e-6),
        "{cumulative:?}"
    );
    let mats: Vec<u32> = p0.entries.iter().map(|e| e.1).collect();
    assert_eq!(mats, [bi + 1, bi + 2, bi + 1, bi + 3]);
    assert_eq!((p1.density, p1.radius, p1.seed), (200.0, (0.05, 0.05), 99));
    assert_eq!(p1.entries, vec![(1.0, bi + 2)]);
    match p1.orientation {
        Orientation::Aligned { axis, spread } => {
            assert!(
                (axis - Vec3::new(0.0, 0.6, 0.8)).length() < 1e-6,
                "axis {axis}"
            );
            assert!(
                (spread - 12.5f32.to_radians()).abs() < 1e-7,
                "spread {spread}"
            );
        }
        o => panic!("{o:?}"),
    }
    match p2.orientation {
        Orientation::Aligned { axis, spread } => {
            assert!(axis == Vec3::NEG_Z && spread == 0.0, "{axis} {spread}")
        }
        o => panic!("{o:?}"),
    }
    assert_eq!(p2.entries, vec![(1.0, bi + 4)]);
    // Seeds: deterministic, distinct per population, following the recipe's seed.
    let again = scene(&text);
    assert_eq!(again.surface.body.as_ref().unwrap().platelets, b.platelets);
    assert_ne!(p0.seed, p2.seed);
    let reseeded = scene(&text.replacen("(materials", "(seed: 5, materials", 1));
    let rb = &reseeded.surface.body.as_ref().unwrap().platelets;
    assert_ne!(rb[0].seed, p0.seed);
    assert_eq!(rb[1].seed, 99, "an explicit seed is kept");
    // The world's material table holds the faces after the body.
    let (_, world) = build(&text);
    for k in 1..=4 {
        assert!(
            world.materials[(bi + k) as usize].is_some(),
            "platelet material {k} missing"
        );
    }
    assert_eq!(world.platelets, b.platelets);
}

/// Entry weights give the material frequencies: the compiled population of
/// [`recipe_fields_arrive`] (weights mirror 1 + 0.5, copper 3, copper_smooth 1.5) over 27 000
/// cells (54 000 platelets), chi-square over the three materials at 0.01. Negative control: equal
/// weights are rejected.
#[test]
fn entry_weights_give_the_material_frequencies() {
    let s = scene(&gem(
        "(ior: 1.52, platelets: [(density: 3000.0, radius: (0.01, 0.03), orientation: Uniform,
          entries: [(1.0, \"mirror\"), (3.0, \"copper\"), (0.5, \"mirror\"), (1.5, \"copper_smooth\")])])",
        "",
    ));
    let bi = s.surface.body_index();
    let pop = &s.surface.body.as_ref().unwrap().platelets[0];
    let mut hist = vec![0u64; 4]; // mirror, copper, copper_smooth, anything else
    for (_, p) in platelets(pop) {
        let k = p.material.wrapping_sub(bi + 1) as usize;
        hist[k.min(3)] += 1;
    }
    let n: u64 = hist.iter().sum();
    let e = |w: f64| w / 6.0 * n as f64;
    let chi = chi_square_pooled(&hist, &[e(1.5), e(3.0), e(1.5), 0.0], 5.0);
    println!(
        "materials {hist:?} of {n}: χ² {:.2}/{} (p {:.3})",
        chi.chi2, chi.dof, chi.p_value
    );
    assert!(chi.passes(ALPHA), "{chi:?}");
    let equal = chi_square_pooled(&hist, &[e(2.0), e(2.0), e(2.0), 0.0], 5.0);
    assert!(
        !equal.passes(ALPHA),
        "equal weights not rejected: {equal:?}"
    );
}
