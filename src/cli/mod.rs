//! The `lapidary` command line: argument definitions (clap derive) and dispatch. Each subcommand
//! lives in its own file.

/// `print!` that never panics: when standard output is closed (`lapidary info … | head`), the rest
/// of the output is dropped instead of aborting with a panic.
macro_rules! out {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        let _ = write!(std::io::stdout().lock(), $($t)*);
    }};
}

/// `println!` that never panics (see [`out!`]).
macro_rules! outln {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout().lock(), $($t)*);
    }};
}

pub mod args;
pub mod brdf;
pub mod check;
pub mod compare;
pub mod cut;
pub mod farm;
pub mod info;
mod info_body;
pub mod knobs;
pub mod load;
pub mod map;
pub mod merge;
pub mod plot;
pub mod preview;
pub mod regress;
pub mod render;
pub mod tradeoff;
pub mod tradeoff_plot;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Atomic file replacement, shared with the image writers (see [`crate::image::atomic`]).
pub use crate::image::write_atomically;

/// lapidary — layered BRDFs and procedural gemstones.
#[derive(Debug, Parser)]
#[command(name = "lapidary", version, about, long_about = None)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Inspect a layered BRDF: list, evaluate, sample, measure albedo, plot. With no arguments it
    /// prints the albedo table of the built-in course catalogue under the three models.
    Brdf(brdf::BrdfArgs),
    /// Draw a gem recipe's map tree on a plane (flat colour per material, glitter cells outlined,
    /// facet tilt shaded) to a PNG, and print each material's share of the plane.
    Map(map::MapArgs),
    /// Check gem recipes and material libraries: syntax, includes, materials, map tree, stage.
    /// Prints every error as file:line:col and exits with 1 if any file has one.
    Check(check::CheckArgs),
    /// Describe a gem recipe: materials and their shares of the stone, map statistics, the stage,
    /// and every effect with the recipe element that turned it on.
    Info(info::InfoArgs),
    /// Path-trace a gem recipe to NAME.exr (colour, AOVs, metadata) and NAME.png. Ctrl-C or
    /// --time-limit stop early and write what was rendered, marked partial (Ctrl-C exits 130).
    Render(render::RenderArgs),
    /// Author a recipe live in the browser: serves a page (on 127.0.0.1, with a token in its URL)
    /// that refines the image progressively, re-renders when the recipe or a file it reads is
    /// saved, shows errors over the last good image, and orbits, tilts, rocks and inspects the
    /// stone. Runs until Ctrl-C.
    Preview(preview::PreviewArgs),
    /// The cut report: the stone face-up under ISO, COS and ASET lighting at each tilt — a
    /// contact sheet, a CSV and a table of light return, ASET shares and leakage with their
    /// standard errors.
    Cut(cut::CutArgs),
    /// Merge part renders (`render --samples A..B`) into the render of the whole range: checks
    /// they belong together and cover every sample once; the result equals a one-machine
    /// render bit for bit.
    Merge(merge::MergeArgs),
    /// Split a render over a cluster: `farm slurm RECIPE --parts N` writes (and with --submit
    /// submits) a Slurm job array of part renders and a merge job after it; re-running it
    /// renders only the parts still missing.
    Farm(farm::FarmArgs),
    /// Compare a test render with a reference (EXR): RMSE, relMSE, MAE, PSNR and a per-pixel
    /// z-test; exits 0 on pass, 1 on fail, 2 on unusable input.
    Compare(compare::CompareArgs),
    /// Run a folder of recipes against the reference EXRs beside them (NAME.ron + NAME.exr) and
    /// print a table; --update makes the references. Exits as compare does.
    Regress(regress::RegressArgs),
    /// Measure what accuracy costs in time: render a converged reference (cached), then each knob
    /// setting for a time budget; print time and error (relMSE, FLIP, energy) at equal spp and
    /// equal time, and write a CSV and a log-log plot of error against time.
    Tradeoff(tradeoff::TradeoffArgs),
}

/// Parses the process arguments and runs; errors are printed as `error: …` and exit with 1.
pub fn run() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Brdf(args) => brdf::run(&args),
        Command::Map(args) => map::run(&args),
        Command::Info(args) => info::run(&args),
        Command::Tradeoff(args) => tradeoff::run(&args),
        Command::Merge(args) => merge::run(&args),
        Command::Preview(args) => preview::run(&args),
        Command::Cut(args) => cut::run(&args),
        Command::Farm(args) => farm::run(&args),
        Command::Render(args) => match render::run(&args) {
            Ok(false) => Ok(()),
            Ok(true) => return ExitCode::from(130),
            Err(e) => Err(e),
        },
        Command::Compare(args) => {
            return match compare::run(&args) {
                Ok(compare::Verdict::Pass) => ExitCode::SUCCESS,
                Ok(compare::Verdict::Fail) => ExitCode::from(1),
                Err(e) => {
                    eprintln!("error: {e:#}");
                    ExitCode::from(2)
                }
            };
        }
        Command::Regress(args) if args.farm.farm.is_some() => farm::regress::run(&args),
        Command::Regress(args) => {
            return match regress::run(&args) {
                Ok(regress::Outcome::Pass) => ExitCode::SUCCESS,
                Ok(regress::Outcome::Fail) => ExitCode::from(1),
                Ok(regress::Outcome::Unusable) => ExitCode::from(2),
                Err(e) => {
                    eprintln!("error: {e:#}");
                    ExitCode::from(2)
                }
            };
        }
        Command::Check(args) => match check::run(&args) {
            Ok(true) => Ok(()),
            Ok(false) => return ExitCode::from(1),
            Err(e) => Err(e),
        },
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // The reader of standard output went away (`… | head`): what it wanted was printed.
        Err(e) if is_broken_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
    }
}

/// Whether an error comes from writing to a closed pipe (standard output read by `head`).
/// Rust ignores SIGPIPE, so such a write fails with `BrokenPipe` instead of ending the process.
pub fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}
