//! `lapidary regress DIR`: a user's own regression suite. `DIR` holds recipes (`NAME.ron`) with
//! their references beside them (`NAME.exr`, made once with `--update`). Each recipe is rendered
//! at its reference's size, fast (default 256 spp, independent sampler, seed 7), and tested
//! against the reference like `lapidary compare` (per-pixel z-test and the aggregate test at
//! each tile scale); a table shows every result, each row followed by its per-scale verdicts,
//! and a summary counts the failures by kind. Exit status: 0 all pass, 1 some fail, 2 unusable input (a recipe without reference, an unreadable reference, a
//! recipe that does not compile, an empty folder).

use crate::image::compare::{Comparison, Options, compare_with};
use crate::image::write_heatmap;
use crate::image::{ExrImage, read_exr, write_exr};
use crate::render::world::Setup;
use crate::render::{Control, Metadata, exr_image, render_scene};
use crate::sampler::SamplerKind;
use crate::scene::Accuracy;
use anyhow::{Result, anyhow, bail};
use clap::Args;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Arguments of `lapidary regress`.
#[derive(Debug, Args)]
pub struct RegressArgs {
    /// Folder of recipes (`NAME.ron`) with references beside them (`NAME.exr`).
    pub dir: PathBuf,
    /// Samples per pixel of the test renders (256: at 64, rare glints on glitter made a few
    /// pixels of a gem look both dim and quiet, failing the z-test without any change).
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(2..=1_048_576))]
    pub spp: u32,
    /// Seed of the test renders (use one the references were not made with).
    #[arg(long, default_value_t = 7)]
    pub seed: u64,
    /// Where failed tests write their render and heatmap.
    #[arg(long, default_value = "regress-out")]
    pub out: PathBuf,
    /// Make (or remake) every reference instead of testing: `--ref-spp` samples, Sobol', seed
    /// 1000, at the recipe's size or `--size`.
    #[arg(long)]
    pub update: bool,
    /// Samples per pixel of references made by `--update`.
    #[arg(long, default_value_t = 2048, value_parser = clap::value_parser!(u32).range(2..=1_048_576))]
    pub ref_spp: u32,
    /// Size of references made by `--update` (default: the recipe's).
    #[arg(long, value_parser = super::render::parse_size)]
    pub size: Option<(u32, u32)>,
    /// Largest |mean_t/mean_r − 1| of a channel that passes when a reference has no variance
    /// (the z-tests cannot run): a fraction in [0, 1].
    #[arg(long, value_name = "FRACTION",
          default_value_t = crate::image::compare::MEAN_TOLERANCE,
          value_parser = super::compare::parse_mean_tolerance)]
    pub mean_tolerance: f64,
    /// Worker threads (default: one per core).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    /// Run only the recipe with this name (`NAME` of `NAME.ron`).
    #[arg(long, value_name = "NAME")]
    pub only: Option<String>,
    /// A folder of test renders (`NAME.exr`): with `--render-only` they are written there;
    /// without, they are read from there instead of rendered (how a farm's table is made).
    #[arg(long, value_name = "DIR")]
    pub renders: Option<PathBuf>,
    /// Only render the test renders into `--renders`, without comparing.
    #[arg(long, requires = "renders", conflicts_with = "update")]
    pub render_only: bool,
    /// Split the suite over a cluster: one array task per recipe, then the table (see
    /// `lapidary farm`).
    #[command(flatten)]
    pub farm: super::farm::args::RegressFarmArgs,
}

/// Outcome of `lapidary regress`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// Every recipe passed (or every reference was written).
    Pass,
    /// Some recipe failed its comparison.
    Fail,
    /// Some input could not be used.
    Unusable,
}

