//! Issue 21 on a real Slurm: a single-node cluster (Debian's `slurm-wlm` and `munge`, started by
//! `scripts/slurm-local`) renders a gem as a 4-part job array with a merge job after it, and a
//! 3-recipe regression suite as an array with its table after it; the results must equal the
//! one-machine render bit for bit and the local table row for row. Then one part is deleted and
//! the farm re-run: only that part is rendered again, and the merge is again identical.
//!
//! Ignored by `cargo test` (it needs root and the Slurm packages); `.ci/run` installs them and
//! runs it, and README names the command:
//! `scripts/slurm-local install && cargo test --test slurm -- --ignored --nocapture`.
//! It prints the figures of issue 21's report: the single render's time, the 4-part render's
//! time through Slurm (submission to merged EXR), and the merge's cost.

use lapidary::image::{ExrImage, read_exr};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Instant;

#[path = "common/scratch.rs"]
mod scratch;
use scratch::{Scratch, text};
#[path = "common/farm.rs"]
mod farm;
use farm::{RECIPE, ok, table};

const SUNSTONE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/gems/sunstone.ron");
const SCRIPT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/scripts/slurm-local");
const ARGS: [&str; 4] = ["--size", "320x240", "--spp", "64"];

/// The test cluster; stopped when dropped, whatever happened.
struct Cluster {
    dir: PathBuf,
    conf: String,
}

impl Cluster {
    fn start(dir: &Path) -> Cluster {
        let out = Command::new(SCRIPT).arg("start").arg(dir).output().unwrap();
        assert!(
            out.status.success(),
            "starting Slurm failed (run `scripts/slurm-local install` first):\n{}{}",
            text(&out.stdout),
            text(&out.stderr)
        );
        let stdout = text(&out.stdout);
        let conf = stdout
            .lines()
            .find_map(|l| l.strip_prefix("export SLURM_CONF="))
            .expect("slurm-local prints SLURM_CONF")
            .trim()
            .to_string();
        Cluster {
            dir: dir.to_path_buf(),
            conf,
        }
    }

    /// Waits until the jobs ended; panics unless all completed.
    fn wait(&self, jobs: &[String]) {
        let out = Command::new(SCRIPT)
            .args(["wait", "-t", "900"])
            .args(jobs)
            .env("SLURM_CONF", &self.conf)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "jobs {jobs:?} did not all complete:\n{}{}",
            text(&out.stdout),
            text(&out.stderr)
        );
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        let _ = Command::new(SCRIPT).arg("stop").arg(&self.dir).output();
    }
}

fn lapidary(dir: &Path, conf: &str, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lapidary"))
        .args(args)
        .current_dir(dir)
        .env("SLURM_CONF", conf)
        .output()
        .expect("run lapidary")
}

/// The job ids a `--submit` run printed ("submitted array job 12 and merge job 13").
fn job_ids(stdout: &str) -> Vec<String> {
    stdout
        .lines()
        .filter(|l| l.contains("submitted"))
        .flat_map(|l| l.split_whitespace())
        .map(|w| w.trim_end_matches(|c: char| !c.is_ascii_digit()))
        .filter(|w| !w.is_empty() && w.chars().all(|c| c.is_ascii_digit()))
        .map(str::to_string)
        .collect()
}

fn assert_same_channels(a: &ExrImage, b: &ExrImage) {
    assert_eq!(a.channel_names(), b.channel_names());
    for c in &a.channels {
        let d = b.channel(&c.name).unwrap();
        assert!(
            c.data
                .iter()
                .zip(d)
                .all(|(x, y)| x.to_bits() == y.to_bits()),
            "channel {} differs",
            c.name
        );
    }
}

#[test]
#[ignore = "needs root and Slurm: scripts/slurm-local install, then --ignored"]
fn a_four_part_render_and_a_regress_suite_through_slurm() {
    let s = Scratch::new("slurm", "farm");
    let cluster = Cluster::start(&s.path("cluster"));
    let conf = cluster.conf.clone();

    // The one-machine render.
    let t = Instant::now();
    let mut a = vec!["render", SUNSTONE, "--quiet", "-o", "whole.exr"];
    a.extend(ARGS);
    ok(&lapidary(&s.0, &conf, &a));
    let single = t.elapsed().as_secs_f64();

    // Four parts through Slurm.
    let t = Instant::now();
    let mut a = vec![
        "farm", "slurm", SUNSTONE, "--parts", "4", "--dir", "farm", "--submit",
    ];
    a.extend(ARGS);
    let out = ok(&lapidary(&s.0, &conf, &a));
    let jobs = job_ids(&out);
    assert_eq!(jobs.len(), 2, "{out}");
    cluster.wait(&jobs);
    let farmed = t.elapsed().as_secs_f64();
    let whole = read_exr(&s.path("whole.exr")).unwrap();
    assert_same_channels(&read_exr(&s.path("farm/sunstone.exr")).unwrap(), &whole);
    assert_eq!(
        std::fs::read(s.path("farm/sunstone.png")).unwrap(),
        std::fs::read(s.path("whole.png")).unwrap()
    );
    let merge_log = std::fs::read_to_string(s.path("farm/logs/merge.log")).unwrap();
    eprintln!(
        "single render {single:.1} s; 4 parts through Slurm (submit to merged EXR) {farmed:.1} s \
         = {:.2}x\nmerge job: {}",
        farmed / single,
        merge_log.lines().next().unwrap_or_default()
    );

    // Resume: a lost part is rendered again, alone.
    std::fs::remove_file(s.path("farm/parts/part-2.exr")).unwrap();
    std::fs::remove_file(s.path("farm/sunstone.exr")).unwrap();
    let out = ok(&lapidary(&s.0, &conf, &a));
    assert!(out.contains("1 to render (3 already done)"), "{out}");
    cluster.wait(&job_ids(&out));
    assert_same_channels(&read_exr(&s.path("farm/sunstone.exr")).unwrap(), &whole);

    // A 3-recipe regression suite: one array task per recipe, then the table.
    let suite = s.path("suite");
    std::fs::create_dir_all(&suite).unwrap();
    for (name, grey) in [("a", "0.5"), ("b", "0.8"), ("c", "0.2")] {
        std::fs::write(
            suite.join(format!("{name}.ron")),
            RECIPE.replace("0.5", grey),
        )
        .unwrap();
    }
    ok(&lapidary(
        &s.0,
        &conf,
        &[
            "regress",
            "suite",
            "--update",
            "--ref-spp",
            "512",
            "--size",
            "48x36",
        ],
    ));
    let local = ok(&lapidary(&s.0, &conf, &["regress", "suite"]));
    let out = ok(&lapidary(
        &s.0,
        &conf,
        &[
            "regress",
            "suite",
            "--farm",
            "slurm",
            "--farm-dir",
            "rfarm",
            "--submit",
        ],
    ));
    let jobs = job_ids(&out);
    assert_eq!(jobs.len(), 2, "{out}");
    cluster.wait(&jobs);
    let farmed = std::fs::read_to_string(s.path("rfarm/table.txt")).unwrap();
    assert_eq!(
        table(&farmed),
        table(&local),
        "farm:\n{farmed}\nlocal:\n{local}"
    );
    assert!(
        farmed.contains("summary: 3 passed, 0 failed, 0 unusable"),
        "{farmed}"
    );
    eprintln!("regress table through Slurm:\n{farmed}");
}
