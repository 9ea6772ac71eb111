//! `lapidary tradeoff RECIPE`: what accuracy costs in time (docs/design.md §9). It renders a converged
//! reference (Reference model, exact Fresnel, deep paths, many samples; cached in the output
//! folder), then renders the recipe once per knob setting for a fixed time budget, capturing the
//! film at every power-of-two spp ([`crate::render::study`]). For each setting it reports the
//! time and the error (relMSE, HDR-FLIP, the stone's energy against the reference) at equal spp
//! and at equal time, prints a table, and writes `tradeoff.csv` (a row per setting),
//! `tradeoff-curves.csv` (a row per capture) and `tradeoff.png` (error against time, log-log,
//! one series per setting).

mod csv;
pub mod row;

use self::csv::{curves_csv, summary_csv, write_csv};
pub use self::row::Row;
use self::row::at_spp;
use super::knobs::KnobArgs;
use super::load::build_world;
use super::render::parse_size;
use crate::image::atomic::all_or_nothing;
use crate::image::outputs::{Format, OutputPlan};
use crate::image::{read_exr, write_exr};
use crate::render::study::{Convergence, Errors, Reference, converge};
use crate::render::world::Setup;
use crate::render::{Control, Metadata, exr_image, render_scene};
use crate::sampler::{SamplerKind, hash_words};
use crate::scene::{Knobs, Scene};
use anyhow::{Context, Result, anyhow};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The settings studied when none are given: the recipe as written, then one knob changed at a
/// time.
pub const DEFAULT_SETTINGS: [&str; 15] = [
    "baseline",
    "model=course",
    "model=reference",
    "fresnel=schlick",
    "fresnel=table",
    "t-term=on",
    "absorption=off",
    "bump=off",
    "sampler=independent",
    "max-depth=2",
    "max-depth=4",
    "max-depth=16",
    "model=course,fresnel=table",
    // RGB against spectral transport: one of the two is the recipe's own variant.
    "spectral=on",
    "spectral=off",
];

/// Arguments of `lapidary tradeoff`.
#[derive(Debug, Args)]
pub struct TradeoffArgs {
    /// Gem recipe (RON).
    pub recipe: PathBuf,
    /// Render time per setting in seconds: each setting renders until then (equal time).
    #[arg(long, default_value_t = 10.0, value_parser = parse_budget)]
    pub budget: f64,
    /// Image size `WxH` in pixels.
    #[arg(long, value_parser = parse_size, default_value = "160x120")]
    pub size: (u32, u32),
    /// Output folder: tables, plot, and the cached reference.
    #[arg(long, default_value = "tradeoff-out")]
    pub out: PathBuf,
    /// The equal-spp comparison point (a power of two ≥ 4).
    #[arg(long, default_value_t = 16, value_parser = parse_spp)]
    pub spp: u32,
    /// A knob setting `key=value,…` (repeatable; default: the built-in list, see the README).
    /// Keys: model, fresnel, distribution, masking, compensation, calibration, t-term, absorption,
    /// bump, sampler, max-depth, medium-depth, medium-scattering and any effect name.
    #[arg(long = "setting")]
    pub settings: Vec<String>,
    /// Samples per pixel of the reference.
    #[arg(long, default_value_t = 4096, value_parser = clap::value_parser!(u32).range(16..=1_048_576))]
    pub ref_spp: u32,
    /// Longest path of the reference, in scattering events.
    #[arg(long, default_value_t = 32, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub ref_depth: u32,
    /// Seed of the settings' pixel samples (the reference uses an unrelated one).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Worker threads (default: one per core).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    /// Knobs applied to the baseline before every setting (e.g. `--bump off`).
    #[command(flatten)]
    pub knobs: KnobArgs,
    /// No progress output.
    #[arg(short, long)]
    pub quiet: bool,
}

fn parse_budget(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if (0.05..=86_400.0).contains(&v) => Ok(v),
        _ => Err(format!("`{s}`: expected seconds in 0.05..=86400")),
    }
}

fn parse_spp(s: &str) -> Result<u32, String> {
    match s.parse::<u32>() {
        Ok(v) if (4..=1 << 20).contains(&v) && v.is_power_of_two() => Ok(v),
        _ => Err(format!("`{s}`: expected a power of two in 4..=1048576")),
    }
}

