//! `lapidary render RECIPE`: path-trace a gem recipe to an EXR (colour, AOVs, metadata) and a
//! tone-mapped PNG, with a progress bar and a closing summary. Ctrl-C, SIGTERM or `--time-limit`
//! stop the render cleanly and write what was accumulated, marked partial in the EXR's metadata;
//! stopped before the first pass over the image completed, they write nothing. A second Ctrl-C
//! or SIGTERM aborts at once (exit 130) without writing. Outputs are checked before any work
//! ([`crate::image::outputs`]) and written all or nothing.

use crate::image::atomic::{abort_process, all_or_nothing};
use crate::image::outputs::{Format, OutputPlan};
use crate::image::{Curve, ToneMap, write_exr, write_exr_raw, write_png};
use crate::render::part::{PartSettings, part_image};
use crate::render::{Control, Metadata, Rendered, Strategy, exr_image, render_scene};
use crate::scene::stage::SamplerKind;
use crate::scene::{Effect, Scene};
use anyhow::{Context, Result, anyhow, bail};
use clap::{Args, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Arguments of `lapidary render`.
#[derive(Debug, Args)]
pub struct RenderArgs {
    /// Gem recipe (RON).
    pub recipe: PathBuf,
    /// Output EXR (default: the recipe's name with `.exr`, in the current directory).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Output PNG (default: the EXR's path with `.png`).
    #[arg(long)]
    pub png: Option<PathBuf>,
    /// Do not write a PNG.
    #[arg(long, conflicts_with = "png")]
    pub no_png: bool,
    /// Samples per pixel (default: the recipe's, else 64).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_048_576))]
    pub spp: Option<u32>,
    /// Render only samples `A..B` of every pixel (of the render's `--spp`) and write a part file:
    /// the EXR of those samples with their exact sums, for `lapidary merge` (docs/farm.md). No
    /// PNG unless `--png` names one.
    #[arg(long, value_name = "A..B", value_parser = crate::render::part::parse_range)]
    pub samples: Option<std::ops::Range<u32>>,
    /// Image size `WxH` in pixels (default: the recipe's, else 640x480).
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Seed of the pixel samples (default: the recipe's `render.seed`, else 0).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Worker threads (default: one per core). The image does not depend on it.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    /// Sample generator (default: the recipe's, else sobol).
    #[arg(long, value_enum)]
    pub sampler: Option<SamplerArg>,
    /// Longest path in scattering events (default: the recipe's, else 8).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub max_depth: Option<u32>,
    /// Most scattering events inside a translucent body's medium per path (default: the
    /// recipe's, else 256).
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=4096))]
    pub medium_depth: Option<u32>,
    /// Whether a body's medium scatters (`off`: absorption only; default: the recipe's, else on).
    #[arg(long, value_parser = super::knobs::switch_arg)]
    pub medium_scattering: Option<bool>,
    /// Whether a manifold walk that fails from the straight line retries by the continuation
    /// in the index (default: the recipe's, else off).
    #[arg(long, value_parser = super::knobs::switch_arg)]
    pub manifold_continuation: Option<bool>,
    /// Most halvings of a failing manifold walk step before it gives up (default: recipe's, else 1)
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=8))]
    pub manifold_halvings: Option<u32>,
    /// Stop after this many seconds, setup included, and write what was rendered (marked
    /// partial; nothing when not one pass completed).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_seconds)]
    pub time_limit: Option<f64>,
    /// Move the recipe's view without editing it: camera orbit and zoom about the stone, stone
    /// tilt, light turn, as `lapidary preview` shows them (e.g. `yaw=30,pitch=-10,zoom=0.8,
    /// tilt_x=5,light_yaw=90`; degrees; see docs/preview.md).
    #[arg(long, allow_hyphen_values = true, value_parser = crate::scene::view::View::parse)]
    pub view: Option<crate::scene::view::View>,
    /// PNG exposure in stops (default: the recipe's, else 0).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_exposure)]
    pub exposure: Option<f32>,
    /// PNG tone curve.
    #[arg(long, value_enum, default_value_t = CurveArg::Filmic)]
    pub tonemap: CurveArg,
    /// Direct-light estimators (for testing the integrator; `mis` is always best).
    #[arg(long, value_enum, default_value_t = StrategyArg::Mis)]
    pub strategy: StrategyArg,
    /// Accuracy knobs (override the recipe's).
    #[command(flatten)]
    pub knobs: super::knobs::KnobArgs,
    /// The lane path loop (eight paths at a time in SIMD registers, docs/design.md §13) where the
    /// scene allows it: the same image bit for bit as the scalar loop, which is the default
    /// because it is faster today (the lane loop's phases are not all vectorised yet).
    #[arg(long, value_parser = super::knobs::switch_arg)]
    pub lanes: Option<bool>,
    /// Also measure the Stokes vector of the light reaching the camera, before any analyser, and
    /// write it as the AOVs `S0`–`S3` (RGB each; frame: the image's right and up). Turns
    /// polarised transport on; one pass measures all four (docs/polarisation.md).
    #[arg(long)]
    pub stokes: bool,
    /// No progress bar and no summary.
    #[arg(short, long)]
    pub quiet: bool,
    /// Refuse, before allocating, a render estimated to need more memory than this (e.g. `8G`,
    /// `512M`; default: the memory available, else 4G).
    #[arg(long, value_parser = crate::render::memory::parse_size)]
    pub max_memory: Option<u64>,
}

