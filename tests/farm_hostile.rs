//! Hostile input to the farm and the merge, without a cluster: names that hold quotes, `$`,
//! backticks, spaces, `;`, `#`, `%` and backslashes reach every command intact and run nothing
//! (the scripts run with `bash` under stand-in `lapidary` and `sbatch` binaries that record their
//! arguments byte for byte; the `#SBATCH` lines are read by a model of sbatch's own parser);
//! control characters are refused; `farm slurm -o` and `--render-arg`s are checked before anything
//! is written; FIFOs are refused without being opened; and `merge` refuses parts whose counts,
//! sums or attributes do not hold together.
#![cfg(unix)]

use std::ffi::OsStr;
use std::os::unix::ffi::OsStrExt;
use std::path::Path;
use std::process::{Command, Output};

#[path = "common/scratch.rs"]
mod scratch;
use scratch::{Scratch, text};
#[path = "common/farm.rs"]
mod farm;
use farm::{
    RECIPE, bash, bounded, fake_lapidary, fake_sbatch, nothing_ran, ok, recorded, refused,
    sbatch_directives, tree,
};

/// Runs `lapidary ARGS…` in `dir` (arguments may be any bytes).
fn lapidary<S: AsRef<OsStr>>(dir: &Path, args: &[S]) -> Output {
    bounded(
        Command::new(env!("CARGO_BIN_EXE_lapidary"))
            .args(args)
            .current_dir(dir),
    )
}

/// A name with everything a shell or sbatch treats specially, but no `.` (it is a file stem).
const HOSTILE: &str = "a b'c\"d$HOME`touch pwned-bt`$(touch pwned-cs);touch pwned-semi;#%j\\x";

