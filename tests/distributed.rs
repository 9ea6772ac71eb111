//! Issue 21: renders split into sample ranges and merged (`render --samples`, `merge`), and the
//! farm scripts (`farm slurm`, `regress --farm slurm`) written without a cluster. The real
//! single-node Slurm run is `tests/slurm.rs` (ignored here; `.ci/run` runs it).
//!
//! Claims: a render of `0..N` equals, bit for bit, the merge of any split of `0..N` into parts
//! merged in any order, rendered with any thread count — in RGB and in spectral mode, through
//! the library and through the command line (EXR channels and PNG bytes); `merge` refuses parts
//! that do not belong together, naming what is missing, what overlaps and what disagrees, and
//! then writes nothing; the farm writes an array of only the parts still missing.

use lapidary::image::{ExrImage, read_exr};
use lapidary::recipe::GemRecipe;
use lapidary::render::{Control, Film, World, render};
use lapidary::scene::{Effect, Scene};
use std::ops::Range;
use std::path::Path;
use std::process::{Command, Output};

#[path = "common/scratch.rs"]
mod scratch;
use scratch::{Scratch, text};
#[path = "common/farm.rs"]
mod farm;
use farm::{RECIPE, ok, table};

const SUNSTONE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/gems/sunstone.ron");

/// A shipped gem at `w × h` and `spp`.
fn gem(name: &str, w: u32, h: u32, spp: u32) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("gems")
        .join(name);
    let mut s = GemRecipe::load(&path)
        .and_then(|r| r.compile())
        .unwrap_or_else(|e| panic!("{e}"));
    let r = &mut s.stage.render;
    (r.width, r.height, r.spp) = (w, h, spp);
    s
}

/// Renders samples `range` of `scene` on `threads` threads.
fn film(world: &World, scene: &Scene, range: Option<Range<u32>>, threads: usize) -> Film {
    let control = Control {
        threads: Some(threads),
        samples: range,
        ..Control::default()
    };
    let r = render(
        world,
        &scene.stage.camera,
        scene.effects.on(Effect::DepthOfField),
        &scene.stage.render,
        &control,
    );
    assert!(!r.stats.partial);
    r.film
}

/// Merges films of consecutive parts in the order given.
fn merged(parts: &[&Film]) -> Film {
    let mut out = Film::new(parts[0].width, parts[0].height);
    for p in parts {
        for (a, b) in out.pixels.iter_mut().zip(&p.pixels) {
            a.merge(b);
        }
    }
    out
}

/// Whole renders equal merged splits, for several splits, merge orders and thread counts.
fn check_splits(name: &str, scene: &Scene, splits: &[&[u32]]) {
    let world = World::new(scene).expect("world");
    let spp = scene.stage.render.spp;
    let whole = film(&world, scene, None, 2);
    for cuts in splits {
        let mut bounds = vec![0];
        bounds.extend_from_slice(cuts);
        bounds.push(spp);
        let parts: Vec<Film> = bounds
            .windows(2)
            .enumerate()
            .map(|(i, b)| film(&world, scene, Some(b[0]..b[1]), 1 + i % 2))
            .collect();
        let forward: Vec<&Film> = parts.iter().collect();
        let backward: Vec<&Film> = parts.iter().rev().collect();
        // The first part must come first for the material AOV only; sums are order-free.
        let mut rotated: Vec<&Film> = parts.iter().collect();
        rotated.rotate_left(1);
        for (order, list) in [
            ("forward", forward),
            ("backward", backward),
            ("rotated", rotated),
        ] {
            let m = merged(&list);
            let same = m
                .pixels
                .iter()
                .zip(&whole.pixels)
                .filter(|(a, b)| {
                    let mut a = **a;
                    let mut b = **b;
                    (a.material, b.material) = (0, 0);
                    a == b
                })
                .count();
            assert_eq!(
                same,
                whole.pixels.len(),
                "{name}: split {cuts:?} {order}: {same} pixels equal"
            );
            if order == "forward" {
                assert_eq!(
                    m, whole,
                    "{name}: split {cuts:?} forward, material included"
                );
            }
        }
    }
    // A control: the parts really differ from each other and from the whole.
    let a = film(&world, scene, Some(0..spp / 2), 2);
    assert_ne!(a, whole, "{name}: half the samples equal all of them");
}

