//! The farm options of `lapidary regress` (`--farm slurm` and its settings), apart from the farm
//! itself so that `cli::regress` can hold them without depending on [`super::regress`].

use super::MAX_TASKS;
use clap::{Args, ValueEnum};
use std::path::PathBuf;

/// Schedulers `--farm` knows.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum FarmKind {
    /// Slurm job arrays.
    Slurm,
}

/// The farm options of `lapidary regress`.
#[derive(Debug, Default, Args)]
pub struct RegressFarmArgs {
    /// Write (and with --submit submit) the suite as cluster jobs instead of running it here.
    #[arg(long, value_enum)]
    pub farm: Option<FarmKind>,
    /// The farm folder, on a filesystem every node sees (default: `farm-regress-NAME` for the
    /// suite folder NAME).
    #[arg(long, requires = "farm")]
    pub farm_dir: Option<PathBuf>,
    /// Submit with `sbatch` (else only write the scripts and `submit.sh`).
    #[arg(long, requires = "farm")]
    pub submit: bool,
    /// Run at most this many tasks at once.
    #[arg(long, requires = "farm",
          value_parser = clap::value_parser!(u32).range(1..=i64::from(MAX_TASKS)))]
    pub max_running: Option<u32>,
    /// The `lapidary` binary the nodes run (default: this one).
    #[arg(long, requires = "farm")]
    pub lapidary: Option<PathBuf>,
    /// Options for `sbatch`, after `--`.
    #[arg(last = true, allow_hyphen_values = true)]
    pub sbatch_args: Vec<String>,
}
