//! `lapidary regress DIR --farm slurm`: a regression suite split over Slurm, one array task per
//! recipe (`regress --only NAME --render-only --renders FARM/renders`), then the table
//! (`regress --renders FARM/renders`, after every task ended: `afterany`, so a recipe that
//! failed to render shows in the table as unusable instead of hiding the others' results).
//! Re-running renders only the recipes without a current test render.

use super::MAX_TASKS;
use super::slurm::{TASK, absolute, binary};
use super::submit::{Jobs, MARKER, check_own, write_script};
use super::text::Text;
use crate::cli::regress::{RegressArgs, render_matches, selected};
use crate::image::atomic::all_or_nothing;
use crate::image::input_kind::{NotAFile, regular_file};
use crate::image::{ExrImage, read_exr};
use crate::scene::Accuracy;
use anyhow::{Result, anyhow, bail};
use std::path::{Path, PathBuf};

/// Reads a stored EXR the farm compares with (a reference, a test render) if it is a regular
/// file: `None` when nothing is there or it does not read. Anything else at the path (a FIFO
/// would block the read, a device never end it) is refused without opening it.
fn read_stored(path: &Path, what: &str) -> Result<Option<ExrImage>> {
    match regular_file(path) {
        Ok(_) => Ok(read_exr(path).ok()),
        Err(NotAFile::Missing) => Ok(None),
        Err(e) => bail!("{}: {e}: not readable as {what}", path.display()),
    }
}

/// Writes (and submits) the suite's jobs.
pub fn run(args: &RegressArgs) -> Result<()> {
    if args.update || args.render_only || args.renders.is_some() {
        bail!(
            "--farm runs the tests: it cannot be combined with --update, --render-only or --renders"
        );
    }
    let f = &args.farm;
    let list = selected(args)?;
    if list.len() > MAX_TASKS as usize {
        bail!(
            "{} recipes: a farm array holds at most {MAX_TASKS}",
            list.len()
        );
    }
    // Every path and name a script holds is checked before anything is written.
    let suite = absolute(&args.dir)?;
    let suite_t = Text::path(&suite, "the suite")?;
    let suite_name = suite
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "suite".into());
    let dir = absolute(
        &f.farm_dir
            .clone()
            .unwrap_or_else(|| PathBuf::from(format!("farm-regress-{suite_name}"))),
    )?;
    let what = "the farm folder (--farm-dir)";
    let dir_t = |sub: &str| Text::path(&dir.join(sub), what);
    let (renders_t, out_t, table_t) = (
        dir_t("renders")?,
        dir_t("regress-out")?,
        dir_t("table.txt")?,
    );
    let logs = dir_t("logs")?.slurm_file(what)?;
    let table_log = table_t.slurm_file(what)?;
    let lapidary = binary(f.lapidary.as_deref())?;
    let lapidary_t = Text::path(&lapidary, "the lapidary binary (--lapidary)")?;
    let sbatch_args = f
        .sbatch_args
        .iter()
        .map(|a| Text::new(a, "the sbatch option"))
        .collect::<Result<Vec<_>>>()?;
    let names = list
        .iter()
        .map(|r| {
            let name = r.file_stem().and_then(|s| s.to_str()).ok_or_else(|| {
                anyhow!(
                    "the suite's recipe {}: is not valid UTF-8: a farm script is text and \
                     cannot name it",
                    r.display()
                )
            })?;
            Text::new(name, "the suite's recipe name")
        })
        .collect::<Result<Vec<_>>>()?;
    let renders = dir.join("renders");
    // The farm's folders: each a directory or nothing yet (a file in the way is named as one).
    let mut plan = crate::image::outputs::OutputPlan::new();
    for folder in [&dir, &renders, &dir.join("logs")] {
        plan.folder(folder)?;
    }
    let mut missing = Vec::new();
    for (i, recipe) in list.iter().enumerate() {
        // A broken recipe fails now, not on a node.
        let hash = crate::cli::load::load_scene(recipe, &Accuracy::default(), None)?
            .scene
            .hash;
        // Current: this recipe, spp, seed and sampler, at the reference's size.
        let size =
            read_stored(&recipe.with_extension("exr"), "a reference")?.map(|r| (r.width, r.height));
        let stored = renders.join(format!("{}.exr", names[i].as_str()));
        let current = read_stored(&stored, "a test render")?.is_some_and(|img| {
            render_matches(&img, hash, args.spp, args.seed).is_ok()
                && size == Some((img.width, img.height))
        });
        if !current {
            missing.push(i as u32);
        }
    }
    for script in ["regress.sbatch", "table.sbatch", "submit.sh"] {
        check_own(&dir.join(script))?;
    }
    for d in [&renders, &dir.join("logs")] {
        std::fs::create_dir_all(d).map_err(|e| anyhow!("{}: {e}", d.display()))?;
    }
    let common = format!(
        "--spp {} --seed {} --mean-tolerance {}",
        args.spp, args.seed, args.mean_tolerance
    );
    let names_text: Vec<String> = names.iter().map(Text::sh).collect();
    let array_text = format!(
        "#!/bin/bash\n{MARKER} slurm: test renders of the suite {suite}, one array task per \
             recipe.\n#SBATCH --job-name=lapidary-regress\n#SBATCH --output={logs}\n\
             set -euo pipefail\nnames=({names})\n{TASK}\
             threads=()\nif [ -n \"${{SLURM_CPUS_PER_TASK:-}}\" ]; then threads=(--threads \"$SLURM_CPUS_PER_TASK\"); fi\n\
             exec {lapidary} regress {suite} --only=\"${{names[$i]}}\" --render-only --renders {renders} \\\n    {common} ${{threads[@]+\"${{threads[@]}}\"}}\n",
        suite = suite_t.sh(),
        logs = Text::new(&format!("{}/%a.log", logs.as_str()), what)?.sbatch(),
        names = names_text.join(" "),
        lapidary = lapidary_t.sh(),
        renders = renders_t.sh(),
    );
    let table_text = format!(
        "#!/bin/bash\n{MARKER} slurm: the table of the suite {suite} from the array's renders.\n\
             #SBATCH --job-name=lapidary-regress-table\n#SBATCH --output={table}\nset -euo pipefail\n\
             exec {lapidary} regress {suite} --renders {renders} --out {out} {common}\n",
        suite = suite_t.sh(),
        table = table_log.sbatch(),
        lapidary = lapidary_t.sh(),
        renders = renders_t.sh(),
        out = out_t.sh(),
    );
    let jobs = Jobs {
        dir: dir.clone(),
        array_script: dir.join("regress.sbatch"),
        indices: missing.clone(),
        max_running: f.max_running,
        final_script: dir.join("table.sbatch"),
        dependency: "afterany",
        sbatch_args,
    };
    // Every script or none: a failed write leaves the last run's set as it was.
    let submit_sh = all_or_nothing(|| {
        write_script(&jobs.array_script, &array_text)?;
        write_script(&jobs.final_script, &table_text)?;
        jobs.write_submit_sh()
    })?;
    outln!(
        "suite {}: {} recipes; {} to render ({} current)",
        suite.display(),
        list.len(),
        missing.len(),
        list.len() - missing.len()
    );
    if f.submit {
        let (array, table) = jobs.submit()?;
        match array {
            Some(a) => outln!("  submitted array job {a} and table job {table} (afterany:{a})"),
            None => outln!("  submitted table job {table}"),
        }
        outln!("  the table will be {}", dir.join("table.txt").display());
    } else {
        outln!("  submit with {}", submit_sh.display());
    }
    Ok(())
}