/// Least-squares intercept of `y = a x + b` over `(x, y)`; `None` for fewer than 3 points.
pub fn intercept(points: &[(f64, f64)]) -> Option<f64> {
    if points.len() < 3 {
        return None;
    }
    let n = points.len() as f64;
    let (sx, sy) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), p| (a + p.0, b + p.1));
    let (mx, my) = (sx / n, sy / n);
    let (sxx, sxy) = points.iter().fold((0.0, 0.0), |(a, b), p| {
        (a + (p.0 - mx) * (p.0 - mx), b + (p.0 - mx) * (p.1 - my))
    });
    if sxx <= 0.0 {
        return None;
    }
    Some(my - sxy / sxx * mx)
}

/// Runs `lapidary tradeoff`.
pub fn run(args: &TradeoffArgs) -> Result<()> {
    let labels: Vec<String> = if args.settings.is_empty() {
        DEFAULT_SETTINGS.iter().map(|s| s.to_string()).collect()
    } else {
        args.settings.clone()
    };
    let settings: Vec<Knobs> = labels
        .iter()
        .map(|l| {
            super::knobs::check_setting(l).map_err(|e| anyhow!("--setting `{l}`: {e}"))?;
            l.parse().map_err(|e| anyhow!("--setting `{l}`: {e}"))
        })
        .collect::<Result<_>>()?;
    let mut plan = OutputPlan::new();
    plan.input(&args.recipe, "the recipe")?;
    plan.folder(&args.out)?;
    let mut base = super::load::load_scene(
        &args.recipe,
        &args.knobs.accuracy().map_err(anyhow::Error::msg)?,
        Some(&mut plan),
    )?
    .scene;
    let (w, h) = args.size;
    base.stage.render.width = w;
    base.stage.render.height = h;
    base.stage.render.seed = args.seed;
    // Check every setting before the long renders.
    for (k, l) in settings.iter().zip(&labels) {
        k.apply(&mut base.clone(), "tradeoff")
            .map_err(|e| anyhow!("--setting `{l}`: {e}"))?;
    }
    let name = args
        .recipe
        .file_stem()
        .map_or("recipe".into(), |s| s.to_string_lossy().to_string());
    let (ref_scene, ref_name) = reference_scene(args, &base, &name)?;
    // Every output is checked before the first render.
    let ref_path = plan.output_in(&args.out, &ref_name, Format::Exr)?;
    let csv_path = plan.output_in(&args.out, "tradeoff.csv", Format::Csv)?;
    let curves_path = plan.output_in(&args.out, "tradeoff-curves.csv", Format::Csv)?;
    let plot = plan.output_in(&args.out, "tradeoff.png", Format::Png)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let threads = args.threads.map(|t| t as usize);

    let reference = reference(args, ref_scene, &ref_path, threads)?;
    let budget = Duration::from_secs_f64(args.budget);
    // Warm up (thread pool, caches, clock frequency) on the baseline, so the first setting is not
    // timed cold: unwarmed, it ran about 10 % slower than the same work later in the run.
    {
        let world = build_world(&args.recipe, &base, &Setup::default())?;
        converge(
            &world,
            &base,
            budget.min(Duration::from_secs(1)),
            1 << 20,
            threads,
        );
    }
    // The setup column is the cost of measuring each setting's tables, not of reading them back
    // from an earlier run (crate::bsdf::store).
    crate::bsdf::store::measure_always();
    let mut rows = Vec::with_capacity(settings.len());
    for (i, (knobs, label)) in settings.iter().zip(&labels).enumerate() {
        let mut scene = base.clone();
        knobs
            .apply(&mut scene, "tradeoff")
            .map_err(|e| anyhow!("--setting `{label}`: {e}"))?;
        let spinner = spinner(
            args.quiet,
            format!("[{}/{}] {label}", i + 1, settings.len()),
        );
        let t0 = Instant::now();
        let world = build_world(&args.recipe, &scene, &Setup::default())?;
        let setup = t0.elapsed().as_secs_f64();
        let conv = converge(&world, &scene, budget, 1 << 20, threads);
        spinner.finish_and_clear();
        rows.push(measure(label, setup, &conv, &reference));
    }
    let table = table(args, &rows, &reference);
    out!("{table}");
    // The three files together or none of them.
    all_or_nothing(|| {
        write_csv(&csv_path, &summary_csv(args.spp, args.budget, &rows))?;
        write_csv(&curves_path, &curves_csv(&rows))?;
        super::tradeoff_plot::plot(&name, &rows, reference.noise_floor(), &plot)
    })?;
    outln!(
        "wrote {}, {}, {}",
        args.out.join("tradeoff.csv").display(),
        args.out.join("tradeoff-curves.csv").display(),
        plot.display()
    );
    Ok(())
}

