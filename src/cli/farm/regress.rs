//! `lapidary regress DIR --farm slurm`: a regression suite split over Slurm, one array task per
//! recipe (`regress --only NAME --render-only --renders FARM/renders`), then the table
//! (`regress --renders FARM/renders`, after every task ended: `afterany`, so a recipe that
//! failed to render shows in the table as unusable instead of hiding the others' results).
//! Re-running renders only the recipes without a current test render.

use super::slurm::{absolute, binary};
use super::submit::{Jobs, MARKER, write_script};
use super::{MAX_TASKS, shell_quote as q};
use crate::cli::regress::{RegressArgs, render_matches, selected, stem};
use crate::image::read_exr;
use crate::scene::Accuracy;
use anyhow::{Result, anyhow, bail};
use std::path::PathBuf;

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
    let suite = absolute(&args.dir)?;
    let suite_name = suite
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "suite".into());
    let dir = absolute(
        &f.farm_dir
            .clone()
            .unwrap_or_else(|| PathBuf::from(format!("farm-regress-{suite_name}"))),
    )?;
    let renders = dir.join("renders");
    for d in [&renders, &dir.join("logs")] {
        std::fs::create_dir_all(d).map_err(|e| anyhow!("{}: {e}", d.display()))?;
    }
    let lapidary = binary(f.lapidary.as_deref())?;
    let names: Vec<String> = list.iter().map(|r| stem(r)).collect();
    let mut missing = Vec::new();
    for (i, recipe) in list.iter().enumerate() {
        // A broken recipe fails now, not on a node.
        let hash = crate::cli::load::load_scene(recipe, &Accuracy::default(), None)?
            .scene
            .hash;
        // Current: this recipe, spp, seed and sampler, at the reference's size.
        let size = read_exr(&recipe.with_extension("exr"))
            .ok()
            .map(|r| (r.width, r.height));
        let current = read_exr(&renders.join(format!("{}.exr", names[i])))
            .ok()
            .is_some_and(|img| {
                render_matches(&img, hash, args.spp, args.seed).is_ok()
                    && size == Some((img.width, img.height))
            });
        if !current {
            missing.push(i as u32);
        }
    }
    let common = format!(
        "--spp {} --seed {} --mean-tolerance {}",
        args.spp, args.seed, args.mean_tolerance
    );
    let names_text: Vec<String> = names.iter().map(|n| q(n)).collect();
    let array_script = dir.join("regress.sbatch");
    write_script(
        &array_script,
        &format!(
            "#!/bin/bash\n{MARKER} slurm: test renders of the suite {suite}, one array task per \
             recipe.\n#SBATCH --job-name=lapidary-regress\n#SBATCH --output={logs}/%a.log\n\
             set -euo pipefail\nnames=({names})\ni=${{SLURM_ARRAY_TASK_ID:?submit with sbatch --array}}\n\
             threads=()\nif [ -n \"${{SLURM_CPUS_PER_TASK:-}}\" ]; then threads=(--threads \"$SLURM_CPUS_PER_TASK\"); fi\n\
             exec {lapidary} regress {suite_q} --only \"${{names[$i]}}\" --render-only --renders {renders} \\\n    {common} ${{threads[@]+\"${{threads[@]}}\"}}\n",
            suite = suite.display(),
            logs = q(&dir.join("logs").display().to_string()),
            names = names_text.join(" "),
            lapidary = q(&lapidary.display().to_string()),
            suite_q = q(&suite.display().to_string()),
            renders = q(&renders.display().to_string()),
        ),
    )?;
    let final_script = dir.join("table.sbatch");
    write_script(
        &final_script,
        &format!(
            "#!/bin/bash\n{MARKER} slurm: the table of the suite {suite} from the array's renders.\n\
             #SBATCH --job-name=lapidary-regress-table\n#SBATCH --output={table}\nset -euo pipefail\n\
             exec {lapidary} regress {suite_q} --renders {renders} --out {out} {common}\n",
            suite = suite.display(),
            table = q(&dir.join("table.txt").display().to_string()),
            lapidary = q(&lapidary.display().to_string()),
            suite_q = q(&suite.display().to_string()),
            renders = q(&renders.display().to_string()),
            out = q(&dir.join("regress-out").display().to_string()),
        ),
    )?;
    let jobs = Jobs {
        dir: dir.clone(),
        array_script,
        indices: missing.clone(),
        max_running: f.max_running,
        final_script,
        dependency: "afterany",
        sbatch_args: f.sbatch_args.clone(),
    };
    let submit_sh = jobs.write_submit_sh()?;
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