#[test]
fn hostile_names_reach_every_command_intact_and_run_nothing() {
    let s = Scratch::new("farm-hostile", "names");
    let recipe = s.path(&format!("{HOSTILE}.ron"));
    std::fs::write(&recipe, RECIPE).unwrap();
    let bin_dir = s.path(&format!("bin {HOSTILE}"));
    std::fs::create_dir_all(&bin_dir).unwrap();
    let fake = bin_dir.join("fake lapidary");
    fake_lapidary(&fake);
    // The farm folder may not hold a backslash (it would turn off Slurm's `%a`); all else goes.
    let dir = s.path(&format!("farm {}", HOSTILE.replace('\\', "")));
    let out_exr = s.path(&format!("out {HOSTILE}.exr"));
    let sbatch_opts = [
        "--comment=it's $(touch pwned-sb) \"x\" #y",
        "--partition=a b",
    ];
    let mut args: Vec<&OsStr> = ["farm", "slurm"].map(OsStr::new).into();
    args.push(recipe.as_os_str());
    args.extend(["--parts", "2", "--spp", "8", "--size", "8x6", "--seed", "3"].map(OsStr::new));
    args.extend(["--render-arg=--model=reference", "--render-arg=--exposure"].map(OsStr::new));
    args.extend(["--render-arg", "-1.5", "--dir"].map(OsStr::new));
    args.push(dir.as_os_str());
    args.push(OsStr::new("-o"));
    args.push(out_exr.as_os_str());
    args.push(OsStr::new("--lapidary"));
    args.push(fake.as_os_str());
    args.push(OsStr::new("--"));
    args.extend(sbatch_opts.map(OsStr::new));
    let out = lapidary(&s.0, &args);
    ok(&out);
    for name in ["render.sbatch", "merge.sbatch", "submit.sh"] {
        let check = Command::new("bash")
            .arg("-n")
            .arg(dir.join(name))
            .output()
            .unwrap();
        assert!(check.status.success(), "{name}: {}", text(&check.stderr));
    }
    // sbatch reads the job name and the log pattern whole; `%` of the folder stays itself.
    let job: String = format!("lapidary-{HOSTILE}")
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "._-".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    let logs = dir.join("logs").to_str().unwrap().replace('%', "%%");
    let script = std::fs::read_to_string(dir.join("render.sbatch")).unwrap();
    assert_eq!(
        sbatch_directives(&script),
        [
            format!("--job-name={job}"),
            format!("--output={logs}/part-%a.log")
        ]
    );
    let merge_script = std::fs::read_to_string(dir.join("merge.sbatch")).unwrap();
    assert_eq!(
        sbatch_directives(&merge_script),
        [
            format!("--job-name={job}-merge"),
            format!("--output={logs}/merge.log")
        ]
    );

    // Task 1 as Slurm runs it: the stand-in receives every argument byte for byte.
    let run = s.path("run");
    std::fs::create_dir_all(&run).unwrap();
    let argv_log = s.path("argv");
    let env = |task: &'static str| {
        [
            ("SLURM_ARRAY_TASK_ID", OsStr::new(task)),
            ("SLURM_CPUS_PER_TASK", OsStr::new("3")),
            ("ARGV_LOG", argv_log.as_os_str()),
        ]
    };
    ok(&bash(&dir.join("render.sbatch"), &run, &env("1")));
    let part = |i: u32| dir.join("parts").join(format!("part-{i}.exr"));
    let p = |p: &Path| p.to_str().unwrap().to_string();
    let mut want: Vec<String> = vec!["render".into(), p(&recipe)];
    want.extend(
        [
            "--spp",
            "8",
            "--size",
            "8x6",
            "--seed",
            "3",
            "--model=reference",
            "--exposure",
            "-1.5",
            "--samples",
            "4..8",
            "--threads",
            "3",
            "--quiet",
            "-o",
        ]
        .map(String::from),
    );
    want.push(p(&part(1)));
    assert_eq!(recorded(&argv_log), want);
    ok(&bash(&dir.join("merge.sbatch"), &run, &env("0")));
    assert_eq!(
        recorded(&argv_log),
        [
            "merge".into(),
            p(&part(0)),
            p(&part(1)),
            "-o".into(),
            p(&out_exr)
        ]
    );
    // A task index that is not a number is refused before bash evaluates it as arithmetic.
    std::fs::remove_file(&argv_log).unwrap();
    let out = bash(
        &dir.join("render.sbatch"),
        &run,
        &env("a[$(touch pwned-index)]"),
    );
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("not a task index"));
    assert!(!argv_log.exists(), "the render ran");

    // submit.sh and --submit hand sbatch every option whole.
    let fake_bin = s.path("fakebin");
    fake_sbatch(&fake_bin);
    let path = format!("{}:{}", fake_bin.display(), std::env::var("PATH").unwrap());
    let calls = |log: &Path| -> Vec<Vec<String>> {
        let n = std::fs::read_dir(log).unwrap().count();
        (0..n).map(|i| recorded(&log.join(i.to_string()))).collect()
    };
    let (log1, log2) = (s.path("sbatch1"), s.path("sbatch2"));
    for l in [&log1, &log2] {
        std::fs::create_dir_all(l).unwrap();
    }
    let mut c = Command::new("bash");
    c.arg(dir.join("submit.sh"))
        .arg("--qos=x $(touch pwned-qos)");
    c.current_dir(&run)
        .env("PATH", &path)
        .env("SBATCH_LOG", &log1);
    ok(&bounded(&mut c));
    let opts = sbatch_opts.map(String::from);
    let call = |head: &str, extra: Option<&str>, script: &str| -> Vec<String> {
        let mut v = vec!["--parsable".to_string(), head.to_string()];
        v.extend(opts.iter().cloned());
        v.extend(extra.map(String::from));
        v.push(p(&dir.join(script)));
        v
    };
    let qos = Some("--qos=x $(touch pwned-qos)");
    assert_eq!(
        calls(&log1),
        [
            call("--array=0-1", qos, "render.sbatch"),
            call("--dependency=afterok:4240", qos, "merge.sbatch")
        ]
    );
    let mut c = Command::new(env!("CARGO_BIN_EXE_lapidary"));
    c.args(&args[..args.len() - 3]).arg("--submit").arg("--");
    c.args(sbatch_opts).current_dir(&s.0);
    c.env("PATH", &path).env("SBATCH_LOG", &log2);
    ok(&bounded(&mut c));
    assert_eq!(
        calls(&log2),
        [
            call("--array=0-1", None, "render.sbatch"),
            call("--dependency=afterok:4240", None, "merge.sbatch")
        ]
    );
    nothing_ran(&s.0);
}

