//! The adding solution of a stack (`lapidary::bsdf::layered::adding`, issue 16): a deterministic
//! directional albedo over 64 bins of `cos² θ` that should equal what the Reference random walk
//! measures, and that the Corrected model is calibrated to.
//!
//! 1. **Against the walk** (`adding_matches_the_walk_for_the_catalogue`): every catalogue material,
//!    built under Corrected (as the calibration builds it), at θo = 0, 30, 60, 80°, every channel:
//!    the adding albedo at the exact `cos θo` ([`adding::Solution::albedo`] with the table's
//!    24² · 4 first-event samples) and the table [`adding::albedo`] interpolated at `cos θo` must
//!    both satisfy `|adding − walk| ≤ 4σ_walk + 0.006·walk`, `walk` the mean weight of
//!    [`WALK_SAMPLES`] Reference walks (`Model::Reference(ReferenceParams::default())`,
//!    `albedo_by_sampling`, fixed seeds) and `σ_walk` its standard error. The relative allowance is
//!    for what is not the walk's noise: the binning over `cos² θ` (a near-specular chain keeps its
//!    exact angle in the walk but is spread over its bin here), the Monte Carlo estimate of each
//!    operator's columns (1 024 stratified samples per bin), the first event's 2 304 samples and
//!    the table's interpolation, stated by src/bsdf/layered/adding.rs as ≲ 0.5 %. 132 comparisons
//!    (11 materials × 4 angles × 3 channels; some channels are identical, which only makes the
//!    family smaller): two-sided 4σ has per-comparison false-alarm probability 6.33e-5,
//!    family-wise (Šidák) 0.83 % — an upper bound, the relative allowance makes it smaller.
//!    Measured at 100 000 walks: all pass, largest |z| 4.4 (gold_car_paint 0° R, −0.71 %). At
//!    1 000 000 (`--ignored`) **brass at θo 60° fails**: adding 0.55408 against the walk's
//!    0.55915 ± 0.00030 in R (−0.91 %, 17σ; G −0.87 %), and gold_car_paint at 0° is −0.67 % (R)
//!    and −0.84 % (G) at 13σ and 6.5σ — near-specular coats (m 1°) over glossy metals, where the
//!    binning of near-specular chains is the approximation src/bsdf/layered/adding.rs names.
//!    Negative control: the adding albedo of `sugar` with its base albedo lowered from 0.8 to 0.75
//!    fails the same comparison against the walk of the true `sugar` in all 12 cells
//!    (`a_wrong_base_albedo_is_rejected`).
//! 2. **Closed form** (`smooth_coat_over_lambert_matches_the_closed_form`): a smooth coat
//!    (m = 0.01°, the smallest `validate` accepts) of η 1.5 and 2.0 with optical depths 0, 0.5, 2
//!    (one per channel) over a Lambert base of albedo 0.2, 0.8, 1.0: every table entry of
//!    `adding::albedo` against `F(μo) + (1 − F(μo)) τ(μ'o) ρ E_out / (1 − ρ E_back)` (the closed
//!    form of tests/reference_closed_form.rs, whose f64 quadrature is copied to
//!    tests/adding/closed_form.rs) within `0.005·closed + 1e-3`. Deterministic. Measured: worst
//!    |Δ| 6.5e-4 (at the grazing entry, cos θ = 1e-3), worst relative 0.20 %, over 1 152 entries.
//!    Negative control (`closed_form_rejects_a_wrong_base_albedo`): a base albedo of 0.75 against
//!    the closed form of 0.8, and the other way round, fails at 117 and 118 of 192 entries.
//! 3. **Energy** (`white_lambert_under_a_clear_rough_coat_keeps_its_energy`): a white Lambert under
//!    a clear rough coat (η 1.5, m 20°; η 1.3, m 30°) with compensation on reflects everything:
//!    every table entry with `cos θ ≥ 0.1` within 0.5 % of 1 (the interface's single-scattering
//!    tables, from 4 096 samples per entry, carry ~0.2 % rms, and the lobe returns exactly
//!    `1 − E` of them; measured worst 0.36 % and 0.39 %; it was 0.65 % and 1.0 % with 1 024
//!    samples per entry and a 2 304-sample first event). Negative control
//!    (`an_uncompensated_coat_fails_the_energy_check`): with compensation off (no
//!    multiple-scattering lobe at the interface) the same check fails (19 % lost).
//!
//! Runtime ≈ 17 s of CPU in the test profile (`cargo test --test adding -- --nocapture` prints the
//! tables). Full version of item 1 with 1 000 000 walks per cell (≈ 70 s of CPU):
//! `cargo test --release --test adding -- --ignored --nocapture`.