fn spinner(quiet: bool, msg: String) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let s = ProgressBar::new_spinner();
    s.set_style(
        ProgressStyle::with_template("{spinner} [{elapsed}] {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    s.set_message(msg);
    s.enable_steady_tick(Duration::from_millis(200));
    s
}

/// The reference's scene (Reference model, exact Fresnel, `--ref-depth`, `--ref-spp`,
/// independent sampler, a seed unrelated to the settings') and its cache file's name, a hash of
/// everything it depends on.
fn reference_scene(args: &TradeoffArgs, base: &Scene, name: &str) -> Result<(Scene, String)> {
    let mut scene = base.clone();
    let knobs: Knobs = "model=reference,fresnel=exact".parse()?;
    knobs.apply(&mut scene, "tradeoff reference")?;
    let r = &mut scene.stage.render;
    r.spp = args.ref_spp;
    r.max_depth = args.ref_depth;
    // Independent samples make the reference's variance an honest estimate of its error, which
    // the relMSE subtracts (see `study::Errors`).
    r.sampler = SamplerKind::Independent;
    r.seed = hash_words(&[args.seed, 0x07ef_5eed]);
    let key = hash_words(&[
        scene.hash,
        u64::from(r.width),
        u64::from(r.height),
        u64::from(r.spp),
        u64::from(r.max_depth),
        r.seed,
        hash_words(
            &scene
                .accuracy
                .to_string()
                .bytes()
                .map(u64::from)
                .collect::<Vec<_>>(),
        ),
        hash_words(
            &env!("CARGO_PKG_VERSION")
                .bytes()
                .map(u64::from)
                .collect::<Vec<_>>(),
        ),
    ]);
    Ok((scene, format!("{name}-reference-{key:016x}.exr")))
}

/// Loads the cached reference at `path` or renders `scene` and writes it there.
fn reference(
    args: &TradeoffArgs,
    scene: Scene,
    path: &Path,
    threads: Option<usize>,
) -> Result<Reference> {
    let r = &scene.stage.render;
    if let Ok(img) = read_exr(path)
        && let Ok(reference) = Reference::from_exr(&img)
        && (img.width, img.height) == (r.width, r.height)
    {
        if !args.quiet {
            eprintln!("reference: {} (cached)", path.display());
        }
        return Ok(reference);
    }
    let spinner = spinner(
        args.quiet,
        format!(
            "reference: {}×{}, {} spp, Reference model, depth {}",
            r.width, r.height, r.spp, r.max_depth
        ),
    );
    let world = build_world(&args.recipe, &scene, &Setup::default())?;
    let control = Control {
        threads,
        ..Control::default()
    };
    let rendered = render_scene(&world, &scene, &control);
    spinner.finish_and_clear();
    let meta = Metadata::of(&args.recipe.display().to_string(), &scene);
    let img = exr_image(&rendered, &meta);
    write_exr(path, &img).with_context(|| format!("writing {}", path.display()))?;
    if !args.quiet {
        eprintln!(
            "reference: {} ({:.1} s)",
            path.display(),
            rendered.stats.elapsed.as_secs_f64()
        );
    }
    Reference::from_exr(&img).map_err(|e| anyhow!(e))
}

fn measure(label: &str, setup: f64, conv: &Convergence, reference: &Reference) -> Row {
    let curve: Vec<(u32, f64, Errors)> = conv
        .snapshots
        .par_iter()
        .map(|s| (s.spp, s.seconds, reference.errors(&s.rgb)))
        .collect();
    let last = conv
        .last
        .as_ref()
        .map(|s| (s.spp, s.seconds, reference.errors(&s.rgb)));
    let secs = conv.stats.elapsed.as_secs_f64().max(1e-9);
    let fit: Vec<(f64, f64)> = conv
        .snapshots
        .iter()
        .zip(&curve)
        .filter(|(s, _)| s.spp >= 16)
        .map(|(s, c): (_, &(u32, f64, Errors))| (1.0 / f64::from(s.spp), c.2.rel_mse))
        .collect();
    Row {
        bias: intercept(&fit),
        label: label.to_string(),
        setup,
        paths_per_second: conv.stats.paths as f64 / secs,
        curve,
        last,
    }
}

fn cell(v: Option<f64>, fmt: fn(f64) -> String) -> String {
    v.filter(|v| v.is_finite()).map_or("—".to_string(), fmt)
}

fn table(args: &TradeoffArgs, rows: &[Row], reference: &Reference) -> String {
    let mut o = String::new();
    let _ = writeln!(
        o,
        "\n{}: {}×{}; equal spp = {} spp, equal time = {} s per setting; reference noise (relMSE) {:.2e}",
        args.recipe.display(),
        args.size.0,
        args.size.1,
        args.spp,
        args.budget,
        reference.noise_floor()
    );
    let _ = writeln!(
        o,
        "{:<28} {:>7} {:>8} | {:>8} {:>9} {:>7} {:>7} | {:>6} {:>9} {:>7} {:>7} | {:>9}",
        "setting",
        "setup s",
        "Mpath/s",
        "time s",
        "relMSE",
        "FLIP",
        "energy",
        "spp",
        "relMSE",
        "FLIP",
        "energy",
        "bias"
    );
    let sci = |v: f64| format!("{v:.2e}");
    let f3 = |v: f64| format!("{v:.3}");
    let f4 = |v: f64| format!("{v:.4}");
    for r in rows {
        let eq = at_spp(r, args.spp);
        let _ = writeln!(
            o,
            "{:<28} {:>7.2} {:>8.3} | {:>8} {:>9} {:>7} {:>7} | {:>6} {:>9} {:>7} {:>7} | {:>9}",
            r.label,
            r.setup,
            r.paths_per_second / 1e6,
            cell(eq.map(|e| e.0), f3),
            cell(eq.map(|e| e.1.rel_mse), sci),
            cell(eq.map(|e| e.1.flip), f4),
            cell(eq.map(|e| e.1.stone_ratio), f4),
            r.last.map_or("—".into(), |l| l.0.to_string()),
            cell(r.last.map(|l| l.2.rel_mse), sci),
            cell(r.last.map(|l| l.2.flip), f4),
            cell(r.last.map(|l| l.2.stone_ratio), f4),
            cell(r.bias, sci),
        );
    }
    let _ = writeln!(
        o,
        "(left: at {} spp and the time it took; right: after {} s. relMSE: against the true image, the \
         reference's noise subtracted; energy: the stone's luminance over the reference's; bias: the relMSE \
         left at infinite spp, from a fit a/spp + b)",
        args.spp, args.budget
    );
    o
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn intercept_of_a_line() {
        let pts: Vec<(f64, f64)> = [4.0, 8.0, 16.0, 32.0]
            .iter()
            .map(|s| (1.0 / s, 0.3 / s + 0.002))
            .collect();
        assert!((intercept(&pts).unwrap() - 0.002).abs() < 1e-12);
        assert_eq!(intercept(&pts[..2]), None);
    }

    #[test]
    fn default_settings_parse() {
        for s in DEFAULT_SETTINGS {
            assert!(s.parse::<Knobs>().is_ok(), "{s}");
            assert_eq!(super::super::knobs::check_setting(s), Ok(()), "{s}");
        }
        assert!(parse_spp("12").is_err() && parse_spp("2").is_err() && parse_spp("64").is_ok());
        assert!(parse_budget("0").is_err() && parse_budget("3.5").is_ok());
    }
}
