//! `lapidary farm slurm RECIPE --parts N`: the render farm (see [`super`]).

use super::MAX_TASKS;
use super::render_args::{self, Whole};
use super::submit::{Jobs, MARKER, check_own, write_script};
use super::text::Text;
use crate::image::atomic::all_or_nothing;
use crate::image::input_kind::regular_file;
use crate::image::outputs::{Format, OutputPlan};
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

/// Whether `path` holds part `range` of this render, complete ([`Part::read`] checks the file's
/// type before opening it, and everything the part says of itself).
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

/// Checks an output of the merge job (`OUT.exr`, the PNG beside it) as `render -o` is checked,
/// before anything is written: not one of the recipe's inputs nor a part, a regular file or a new
/// name in a directory that exists (or in a folder this run creates: the farm folder, its
/// `parts/` and `logs/`), ending in the format's extension.
fn check_output(
    plan: &mut OutputPlan,
    path: &Path,
    format: Format,
    dir: &Path,
    parts: &[PathBuf],
) -> Result<()> {
    // A part that does not exist yet has no identity for the plan: compare names.
    let canonical = |p: &Path| match (p.parent().map(std::fs::canonicalize), p.file_name()) {
        (Some(Ok(d)), Some(n)) => d.join(n),
        _ => p.to_path_buf(),
    };
    if let Some(part) = parts.iter().find(|p| canonical(p) == canonical(path)) {
        bail!(
            "{}: is a part the merge job reads ({}): give -o another name",
            path.display(),
            part.display()
        );
    }
    match path.parent() {
        Some(parent)
            if !parent.exists()
                && [dir.to_path_buf(), dir.join("parts"), dir.join("logs")]
                    .contains(&parent.to_path_buf()) =>
        {
            let name = path.file_name().unwrap_or_default().to_string_lossy();
            plan.output_in(parent, &name, format)?;
        }
        _ => {
            plan.output(path, format)?;
        }
    }
    Ok(())
}

/// Refuses a part path that exists but is not a regular file (a FIFO, a device, a directory),
/// checked without opening it: the farm would block reading it, the task could not write it.
fn check_part_kind(path: &Path) -> Result<()> {
    if std::fs::symlink_metadata(path).is_err() {
        return Ok(());
    }
    match regular_file(path) {
        Ok(_) => Ok(()),
        Err(e) => bail!(
            "{}: {e}: where the farm keeps a part; remove it, or choose another --dir",
            path.display()
        ),
    }
}