/// `--sampler` values.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum SamplerArg {
    /// Owen-scrambled Sobol' (best with a power-of-two spp).
    Sobol,
    /// Independent hashed uniforms.
    Independent,
}

/// `--tonemap` values.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum CurveArg {
    /// A filmic shoulder that keeps highlights from clipping.
    Filmic,
    /// Plain clamp to [0, 1].
    Clamp,
}

/// `--strategy` values.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum StrategyArg {
    /// Light and BSDF sampling with MIS (power heuristic).
    Mis,
    /// Light sampling only.
    Light,
    /// BSDF sampling only.
    Bsdf,
}

impl StrategyArg {
    /// The value as written on the command line.
    pub fn name(self) -> &'static str {
        match self {
            StrategyArg::Mis => "mis",
            StrategyArg::Light => "light",
            StrategyArg::Bsdf => "bsdf",
        }
    }
}

pub(crate) use super::args::{parse_exposure, parse_seconds, parse_size};

/// The Ctrl-C / SIGTERM flag, installed once per process. The first signal sets it; the second
/// removes this process's temporary files and exits with 130 at once.
pub(crate) fn interrupted() -> &'static AtomicBool {
    static FLAG: OnceLock<&'static AtomicBool> = OnceLock::new();
    FLAG.get_or_init(|| {
        let flag: &'static AtomicBool = Box::leak(Box::new(AtomicBool::new(false)));
        // If a handler cannot be installed, Ctrl-C simply kills the process as usual.
        let _ = ctrlc::set_handler(move || {
            if flag.swap(true, Ordering::SeqCst) {
                eprintln!("second interrupt: aborted, nothing written");
                abort_process(130);
            }
        });
        flag
    })
}

/// Where the EXR and PNG go.
fn outputs(args: &RenderArgs) -> Result<(PathBuf, Option<PathBuf>)> {
    let exr = match &args.output {
        Some(p) => p.clone(),
        None => {
            let stem = args
                .recipe
                .file_stem()
                .ok_or_else(|| anyhow!("{}: not a file name", args.recipe.display()))?;
            PathBuf::from(stem).with_extension("exr")
        }
    };
    let png = if args.no_png || (args.samples.is_some() && args.png.is_none()) {
        None
    } else {
        Some(
            args.png
                .clone()
                .unwrap_or_else(|| exr.with_extension("png")),
        )
    };
    Ok((exr, png))
}

/// The scene with the command line's overrides applied.
fn settings(args: &RenderArgs, scene: &mut Scene) {
    let r = &mut scene.stage.render;
    if let Some(spp) = args.spp {
        r.spp = spp;
    }
    if let Some((w, h)) = args.size {
        r.width = w;
        r.height = h;
    }
    if let Some(seed) = args.seed {
        r.seed = seed;
    }
    if let Some(s) = args.sampler {
        r.sampler = match s {
            SamplerArg::Sobol => SamplerKind::Sobol,
            SamplerArg::Independent => SamplerKind::Independent,
        };
    }
    if let Some(d) = args.max_depth {
        r.max_depth = d;
    }
    if let Some(d) = args.medium_depth {
        r.medium_depth = d;
    }
    if let Some(s) = args.medium_scattering {
        r.medium_scattering = s;
    }
    if let Some(c) = args.manifold_continuation {
        r.manifold_continuation = c;
    }
    if let Some(h) = args.manifold_halvings {
        r.manifold_halvings = h;
    }
    if let Some(e) = args.exposure {
        r.exposure = e;
    }
    if let Some(v) = &args.view {
        v.apply(&mut scene.stage);
    }
    scene.stage.stokes = args.stokes;
}

