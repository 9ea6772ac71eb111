//! `lapidary check FILE…`: checks gem recipes and material libraries completely — syntax, includes,
//! every material, the whole map tree, the stage — and prints every error found as
//! `file:line:col: message`, warnings likewise, and one summary line per file. Exits non-zero when
//! any file has an error. A number out of range does not hide what follows it (the parser records
//! it and goes on, [`crate::recipe::source::recover`]); a syntax error still ends the file's check.

use crate::recipe::{GemRecipe, MaterialLibrary, RecipeError, Source};
use clap::Args;
use std::path::{Path, PathBuf};

/// Arguments of `lapidary check`.
#[derive(Debug, Args)]
pub struct CheckArgs {
    /// Gem recipes (files with a `surface`) and material libraries, checked in turn.
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// Print only errors and the final count.
    #[arg(long, short)]
    pub quiet: bool,
}

/// What a file holds, judged from its top-level keys.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileKind {
    /// A gem recipe (it has a `surface`).
    Gem,
    /// A material library.
    Library,
}

/// The kind of description file `source` is: a recipe if it has a `surface:` key outside comments.
pub fn kind(source: &Source) -> FileKind {
    if source.find(&["surface", ":"]).is_some() {
        FileKind::Gem
    } else {
        FileKind::Library
    }
}

/// The result of checking one file.
#[derive(Debug, Default)]
pub struct FileReport {
    /// Errors, in the order found.
    pub errors: Vec<RecipeError>,
    /// Warnings.
    pub warnings: Vec<RecipeError>,
    /// A one-line description of what was checked when it is clean.
    pub summary: String,
}

/// Checks one file of either kind.
pub fn check_file(path: &Path) -> FileReport {
    let source = match Source::read(path) {
        Ok(s) => s,
        Err(e) => {
            return FileReport {
                errors: vec![e],
                ..FileReport::default()
            };
        }
    };
    match kind(&source) {
        FileKind::Gem => {
            let report = GemRecipe::check_source(source, Some(path));
            let summary = report.scene.as_ref().map_or_else(String::new, |s| {
                format!(
                    "gem recipe: {} materials, {} map nodes, {} effects on",
                    s.surface.names.len(),
                    s.surface.map.nodes.len(),
                    s.effects.iter().count()
                )
            });
            FileReport {
                errors: report.errors,
                warnings: report.warnings,
                summary,
            }
        }
        FileKind::Library => {
            let (lib, errors) = MaterialLibrary::check(path);
            let summary = lib.map_or_else(String::new, |l| {
                format!(
                    "material library: {} materials from {} file(s)",
                    l.len(),
                    l.sources().len()
                )
            });
            FileReport {
                errors,
                warnings: vec![],
                summary,
            }
        }
    }
}

/// Runs `lapidary check`; `Ok(false)` when some file has an error.
pub fn run(args: &CheckArgs) -> anyhow::Result<bool> {
    let mut total = 0;
    for path in &args.files {
        let report = check_file(path);
        for e in &report.errors {
            eprintln!("error: {e}");
        }
        if !args.quiet {
            for w in &report.warnings {
                eprintln!("warning: {w}");
            }
        }
        total += report.errors.len();
        if report.errors.is_empty() {
            if !args.quiet {
                outln!("{}: ok ({})", path.display(), report.summary);
            }
        } else {
            outln!(
                "{}: {} error{}",
                path.display(),
                report.errors.len(),
                if report.errors.len() == 1 { "" } else { "s" }
            );
        }
    }
    if total > 0 {
        eprintln!(
            "{total} error{} in {} file{}",
            if total == 1 { "" } else { "s" },
            args.files.len(),
            if args.files.len() == 1 { "" } else { "s" }
        );
    }
    Ok(total == 0)
}
