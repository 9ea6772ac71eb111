//! `lapidary farm slurm RECIPE --parts N`: the render farm (see [`super`]).

use super::submit::{Jobs, MARKER, write_script};
use super::{MAX_TASKS, shell_quote as q};
use crate::render::part::{Part, format_range};
use crate::scene::Accuracy;
use anyhow::{Context, Result, anyhow, bail};
use clap::Args;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// Arguments of `lapidary farm slurm`.
#[derive(Debug, Args)]
pub struct SlurmArgs {
    /// Gem recipe (RON).
    pub recipe: PathBuf,
    /// Parts (array tasks) to split the samples into.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=i64::from(MAX_TASKS)))]
    pub parts: u32,
    /// Samples per pixel of the whole render (default: the recipe's, else 64); at least --parts.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_048_576))]
    pub spp: Option<u32>,
    /// Image size `WxH` (default: the recipe's).
    #[arg(long, value_parser = crate::cli::render::parse_size)]
    pub size: Option<(u32, u32)>,
    /// Seed (default: the recipe's).
    #[arg(long)]
    pub seed: Option<u64>,
    /// An argument passed on to every part's `lapidary render` (repeatable), e.g.
    /// `--render-arg=--model=reference`.
    #[arg(long = "render-arg", allow_hyphen_values = true, value_name = "ARG")]
    pub render_args: Vec<String>,
    /// The farm folder, on a filesystem every node sees (default: `farm-NAME`).
    #[arg(long)]
    pub dir: Option<PathBuf>,
    /// The merged EXR (default: `DIR/NAME.exr`; the PNG beside it).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Run at most this many tasks at once (Slurm's `--array=…%K`).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=i64::from(MAX_TASKS)))]
    pub max_running: Option<u32>,
    /// The `lapidary` binary the nodes run (default: this one).
    #[arg(long)]
    pub lapidary: Option<PathBuf>,
    /// Submit with `sbatch` (else only write the scripts and `submit.sh`).
    #[arg(long)]
    pub submit: bool,
    /// Options for `sbatch`, after `--` (e.g. `-- --partition=render --time=1:00:00`).
    #[arg(last = true, allow_hyphen_values = true)]
    pub sbatch_args: Vec<String>,
}

/// Part `i` of `n` over `0..spp`: `i·spp/n .. (i+1)·spp/n`.
pub fn part_range(i: u32, n: u32, spp: u32) -> Range<u32> {
    let at = |k: u32| (u64::from(k) * u64::from(spp) / u64::from(n)) as u32;
    at(i)..at(i + 1)
}

/// An absolute path (the nodes may start in another directory).
pub fn absolute(p: &Path) -> Result<PathBuf> {
    std::path::absolute(p).map_err(|e| anyhow!("{}: {e}", p.display()))
}

/// The `lapidary` binary to put in scripts.
pub fn binary(given: Option<&Path>) -> Result<PathBuf> {
    match given {
        Some(p) => absolute(p),
        None => {
            std::env::current_exe().context("cannot find this program's path (give --lapidary)")
        }
    }
}

/// What a done part must say of itself.
struct Expect {
    hash: String,
    seed: String,
    spp: String,
    size: (u32, u32),
}

/// Whether `path` holds part `range` of this render, complete.
fn done(path: &Path, range: &Range<u32>, e: &Expect) -> bool {
    let Ok(p) = Part::read(path) else {
        return false;
    };
    p.complete()
        && p.samples == *range
        && p.attr("lapidary.recipe_hash") == e.hash
        && p.attr("lapidary.seed") == e.seed
        && p.attr("lapidary.spp") == e.spp
        && (p.image.width, p.image.height) == e.size
}

