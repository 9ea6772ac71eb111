//! The `lapidary` command line: argument definitions (clap derive) and dispatch. Each subcommand
//! lives in its own file.

pub mod brdf;
pub mod check;
pub mod info;
pub mod map;
pub mod plot;

use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

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
}

/// Parses the process arguments and runs; errors are printed as `error: …` and exit with 1.
pub fn run() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Brdf(args) => brdf::run(&args),
        Command::Map(args) => map::run(&args),
        Command::Info(args) => info::run(&args),
        Command::Check(args) => match check::run(&args) {
            Ok(true) => Ok(()),
            Ok(false) => return ExitCode::from(1),
            Err(e) => Err(e),
        },
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
    }
}

/// Writes a file atomically: `write` fills a temporary file beside `path` (same extension, so
/// encoders that look at it still work), which then replaces `path` by a rename. A failure leaves
/// an existing `path` untouched.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&Path) -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .ok_or_else(|| anyhow::anyhow!("{}: not a file path", path.display()))?;
    let ext = path
        .extension()
        .map(|e| format!(".{}", e.to_string_lossy()))
        .unwrap_or_default();
    let tmp: PathBuf = dir.join(format!(
        ".{}.{}.tmp{ext}",
        name.to_string_lossy(),
        std::process::id()
    ));
    let result = write(&tmp).and_then(|()| {
        std::fs::rename(&tmp, path)
            .map_err(|e| anyhow::anyhow!("{}: cannot replace: {e}", path.display()))
    });
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}