/// The accuracy knobs of the command line, with polarised transport forced on by `--stokes`.
fn accuracy(args: &RenderArgs) -> Result<crate::scene::accuracy::Accuracy> {
    let acc = args.knobs.accuracy().map_err(anyhow::Error::msg)?;
    super::knobs::with_stokes(acc, args.stokes)
}

/// Runs `lapidary render`; returns whether the render was interrupted by Ctrl-C or SIGTERM
/// (exit 130). A render stopped by `--time-limit` before its first pass is an error (exit 1).
pub fn run(args: &RenderArgs) -> Result<bool> {
    // Installed first, so that a signal during setup also stops cleanly. The flag is never
    // reset: a signal that arrives right after the handler is installed must not be lost.
    let cancel = interrupted();
    let started = Instant::now();
    if args.samples.is_some() && args.view.as_ref().is_some_and(|v| !v.is_identity()) {
        // A part's metadata does not record the view, so `merge` could not tell parts of two
        // views apart: refused rather than merged wrongly.
        bail!(
            "--view with --samples: part renders do not record the view; render the whole image \
             with --view, or put the camera in the recipe for a farm render"
        );
    }
    let (exr_path, png_path) = outputs(args)?;
    let mut plan = OutputPlan::new();
    plan.input(&args.recipe, "the recipe")?;
    let exr_file = plan.output(&exr_path, Format::Exr)?;
    let png_file = match &png_path {
        Some(p) => Some(plan.output(p, Format::Png)?),
        None => None,
    };
    let loaded = super::load::load_scene(&args.recipe, &accuracy(args)?, Some(&mut plan))?;
    let mut scene = loaded.scene;
    settings(args, &mut scene);
    // A range past the render's samples is refused before any setup.
    let spp = scene.stage.render.spp;
    if let Some(range) = &args.samples
        && range.end > spp
    {
        bail!(
            "--samples {}: goes past the render's {spp} spp (its samples are 0..{spp}; set --spp \
             for the whole render)",
            crate::render::part::format_range(range),
        );
    }
    let limit = args
        .max_memory
        .unwrap_or_else(crate::render::memory::default_limit);
    crate::render::memory::MemoryEstimate::of(&scene)
        .check(limit)
        .map_err(|e| anyhow!("{}: {e}", args.recipe.display()))?;
    // The time limit covers setup too.
    let deadline = args
        .time_limit
        .map(|s| Instant::now() + Duration::from_secs_f64(s));
    let setup = crate::render::world::Setup {
        deadline,
        cancel: Some(cancel),
        progress: !args.quiet,
        cache: None,
    };
    let world = match super::load::build_world(&args.recipe, &scene, &setup) {
        Ok(w) => w,
        Err(e) if e.stopped() && cancel.load(Ordering::SeqCst) => {
            eprintln!("{e} (Ctrl-C or SIGTERM)");
            return Ok(true);
        }
        Err(e) => return Err(e.into()),
    };
    let setup_time = started.elapsed();
    for w in world.environment.warnings() {
        eprintln!("warning: {}: {w}", args.recipe.display());
    }
    let r = scene.stage.render;
    let spp_here = args.samples.as_ref().map_or(r.spp, |s| s.end - s.start);
    let total = u64::from(r.width) * u64::from(r.height) * u64::from(spp_here);
    let bar = if args.quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(total)
    };
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {wide_bar} {human_pos}/{human_len} samples \
             {per_sec:0} ETA {eta}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let progress = |n: u64| bar.inc(n);
    let control = Control {
        threads: args.threads.map(|t| t as usize),
        strategy: match args.strategy {
            StrategyArg::Mis => Strategy::Mis,
            StrategyArg::Light => Strategy::LightOnly,
            StrategyArg::Bsdf => Strategy::BsdfOnly,
        },
        deadline,
        cancel: Some(cancel),
        progress: Some(&progress),
        on_pass: None,
        samples: args.samples.clone(),
        lanes: args.lanes == Some(true),
    };
    let rendered = render_scene(&world, &scene, &control);
    bar.finish_and_clear();
    let was_interrupted = cancel.load(Ordering::SeqCst);
    if rendered.stats.spp_complete == 0 {
        // Not one complete pass: some pixels would have no sample at all.
        if was_interrupted {
            eprintln!(
                "stopped by Ctrl-C or SIGTERM before the first pass over the image completed: \
                 nothing written"
            );
            return Ok(true);
        }
        bail!(
            "--time-limit {} s ended before the first pass over the image completed: nothing \
             written (allow more time, or render fewer pixels)",
            args.time_limit.unwrap_or_default()
        );
    }

    let meta = Metadata::of(&args.recipe.display().to_string(), &scene);
    // Both files or neither: a PNG that cannot be written leaves the old EXR in place.
    all_or_nothing(|| {
        match &args.samples {
            Some(requested) => {
                let part = PartSettings {
                    requested: requested.clone(),
                    strategy: args.strategy.name().to_string(),
                    exposure: r.exposure,
                };
                let (img, raw) = part_image(&rendered, &meta, &part);
                write_exr_raw(&exr_file, &img, &raw)
            }
            None => write_exr(&exr_file, &exr_image(&rendered, &meta)),
        }
        .with_context(|| format!("writing {}", exr_path.display()))?;
        if let (Some(png), Some(shown)) = (&png_file, &png_path) {
            let tm = ToneMap {
                exposure: r.exposure,
                curve: match args.tonemap {
                    CurveArg::Filmic => Curve::Filmic,
                    CurveArg::Clamp => Curve::Clamp,
                },
            };
            write_png(png, r.width, r.height, &rendered.film.rgb(), &tm)
                .with_context(|| format!("writing {}", shown.display()))?;
        }
        Ok(())
    })?;
    if !args.quiet {
        out!(
            "{}",
            summary(
                args,
                &scene,
                &rendered,
                setup_time,
                &exr_path,
                png_path.as_deref(),
                was_interrupted
            )
        );
    }
    Ok(was_interrupted)
}