/// Renders `recipe` with the given overrides into an EXR image.
fn render_recipe(
    recipe: &Path,
    size: Option<(u32, u32)>,
    spp: u32,
    seed: u64,
    sampler: SamplerKind,
    threads: Option<u32>,
) -> Result<ExrImage> {
    let mut loaded = super::load::load_scene(recipe, &Accuracy::default(), None)?;
    let r = &mut loaded.scene.stage.render;
    if let Some((w, h)) = size {
        r.width = w;
        r.height = h;
    }
    r.spp = spp;
    r.seed = seed;
    r.sampler = sampler;
    let world = loaded.world(&Setup::default())?;
    let scene = &loaded.scene;
    let control = Control {
        threads: threads.map(|t| t as usize),
        ..Control::default()
    };
    let rendered = render_scene(&world, scene, &control);
    Ok(exr_image(
        &rendered,
        &Metadata::of(&recipe.display().to_string(), scene),
    ))
}

/// The recipes in `dir`, sorted.
fn recipes(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut out: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| anyhow!("{}: {e}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    out.sort();
    if out.is_empty() {
        bail!("{}: no recipes (*.ron) in this folder", dir.display());
    }
    Ok(out)
}

/// One table row.
fn row(name: &str, c: &Comparison, spp: u32, secs: f64) -> String {
    let (pass, max_z, bias) = match &c.ztest {
        Some(z) => (
            format!("{:.2} %", 100.0 * z.pass_fraction),
            format!("{:.2}", z.max_abs_z),
            format!(
                "{}/{} ok",
                z.scales.iter().filter(|s| s.passed).count(),
                z.scales.len()
            ),
        ),
        None => ("—".to_string(), "—".to_string(), "—".to_string()),
    };
    format!(
        "{name:<24} {:>9} {spp:>6} {pass:>10} {max_z:>7} {bias:>8} {:>9.2e} {:>8.1} {:>6.1} s  {}",
        format!("{}x{}", c.width, c.height),
        c.rel_mse,
        c.psnr,
        secs,
        if c.passed { "pass" } else { "FAIL" }
    )
}

/// The files a run may write, per recipe: its reference (`--update`), or a failed test's EXR and
/// heatmap in `--out`; each checked ([`crate::image::outputs`]) before the first render.
fn planned_outputs(args: &RegressArgs, list: &[PathBuf]) -> Result<Vec<Vec<PathBuf>>> {
    use crate::image::outputs::{Format, OutputPlan};
    let mut plan = OutputPlan::new();
    for recipe in list {
        plan.input(recipe, "the recipe")?;
    }
    if args.update {
        return list
            .iter()
            .map(|r| Ok(vec![plan.output(&r.with_extension("exr"), Format::Exr)?]))
            .collect();
    }
    for recipe in list {
        plan.input(&recipe.with_extension("exr"), "the reference")?;
    }
    plan.folder(&args.out)?;
    list.iter()
        .map(|r| {
            let name = r.file_stem().unwrap_or_default().to_string_lossy();
            Ok(vec![
                plan.output_in(&args.out, &format!("{name}-test.exr"), Format::Exr)?,
                plan.output_in(&args.out, &format!("{name}-heatmap.png"), Format::Png)?,
            ])
        })
        .collect()
}

/// The recipe's name (`NAME` of `NAME.ron`).
pub fn stem(recipe: &Path) -> String {
    recipe
        .file_stem()
        .unwrap_or_default()
        .to_string_lossy()
        .into_owned()
}

/// The suite's recipes, or only the one `--only` names.
pub fn selected(args: &RegressArgs) -> Result<Vec<PathBuf>> {
    let list = recipes(&args.dir)?;
    match &args.only {
        None => Ok(list),
        Some(name) => {
            let one: Vec<PathBuf> = list.iter().filter(|r| stem(r) == *name).cloned().collect();
            if one.is_empty() {
                bail!(
                    "--only {name}: no {name}.ron in {} (it has {})",
                    args.dir.display(),
                    list.iter().map(|r| stem(r)).collect::<Vec<_>>().join(", ")
                );
            }
            Ok(one)
        }
    }
}

/// Whether a stored test render is what this run would render of `recipe` (hash, spp, seed).
pub fn render_matches(img: &ExrImage, recipe_hash: u64, spp: u32, seed: u64) -> Result<(), String> {
    for (key, want) in [
        ("lapidary.recipe_hash", format!("{recipe_hash:016x}")),
        ("lapidary.spp", spp.to_string()),
        ("lapidary.seed", seed.to_string()),
        ("lapidary.sampler", "independent".to_string()),
    ] {
        let have = img.attribute(key).unwrap_or("(none)");
        if have != want {
            return Err(format!("its `{key}` is {have}, not {want}"));
        }
    }
    Ok(())
}

/// The test render of `recipe`: read from `--renders` when given (and not `--render-only`),
/// else rendered. Returns it with its render time in seconds.
fn test_render(args: &RegressArgs, recipe: &Path, reference: &ExrImage) -> Result<(ExrImage, f64)> {
    if let (Some(dir), false) = (&args.renders, args.render_only) {
        let path = dir.join(format!("{}.exr", stem(recipe)));
        let img = read_exr(&path)?;
        let hash = super::load::load_scene(recipe, &Accuracy::default(), None)?
            .scene
            .hash;
        render_matches(&img, hash, args.spp, args.seed)
            .map_err(|e| anyhow!("{}: stale test render: {e}", path.display()))?;
        if (img.width, img.height) != (reference.width, reference.height) {
            bail!("{}: not the reference's size", path.display());
        }
        let secs = img
            .attribute("lapidary.render_time")
            .and_then(|t| t.parse().ok())
            .unwrap_or(0.0);
        return Ok((img, secs));
    }
    let start = Instant::now();
    let img = render_recipe(
        recipe,
        Some((reference.width, reference.height)),
        args.spp,
        args.seed,
        SamplerKind::Independent,
        args.threads,
    )?;
    Ok((img, start.elapsed().as_secs_f64()))
}

/// Runs `lapidary regress` here (`--farm` is dispatched by [`super::run`] to the farm).
pub fn run(args: &RegressArgs) -> Result<Outcome> {
    let list = selected(args)?;
    if args.render_only {
        return render_only(args, &list);
    }
    let files = planned_outputs(args, &list)?;
    let mut outcome = Outcome::Pass;
    if args.update {
        for (recipe, file) in list.iter().zip(&files) {
            let img = render_recipe(
                recipe,
                args.size,
                args.ref_spp,
                1000,
                SamplerKind::Sobol,
                args.threads,
            )?;
            let out = recipe.with_extension("exr");
            write_exr(&file[0], &img)?;
            outln!(
                "{}: reference written ({} spp)",
                out.display(),
                args.ref_spp
            );
        }
        return Ok(outcome);
    }
    outln!(
        "{:<24} {:>9} {:>6} {:>10} {:>7} {:>8} {:>9} {:>8} {:>8}  verdict",
        "recipe",
        "size",
        "spp",
        "pixels ok",
        "max |z|",
        "scales",
        "relMSE",
        "PSNR dB",
        "time"
    );
    let mut tally = Tally::default();
    for (recipe, file) in list.iter().zip(&files) {
        let name = recipe
            .file_stem()
            .unwrap_or_default()
            .to_string_lossy()
            .into_owned();
        let ref_path = recipe.with_extension("exr");
        let reference = match read_exr(&ref_path) {
            Ok(r) => r,
            Err(e) => {
                outln!("{name:<24} unusable: {e} (make it with --update)");
                outcome = Outcome::Unusable;
                continue;
            }
        };
        let (test, secs) = match test_render(args, recipe, &reference) {
            Ok(t) => t,
            Err(e) => {
                outln!("{name:<24} unusable: {e:#}");
                outcome = Outcome::Unusable;
                continue;
            }
        };
        let options = Options {
            mean_tolerance: args.mean_tolerance,
        };
        let c = match compare_with(&test, &reference, &options) {
            Ok(c) => c,
            Err(e) => {
                outln!("{name:<24} unusable: {e}");
                outcome = Outcome::Unusable;
                continue;
            }
        };
        outln!("{}", row(&name, &c, args.spp, secs));
        tally.count(&c);
        match &c.ztest {
            Some(z) => outln!(
                "    bias (tiles) |z|/limit: {}",
                super::compare::scale_summary(z)
            ),
            None => outln!(
                "    z-tests skipped ({}); mean ratio {:.4} {:.4} {:.4}",
                c.ztest_skipped.as_deref().unwrap_or("no variance"),
                c.mean_ratio.ratio[0],
                c.mean_ratio.ratio[1],
                c.mean_ratio.ratio[2]
            ),
        }
        if !c.passed {
            outln!(
                "    fails: {}",
                super::compare::failure_reasons(&c).join("; ")
            );
            std::fs::create_dir_all(&args.out)
                .map_err(|e| anyhow!("{}: {e}", args.out.display()))?;
            let t = args.out.join(format!("{name}-test.exr"));
            let h = args.out.join(format!("{name}-heatmap.png"));
            // Both or neither, to the paths checked before the first render.
            crate::image::atomic::all_or_nothing(|| {
                write_exr(&file[0], &test)?;
                Ok(write_heatmap(&file[1], &c)?)
            })?;
            outln!("    wrote {} and {}", t.display(), h.display());
            if outcome == Outcome::Pass {
                outcome = Outcome::Fail;
            }
        }
    }
    tally.unusable = list.len() - tally.passed - tally.failed;
    outln!("{}", tally.summary());
    Ok(outcome)
}

/// `--render-only`: renders each recipe at its reference's size into `--renders`.
fn render_only(args: &RegressArgs, list: &[PathBuf]) -> Result<Outcome> {
    use crate::image::outputs::{Format, OutputPlan};
    let Some(dir) = &args.renders else {
        bail!("--render-only needs --renders DIR");
    };
    std::fs::create_dir_all(dir).map_err(|e| anyhow!("{}: {e}", dir.display()))?;
    let mut plan = OutputPlan::new();
    for recipe in list {
        plan.input(recipe, "the recipe")?;
        plan.input(&recipe.with_extension("exr"), "the reference")?;
    }
    plan.folder(dir)?;
    let mut outcome = Outcome::Pass;
    for recipe in list {
        let name = stem(recipe);
        let file = plan.output_in(dir, &format!("{name}.exr"), Format::Exr)?;
        let made = read_exr(&recipe.with_extension("exr"))
            .map_err(anyhow::Error::from)
            .and_then(|reference| test_render(args, recipe, &reference));
        match made {
            Ok((img, secs)) => {
                write_exr(&file, &img)?;
                outln!(
                    "{name}: test render written to {} in {secs:.1} s",
                    file.display()
                );
            }
            Err(e) => {
                outln!("{name}: unusable: {e:#}");
                outcome = Outcome::Unusable;
            }
        }
    }
    Ok(outcome)
}

/// Counts of a suite's outcomes, for the summary line.
#[derive(Debug, Default)]
struct Tally {
    passed: usize,
    failed: usize,
    unusable: usize,
    /// Failures of the per-pixel z-test.
    pixel: usize,
    /// Failures of the aggregate test, per scale label.
    scales: Vec<(String, usize)>,
    /// Failures without the z-tests (relMSE, NaN, mean ratio).
    no_variance: usize,
}

impl Tally {
    fn count(&mut self, c: &Comparison) {
        if c.passed {
            self.passed += 1;
            return;
        }
        self.failed += 1;
        let Some(z) = &c.ztest else {
            self.no_variance += 1;
            return;
        };
        if !z.pixels_passed {
            self.pixel += 1;
        }
        for s in z.failed_scales() {
            match self.scales.iter_mut().find(|(l, _)| *l == s.label()) {
                Some((_, n)) => *n += 1,
                None => self.scales.push((s.label(), 1)),
            }
        }
    }

    fn summary(&self) -> String {
        let mut out = format!(
            "summary: {} passed, {} failed, {} unusable",
            self.passed, self.failed, self.unusable
        );
        if self.failed > 0 {
            let mut kinds = vec![format!("pixel z-test {}", self.pixel)];
            kinds.extend(self.scales.iter().map(|(l, n)| format!("bias {l} {n}")));
            if self.no_variance > 0 {
                kinds.push(format!("without variance {}", self.no_variance));
            }
            out += &format!(" (failures by test: {})", kinds.join(", "));
        }
        out
    }
}