#[test]
fn control_characters_and_non_utf8_names_are_refused_before_anything_is_written() {
    let s = Scratch::new("farm-hostile", "control");
    std::fs::write(s.path("gem.ron"), RECIPE).unwrap();
    // A newline in a recipe's name would start a command (or an #SBATCH line) in every task.
    let evil = "gem\n#SBATCH --wrap=touch pwned\ntouch pwned-nl\n.ron";
    std::fs::write(s.path(evil), RECIPE).unwrap();
    let before = tree(&s.0);
    let farm = |extra: &[&OsStr]| {
        let mut a: Vec<&OsStr> = ["farm", "slurm", "gem.ron", "--parts", "2", "--spp", "4"]
            .map(OsStr::new)
            .into();
        a.extend(["--size", "8x6"].map(OsStr::new));
        if !extra.contains(&OsStr::new("--dir")) {
            a.extend(["--dir", "f"].map(OsStr::new));
        }
        a.extend(extra);
        lapidary(&s.0, &a)
    };
    let o = |s: &'static str| OsStr::new(s);
    let newline = "contains a newline (U+000A): control characters are not allowed in names a \
                   farm script holds";
    refused(
        &lapidary(
            &s.0,
            &["farm", "slurm", evil, "--parts", "1", "--size", "8x6"],
        ),
        &[
            "the recipe",
            "gem\\n#SBATCH --wrap=touch pwned\\ntouch pwned-nl\\n.ron",
            newline,
        ],
    );
    refused(
        &farm(&[o("--dir"), o("f\nx")]),
        &["the farm folder (--dir)", newline],
    );
    refused(&farm(&[o("-o"), o("o\tx.exr")]), &["-o", "a tab (U+0009)"]);
    refused(
        &farm(&[o("--lapidary"), o("l\rx")]),
        &["--lapidary", "a carriage return (U+000D)"],
    );
    refused(
        &farm(&[o("--render-arg=--model=reference\ntouch pwned")]),
        &["--render-arg", newline],
    );
    refused(
        &farm(&[o("--"), o("--comment=a\u{1b}[2Jb")]),
        &["sbatch option", "an escape (U+001B)"],
    );
    refused(
        &farm(&[o("--dir"), OsStr::from_bytes(b"f\xff")]),
        &["the farm folder (--dir)", "is not valid UTF-8"],
    );
    // A suite: its folder and every recipe name go into the scripts.
    for (suite, recipe, needle) in [
        ("suite\nx", "a.ron", "the suite"),
        ("suite", "a\nb.ron", "the suite's recipe name"),
    ] {
        std::fs::create_dir_all(s.path(suite)).unwrap();
        std::fs::write(s.path(suite).join(recipe), RECIPE).unwrap();
        let out = lapidary(
            &s.0,
            &["regress", suite, "--farm", "slurm", "--farm-dir", "r"],
        );
        refused(&out, &[needle, newline]);
        std::fs::remove_dir_all(s.path(suite)).unwrap();
    }
    assert_eq!(tree(&s.0), before, "nothing written");
    nothing_ran(&s.0);
}

#[test]
fn farm_output_and_render_args_are_checked_before_anything_is_written() {
    let s = Scratch::new("farm-hostile", "checks");
    // A recipe reading an environment map (an input the merged render may not replace).
    let sky = lapidary::image::ExrImage {
        width: 4,
        height: 2,
        channels: ["R", "G", "B"]
            .map(|n| lapidary::image::Channel::new(n, vec![1.0; 8]))
            .into(),
        attributes: vec![],
    };
    lapidary::image::write_exr(&s.path("sky.exr"), &sky).unwrap();
    std::fs::write(
        s.path("env.ron"),
        r#"(materials: { "a": (base: Lambert(albedo: Gray(0.5))) }, surface: Material("a"),
            stage: (shape: Sphere(radius: 0.8), environment: Map(file: "sky.exr")))"#,
    )
    .unwrap();
    std::fs::create_dir_all(s.path("d.exr")).unwrap();
    std::fs::create_dir_all(s.path("x.png")).unwrap();
    let before = tree(&s.0);
    let farm = |extra: &[&str]| {
        let mut a = vec!["farm", "slurm", "env.ron", "--parts", "2", "--spp", "8"];
        a.extend(["--size", "8x6", "--dir", "f"]);
        a.extend(extra);
        lapidary(&s.0, &a)
    };
    for (o, needles) in [
        (
            "sky.exr",
            &["sky.exr: is also an input (the environment map"][..],
        ),
        ("d.exr", &["d.exr", "is a directory"]),
        (
            "out.png",
            &["out.png: EXR output, but the name ends in .png"],
        ),
        ("x.exr", &["x.png", "is a directory"]),
        ("f/parts/part-1.exr", &["is a part the merge job reads"]),
        ("nowhere/out.exr", &["nowhere", "does not exist"]),
    ] {
        refused(&farm(&["-o", o]), needles);
    }
    // Render arguments go through `lapidary render`'s own parser, and the farm's own are refused.
    for (arg, needles) in [
        (
            &["--render-arg=--bogus"][..],
            &["unexpected argument '--bogus'"][..],
        ),
        (
            &["--render-arg=--spp=64"],
            &["--render-arg --spp", "farm slurm --spp"],
        ),
        (
            &["--render-arg=--samples=0..4", "--render-arg=--samples=4..8"],
            &["--samples", "cannot be used multiple times"],
        ),
        (&["--render-arg=--samples=0..4"], &["farm slurm --parts"]),
        (
            &["--render-arg=--time-limit=60"],
            &["a part must be complete"],
        ),
        (&["--render-arg=--model=nonsense"], &["--model"]),
        (
            &["--render-arg=other.ron"],
            &["a recipe among the render arguments"],
        ),
    ] {
        refused(&farm(arg), needles);
    }
    assert_eq!(tree(&s.0), before, "nothing written");
    // Accepted: a render option, and outputs inside the farm folder that does not exist yet.
    ok(&farm(&[
        "--render-arg=--model=reference",
        "-o",
        "f/out.exr",
    ]));
    let script = std::fs::read_to_string(s.path("f/render.sbatch")).unwrap();
    assert!(script.contains(" --model=reference --samples "), "{script}");
    ok(&farm(&["-o", "env.exr"]));
}