/// Thousands separated by spaces.
fn grouped(n: u64) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i).is_multiple_of(3) {
            out.push(' ');
        }
        out.push(c);
    }
    out
}

/// The closing summary. The time is split into setup (reading the recipe, building the material
/// tables, maps and lights: `setup`) and rendering (the samples: the rates are per second of it).
fn summary(
    args: &RenderArgs,
    scene: &Scene,
    r: &Rendered,
    setup: Duration,
    exr: &Path,
    png: Option<&Path>,
    interrupted: bool,
) -> String {
    let s = &r.stats;
    let set = &scene.stage.render;
    let secs = s.elapsed.as_secs_f64().max(1e-9);
    let setup = setup.as_secs_f64();
    let mut out = format!(
        "rendered {}: {}x{}, {} spp ({}), depth {} in {:.1} s: setup {:.1} s, rendering {:.1} s\n",
        args.recipe.display(),
        set.width,
        set.height,
        set.spp,
        set.sampler.name(),
        set.max_depth,
        setup + secs,
        setup,
        secs
    );
    if let Some(range) = &args.samples {
        out += &format!(
            "  part: samples {} of 0..{} (merge the parts with `lapidary merge`)\n",
            crate::render::part::format_range(&(range.start..range.start + s.spp_complete)),
            set.spp
        );
    }
    if s.partial {
        let why = if interrupted {
            "Ctrl-C or SIGTERM"
        } else {
            "time limit"
        };
        out += &format!(
            "  stopped by {why}: partial, {} of {} spp in every pixel (the EXR says so)\n",
            s.spp_complete,
            args.samples.as_ref().map_or(set.spp, |r| r.end - r.start)
        );
    }
    out += &format!(
        "  {} paths ({:.0} paths/s), {} rays ({:.2} M rays/s), {} dropped samples\n",
        grouped(s.paths),
        s.paths as f64 / secs,
        grouped(s.rays),
        s.rays as f64 / secs / 1e6,
        grouped(s.dropped)
    );
    if let Some(store) = crate::bsdf::store::global() {
        let (read, measured) = store.counts();
        if read + measured > 0 {
            out += &format!(
                "  material tables: {measured} measured, {read} read back ({})\n",
                store.dir().display()
            );
        }
    }
    let effects: Vec<&str> = scene.effects.iter().map(Effect::name).collect();
    out += &format!(
        "  effects: {}\n",
        if effects.is_empty() {
            "none".to_string()
        } else {
            effects.join(", ")
        }
    );
    if !scene.accuracy.is_default() {
        out += &format!("  accuracy knobs: {}\n", scene.accuracy);
    }
    out += &format!("  wrote {}", exr.display());
    if let Some(p) = png {
        out += &format!(", {}", p.display());
    }
    out.push('\n');
    out
}