#[test]
fn rgb_splits_merge_to_the_whole_render_bit_for_bit() {
    let s = gem("sunstone.ron", 40, 30, 16);
    check_splits(
        "sunstone",
        &s,
        &[&[8], &[1], &[15], &[3, 4, 11], &[1, 2, 3, 5, 8, 13]],
    );
    let s = gem("aventurine-glass.ron", 32, 24, 12);
    check_splits("aventurine glass", &s, &[&[5], &[4, 8]]);
}

#[test]
fn spectral_splits_merge_to_the_whole_render_bit_for_bit() {
    let s = gem("brilliant-diamond.ron", 32, 24, 8);
    assert!(s.effects.on(Effect::Spectral));
    check_splits("brilliant diamond (spectral)", &s, &[&[3], &[1, 6]]);
}

fn lapidary(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lapidary"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run lapidary")
}

/// Channels equal bit for bit, and attributes equal but for the render time.
fn assert_same_render(a: &ExrImage, b: &ExrImage) {
    assert_eq!((a.width, a.height), (b.width, b.height));
    assert_eq!(a.channel_names(), b.channel_names());
    for c in &a.channels {
        let d = b.channel(&c.name).unwrap();
        let differ = c
            .data
            .iter()
            .zip(d)
            .filter(|(x, y)| x.to_bits() != y.to_bits())
            .count();
        assert_eq!(differ, 0, "channel {}: {differ} pixels differ", c.name);
    }
    let strip = |img: &ExrImage| -> Vec<(String, String)> {
        img.attributes
            .iter()
            .filter(|(k, _)| k != "lapidary.render_time")
            .cloned()
            .collect()
    };
    assert_eq!(strip(a), strip(b));
}

const ARGS: [&str; 4] = ["--size", "40x30", "--spp", "12"];

fn render_part(s: &Scratch, range: &str, out: &str, threads: &str) -> Output {
    let mut a = vec![
        "render",
        SUNSTONE,
        "--quiet",
        "--threads",
        threads,
        "-o",
        out,
    ];
    a.extend(ARGS);
    a.extend(["--samples", range]);
    lapidary(&s.0, &a)
}

#[test]
fn the_command_line_merge_equals_the_single_render_exr_and_png() {
    let s = Scratch::new("distributed", "cli");
    let mut a = vec!["render", SUNSTONE, "--quiet", "-o", "whole.exr"];
    a.extend(ARGS);
    ok(&lapidary(&s.0, &a));
    for (range, out, threads) in [
        ("0..5", "a.exr", "1"),
        ("5..6", "b.exr", "2"),
        ("6..12", "c.exr", "2"),
    ] {
        ok(&render_part(&s, range, out, threads));
    }
    // A part opens as an ordinary render of its own samples.
    let b = read_exr(&s.path("b.exr")).unwrap();
    assert_eq!(b.attribute("lapidary.samples"), Some("5..6"));
    assert!(b.channel("samples.Y").unwrap().iter().all(|&n| n == 1.0));
    assert!(!s.path("b.png").exists(), "a part writes no PNG by default");
    let out = ok(&lapidary(
        &s.0,
        &["merge", "c.exr", "a.exr", "b.exr", "-o", "merged.exr"],
    ));
    assert!(out.contains("merged 3 parts"), "{out}");
    let whole = read_exr(&s.path("whole.exr")).unwrap();
    assert_same_render(&read_exr(&s.path("merged.exr")).unwrap(), &whole);
    assert_eq!(
        std::fs::read(s.path("merged.png")).unwrap(),
        std::fs::read(s.path("whole.png")).unwrap()
    );
}