#[test]
fn fifos_where_files_are_expected_are_refused_without_opening_them() {
    let s = Scratch::new("farm-hostile", "fifo");
    std::fs::write(s.path("gem.ron"), RECIPE).unwrap();
    let farm = |dir: &str| {
        lapidary(
            &s.0,
            &[
                "farm", "slurm", "gem.ron", "--parts", "2", "--spp", "4", "--size", "8x6", "--dir",
                dir,
            ],
        )
    };
    // A part (of a farm run before, so that its parts are read), a script, the record of the
    // part command.
    ok(&farm("a"));
    for (dir, fifo) in [
        ("a", "a/parts/part-1.exr"),
        ("b", "b/render.sbatch"),
        ("c", "c/submit.sh"),
        ("d", "d/parts/command.txt"),
    ] {
        std::fs::create_dir_all(s.path(dir).join("parts")).unwrap();
        farm::mkfifo(&s.path(fifo));
        refused(&farm(dir), &[fifo, "is a FIFO (named pipe)"]);
        assert_eq!(
            s.path(dir).join("logs").exists(),
            dir == "a",
            "{dir}: a folder made"
        );
    }
    // A test render of a suite.
    std::fs::create_dir_all(s.path("suite")).unwrap();
    std::fs::write(s.path("suite/one.ron"), RECIPE).unwrap();
    std::fs::create_dir_all(s.path("r/renders")).unwrap();
    farm::mkfifo(&s.path("r/renders/one.exr"));
    let out = lapidary(
        &s.0,
        &["regress", "suite", "--farm", "slurm", "--farm-dir", "r"],
    );
    refused(&out, &["one.exr", "is a FIFO (named pipe)"]);
    // Merge: a FIFO part and a device.
    ok(&lapidary(
        &s.0,
        &[
            "render",
            "gem.ron",
            "--size",
            "8x6",
            "--spp",
            "4",
            "--samples",
            "0..2",
            "-o",
            "p.exr",
        ],
    ));
    farm::mkfifo(&s.path("q.exr"));
    let out = lapidary(&s.0, &["merge", "p.exr", "q.exr", "-o", "m.exr"]);
    refused(&out, &["q.exr: is a FIFO (named pipe)"]);
    let out = lapidary(&s.0, &["merge", "p.exr", "/dev/zero", "-o", "m.exr"]);
    refused(&out, &["/dev/zero: is a device"]);
    assert!(!s.path("m.exr").exists());
}

/// Renders samples `range` of a tiny 8×6, 8 spp render of [`RECIPE`] into `out`.
fn tiny_part(s: &Scratch, range: &str, out: &str) {
    let a = [
        "render",
        "gem.ron",
        "--size",
        "8x6",
        "--spp",
        "8",
        "--samples",
        range,
        "-o",
        out,
    ];
    ok(&lapidary(&s.0, &a));
}