use closed_form::{closed_form, coat_over_lambert};
use lapidary::bsdf::layered::adding;
use lapidary::bsdf::measure::{Estimate, albedo_by_sampling, direction_deg};
use lapidary::bsdf::table::{ENTRIES, entry_cos};
use lapidary::bsdf::{Base, LayeredBsdf, Model, ReferenceParams};
use lapidary::color::Rgb;
use lapidary::recipe::MaterialLibrary;
use lapidary::sampler::hash_words;
use lapidary::spectrum::RgbSample;
use rayon::prelude::*;
use std::sync::OnceLock;

#[path = "adding/closed_form.rs"]
mod closed_form;

/// Viewing angles of item 1, degrees.
const ANGLES: [f32; 4] = [0.0, 30.0, 60.0, 80.0];
/// Reference walks per cell (CI) and in the `--ignored` run.
const WALK_SAMPLES: u64 = 100_000;
const WALK_SAMPLES_FULL: u64 = 1_000_000;
/// Standard errors of the walk allowed (two-sided p = 6.33e-5 per comparison).
const Z: f64 = 4.0;
/// Relative allowance for binning and the operators' Monte Carlo (module docs).
const REL_WALK: f64 = 0.006;
/// First-event grid of the exact-angle adding solution (as `adding::albedo` uses).
const FIRST_EVENT_GRID: usize = 24;

// ---------------------------------------------------------------------------------------------
// 1. Against the Reference walk.

/// One (material, angle) comparison.
struct Cell {
    theta: f32,
    /// `Solution::albedo` at the exact `cos θo`.
    exact: RgbSample,
    /// `adding::albedo` interpolated at `cos θo`.
    table: RgbSample,
    walk: Estimate,
}

impl Cell {
    fn passes(&self, ch: usize, value: RgbSample) -> bool {
        let w = f64::from(self.walk.mean[ch]);
        (f64::from(value[ch]) - w).abs()
            <= Z * f64::from(self.walk.std_error[ch]) + REL_WALK * w.abs()
    }
}

fn walk_seed(material: &str, theta: f32, n: u64) -> u64 {
    let mut words: Vec<u64> = material.bytes().map(u64::from).collect();
    words.extend([u64::from(theta.to_bits()), n, 0xadda1]);
    hash_words(&words)
}

/// Adding solution and walk of every catalogue material at every angle of [`ANGLES`].
fn catalogue(n: u64) -> Vec<(String, Vec<Cell>)> {
    let lib = MaterialLibrary::course();
    let names: Vec<String> = lib.names().map(str::to_string).collect();
    let stacks: Vec<(LayeredBsdf, LayeredBsdf)> = names
        .par_iter()
        .map(|name| {
            let corrected = lib
                .build(name, Some(Model::Corrected))
                .expect("catalogue material builds");
            let reference = corrected.with_model(Model::Reference(ReferenceParams::default()));
            (corrected, reference)
        })
        .collect();
    let additions: Vec<Vec<(RgbSample, RgbSample)>> = stacks
        .par_iter()
        .map(|(corrected, _)| {
            let table = adding::albedo(corrected);
            let solution = adding::Solution::new(corrected);
            ANGLES
                .iter()
                .map(|&th| {
                    let mu = direction_deg(th, 0.0).z;
                    (solution.albedo(mu, FIRST_EVENT_GRID), table.at(mu))
                })
                .collect()
        })
        .collect();
    let jobs: Vec<(usize, usize)> = (0..names.len())
        .flat_map(|m| (0..ANGLES.len()).map(move |a| (m, a)))
        .collect();
    let walks: Vec<Estimate> = jobs
        .par_iter()
        .map(|&(m, a)| {
            let wo = direction_deg(ANGLES[a], 0.0);
            albedo_by_sampling(&stacks[m].1, wo, n, walk_seed(&names[m], ANGLES[a], n))
        })
        .collect();
    let mut walks = walks.into_iter();
    names
        .into_iter()
        .zip(additions)
        .map(|(name, adds)| {
            let cells = ANGLES
                .iter()
                .zip(adds)
                .map(|(&theta, (exact, table))| Cell {
                    theta,
                    exact,
                    table,
                    walk: walks.next().expect("one walk per cell"),
                })
                .collect();
            (name, cells)
        })
        .collect()
}