#[test]
fn merge_names_what_is_missing_overlapping_or_different_and_writes_nothing() {
    let s = Scratch::new("distributed", "refuse");
    for (range, out) in [("0..4", "a.exr"), ("3..8", "b.exr"), ("10..12", "c.exr")] {
        ok(&render_part(&s, range, out, "2"));
    }
    std::fs::write(s.path("out.exr"), b"keep me").unwrap();
    let out = lapidary(&s.0, &["merge", "a.exr", "b.exr", "c.exr", "-o", "out.exr"]);
    assert_eq!(out.status.code(), Some(1));
    let err = text(&out.stderr);
    assert!(
        err.contains("b.exr (samples 3..8) overlaps") && err.contains("a.exr at samples 3..4"),
        "{err}"
    );
    assert!(err.contains("samples 8..10 are missing"), "{err}");
    assert_eq!(std::fs::read(s.path("out.exr")).unwrap(), b"keep me");
    assert!(!s.path("out.png").exists());

    // Missing tail, and a part of another seed.
    let mut a = vec![
        "render",
        SUNSTONE,
        "--quiet",
        "-o",
        "seed.exr",
        "--seed",
        "5",
        "--samples",
        "4..12",
    ];
    a.extend(ARGS);
    ok(&lapidary(&s.0, &a));
    let out = lapidary(&s.0, &["merge", "a.exr", "seed.exr", "-o", "out.exr"]);
    let err = text(&out.stderr);
    assert!(
        err.contains("`lapidary.seed` is 5 in") && err.contains("but 0 in"),
        "{err}"
    );
    let out = lapidary(&s.0, &["merge", "a.exr", "-o", "out.exr"]);
    assert!(
        text(&out.stderr).contains("samples 4..12 are missing"),
        "{}",
        text(&out.stderr)
    );

    // An ordinary render is not a part.
    let mut a = vec!["render", SUNSTONE, "--quiet", "--no-png", "-o", "plain.exr"];
    a.extend(ARGS);
    ok(&lapidary(&s.0, &a));
    let out = lapidary(&s.0, &["merge", "plain.exr", "-o", "out.exr"]);
    assert!(
        text(&out.stderr).contains("not a part file"),
        "{}",
        text(&out.stderr)
    );
    // A range past the render's spp is refused before rendering.
    let out = render_part(&s, "8..13", "past.exr", "1");
    assert!(
        text(&out.stderr).contains("goes past the render's 12 spp"),
        "{}",
        text(&out.stderr)
    );
    assert!(!s.path("past.exr").exists());
    // The output may not be one of the parts.
    let out = lapidary(&s.0, &["merge", "a.exr", "-o", "a.exr", "--no-png"]);
    assert!(!out.status.success());
    assert!(
        read_exr(&s.path("a.exr"))
            .unwrap()
            .attribute("lapidary.samples")
            .is_some()
    );
}

#[test]
fn the_farm_writes_an_array_of_the_missing_parts_only() {
    let s = Scratch::new("distributed", "farm");
    let farm = |extra: &[&str]| {
        let mut a = vec!["farm", "slurm", SUNSTONE, "--parts", "3", "--dir", "f"];
        a.extend(ARGS);
        a.extend(extra);
        lapidary(&s.0, &a)
    };
    let out = ok(&farm(&["--", "--partition=render"]));
    assert!(out.contains("3 to render (0 already done)"), "{out}");
    let submit = std::fs::read_to_string(s.path("f/submit.sh")).unwrap();
    assert!(
        submit.contains("--array=0-2 --partition=render"),
        "{submit}"
    );
    assert!(submit.contains("--dependency=afterok:"), "{submit}");
    let script = std::fs::read_to_string(s.path("f/render.sbatch")).unwrap();
    assert!(script.contains("ranges=(0..4 4..8 8..12)"), "{script}");
    // Run the array's tasks 0 and 2 here, as Slurm would.
    for task in ["0", "2"] {
        let out = Command::new("bash")
            .arg(s.path("f/render.sbatch"))
            .env("SLURM_ARRAY_TASK_ID", task)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", text(&out.stderr));
    }
    let out = ok(&farm(&[]));
    assert!(out.contains("1 to render (2 already done)"), "{out}");
    let submit = std::fs::read_to_string(s.path("f/submit.sh")).unwrap();
    assert!(submit.contains("--array=1 "), "{submit}");
    // Another render command (a knob through --render-arg) makes every part stale.
    let out = ok(&farm(&["--render-arg=--max-depth=4"]));
    assert!(
        out.contains("the render command changed") && out.contains("3 to render"),
        "{out}"
    );
    ok(&farm(&[]));
    // A stale part (another seed) counts as missing.
    let out = ok(&farm(&["--seed", "9"]));
    assert!(out.contains("3 to render (0 already done)"), "{out}");

    // More parts than samples, and a foreign file where a script goes.
    let mut a = vec!["farm", "slurm", SUNSTONE, "--parts", "13", "--dir", "f"];
    a.extend(ARGS);
    let out = lapidary(&s.0, &a);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("--parts 13 is more than the 12 samples"),
        "{}",
        text(&out.stderr)
    );
    std::fs::create_dir_all(s.path("g")).unwrap();
    std::fs::write(s.path("g/submit.sh"), "#!/bin/sh\necho mine\n").unwrap();
    let mut a = vec!["farm", "slurm", SUNSTONE, "--parts", "2", "--dir", "g"];
    a.extend(ARGS);
    let out = lapidary(&s.0, &a);
    assert!(
        text(&out.stderr).contains("not written by `lapidary farm`"),
        "{}",
        text(&out.stderr)
    );
    assert_eq!(
        std::fs::read_to_string(s.path("g/submit.sh")).unwrap(),
        "#!/bin/sh\necho mine\n"
    );
}

