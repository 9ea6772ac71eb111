//! `lapidary brdf`: look at a layered BRDF from outside — list a library, evaluate `f` and `pdf` for
//! directions read from stdin, draw samples, measure directional albedo, plot slices.

use super::plot;
use crate::bsdf::measure::{Estimate, albedo_by_sampling, direction_deg};
use crate::bsdf::{Bxdf, LayeredBsdf, Model, ReferenceParams};
use crate::recipe::MaterialLibrary;
use crate::sampler::{Rng, hash_words};
use anyhow::{Context, Result, bail};
use clap::ValueEnum;
use glam::Vec3;
use rayon::prelude::*;
use std::io::{BufRead, Write};
use std::path::PathBuf;

/// Largest `--walks`: each Reference evaluation costs this many random walks.
pub const MAX_WALKS: u32 = 4096;
/// Largest `--sample N` (lines printed).
pub const MAX_SAMPLE: u64 = 100_000_000;
/// Largest `--samples` per albedo estimate (`--albedo` makes 90 estimates).
pub const MAX_SAMPLES: u64 = 10_000_000;

/// Evaluation model chosen on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ModelArg {
    /// Course eqs. 3.1–3.3 as published.
    Course,
    /// Energy-consistent local model.
    Corrected,
    /// Stochastic random walk (see --walks).
    Reference,
}

/// A viewing direction in degrees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wo {
    /// Polar angle from the normal, 0 ..< 90.
    pub theta: f32,
    /// Azimuth.
    pub phi: f32,
}

fn parse_wo(s: &str) -> Result<Wo, String> {
    let mut it = s.split(',');
    let num = |t: Option<&str>, what: &str| -> Result<Option<f32>, String> {
        match t {
            None => Ok(None),
            Some(t) => t
                .trim()
                .parse::<f32>()
                .map(Some)
                .map_err(|_| format!("{what} `{t}` is not a number")),
        }
    };
    let theta = num(it.next(), "THETA_DEG")?.ok_or("expected THETA_DEG[,PHI_DEG]")?;
    let phi = num(it.next(), "PHI_DEG")?.unwrap_or(0.0);
    if it.next().is_some() {
        return Err("expected THETA_DEG[,PHI_DEG] (at most two numbers)".into());
    }
    if !(0.0..90.0).contains(&theta) {
        return Err(format!(
            "THETA_DEG = {theta} is out of range: allowed 0 ..< 90"
        ));
    }
    if !phi.is_finite() {
        return Err("PHI_DEG must be finite".into());
    }
    Ok(Wo { theta, phi })
}

/// Arguments of `lapidary brdf`.
#[derive(Debug, clap::Args)]
#[command(group = clap::ArgGroup::new("mode").multiple(false))]
pub struct BrdfArgs {
    /// Material library (RON). Default: the built-in course catalogue (materials/course.ron).
    pub file: Option<PathBuf>,
    /// Print the material names, one per line.
    #[arg(long, group = "mode")]
    pub list: bool,
    /// The material to inspect.
    #[arg(long, short)]
    pub material: Option<String>,
    /// Evaluation model; default: what the material says (Corrected unless it says otherwise).
    #[arg(long, value_enum)]
    pub model: Option<ModelArg>,
    /// Random walks per evaluation for the Reference model, 1 ..= 4096.
    #[arg(long, default_value_t = ReferenceParams::default().samples,
          value_parser = clap::value_parser!(u32).range(1..=i64::from(MAX_WALKS)))]
    pub walks: u32,
    /// Viewing direction `THETA_DEG[,PHI_DEG]` from the normal (0 ≤ θ < 90).
    #[arg(long, value_parser = parse_wo, default_value = "45,0", allow_hyphen_values = true)]
    pub wo: Wo,
    /// Read directions `x y z` (wi, local frame, any non-zero length: they are normalised) from
    /// stdin; print `f_r f_g f_b pdf` per line.
    #[arg(long, group = "mode")]
    pub eval: bool,
    /// Draw N samples, 1 ..= 10⁸; print `x y z w_r w_g w_b pdf` per line (a failed sample prints
    /// zeros).
    #[arg(long, group = "mode", value_name = "N",
          value_parser = clap::value_parser!(u64).range(1..=MAX_SAMPLE))]
    pub sample: Option<u64>,
    /// Seed for --sample and --albedo.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Print the directional albedo per channel for θo = 0 … 89°, with standard errors.
    #[arg(long, group = "mode")]
    pub albedo: bool,
    /// Plot in-plane slices at a few θo and the albedo curve, the three models overlaid.
    #[arg(long, group = "mode", value_name = "OUT.png")]
    pub plot: Option<PathBuf>,
    /// Samples per albedo estimate (--albedo, --plot, and the catalogue summary), 1 ..= 10⁷.
    #[arg(long, default_value_t = 50_000,
          value_parser = clap::value_parser!(u64).range(1..=MAX_SAMPLES))]
    pub samples: u64,
}

