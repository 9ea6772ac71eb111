//! `lapidary compare TEST.exr REF.exr [--heatmap diff.png]`: regression check of a render against
//! a reference (DESIGN §8). Prints one line per metric and a verdict; the rules are those of
//! [`mod@crate::image::compare`]. Exit status: 0 pass, 1 fail, 2 unusable input (a missing or
//! unreadable file, sizes that differ, a missing colour channel) or an unwritable heatmap.

use crate::image::compare::{
    CompareError, Comparison, REL_MSE_THRESHOLD, Role, TestVariance, compare,
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
    /// Write a false-colour error map (viridis PNG; yellow = failing, white = NaN/∞) here.
    #[arg(long, value_name = "PATH")]
    pub heatmap: Option<PathBuf>,
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
    let test = read_exr(&args.test)?;
    let reference = read_exr(&args.reference)?;
    let c = compare(&test, &reference).map_err(|e| describe(args, e))?;
    out!("{}", report(&args.test, &args.reference, &c));
    if let Some(path) = &args.heatmap {
        write_heatmap(path, &c)?;
        let top = match &c.ztest {
            Some(z) => format!("|z| ≥ {:.2}", z.z_crit),
            None => format!("relative error ≥ {}", c.error_scale),
        };
        outln!(
            "  heatmap   {} (viridis, yellow = {top}, white = NaN/∞)",
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
        }
        (None, why) => {
            let why = why.as_deref().unwrap_or("no variance");
            let _ = writeln!(
                out,
                "  z-test    skipped: {why}; verdict from relMSE ≤ {REL_MSE_THRESHOLD:e}"
            );
        }
    }
    out
}

/// `PASS` or `FAIL (why)`.
fn verdict_line(c: &Comparison) -> String {
    if c.passed {
        return "PASS".into();
    }
    match &c.ztest {
        Some(z) => format!(
            "FAIL ({} of {} pixels fail the z-test)",
            z.failed_pixels, z.pixels
        ),
        None if c.non_finite_pixels > 0 => {
            format!("FAIL ({} pixels are NaN or ∞)", c.non_finite_pixels)
        }
        None => format!("FAIL (relMSE {:.3e} > {REL_MSE_THRESHOLD:e})", c.rel_mse),
    }
}