#[test]
fn a_regress_table_from_stored_renders_equals_the_local_one() {
    let s = Scratch::new("distributed", "regress");
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
        &[
            "regress",
            "suite",
            "--update",
            "--ref-spp",
            "256",
            "--size",
            "24x18",
        ],
    ));
    let local = ok(&lapidary(&s.0, &["regress", "suite", "--spp", "64"]));
    // The farm's array tasks, one recipe each, then its table.
    let out = ok(&lapidary(
        &s.0,
        &[
            "regress",
            "suite",
            "--spp",
            "64",
            "--farm",
            "slurm",
            "--farm-dir",
            "f",
        ],
    ));
    assert!(out.contains("3 recipes; 3 to render"), "{out}");
    for task in ["0", "1", "2"] {
        let out = Command::new("bash")
            .arg(s.path("f/regress.sbatch"))
            .env("SLURM_ARRAY_TASK_ID", task)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", text(&out.stderr));
    }
    let out = ok(&lapidary(
        &s.0,
        &[
            "regress",
            "suite",
            "--spp",
            "64",
            "--farm",
            "slurm",
            "--farm-dir",
            "f",
        ],
    ));
    assert!(out.contains("0 to render (3 current)"), "{out}");
    let farmed = ok(&Command::new("bash")
        .arg(s.path("f/table.sbatch"))
        .output()
        .unwrap());
    assert_eq!(table(&farmed), table(&local), "{farmed}\n{local}");
    assert_eq!(
        local.lines().filter(|l| l.ends_with(" pass")).count(),
        3,
        "{local}"
    );
    // Renders of another spp are stale: the table says so.
    let out = lapidary(
        &s.0,
        &["regress", "suite", "--spp", "32", "--renders", "f/renders"],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out.stdout).contains("stale test render"),
        "{}",
        text(&out.stdout)
    );
}

/// A part stopped in the middle of a pass holds exactly the samples it reports: the finished
/// tiles of the stopped pass are dropped, so it merges with a part for the rest.
#[test]
fn a_part_stopped_mid_pass_holds_exactly_its_reported_range() {
    use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
    let s = gem("sunstone.ron", 40, 30, 16);
    let world = World::new(&s).expect("world");
    let tiles = 40u32.div_ceil(16) * 30u32.div_ceil(16);
    let cancel = AtomicBool::new(false);
    let seen = AtomicU32::new(0);
    // Stop after the first pass and two tiles of the second (one thread: tiles in order).
    let progress = |_: u64| {
        if seen.fetch_add(1, Ordering::SeqCst) + 1 == tiles + 2 {
            cancel.store(true, Ordering::SeqCst);
        }
    };
    let control = Control {
        threads: Some(1),
        samples: Some(2..16),
        cancel: Some(&cancel),
        progress: Some(&progress),
        ..Control::default()
    };
    let r = render(&world, &s.stage.camera, false, &s.stage.render, &control);
    assert!(r.stats.partial);
    assert_eq!(r.stats.spp_complete, 4, "one pass of 4 samples");
    assert!(r.film.pixels.iter().all(|p| p.n + p.dropped == 4));
    assert_eq!(r.film, film(&world, &s, Some(2..6), 2));
    let rest = film(&world, &s, Some(6..16), 2);
    let head = film(&world, &s, Some(0..2), 1);
    assert_eq!(merged(&[&head, &r.film, &rest]), film(&world, &s, None, 2));
}