/// Prints the table of item 1 and returns the failures.
fn report(rows: &[(String, Vec<Cell>)]) -> Vec<String> {
    let mut out = format!(
        "\nadding albedo vs Reference walk ({} walks per cell), per channel; Δ = adding − walk\n\
         {:<24} {:>3} {:>2} {:>17} {:>8} {:>8} {:>8} {:>6} {:>8} {:>6} {:>8}\n",
        rows.first().map_or(0, |r| r.1[0].walk.samples),
        "material",
        "θo",
        "ch",
        "walk ± σ",
        "adding",
        "table",
        "Δ",
        "z",
        "Δ/walk",
        "allow",
        "Δtab/w"
    );
    let mut failures = Vec::new();
    let (mut worst_rel, mut worst_z) = ((0.0f64, String::new()), (0.0f64, String::new()));
    for (name, cells) in rows {
        for c in cells {
            for ch in 0..3 {
                let (w, se) = (f64::from(c.walk.mean[ch]), f64::from(c.walk.std_error[ch]));
                let (a, t) = (f64::from(c.exact[ch]), f64::from(c.table[ch]));
                let allow = Z * se + REL_WALK * w;
                let where_ = format!("{name} θo {}° ch {ch}", c.theta);
                out += &format!(
                    "{name:<24} {:>3.0} {ch:>2} {:>17} {a:>8.5} {t:>8.5} {:>8.5} {:>6.2} {:>7.2}% {:>6.4} {:>7.2}%\n",
                    c.theta,
                    format!("{w:.5} ± {se:.5}"),
                    a - w,
                    (a - w) / se.max(1e-12),
                    100.0 * (a - w) / w.max(1e-12),
                    allow,
                    100.0 * (t - w) / w.max(1e-12),
                );
                let rel = (a - w).abs() / w.max(1e-12);
                if rel > worst_rel.0 {
                    worst_rel = (rel, where_.clone());
                }
                let z = (a - w).abs() / se.max(1e-12);
                if z > worst_z.0 {
                    worst_z = (z, where_.clone());
                }
                for (what, v) in [("adding", c.exact), ("table", c.table)] {
                    if !c.passes(ch, v) {
                        failures.push(format!(
                            "{where_}: {what} {:.5} vs walk {w:.5} ± {se:.5} (allowance {allow:.5})",
                            v[ch]
                        ));
                    }
                }
            }
        }
    }
    out += &format!(
        "worst |Δ|/walk {:.3}% ({}); worst |Δ|/σ {:.2} ({}); {} failures\n",
        100.0 * worst_rel.0,
        worst_rel.1,
        worst_z.0,
        worst_z.1,
        failures.len()
    );
    print!("{out}");
    failures
}

fn ci_rows() -> &'static [(String, Vec<Cell>)] {
    static ROWS: OnceLock<Vec<(String, Vec<Cell>)>> = OnceLock::new();
    ROWS.get_or_init(|| catalogue(WALK_SAMPLES))
}