/// Runs `lapidary brdf`.
pub fn run(args: &BrdfArgs) -> Result<()> {
    // The plot's path is checked before any work (see `crate::image::outputs`).
    let plot_file = match &args.plot {
        Some(p) => {
            let mut plan = crate::image::outputs::OutputPlan::new();
            if let Some(f) = &args.file {
                plan.input(f, "the material library")?;
            }
            Some(plan.output(p, crate::image::outputs::Format::Png)?)
        }
        None => None,
    };
    let lib = match &args.file {
        Some(p) => MaterialLibrary::load(p)?,
        None => MaterialLibrary::course(),
    };
    let out = std::io::stdout();
    let mut out = std::io::BufWriter::new(out.lock());
    if args.list {
        for n in lib.names() {
            writeln!(out, "{n}")?;
        }
        return Ok(out.flush()?);
    }
    let Some(name) = &args.material else {
        if args.eval || args.sample.is_some() || args.albedo || args.plot.is_some() {
            bail!("--material NAME is required (see --list)");
        }
        return summary(&lib, args, &mut out);
    };
    let model = args.model.map(|m| model_of(m, args.walks));
    let bsdf = lib.build(name, model)?;
    let wo = direction_deg(args.wo.theta, args.wo.phi);
    if args.eval {
        eval_stdin(&bsdf, wo, &mut out)?;
    } else if let Some(n) = args.sample {
        let mut rng = Rng::new(hash_words(&[args.seed, 0x5a3b1e]));
        for _ in 0..n {
            match bsdf.sample(wo, rng.uniform(), rng.uniform2()) {
                Some(s) => writeln!(
                    out,
                    "{} {} {} {} {} {} {}",
                    s.wi.x, s.wi.y, s.wi.z, s.weight[0], s.weight[1], s.weight[2], s.pdf
                )?,
                None => writeln!(out, "0 0 0 0 0 0 0")?,
            }
        }
    } else if args.albedo {
        writeln!(
            out,
            "# {name}: {}; {} samples per angle, seed {}",
            bsdf.knobs(),
            args.samples,
            args.seed
        )?;
        writeln!(
            out,
            "# theta_o  albedo_r albedo_g albedo_b  stderr_r stderr_g stderr_b  samples"
        )?;
        let rows: Vec<(u32, Estimate)> = (0..90u32)
            .into_par_iter()
            .map(|t| {
                (
                    t,
                    albedo_by_sampling(
                        &bsdf,
                        direction_deg(t as f32, args.wo.phi),
                        args.samples,
                        args.seed,
                    ),
                )
            })
            .collect();
        for (t, e) in rows {
            writeln!(
                out,
                "{t:>3} {:.6} {:.6} {:.6} {:.2e} {:.2e} {:.2e} {}",
                e.mean[0],
                e.mean[1],
                e.mean[2],
                e.std_error[0],
                e.std_error[1],
                e.std_error[2],
                e.samples
            )?;
        }
    } else if let Some(path) = &args.plot {
        let models = [
            Model::Course,
            Model::Corrected,
            model_of(ModelArg::Reference, args.walks.max(256)),
        ];
        let stacks: Vec<LayeredBsdf> = models.iter().map(|&m| bsdf.with_model(m)).collect();
        let file = plot_file.as_deref().unwrap_or(path);
        plot::plot_stack(name, &stacks, args.samples.min(20_000), args.seed, file)?;
        writeln!(out, "wrote {}", path.display())?;
    } else {
        summary_one(name, &bsdf, args, &mut out)?;
    }
    Ok(out.flush()?)
}

fn model_of(m: ModelArg, walks: u32) -> Model {
    match m {
        ModelArg::Course => Model::Course,
        ModelArg::Corrected => Model::Corrected,
        ModelArg::Reference => Model::Reference(ReferenceParams {
            samples: walks,
            ..ReferenceParams::default()
        }),
    }
}

fn eval_stdin(bsdf: &LayeredBsdf, wo: Vec3, out: &mut impl Write) -> Result<()> {
    let stdin = std::io::stdin();
    for (i, line) in stdin.lock().lines().enumerate() {
        let line = line.context("reading stdin")?;
        let t = line.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        let wi = parse_direction(t).map_err(|e| anyhow::anyhow!("stdin:{}: {e}", i + 1))?;
        let f = bsdf.eval(wo, wi);
        writeln!(out, "{} {} {} {}", f[0], f[1], f[2], bsdf.pdf(wo, wi))?;
    }
    Ok(())
}

