//! `lapidary compare TEST.exr REF.exr [--heatmap diff.png]`: regression check of a render against
//! a reference (docs/design.md §10). Prints one line per metric and a verdict; the rules are those of
//! [`mod@crate::image::compare`]: the per-pixel z-test, the aggregate test at each tile scale
//! (one line per scale: tiles, largest |z|, limit, verdict) and the mean ratio. Exit status: 0
//! pass, 1 fail, 2 unusable input (a missing or unreadable file, sizes that differ, a missing
//! colour channel, a NaN, infinite or negative variance) or an unwritable heatmap.

use crate::image::compare::{
    AGGREGATE_ALPHA, CompareError, Comparison, MEAN_TOLERANCE, Options, REL_MSE_THRESHOLD, Rgb,
    Role, Scale, TestVariance, ZTest, compare_with,
};
use crate::image::{read_exr, write_heatmap};
use anyhow::{Result, anyhow};
use clap::Args;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Arguments of `lapidary compare`.
#[derive(Debug, Args)]
pub struct CompareArgs {
    /// The render under test (EXR with R, G, B or Y; `variance.*` and `samples.Y` used if present).
    pub test: PathBuf,
    /// The reference render (EXR; its `variance.R/G/B` enable the per-pixel z-test).
    pub reference: PathBuf,
    /// Write a false-colour error map (viridis PNG; yellow = failing, white = NaN/∞, magenta
    /// outline = the worst tile of a failed aggregate scale) here.
    #[arg(long, value_name = "PATH")]
    pub heatmap: Option<PathBuf>,
    /// Largest |mean_t/mean_r − 1| of a channel that passes when the z-tests cannot run (no
    /// variance): a fraction in [0, 1].
    #[arg(long, value_name = "FRACTION", default_value_t = MEAN_TOLERANCE,
          value_parser = parse_mean_tolerance)]
    pub mean_tolerance: f64,
}

/// Parses `--mean-tolerance`: a fraction in `[0, 1]` (0.005 is 0.5 %).
pub fn parse_mean_tolerance(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if (0.0..=1.0).contains(&v) => Ok(v),
        _ => Err(format!(
            "`{s}` is not a fraction in [0, 1] (e.g. 0.005 for 0.5 %)"
        )),
    }
}

/// The outcome of `lapidary compare`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// The test matches the reference (exit 0).
    Pass,
    /// It does not (exit 1).
    Fail,
}

/// Runs `lapidary compare`, printing the report on stdout. An error means unusable input (or an
/// unwritable heatmap), for exit status 2; its message names the file.
pub fn run(args: &CompareArgs) -> Result<Verdict> {
    let heatmap = match &args.heatmap {
        Some(path) => {
            let mut plan = crate::image::outputs::OutputPlan::new();
            plan.input(&args.test, "the test image")?;
            plan.input(&args.reference, "the reference")?;
            Some(plan.output(path, crate::image::outputs::Format::Png)?)
        }
        None => None,
    };
    let test = read_exr(&args.test)?;
    let reference = read_exr(&args.reference)?;
    let options = Options {
        mean_tolerance: args.mean_tolerance,
    };
    let c = compare_with(&test, &reference, &options).map_err(|e| describe(args, e))?;
    out!("{}", report(&args.test, &args.reference, &c));
    if let (Some(path), Some(file)) = (&args.heatmap, &heatmap) {
        write_heatmap(file, &c)?;
        let top = match &c.ztest {
            Some(z) => format!("|z| ≥ {:.2}", z.z_crit),
            None => format!("relative error ≥ {}", c.error_scale),
        };
        outln!(
            "  heatmap   {} (viridis, yellow = {top}, white = NaN/∞, magenta = worst failing tile)",
            path.display()
        );
    }
    let verdict = if c.passed {
        Verdict::Pass
    } else {
        Verdict::Fail
    };
    outln!("  verdict   {}", verdict_line(&c));
    Ok(verdict)
}

/// A comparison error with the file it concerns named.
fn describe(args: &CompareArgs, e: CompareError) -> anyhow::Error {
    let path = |role| match role {
        Role::Test => args.test.display(),
        Role::Reference => args.reference.display(),
    };
    match e {
        CompareError::SizeMismatch { test, reference } => anyhow!(
            "{} is {}x{} but {} is {}x{}: sizes differ",
            path(Role::Test),
            test.0,
            test.1,
            path(Role::Reference),
            reference.0,
            reference.1
        ),
        CompareError::MissingChannel {
            which,
            channel,
            found,
        } => anyhow!(
            "{}: no channel `{channel}` (R, G, B or Y needed); the file has: {}",
            path(which),
            if found.is_empty() {
                "no channels".to_string()
            } else {
                found.join(", ")
            }
        ),
        CompareError::BadVariance {
            which,
            channel,
            x,
            y,
            value,
            count,
        } => anyhow!(
            "{}: `{channel}` is {value} at pixel ({x}, {y}) ({count} such values); a variance \
             must be finite and ≥ 0, so the file's error estimate cannot be used",
            path(which)
        ),
        e @ CompareError::BadTolerance(_) => e.into(),
        CompareError::Empty => anyhow!(
            "{} and {}: the images have no pixels",
            path(Role::Test),
            path(Role::Reference)
        ),
        CompareError::Image(e) => e.into(),
    }
}