/// Runs `lapidary farm slurm`.
pub fn run(args: &SlurmArgs) -> Result<()> {
    // Load the recipe here: a broken recipe fails now, not on every node.
    let loaded = crate::cli::load::load_scene(&args.recipe, &Accuracy::default(), None)?;
    let r = loaded.scene.stage.render;
    let spp = args.spp.unwrap_or(r.spp);
    let (w, h) = args.size.unwrap_or((r.width, r.height));
    let seed = args.seed.unwrap_or(r.seed);
    if args.parts > spp {
        bail!(
            "--parts {} is more than the {spp} samples per pixel to split (give --spp ≥ --parts)",
            args.parts
        );
    }
    let name = args
        .recipe
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .ok_or_else(|| anyhow!("{}: not a file name", args.recipe.display()))?;
    let dir = absolute(
        &args
            .dir
            .clone()
            .unwrap_or_else(|| PathBuf::from(format!("farm-{name}"))),
    )?;
    let recipe = absolute(&args.recipe)?;
    let lapidary = binary(args.lapidary.as_deref())?;
    let output = match &args.output {
        Some(o) => absolute(o)?,
        None => dir.join(format!("{name}.exr")),
    };
    for sub in ["parts", "logs"] {
        std::fs::create_dir_all(dir.join(sub))
            .map_err(|e| anyhow!("{}: {e}", dir.join(sub).display()))?;
    }
    let expect = Expect {
        hash: format!("{:016x}", loaded.scene.hash),
        seed: seed.to_string(),
        spp: spp.to_string(),
        size: (w, h),
    };
    let part_path = |i: u32| dir.join("parts").join(format!("part-{i}.exr"));
    let ranges: Vec<Range<u32>> = (0..args.parts)
        .map(|i| part_range(i, args.parts, spp))
        .collect();

    // The array: each task renders its range.
    let mut render = vec![
        q(&lapidary.display().to_string()),
        "render".into(),
        q(&recipe.display().to_string()),
        format!("--spp {spp}"),
        format!("--size {w}x{h}"),
        format!("--seed {seed}"),
    ];
    render.extend(args.render_args.iter().map(|a| q(a)));
    // The parts' command, less the range: parts made by another command (other knobs through
    // --render-arg, another binary) are not this render's, whatever their headers say.
    let command_file = dir.join("parts").join("command.txt");
    let command = format!(
        "{MARKER}: the command of every part, less its range.\n{}\n",
        render.join(" ")
    );
    let same_command = std::fs::read_to_string(&command_file).is_ok_and(|c| c == command);
    if !same_command && command_file.exists() {
        outln!("the render command changed since the last run: every part is rendered again");
    }
    let missing: Vec<u32> = (0..args.parts)
        .filter(|&i| !same_command || !done(&part_path(i), &ranges[i as usize], &expect))
        .collect();
    write_script(&command_file, &command)?;
    let ranges_text: Vec<String> = ranges.iter().map(format_range).collect();
    let array_script = dir.join("render.sbatch");
    write_script(
        &array_script,
        &format!(
            "#!/bin/bash\n{MARKER} slurm: part renders of {recipe}, one array task per part.\n\
             #SBATCH --job-name=lapidary-{name}\n#SBATCH --output={logs}/part-%a.log\n\
             set -euo pipefail\nranges=({ranges})\ni=${{SLURM_ARRAY_TASK_ID:?submit with sbatch --array}}\n\
             threads=()\nif [ -n \"${{SLURM_CPUS_PER_TASK:-}}\" ]; then threads=(--threads \"$SLURM_CPUS_PER_TASK\"); fi\n\
             exec {render} --samples \"${{ranges[$i]}}\" ${{threads[@]+\"${{threads[@]}}\"}} --quiet \\\n    -o {parts}/part-\"$i\".exr\n",
            recipe = recipe.display(),
            logs = q(&dir.join("logs").display().to_string()),
            ranges = ranges_text.join(" "),
            render = render.join(" "),
            parts = q(&dir.join("parts").display().to_string()),
        ),
    )?;
    // The merge, after every task succeeded.
    let parts_list: Vec<String> = (0..args.parts)
        .map(|i| q(&part_path(i).display().to_string()))
        .collect();
    let final_script = dir.join("merge.sbatch");
    write_script(
        &final_script,
        &format!(
            "#!/bin/bash\n{MARKER} slurm: merges the parts of {recipe}.\n\
             #SBATCH --job-name=lapidary-{name}-merge\n#SBATCH --output={log}\nset -euo pipefail\n\
             exec {lapidary} merge \\\n    {parts} \\\n    -o {out}\n",
            recipe = recipe.display(),
            log = q(&dir.join("logs").join("merge.log").display().to_string()),
            lapidary = q(&lapidary.display().to_string()),
            parts = parts_list.join(" \\\n    "),
            out = q(&output.display().to_string()),
        ),
    )?;
    let jobs = Jobs {
        dir: dir.clone(),
        array_script,
        indices: missing.clone(),
        max_running: args.max_running,
        final_script,
        dependency: "afterok",
        sbatch_args: args.sbatch_args.clone(),
    };
    let submit_sh = jobs.write_submit_sh()?;
    outln!(
        "{name}: {w}x{h}, {spp} spp in {} parts; {} to render ({} already done)",
        args.parts,
        missing.len(),
        args.parts as usize - missing.len()
    );
    outln!(
        "  wrote {}, merge.sbatch, submit.sh",
        jobs.array_script.display()
    );
    if args.submit {
        let (array, merge) = jobs.submit()?;
        match array {
            Some(a) => outln!("  submitted array job {a} and merge job {merge} (afterok:{a})"),
            None => outln!("  submitted merge job {merge}"),
        }
        outln!("  the merged render will be {}", output.display());
    } else {
        outln!("  submit with {}", submit_sh.display());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parts_cover_the_range_once() {
        for (n, spp) in [(1, 1), (4, 64), (3, 10), (7, 7), (1000, 1 << 20)] {
            let mut next = 0;
            for i in 0..n {
                let r = part_range(i, n, spp);
                assert_eq!(r.start, next);
                assert!(r.end > r.start);
                next = r.end;
            }
            assert_eq!(next, spp);
        }
    }
}