#[test]
fn adding_matches_the_walk_for_the_catalogue() {
    let rows = ci_rows();
    assert_eq!(rows.len(), 11, "the catalogue has 11 materials");
    let failures = report(rows);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Item 1 with [`WALK_SAMPLES_FULL`] walks per cell:
/// `cargo test --release --test adding -- --ignored --nocapture`.
#[test]
#[ignore = "slow: cargo test --release --test adding -- --ignored --nocapture"]
fn adding_matches_the_walk_for_the_catalogue_full() {
    let failures = report(&catalogue(WALK_SAMPLES_FULL));
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Negative control of item 1: `sugar`'s base albedo 0.8 lowered to 0.75 in the adding solution
/// is rejected against the walk of the true material (at least three of its 12 cells fail).
#[test]
fn a_wrong_base_albedo_is_rejected() {
    let rows = ci_rows();
    let (_, cells) = rows
        .iter()
        .find(|(n, _)| n == "sugar")
        .expect("sugar is in the catalogue");
    let lib = MaterialLibrary::course();
    let mut desc = lib
        .stack("sugar")
        .expect("sugar")
        .with_model(Model::Corrected);
    let Base::OrenNayar { albedo, sigma } = desc.base else {
        panic!("sugar has an Oren–Nayar base: {:?}", desc.base);
    };
    assert_eq!(albedo, Rgb::splat(0.8));
    desc.base = Base::OrenNayar {
        albedo: Rgb::splat(0.75),
        sigma,
    };
    let wrong = LayeredBsdf::new(&desc).expect("valid stack");
    let solution = adding::Solution::new(&wrong);
    let mut rejected = 0;
    for c in cells {
        let v = solution.albedo(direction_deg(c.theta, 0.0).z, FIRST_EVENT_GRID);
        for ch in 0..3 {
            let ok = c.passes(ch, v);
            println!(
                "sugar with ρ 0.75: θo {}° ch {ch}: adding {:.5} vs walk of ρ 0.8 {:.5} ± {:.5}: {}",
                c.theta,
                v[ch],
                c.walk.mean[ch],
                c.walk.std_error[ch],
                if ok { "accepted" } else { "rejected" }
            );
            rejected += usize::from(!ok);
            // The control itself is sound: the true material passes in the same cells.
            assert!(c.passes(ch, c.exact), "sugar θo {} ch {ch}", c.theta);
        }
    }
    assert!(
        rejected >= 3,
        "a 6 % lower base albedo passes the comparison: only {rejected} of 12 rejected"
    );
}

// ---------------------------------------------------------------------------------------------
// 2. The closed form for a smooth coat over Lambert (f64 quadrature copied from
//    tests/reference_closed_form.rs; see there for the derivation).

/// Smallest roughness `validate` accepts, degrees.
const M_SMOOTH: f32 = 0.01;
/// Optical depth per channel (absorption at thickness 1).
const OD: [f32; 3] = [0.0, 0.5, 2.0];
/// Allowance of item 2: relative and absolute.
const REL_CLOSED: f64 = 0.005;
const ABS_CLOSED: f64 = 1e-3;

/// Table entries of `adding::albedo` for a smooth coat with base albedo `rho_stack` compared
/// with the closed form for `rho_closed`: `(entries × channels, failures, worst |Δ|, worst
/// |Δ|/closed, the rows printed)`.
fn compare_closed(eta: f32, rho_stack: f32, rho_closed: f32) -> (usize, usize, f64, f64, String) {
    let stack = coat_over_lambert(
        eta,
        M_SMOOTH,
        Rgb::new(OD[0], OD[1], OD[2]),
        rho_stack,
        true,
    );
    let table = adding::albedo(&stack);
    let (mut k, mut fails, mut worst, mut worst_rel) = (0, 0, 0.0f64, 0.0f64);
    let mut out = String::new();
    for (i, v) in table.values().iter().enumerate() {
        let mu = f64::from(entry_cos(i));
        let mut line = format!("{eta:>4} {rho_stack:>4} {mu:>6.4}");
        for (ch, &od) in OD.iter().enumerate() {
            let cf = closed_form(f64::from(eta), f64::from(od), f64::from(rho_closed), mu);
            let d = f64::from(v[ch]) - cf;
            k += 1;
            worst = worst.max(d.abs());
            worst_rel = worst_rel.max(d.abs() / cf);
            let ok = d.abs() <= REL_CLOSED * cf + ABS_CLOSED;
            fails += usize::from(!ok);
            line += &format!(
                " | {:>8.5} {cf:>8.5} {d:>9.2e}{}",
                v[ch],
                if ok { " " } else { "!" }
            );
        }
        if i % 7 == 0 || i == ENTRIES - 1 {
            out += &line;
            out.push('\n');
        }
    }
    (k, fails, worst, worst_rel, out)
}

#[test]
fn smooth_coat_over_lambert_matches_the_closed_form() {
    let cases: Vec<(f32, f32)> = [1.5f32, 2.0]
        .iter()
        .flat_map(|&eta| [0.2f32, 0.8, 1.0].map(|rho| (eta, rho)))
        .collect();
    let results: Vec<_> = cases
        .par_iter()
        .map(|&(eta, rho)| compare_closed(eta, rho, rho))
        .collect();
    println!(
        "\nadding vs closed form, smooth coat (m {M_SMOOTH}°) over Lambert, every 7th table entry \
         ('!' = outside {REL_CLOSED}·closed + {ABS_CLOSED})\n{:>4} {:>4} {:>6} | od {} adding, closed, Δ | od {} | od {}",
        "η", "ρ", "cos θo", OD[0], OD[1], OD[2]
    );
    let mut failures = Vec::new();
    let (mut worst, mut worst_rel) = (0.0f64, 0.0f64);
    for (&(eta, rho), (k, fails, w, wr, out)) in cases.iter().zip(&results) {
        print!("{out}");
        worst = worst.max(*w);
        worst_rel = worst_rel.max(*wr);
        if *fails > 0 {
            failures.push(format!("η {eta} ρ {rho}: {fails} of {k} entries fail"));
        }
    }
    println!(
        "worst |adding − closed| {worst:.2e}, worst relative {:.3}% over {} entries",
        100.0 * worst_rel,
        cases.len() * ENTRIES * 3
    );
    // The copied quadrature: lossless coats return everything.
    for eta in [1.5, 2.0] {
        for mu in [0.05, 0.5, 1.0] {
            assert!((closed_form(eta, 0.0, 1.0, mu) - 1.0).abs() < 1e-12);
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Negative control of item 2: a base albedo of 0.75 against the closed form of 0.8, and 0.8
/// against 0.75, fails at most entries.
#[test]
fn closed_form_rejects_a_wrong_base_albedo() {
    for (stack, closed) in [(0.75f32, 0.8f32), (0.8, 0.75)] {
        let (k, fails, worst, _, _) = compare_closed(1.5, stack, closed);
        println!(
            "η 1.5, adding of ρ {stack} vs closed form of ρ {closed}: {fails} of {k} entries \
             rejected, worst |Δ| {worst:.4}"
        );
        assert!(
            fails >= k / 2,
            "ρ {stack} vs {closed}: only {fails} of {k} entries rejected"
        );
    }
}

// ---------------------------------------------------------------------------------------------
// 3. Energy.

/// Allowance of item 3 and the smallest `cos θ` it applies at.
const ENERGY_TOL: f64 = 0.005;
const ENERGY_MIN_COS: f32 = 0.1;
/// First-event grid of the diagnostic column: 16× the samples of `adding::albedo`.
const FINE_GRID: usize = 96;

/// The white furnace of item 3 over the entries with `cos θ ≥ 0.1`: `(worst |E − 1| of the table,
/// its cos θ, worst |E − 1| of `Solution::albedo(μ, 96)`, worst |table − Solution(μ, 96)|)`.
fn white_furnace(eta: f32, m: f32, compensation: bool) -> (f64, f32, f64, f64) {
    let stack = coat_over_lambert(eta, m, Rgb::ZERO, 1.0, compensation);
    let table = adding::albedo(&stack);
    let solution = adding::Solution::new(&stack);
    let (mut worst, mut at, mut worst_fine, mut first_event) = (0.0f64, 0.0f32, 0.0f64, 0.0f64);
    for (i, v) in table.values().iter().enumerate() {
        let mu = entry_cos(i);
        if mu < ENERGY_MIN_COS {
            continue;
        }
        let fine = if compensation {
            solution.albedo(mu, FINE_GRID)
        } else {
            *v
        };
        for ch in 0..3 {
            let d = (f64::from(v[ch]) - 1.0).abs();
            if d > worst {
                (worst, at) = (d, mu);
            }
            worst_fine = worst_fine.max((f64::from(fine[ch]) - 1.0).abs());
            first_event = first_event.max(f64::from((v[ch] - fine[ch]).abs()));
        }
    }
    (worst, at, worst_fine, first_event)
}

/// Item 3 (module docs). The message also reports the first event's share of the error: the
/// worst |E − 1| with a 16× finer first event, and the first-event noise of the table itself.
#[test]
fn white_lambert_under_a_clear_rough_coat_keeps_its_energy() {
    println!(
        "\nwhite Lambert under a clear rough coat, compensation on: adding albedo at the entries \
         with cos θ ≥ {ENERGY_MIN_COS}"
    );
    let mut failures = Vec::new();
    for (eta, m) in [(1.5f32, 20.0f32), (1.3, 30.0)] {
        let (worst, at, fine, first_event) = white_furnace(eta, m, true);
        let line = format!(
            "η {eta} m {m}°: worst |E − 1| {worst:.2e} at cos θ {at:.3}; with the first event \
             from {FINE_GRID}² · 4 samples: {fine:.2e}; first-event noise of the table (|table − \
             fine|) up to {first_event:.2e}"
        );
        println!("{line}");
        if worst > ENERGY_TOL {
            failures.push(line);
        }
    }
    assert!(
        failures.is_empty(),
        "|E − 1| > {ENERGY_TOL} (the rest with the fine first event is the interface tables' \
         noise):\n{}",
        failures.join("\n")
    );
}

/// Negative control of item 3: without the interface's multiple-scattering lobe the same stacks
/// lose energy (measured: 19 % at η 1.5, m 20°).
#[test]
fn an_uncompensated_coat_fails_the_energy_check() {
    for (eta, m) in [(1.5f32, 20.0f32), (1.3, 30.0)] {
        let (worst, at, _, _) = white_furnace(eta, m, false);
        println!("η {eta} m {m}°, compensation off: worst |E − 1| {worst:.3} at cos θ {at:.3}");
        assert!(
            worst > ENERGY_TOL,
            "η {eta} m {m}°: compensation off also passes ({worst}): the check has no power"
        );
    }
}
