//! `lapidary farm slurm RECIPE --parts N`: one render split over a Slurm cluster (docs/farm.md).
//!
//! The sample range `0..spp` is cut into `N` parts; a Slurm job array renders one part per task
//! (`lapidary render --samples A..B`, each task's range picked by `$SLURM_ARRAY_TASK_ID`), and a
//! merge job that depends on the array (`--dependency=afterok`) runs `lapidary merge`. The
//! scripts go into a farm folder on the cluster's shared filesystem (`render.sbatch`,
//! `merge.sbatch`, `submit.sh`, `parts/`, `logs/`); `--submit` also submits them with `sbatch`.
//! Re-running the command after a failure writes an array of only the parts not yet rendered
//! (a part file that is complete and matches the recipe, seed, size and spp counts as done).
//! `lapidary regress DIR --farm slurm` does the same for a regression suite ([`regress`]).

pub mod args;
pub mod regress;
pub mod render_args;
pub mod slurm;
pub mod submit;
pub mod text;

use clap::{Args, Subcommand};

/// Arguments of `lapidary farm`.
#[derive(Debug, Args)]
pub struct FarmArgs {
    /// The scheduler.
    #[command(subcommand)]
    pub scheduler: Scheduler,
}

/// Schedulers `lapidary farm` writes jobs for.
#[derive(Debug, Subcommand)]
pub enum Scheduler {
    /// Slurm: a job array of part renders and a merge job after it (`afterok`).
    Slurm(slurm::SlurmArgs),
}

/// Runs `lapidary farm`.
pub fn run(args: &FarmArgs) -> anyhow::Result<()> {
    match &args.scheduler {
        Scheduler::Slurm(a) => slurm::run(a),
    }
}

/// Largest array a farm writes: Slurm's default `MaxArraySize` is 1001 (indices 0..=1000).
pub const MAX_TASKS: u32 = 1000;

/// Slurm's `--array` list for these sorted task indices, runs compressed (`0-3,7,9-10`), with
/// `%K` appended when at most `K` tasks may run at once.
pub fn array_spec(indices: &[u32], max_running: Option<u32>) -> String {
    let mut out = Vec::new();
    let mut i = 0;
    while i < indices.len() {
        let mut j = i;
        while j + 1 < indices.len() && indices[j + 1] == indices[j] + 1 {
            j += 1;
        }
        out.push(if i == j {
            indices[i].to_string()
        } else {
            format!("{}-{}", indices[i], indices[j])
        });
        i = j + 1;
    }
    let mut s = out.join(",");
    if let Some(k) = max_running {
        s += &format!("%{k}");
    }
    s
}

/// `s` quoted for a POSIX shell (single quotes; a single quote inside becomes `'\''`).
pub fn shell_quote(s: &str) -> String {
    if !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./=:,+@%".contains(c))
    {
        return s.to_string();
    }
    format!("'{}'", s.replace('\'', r"'\''"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn array_lists_compress_runs() {
        assert_eq!(array_spec(&[0, 1, 2, 3], None), "0-3");
        assert_eq!(array_spec(&[0, 1, 2, 3, 7, 9, 10], Some(2)), "0-3,7,9-10%2");
        assert_eq!(array_spec(&[5], None), "5");
    }

    #[test]
    fn quoting_survives_spaces_and_quotes() {
        assert_eq!(shell_quote("a/b.ron"), "a/b.ron");
        assert_eq!(shell_quote("my gem's.ron"), r"'my gem'\''s.ron'");
        assert_eq!(shell_quote(""), "''");
    }
}
