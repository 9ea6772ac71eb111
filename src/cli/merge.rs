//! `lapidary merge PARTS... -o OUT.exr`: adds part renders (`lapidary render --samples A..B`)
//! into the render of their whole sample range. The parts must share the recipe hash, seed,
//! size, spp, sampler, depth, knobs and strategy, and their ranges must be disjoint and cover
//! `0..spp`; every problem is listed (files that disagree, ranges missing or overlapping) and
//! nothing is written. Nothing a part says is believed that can be checked ([`Part::read`]): a
//! part is refused by its file type before it is opened (a FIFO would block), and its attributes
//! must lie in the ranges `lapidary render` accepts and agree with its per-pixel sums (every
//! pixel holds exactly the samples of the part's range, kept or dropped). The sums are exact integers ([`crate::render::fixed`]), so the EXR equals
//! a one-machine render bit for bit (all channels; `lapidary.render_time` is the parts' sum).

use crate::image::atomic::all_or_nothing;
use crate::image::outputs::{Format, OutputPlan};
use crate::image::{Curve, ExrImage, ToneMap, write_exr, write_png};
use crate::render::film_channels;
use crate::render::part::{Part, merge};
use anyhow::{Context, Result, anyhow, bail};
use clap::Args;
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `lapidary merge`.
#[derive(Debug, Args)]
pub struct MergeArgs {
    /// Part files (EXR) written by `lapidary render --samples A..B`, in any order.
    #[arg(required = true, num_args = 1..=65_536)]
    pub parts: Vec<PathBuf>,
    /// The merged EXR.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Output PNG (default: the EXR's path with `.png`).
    #[arg(long)]
    pub png: Option<PathBuf>,
    /// Do not write a PNG.
    #[arg(long, conflicts_with = "png")]
    pub no_png: bool,
    /// PNG tone curve.
    #[arg(long, value_enum, default_value_t = super::render::CurveArg::Filmic)]
    pub tonemap: super::render::CurveArg,
    /// No summary.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Runs `lapidary merge`.
pub fn run(args: &MergeArgs) -> Result<()> {
    let start = Instant::now();
    let mut plan = OutputPlan::new();
    for p in &args.parts {
        plan.input(p, "a part")?;
    }
    let exr_file = plan.output(&args.output, Format::Exr)?;
    let png_path = if args.no_png {
        None
    } else {
        Some(
            args.png
                .clone()
                .unwrap_or_else(|| args.output.with_extension("png")),
        )
    };
    let png_file = match &png_path {
        Some(p) => Some(plan.output(p, Format::Png)?),
        None => None,
    };
    let mut parts = Vec::with_capacity(args.parts.len());
    let mut unreadable = Vec::new();
    for p in &args.parts {
        match Part::read(p) {
            Ok(part) => parts.push(part),
            Err(e) => unreadable.push(e),
        }
    }
    if !unreadable.is_empty() {
        bail!("{}", unreadable.join("\n"));
    }
    let n = parts.len();
    let read_secs = start.elapsed().as_secs_f64();
    let merged = merge(parts).map_err(|e| anyhow!("the parts do not make one render:\n{e}"))?;
    let film = &merged.film;
    let image = ExrImage {
        width: film.width,
        height: film.height,
        channels: film_channels(film),
        attributes: merged.attributes.clone(),
    };
    let exposure = merged.exposure;
    all_or_nothing(|| {
        write_exr(&exr_file, &image)
            .with_context(|| format!("writing {}", args.output.display()))?;
        if let (Some(png), Some(shown)) = (&png_file, &png_path) {
            let tm = ToneMap {
                exposure,
                curve: match args.tonemap {
                    super::render::CurveArg::Filmic => Curve::Filmic,
                    super::render::CurveArg::Clamp => Curve::Clamp,
                },
            };
            write_png(png, film.width, film.height, &film.rgb(), &tm)
                .with_context(|| format!("writing {}", shown.display()))?;
        }
        Ok(())
    })?;
    if !args.quiet {
        outln!(
            "merged {n} parts: {}x{}, {} spp, {:.1} s of rendering; read in {read_secs:.2} s, \
             merged and written in {:.2} s",
            film.width,
            film.height,
            merged.spp,
            merged.render_time,
            start.elapsed().as_secs_f64() - read_secs
        );
        let mut wrote = format!("  wrote {}", args.output.display());
        if let Some(p) = &png_path {
            wrote += &format!(", {}", p.display());
        }
        outln!("{wrote}");
    }
    Ok(())
}
