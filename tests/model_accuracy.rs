//! Directional albedo of every catalogue material under the Corrected model against the Reference
//! random walk, per channel (issue 16; the table in docs/materials.md).
//!
//! The albedo `∫ f cos dωi` at `wo = (θo, φ 0)` is the mean sample weight
//! ([`albedo_by_sampling`]), at θo = 0, 15, 30, 45, 60, 75, 80°. Corrected uses `CORRECTED_SAMPLES`
//! samples per cell; the Reference walk is noisier (its weight is a product of interface events
//! and Russian roulette), so it gets `REFERENCE_SAMPLES`. Both counts can be overridden with the
//! environment variables `LAPIDARY_ACC_CORRECTED` and `LAPIDARY_ACC_REFERENCE`. Seeds are fixed,
//! so the table is repeatable for a given commit.
//!
//! Print the markdown table (a few minutes in release on two cores):
//!
//! `cargo test --release --test model_accuracy -- --ignored --nocapture`

use lapidary::bsdf::measure::{Estimate, albedo_by_sampling, direction_deg};
use lapidary::bsdf::{LayeredBsdf, Model, ReferenceParams};
use lapidary::recipe::MaterialLibrary;
use lapidary::sampler::hash_words;
use rayon::prelude::*;

/// Viewing angles of the table, degrees.
const THETAS: [f32; 7] = [0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 80.0];
/// Default sample counts per cell.
const CORRECTED_SAMPLES: u64 = 200_000;
const REFERENCE_SAMPLES: u64 = 1_000_000;

fn count(var: &str, default: u64) -> u64 {
    std::env::var(var)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

/// One table cell: Corrected and Reference albedo at one material and angle.
struct Cell {
    corrected: Estimate,
    reference: Estimate,
}

fn build(lib: &MaterialLibrary, name: &str, model: Model) -> LayeredBsdf {
    lib.build(name, Some(model))
        .expect("catalogue material builds")
}

fn measure(lib: &MaterialLibrary, name: &str, index: u64, n_corr: u64, n_ref: u64) -> Vec<Cell> {
    let corrected = build(lib, name, Model::Corrected);
    let reference = build(lib, name, Model::Reference(ReferenceParams::default()));
    THETAS
        .iter()
        .enumerate()
        .map(|(a, &th)| {
            let wo = direction_deg(th, 0.0);
            Cell {
                corrected: albedo_by_sampling(
                    &corrected,
                    wo,
                    n_corr,
                    hash_words(&[index, a as u64, 1]),
                ),
                reference: albedo_by_sampling(
                    &reference,
                    wo,
                    n_ref,
                    hash_words(&[index, a as u64, 2]),
                ),
            }
        })
        .collect()
}

fn all_cells(n_corr: u64, n_ref: u64) -> Vec<(String, Vec<Cell>)> {
    let lib = MaterialLibrary::course();
    let names: Vec<String> = lib.names().map(str::to_string).collect();
    // One task per (material, angle) would balance better, but per material is simple and the
    // materials cost about the same.
    names
        .par_iter()
        .enumerate()
        .map(|(i, n)| (n.clone(), measure(&lib, n, i as u64, n_corr, n_ref)))
        .collect()
}

/// Corrected / Reference, and its standard error by first-order propagation.
fn ratio(c: &Estimate, r: &Estimate, ch: usize) -> (f32, f32) {
    let (mc, mr) = (c.mean[ch], r.mean[ch]);
    if mr.is_nan() || mr <= 0.0 {
        return (f32::NAN, f32::NAN);
    }
    let q = mc / mr;
    let rel = ((c.std_error[ch] / mc.max(1e-12)).powi(2) + (r.std_error[ch] / mr).powi(2)).sqrt();
    (q, q * rel)
}

#[test]
#[ignore = "several minutes; prints the docs/materials.md table"]
fn print_albedo_table() {
    let (n_corr, n_ref) = (
        count("LAPIDARY_ACC_CORRECTED", CORRECTED_SAMPLES),
        count("LAPIDARY_ACC_REFERENCE", REFERENCE_SAMPLES),
    );
    let rows = all_cells(n_corr, n_ref);
    let mut out = format!(
        "\nDirectional albedo by sampling: Corrected ({n_corr} samples) / Reference ({n_ref} \
         samples, default walk), ± one standard error; ratio = Corrected / Reference.\n\n\
         | material | θo | channel | Corrected | Reference | ratio |\n|---|---:|---|---:|---:|---:|\n"
    );
    let mut worst = Vec::new();
    for (name, cells) in &rows {
        let mut w = (1.0f32, 0.0f32, 0usize, 0.0f32);
        for (cell, &th) in cells.iter().zip(&THETAS) {
            for (ch, chn) in ["R", "G", "B"].iter().enumerate() {
                let (q, sq) = ratio(&cell.corrected, &cell.reference, ch);
                out += &format!(
                    "| {name} | {th:.0}° | {chn} | {:.4} ± {:.4} | {:.4} ± {:.4} | {q:.4} ± {sq:.4} |\n",
                    cell.corrected.mean[ch],
                    cell.corrected.std_error[ch],
                    cell.reference.mean[ch],
                    cell.reference.std_error[ch],
                );
                if (q - 1.0).abs() > (w.0 - 1.0).abs() {
                    w = (q, th, ch, sq);
                }
            }
        }
        worst.push((name.clone(), w));
    }
    out += "\nWorst ratio per material:\n\n| material | worst ratio | θo | channel |\n|---|---:|---:|---|\n";
    for (name, (q, th, ch, sq)) in &worst {
        out += &format!(
            "| {name} | {q:.4} ± {sq:.4} | {th:.0}° | {} |\n",
            ["R", "G", "B"][*ch]
        );
    }
    print!("{out}");
}