/// The metric lines (everything but the heatmap and verdict lines).
fn report(test: &Path, reference: &Path, c: &Comparison) -> String {
    let mut out = format!(
        "{} vs {} ({}x{})\n",
        test.display(),
        reference.display(),
        c.width,
        c.height
    );
    let psnr = if c.psnr == f64::INFINITY {
        "inf dB (identical)".to_string()
    } else {
        format!("{:.1} dB (peak {:.3e})", c.psnr, c.peak)
    };
    let _ = writeln!(out, "  RMSE      {:.3e}", c.rmse);
    let _ = writeln!(out, "  relMSE    {:.3e}", c.rel_mse);
    let _ = writeln!(out, "  MAE       {:.3e}", c.mae);
    let _ = writeln!(out, "  PSNR      {psnr}");
    let _ = writeln!(out, "  FLIP      {:.4} (HDR-FLIP mean, 67 px/°)", c.flip);
    if c.non_finite_pixels > 0 {
        let _ = writeln!(
            out,
            "  NaN/inf   {} pixels (counted as failures, left out of the metrics)",
            c.non_finite_pixels
        );
    }
    match (&c.ztest, &c.ztest_skipped) {
        (Some(z), _) => {
            let _ = write!(
                out,
                "  z-test    {:.2}% of {} pixels pass (need {:.2}%), |z| max {:.3}, limit {:.2} \
                 (α {}, Šidák over {} channels)",
                100.0 * z.pass_fraction,
                z.pixels,
                100.0 * z.required_fraction,
                z.max_abs_z,
                z.z_crit,
                z.alpha,
                z.tested_channels
            );
            if z.test_variance == TestVariance::ScaledFromReference {
                out += "; test variance = reference's × n_ref/n_test";
            }
            out.push('\n');
            let _ = writeln!(
                out,
                "  bias      mean difference per tile or material, α {} shared by {} scales (Šidák):",
                AGGREGATE_ALPHA,
                z.scales.len()
            );
            out += &scale_lines(z);
        }
        (None, why) => {
            let why = why.as_deref().unwrap_or("no variance");
            let _ = writeln!(
                out,
                "  z-test    skipped: {why}; verdict from relMSE ≤ {REL_MSE_THRESHOLD:e} and the \
                 mean ratio"
            );
        }
    }
    let m = &c.mean_ratio;
    let _ = writeln!(
        out,
        "  mean      test/reference R {:.4}  G {:.4}  B {:.4} (tolerance ±{} %{})",
        m.ratio[0],
        m.ratio[1],
        m.ratio[2],
        100.0 * m.tolerance,
        if c.ztest.is_some() {
            ", not used: the z-tests ran"
        } else if m.passed {
            ", pass"
        } else {
            ", FAIL"
        }
    );
    out
}

/// The aggregate test, one indented line per scale: tiles, largest |z|, limit and verdict (with
/// the worst tile when it fails).
pub fn scale_lines(z: &ZTest) -> String {
    let mut out = String::new();
    for s in &z.scales {
        let unit = match s.scale {
            Scale::Material => "material",
            _ => "tile",
        };
        let tiles = format!("{} {unit}{}", s.tiles, if s.tiles == 1 { "" } else { "s" });
        let _ = write!(
            out,
            "    {:<8} {tiles:>12}   |z| max {:>6.2}   limit {:.2}   ",
            s.label(),
            s.max_abs_z,
            s.z_crit
        );
        match (&s.worst, s.passed) {
            (Some(w), false) => {
                let _ = writeln!(
                    out,
                    "FAIL ({} group channel{}; worst {} of {}, z {:+.2})",
                    s.failed,
                    if s.failed == 1 { "" } else { "s" },
                    w.channel,
                    w.region,
                    w.z
                );
            }
            _ => out += if s.passed { "pass\n" } else { "FAIL\n" },
        }
    }
    out
}

/// The aggregate test in one line: `label (groups) |z|/limit` per scale, failing ones marked.
pub fn scale_summary(z: &ZTest) -> String {
    z.scales
        .iter()
        .map(|s| {
            format!(
                "{} ({}) {:.2}/{:.2}{}",
                s.label(),
                s.tiles,
                s.max_abs_z,
                s.z_crit,
                if s.passed { "" } else { " FAIL" }
            )
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// Why `c` failed, each failed part in a few words (empty if it passed).
pub fn failure_reasons(c: &Comparison) -> Vec<String> {
    let mut why = Vec::new();
    if c.passed {
        return why;
    }
    match &c.ztest {
        Some(z) => {
            if !z.pixels_passed {
                why.push(format!(
                    "{} of {} pixels fail the z-test",
                    z.failed_pixels, z.pixels
                ));
            }
            for s in z.failed_scales() {
                let mut line = format!(
                    "bias at {}: |z| {:.2} > {:.2}",
                    s.label(),
                    s.max_abs_z,
                    s.z_crit
                );
                if let Some(w) = &s.worst {
                    let _ = write!(line, " in {} of {}", w.channel, w.region);
                }
                why.push(line);
            }
        }
        None => {
            if c.non_finite_pixels > 0 {
                why.push(format!("{} pixels are NaN or ∞", c.non_finite_pixels));
            }
            if !(c.rel_mse <= REL_MSE_THRESHOLD) {
                why.push(format!("relMSE {:.3e} > {REL_MSE_THRESHOLD:e}", c.rel_mse));
            }
            let m = &c.mean_ratio;
            for (k, q) in m.ratio.iter().enumerate() {
                if !((q - 1.0).abs() <= m.tolerance) {
                    why.push(format!(
                        "mean ratio {} {q:.4} outside 1 ± {}",
                        Rgb::ALL[k],
                        m.tolerance
                    ));
                }
            }
        }
    }
    why
}

/// `PASS` or `FAIL (why; why…)`.
fn verdict_line(c: &Comparison) -> String {
    if c.passed {
        "PASS".into()
    } else {
        format!("FAIL ({})", failure_reasons(c).join("; "))
    }
}