/// A direction `x y z` of any non-zero finite length, normalised. Read in double precision and
/// divided by its largest component first, so lengths from 1e-300 to 1e300 all work.
fn parse_direction(t: &str) -> Result<Vec3, String> {
    let v: Vec<f64> = t
        .split_whitespace()
        .map(|x| x.parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("expected three numbers `x y z`, got `{t}`"))?;
    let [x, y, z] = v[..] else {
        return Err(format!("expected three numbers `x y z`, got `{t}`"));
    };
    if !(x.is_finite() && y.is_finite() && z.is_finite()) {
        return Err(format!("expected three finite numbers `x y z`, got `{t}`"));
    }
    let m = x.abs().max(y.abs()).max(z.abs());
    if m == 0.0 {
        return Err(format!("the direction ({t}) has zero length"));
    }
    let (x, y, z) = (x / m, y / m, z / m);
    let len = (x * x + y * y + z * z).sqrt();
    Ok(Vec3::new(
        (x / len) as f32,
        (y / len) as f32,
        (z / len) as f32,
    ))
}

fn summary_one(
    name: &str,
    bsdf: &LayeredBsdf,
    args: &BrdfArgs,
    out: &mut impl Write,
) -> Result<()> {
    writeln!(out, "{name}: {} coat(s); {}", bsdf.coats(), bsdf.knobs())?;
    for t in [0.0, 30.0, 60.0, 85.0] {
        let e = albedo_by_sampling(bsdf, direction_deg(t, args.wo.phi), args.samples, args.seed);
        writeln!(
            out,
            "  albedo at θo = {t:>2}°: {:.4} {:.4} {:.4} (± {:.1e})",
            e.mean[0],
            e.mean[1],
            e.mean[2],
            e.std_error.max_channel()
        )?;
    }
    Ok(())
}

/// The main job on built-in defaults: the catalogue's albedo (luminance) under the three models.
fn summary(lib: &MaterialLibrary, args: &BrdfArgs, out: &mut impl Write) -> Result<()> {
    let angles = [0.0f32, 45.0, 85.0];
    let models = [
        Model::Course,
        Model::Corrected,
        model_of(ModelArg::Reference, args.walks),
    ];
    let n = args.samples.min(20_000);
    writeln!(
        out,
        "Directional albedo (Rec.709 luminance) of {} — {n} samples per entry, seed {}",
        lib.file(),
        args.seed
    )?;
    writeln!(
        out,
        "{:<24} {:>#25} {:>#25} {:>#25}",
        "", models[0], models[1], models[2]
    )?;
    writeln!(
        out,
        "{:<24} {:>25} {:>25} {:>25}",
        "material  \\  θo =", "0°     45°     85°", "0°     45°     85°", "0°     45°     85°"
    )?;
    let names: Vec<String> = lib.names().map(str::to_owned).collect();
    let rows: Vec<Result<String>> = names
        .par_iter()
        .map(|name| {
            let base = lib.build(name, Some(Model::Corrected))?;
            let mut row = format!("{name:<24}");
            for m in models {
                let b = base.with_model(m);
                let cells: Vec<String> = angles
                    .iter()
                    .map(|&t| {
                        format!(
                            "{:.3}",
                            albedo_by_sampling(&b, direction_deg(t, 0.0), n, args.seed)
                                .mean
                                .luminance()
                        )
                    })
                    .collect();
                row += &format!(" {:>25}", cells.join("   "));
            }
            Ok(row)
        })
        .collect();
    for r in rows {
        writeln!(out, "{}", r?)?;
    }
    writeln!(
        out,
        "\nCourse lacks the 1/η² solid-angle compression: glossy bases under a coat gain energy."
    )?;
    writeln!(
        out,
        "Try: lapidary brdf --material silver_paint --plot silver_paint.png"
    )?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directions_of_any_length_are_normalised() {
        for t in ["0 0 1", "0 0 1e-300", "0 0 1e300", "3 0 4", "1e-40 0 1e-40"] {
            let v = parse_direction(t).unwrap();
            assert!((v.length() - 1.0).abs() < 1e-6, "{t}: {v}");
        }
        assert_eq!(parse_direction("0 0 5e-320").unwrap(), Vec3::Z);
        let v = parse_direction("3e300 0 4e300").unwrap();
        assert!((v - Vec3::new(0.6, 0.0, 0.8)).length() < 1e-6);
        assert!(
            parse_direction("0 0 0")
                .unwrap_err()
                .contains("zero length")
        );
        assert!(parse_direction("0 0 inf").unwrap_err().contains("finite"));
        assert!(parse_direction("0 NaN 1").unwrap_err().contains("finite"));
        assert!(parse_direction("0 1").is_err() && parse_direction("a b c").is_err());
    }
}