/// Runs `lapidary farm slurm`.
pub fn run(args: &SlurmArgs) -> Result<()> {
    // Every path and argument a script holds is checked before anything else.
    let recipe = absolute(&args.recipe)?;
    let recipe_t = Text::path(&recipe, "the recipe")?;
    let name = args
        .recipe
        .file_stem()
        .and_then(|s| s.to_str())
        .ok_or_else(|| anyhow!("{}: not a file name", args.recipe.display()))?
        .to_string();
    let dir = absolute(
        &args
            .dir
            .clone()
            .unwrap_or_else(|| PathBuf::from(format!("farm-{name}"))),
    )?;
    Text::path(&dir, "the farm folder (--dir)")?;
    let logs = Text::path(&dir.join("logs"), "the farm folder (--dir)")?
        .slurm_file("the farm folder (--dir)")?;
    let lapidary = binary(args.lapidary.as_deref())?;
    let lapidary_t = Text::path(&lapidary, "the lapidary binary (--lapidary)")?;
    let output = match &args.output {
        Some(o) => absolute(o)?,
        None => dir.join(format!("{name}.exr")),
    };
    let png = output.with_extension("png");
    let output_t = Text::path(&output, "-o")?;
    Text::path(&png, "-o")?;
    let sbatch_args = args
        .sbatch_args
        .iter()
        .map(|a| Text::new(a, "the sbatch option"))
        .collect::<Result<Vec<_>>>()?;

    // Load the recipe here: a broken recipe fails now, not on every node. Its files are inputs
    // the merged render may not overwrite.
    let mut plan = OutputPlan::new();
    plan.input(&args.recipe, "the recipe")?;
    let loaded = crate::cli::load::load_scene(&args.recipe, &Accuracy::default(), Some(&mut plan))?;
    let r = loaded.scene.stage.render;
    let whole = Whole {
        spp: args.spp.unwrap_or(r.spp),
        size: args.size.unwrap_or((r.width, r.height)),
        seed: args.seed.unwrap_or(r.seed),
    };
    let (spp, (w, h), seed) = (whole.spp, whole.size, whole.seed);
    if args.parts > spp {
        bail!(
            "--parts {} is more than the {spp} samples per pixel to split (give --spp ≥ --parts)",
            args.parts
        );
    }
    // The farm's folders: each a directory or nothing yet (a file in the way is named as one).
    for folder in [dir.clone(), dir.join("parts"), dir.join("logs")] {
        plan.folder(&folder)?;
    }
    let part_path = |i: u32| dir.join("parts").join(format!("part-{i}.exr"));
    let parts: Vec<PathBuf> = (0..args.parts).map(part_path).collect();
    for p in &parts {
        check_part_kind(p)?;
        plan.input(p, "a part")?;
    }
    // Where the merge job writes, and what every part runs, are checked before anything is
    // written: they would fail only after every part had rendered.
    check_output(&mut plan, &output, Format::Exr, &dir, &parts)?;
    check_output(&mut plan, &png, Format::Png, &dir, &parts)?;
    let render_args = render_args::check(&args.render_args, &recipe_t, &whole)?;
    // The farm's own files: each nothing yet, or a regular file this command wrote.
    let command_file = dir.join("parts").join("command.txt");
    let old_command = check_own(&command_file)?;
    for script in ["render.sbatch", "merge.sbatch", "submit.sh"] {
        check_own(&dir.join(script))?;
    }

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
    let ranges: Vec<Range<u32>> = (0..args.parts)
        .map(|i| part_range(i, args.parts, spp))
        .collect();

    // The array: each task renders its range.
    let mut render = vec![lapidary_t.sh(), "render".into(), recipe_t.sh()];
    render.extend(whole.words());
    render.extend(render_args.iter().map(Text::sh));
    // The parts' command, less the range: parts made by another command (other knobs through
    // --render-arg, another binary) are not this render's, whatever their headers say.
    let command = format!(
        "{MARKER}: the command of every part, less its range.\n{}\n",
        render.join(" ")
    );
    let same_command = old_command.as_deref() == Some(command.as_str());
    if !same_command && old_command.is_some() {
        outln!("the render command changed since the last run: every part is rendered again");
    }
    let missing: Vec<u32> = (0..args.parts)
        .filter(|&i| !same_command || !done(&parts[i as usize], &ranges[i as usize], &expect))
        .collect();
    let ranges_text: Vec<String> = ranges.iter().map(format_range).collect();
    let parts_dir = Text::path(&dir.join("parts"), "the farm folder (--dir)")?;
    let job = Text::new(&format!("lapidary-{name}"), "the job name")?.job_name();
    let array_text = format!(
        "#!/bin/bash\n{MARKER} slurm: part renders of {recipe}, one array task per part.\n\
             #SBATCH --job-name={job}\n#SBATCH --output={logs}\n\
             set -euo pipefail\nranges=({ranges})\n{TASK}\
             threads=()\nif [ -n \"${{SLURM_CPUS_PER_TASK:-}}\" ]; then threads=(--threads \"$SLURM_CPUS_PER_TASK\"); fi\n\
             exec {render} --samples \"${{ranges[$i]}}\" ${{threads[@]+\"${{threads[@]}}\"}} --quiet \\\n    -o {parts}/part-\"$i\".exr\n",
        recipe = recipe_t.sh(),
        job = job.sbatch(),
        logs = Text::new(&format!("{}/part-%a.log", logs.as_str()), "the log")?.sbatch(),
        ranges = ranges_text.join(" "),
        render = render.join(" "),
        parts = parts_dir.sh(),
    );
    // The merge, after every task succeeded.
    let parts_list = parts
        .iter()
        .map(|p| Text::path(p, "a part").map(|t| t.sh()))
        .collect::<Result<Vec<_>>>()?;
    let merge_log = Text::path(
        &dir.join("logs").join("merge.log"),
        "the farm folder (--dir)",
    )?
    .slurm_file("the farm folder (--dir)")?;
    let merge_text = format!(
        "#!/bin/bash\n{MARKER} slurm: merges the parts of {recipe}.\n\
             #SBATCH --job-name={job}\n#SBATCH --output={log}\nset -euo pipefail\n\
             exec {lapidary} merge \\\n    {parts} \\\n    -o {out}\n",
        recipe = recipe_t.sh(),
        job = Text::new(&format!("{}-merge", job.as_str()), "the job name")?.sbatch(),
        log = merge_log.sbatch(),
        lapidary = lapidary_t.sh(),
        parts = parts_list.join(" \\\n    "),
        out = output_t.sh(),
    );
    let jobs = Jobs {
        dir: dir.clone(),
        array_script: dir.join("render.sbatch"),
        indices: missing.clone(),
        max_running: args.max_running,
        final_script: dir.join("merge.sbatch"),
        dependency: "afterok",
        sbatch_args,
    };
    // Every file of the farm or none: a failed write leaves the last run's set as it was.
    let submit_sh = all_or_nothing(|| {
        write_script(&command_file, &command)?;
        write_script(&jobs.array_script, &array_text)?;
        write_script(&jobs.final_script, &merge_text)?;
        jobs.write_submit_sh()
    })?;
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

/// The lines of an array script that take the task's index from Slurm into `$i`, refusing
/// anything but a decimal number (bash would evaluate any other text as arithmetic).
pub const TASK: &str = "i=${SLURM_ARRAY_TASK_ID:?submit with sbatch --array}\n\
    case $i in ''|*[!0-9]*) echo \"SLURM_ARRAY_TASK_ID=$i: not a task index\" >&2; exit 2;; esac\n";

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