#[test]
fn merge_believes_no_count_or_attribute_it_can_check() {
    use farm::{forge, raw_mut, set_attr};
    let s = Scratch::new("farm-hostile", "forged");
    std::fs::write(s.path("gem.ron"), RECIPE).unwrap();
    tiny_part(&s, "0..4", "a.exr");
    tiny_part(&s, "4..8", "b.exr");
    let merge = |parts: &[&str]| {
        let mut a = vec!["merge"];
        a.extend(parts);
        a.extend(["-o", "m.exr"]);
        lapidary(&s.0, &a)
    };
    // A control: parts rewritten unchanged still merge.
    for p in ["a.exr", "b.exr"] {
        forge(&s.path(p), |_, _| {});
    }
    ok(&merge(&["a.exr", "b.exr"]));
    std::fs::remove_file(s.path("m.exr")).unwrap();
    std::fs::remove_file(s.path("m.png")).unwrap();
    let copy = |from: &str, to: &str| std::fs::copy(s.path(from), s.path(to)).unwrap();

    // A part of 4 samples relabelled 0..8 would be merged as 8; a count of 0 is no sample.
    copy("a.exr", "relabelled.exr");
    forge(&s.path("relabelled.exr"), |img, _| {
        for (k, v) in [
            ("lapidary.samples", "0..8"),
            ("lapidary.samples_requested", "0..8"),
            ("lapidary.spp_complete", "8"),
        ] {
            set_attr(img, k, v);
        }
    });
    refused(
        &merge(&["relabelled.exr"]),
        &[
            "relabelled.exr: pixel (0, 0) (and 47 more pixels): `raw.n` + `raw.dropped` = 4 + 0, \
           not the 8 samples of its range",
        ],
    );
    copy("b.exr", "empty.exr");
    forge(&s.path("empty.exr"), |_, raw| raw_mut(raw, "raw.n").fill(0));
    refused(
        &merge(&["a.exr", "empty.exr"]),
        &["`raw.n` + `raw.dropped` = 0 + 0, not the 4"],
    );
    // Dropped samples beyond those taken, in a pixel and in the attribute.
    copy("b.exr", "dropped.exr");
    forge(&s.path("dropped.exr"), |img, raw| {
        raw_mut(raw, "raw.dropped")[9] = 5;
        set_attr(img, "lapidary.dropped", "1000");
    });
    refused(
        &merge(&["a.exr", "dropped.exr"]),
        &[
            "dropped.exr: pixel (1, 1): `raw.n` + `raw.dropped` = 4 + 5, not the 4 samples",
            "dropped.exr: `lapidary.dropped` is 1000, beyond the 192 samples taken (4 a pixel)",
        ],
    );
    // Attributes out of the range `render` accepts: every problem of every part is listed.
    for (value, shown) in [("NaN", "\"NaN\""), ("1e30", "\"1e30\"")] {
        copy("a.exr", "bright.exr");
        forge(&s.path("bright.exr"), |img, _| {
            set_attr(img, "lapidary.exposure", value);
            set_attr(img, "lapidary.spp", "0");
        });
        copy("b.exr", "slow.exr");
        forge(&s.path("slow.exr"), |img, raw| {
            set_attr(img, "lapidary.render_time", "-1");
            raw_mut(raw, "raw.depth_n")[0] = 99;
        });
        refused(
            &merge(&["bright.exr", "slow.exr"]),
            &[
                &format!("bright.exr: `lapidary.exposure` is {shown}, not stops in -30..=30"),
                "bright.exr: `lapidary.spp` is \"0\", not a count of samples in 1..=1048576",
                "slow.exr: `lapidary.render_time` is \"-1\", not seconds in 0..=1e9",
                "slow.exr: pixel (0, 0): `raw.depth_n` = 99, more than its 4 samples",
            ],
        );
    }
    assert!(!s.path("m.exr").exists() && !s.path("m.png").exists());
    // A range whose bound does not fit says so.
    let out = lapidary(
        &s.0,
        &[
            "render",
            "gem.ron",
            "--size",
            "8x6",
            "--samples",
            "0..18446744073709551615",
        ],
    );
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    assert!(
        text(&out.stderr).contains(
            "18446744073709551615 is too large: a sample range lies \
                                     within 0..1048576"
        ),
        "{}",
        text(&out.stderr)
    );
}
