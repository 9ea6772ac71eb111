//! The `--render-arg`s of `lapidary farm slurm`, checked with `lapidary render`'s own parser before
//! anything is written: an argument every task would fail on (`--bogus`, a bad value, a flag given
//! twice) is refused here, not after the whole array has run. So are the options the farm sets
//! itself or that would break a part — each with the farm option to use instead.

use super::text::Text;
use crate::cli::render::RenderArgs;
use crate::cli::{Cli, Command};
use anyhow::{Result, bail};
use clap::Parser;
use clap::error::ErrorKind;

/// The whole render's settings the farm writes into every part's command.
#[derive(Clone, Copy, Debug)]
pub struct Whole {
    /// Samples per pixel of the whole render.
    pub spp: u32,
    /// Image size in pixels.
    pub size: (u32, u32),
    /// Seed of the pixel samples.
    pub seed: u64,
}

impl Whole {
    /// `--spp S --size WxH --seed X`, as separate words.
    pub fn words(&self) -> Vec<String> {
        vec![
            "--spp".into(),
            self.spp.to_string(),
            "--size".into(),
            format!("{}x{}", self.size.0, self.size.1),
            "--seed".into(),
            self.seed.to_string(),
        ]
    }
}

/// Checks `args` as the extra arguments of every part's `lapidary render RECIPE`; returns them as
/// script text. The error lists every argument refused.
pub fn check(args: &[String], recipe: &Text, whole: &Whole) -> Result<Vec<Text>> {
    let texts = args
        .iter()
        .map(|a| Text::new(a, "--render-arg"))
        .collect::<Result<Vec<_>>>()?;
    if args.iter().any(|a| a == "--") {
        bail!("--render-arg --: would end the options of every part's `lapidary render`");
    }
    let parse =
        |words: Vec<&str>| Cli::try_parse_from(["lapidary", "render"].into_iter().chain(words));
    // Parsed without the recipe, the arguments only succeed when one of them is a recipe.
    if parse(args.iter().map(String::as_str).collect()).is_ok() {
        bail!(
            "--render-arg: a recipe among the render arguments; the farm renders RECIPE, its own \
             first argument"
        );
    }
    let mut words = vec![recipe.as_str()];
    words.extend(args.iter().map(String::as_str));
    let given = match parse(words) {
        Ok(Cli {
            command: Command::Render(r),
        }) => r,
        Ok(_) => bail!("--render-arg: not arguments of `lapidary render`"),
        Err(e) => bail!("--render-arg: {}", clap_message(&e)),
    };
    let refused = farm_owned(&given);
    if !refused.is_empty() {
        bail!("{}", refused.join("\n"));
    }
    // The command exactly as a task runs it (range, threads, quiet, output added) must parse too.
    let whole_words = whole.words();
    let mut full: Vec<&str> = vec![recipe.as_str()];
    full.extend(whole_words.iter().map(String::as_str));
    full.extend(args.iter().map(String::as_str));
    full.extend([
        "--samples",
        "0..1",
        "--threads",
        "1",
        "--quiet",
        "-o",
        "part-0.exr",
    ]);
    if let Err(e) = parse(full) {
        bail!(
            "--render-arg: every part's command would fail: {}",
            clap_message(&e)
        );
    }
    Ok(texts)
}

/// Render options the farm sets itself, or that would break a part, with what to use instead.
fn farm_owned(r: &RenderArgs) -> Vec<String> {
    let mut out = Vec::new();
    let mut refuse = |given: bool, flag: &str, instead: &str| {
        if given {
            out.push(format!("--render-arg {flag}: {instead}"));
        }
    };
    refuse(
        r.output.is_some(),
        "-o/--output",
        "the farm names every part's file (DIR/parts/part-N.exr); give the merged render's \
         path with `farm slurm -o`",
    );
    refuse(
        r.png.is_some() || r.no_png,
        "--png/--no-png",
        "parts write no PNG; the merge job writes one beside `farm slurm -o`",
    );
    refuse(
        r.spp.is_some(),
        "--spp",
        "give the whole render's samples per pixel with `farm slurm --spp`",
    );
    refuse(
        r.samples.is_some(),
        "--samples",
        "the farm gives every part its range (choose how many with `farm slurm --parts`)",
    );
    refuse(r.size.is_some(), "--size", "use `farm slurm --size`");
    refuse(r.seed.is_some(), "--seed", "use `farm slurm --seed`");
    refuse(
        r.threads.is_some(),
        "--threads",
        "a task runs on $SLURM_CPUS_PER_TASK threads: give `--cpus-per-task` to sbatch after `--`",
    );
    refuse(r.quiet, "--quiet", "parts always run quietly");
    refuse(
        r.time_limit.is_some(),
        "--time-limit",
        "a part must be complete to merge: give Slurm's `--time` after `--` (a task stopped by \
         it is rendered again on the next run)",
    );
    out
}

/// The first line of a clap error, without its `error: ` prefix.
fn clap_message(e: &clap::Error) -> String {
    match e.kind() {
        ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
            "asks for help or the version, not for a render".into()
        }
        _ => {
            let text = e.to_string();
            let line = text.lines().next().unwrap_or_default();
            line.strip_prefix("error: ").unwrap_or(line).to_string()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(args: &[&str]) -> Result<Vec<Text>> {
        let recipe = Text::new("/g/gem.ron", "the recipe").unwrap();
        let whole = Whole {
            spp: 8,
            size: (8, 6),
            seed: 0,
        };
        let args: Vec<String> = args.iter().map(|s| s.to_string()).collect();
        check(&args, &recipe, &whole)
    }

    #[test]
    fn render_options_pass_and_farm_options_are_refused() {
        assert!(run(&["--model=reference", "--max-depth", "4"]).is_ok());
        assert!(run(&["--exposure", "-2"]).is_ok());
        for (args, needle) in [
            (&["--bogus"][..], "unexpected argument '--bogus'"),
            (&["--spp=64"], "farm slurm --spp"),
            (
                &["--samples=0..4", "--samples=4..8"],
                "cannot be used multiple times",
            ),
            (&["--samples=0..4"], "farm slurm --parts"),
            (&["--time-limit=5"], "a part must be complete"),
            (&["-o", "x.exr"], "farm slurm -o"),
            (&["--threads=2"], "--cpus-per-task"),
            (&["--quiet"], "always run quietly"),
            (&["other.ron"], "a recipe among the render arguments"),
            (&["--"], "would end the options"),
            (&["--max-depth"], "a value is required"),
            (&["--help"], "asks for help"),
        ] {
            let e = run(args).unwrap_err().to_string();
            assert!(e.contains(needle), "{args:?}: {e}");
        }
        // Every refusal is listed.
        let e = run(&["--spp=4", "--seed=2"]).unwrap_err().to_string();
        assert!(e.contains("--spp") && e.contains("--seed"), "{e}");
    }
}
