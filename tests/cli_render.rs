//! End-to-end tests of `lapidary render` through the built binary: output names, EXR channels and
//! metadata, determinism, atomic replacement, argument errors, `--time-limit` and Ctrl-C.

use lapidary::image::{ExrImage, read_exr};
use std::path::Path;
use std::process::{Command, Output, Stdio};

#[path = "common/scratch.rs"]
mod scratch;
use scratch::{Scratch, handler_installed, text};
use std::time::{Duration, Instant};

const SUNSTONE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/gems/sunstone.ron");
const LEPIDOLITE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/gems/lepidolite.ron");

/// Small enough for the whole file to run in seconds.
const SMALL: [&str; 4] = ["--size", "32x24", "--spp", "4"];
/// Would take minutes: only ever stopped early.
const LONG: [&str; 4] = ["--size", "200x150", "--spp", "4096"];

/// Every channel the EXR of a render must have.
const CHANNELS: [&str; 15] = [
    "R",
    "G",
    "B",
    "albedo.R",
    "albedo.G",
    "albedo.B",
    "normal.X",
    "normal.Y",
    "normal.Z",
    "depth.Z",
    "variance.R",
    "variance.G",
    "variance.B",
    "samples.Y",
    "material.Y",
];

/// Runs `lapidary render ARGS…` in `dir`.
fn render(dir: &Scratch, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lapidary"))
        .arg("render")
        .args(args)
        .current_dir(&dir.0)
        .stdin(Stdio::null())
        .output()
        .expect("binary runs")
}

/// Asserts a zero exit and returns stdout.
fn ok(out: &Output) -> String {
    assert_eq!(
        out.status.code(),
        Some(0),
        "stdout:\n{}\nstderr:\n{}",
        text(&out.stdout),
        text(&out.stderr)
    );
    text(&out.stdout)
}

fn exr(path: &Path) -> ExrImage {
    read_exr(path).unwrap_or_else(|e| panic!("{e}"))
}

fn channel<'a>(img: &'a ExrImage, name: &str) -> &'a [f32] {
    img.channel(name)
        .unwrap_or_else(|| panic!("no channel {name}; have {:?}", img.channel_names()))
}

fn attribute<'a>(img: &'a ExrImage, name: &str) -> &'a str {
    img.attribute(name)
        .unwrap_or_else(|| panic!("no attribute {name}; have {:?}", img.attributes))
}

fn bits(v: &[f32]) -> Vec<u32> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// The number in the summary line `  N paths (…)`, thousands separators removed.
fn summary_paths(summary: &str) -> u64 {
    let line = summary
        .lines()
        .find(|l| l.contains(" paths ("))
        .unwrap_or_else(|| panic!("no paths line in\n{summary}"));
    let n: String = line
        .split(" paths (")
        .next()
        .unwrap()
        .split_whitespace()
        .collect();
    n.parse()
        .unwrap_or_else(|_| panic!("bad path count in {line:?}"))
}

#[test]
fn default_outputs_are_named_after_the_recipe_in_the_current_directory() {
    let dir = Scratch::new("cli-render", "defaults");
    let mut args = vec![SUNSTONE];
    args.extend(SMALL);
    let out = render(&dir, &args);
    let summary = ok(&out);
    assert_eq!(dir.files(), ["sunstone.exr", "sunstone.png"]);
    for word in [
        "32x24",
        "4 spp",
        "paths/s",
        "rays/s",
        "dropped",
        "effects:",
        "sunstone.exr",
        "sunstone.png",
    ] {
        assert!(summary.contains(word), "{word:?} missing from\n{summary}");
    }
    assert!(
        !summary.contains("partial"),
        "a complete render is not partial:\n{summary}"
    );
    // The recipe's effects are named (the opaque sunstone has a glitter overlay).
    let effects = summary
        .lines()
        .find_map(|l| l.trim().strip_prefix("effects:"))
        .unwrap();
    assert!(effects.contains("glitter"), "{summary}");
    // Every pixel got all its samples: one path each.
    let img = exr(&dir.path("sunstone.exr"));
    assert_eq!(attribute(&img, "lapidary.dropped"), "0");
    assert_eq!(summary_paths(&summary), 32 * 24 * 4, "{summary}");
    assert_eq!((img.width, img.height), (32, 24));
    let png = image::open(dir.path("sunstone.png")).unwrap();
    assert_eq!((png.width(), png.height()), (32, 24));
    // Quiet: the same files, nothing on stdout.
    std::fs::remove_file(dir.path("sunstone.exr")).unwrap();
    std::fs::remove_file(dir.path("sunstone.png")).unwrap();
    args.push("--quiet");
    let out = render(&dir, &args);
    assert_eq!(ok(&out), "");
    assert_eq!(dir.files(), ["sunstone.exr", "sunstone.png"]);
}

#[test]
fn exr_has_every_channel_finite_and_the_metadata() {
    let dir = Scratch::new("cli-render", "exr");
    let run = |gem: &str, out: &str| {
        let mut args = vec![gem, "-o", out, "--no-png"];
        args.extend(SMALL);
        ok(&render(&dir, &args));
        exr(&dir.path(out))
    };
    let img = run(SUNSTONE, "a.exr");
    let n = 32 * 24;
    assert_eq!((img.width, img.height), (32, 24));
    for name in CHANNELS {
        let c = channel(&img, name);
        assert_eq!(c.len(), n, "{name}");
        assert!(
            c.iter().all(|v| v.is_finite()),
            "{name} has non-finite values"
        );
    }
    assert!(channel(&img, "samples.Y").iter().all(|&s| s == 4.0));
    for name in ["variance.R", "variance.G", "variance.B", "depth.Z"] {
        assert!(
            channel(&img, name).iter().all(|&v| v >= 0.0),
            "{name} negative"
        );
    }
    for name in ["R", "G", "B"] {
        let c = channel(&img, name);
        assert!(c.iter().all(|&v| v >= 0.0), "{name} negative");
        assert!(c.iter().any(|&v| v > 0.0), "{name} all black");
    }

    // Material indices: integers ≥ −2, the stone visible, every index named in the metadata.
    let materials = attribute(&img, "lapidary.materials");
    assert!(materials.contains("0="), "{materials}");
    let named: Vec<i64> = materials
        .split(';')
        .map(|p| p.split_once('=').unwrap().0.parse().unwrap())
        .collect();
    let mat = channel(&img, "material.Y");
    for &m in mat {
        assert_eq!(m, m.round(), "material index {m} not an integer");
        assert!(m >= -2.0, "material index {m}");
        assert!(
            m < 0.0 || named.contains(&(m as i64)),
            "{m} not in {materials}"
        );
    }
    assert!(mat.iter().any(|&m| m >= 0.0), "the stone is not visible");
    assert!(
        materials.contains("=body"),
        "sunstone's materials: {materials}"
    );

    // Normals: unit where something was hit, zero where nothing was.
    let (nx, ny, nz) = (
        channel(&img, "normal.X"),
        channel(&img, "normal.Y"),
        channel(&img, "normal.Z"),
    );
    for i in 0..n {
        let len = (nx[i] * nx[i] + ny[i] * ny[i] + nz[i] * nz[i]).sqrt();
        assert!(
            len == 0.0 || (len - 1.0).abs() <= 1e-3,
            "pixel {i}: |normal| = {len}"
        );
        if mat[i] == -2.0 {
            assert_eq!(len, 0.0, "pixel {i}: a normal where nothing was hit");
        }
    }

    assert_eq!(
        attribute(&img, "lapidary.version"),
        env!("CARGO_PKG_VERSION")
    );
    let hash = attribute(&img, "lapidary.recipe_hash");
    assert_eq!(hash.len(), 16, "{hash}");
    assert!(hash.chars().all(|c| c.is_ascii_hexdigit()), "{hash}");
    assert!(attribute(&img, "lapidary.seed").parse::<u64>().is_ok());
    assert_eq!(attribute(&img, "lapidary.spp"), "4");
    assert_eq!(attribute(&img, "lapidary.spp_complete"), "4");
    assert_eq!(attribute(&img, "lapidary.partial"), "false");
    assert_eq!(attribute(&img, "lapidary.sampler"), "sobol");
    assert_eq!(attribute(&img, "lapidary.recipe"), SUNSTONE);
    let t: f64 = attribute(&img, "lapidary.render_time").parse().unwrap();
    assert!(t >= 0.0 && t.is_finite(), "{t}");

    // The hash identifies the recipe: the same for another run, different for another gem.
    let again = run(SUNSTONE, "b.exr");
    assert_eq!(attribute(&again, "lapidary.recipe_hash"), hash);
    let other = run(LEPIDOLITE, "c.exr");
    assert_ne!(attribute(&other, "lapidary.recipe_hash"), hash);
    assert!(attribute(&other, "lapidary.materials").contains("0="));
    assert_eq!(dir.files(), ["a.exr", "b.exr", "c.exr"]);
}

#[test]
fn output_and_png_paths_are_honoured_and_no_png_writes_none() {
    let dir = Scratch::new("cli-render", "paths");
    std::fs::create_dir(dir.path("out")).unwrap();
    let mut args = vec![SUNSTONE, "-o", "out/x.exr", "--png", "y.png"];
    args.extend(SMALL);
    let summary = ok(&render(&dir, &args));
    assert!(
        summary.contains("out/x.exr") && summary.contains("y.png"),
        "{summary}"
    );
    assert_eq!(dir.files(), ["out", "y.png"]);
    assert!(dir.path("out/x.exr").is_file());
    assert_eq!(std::fs::read_dir(dir.path("out")).unwrap().count(), 1);
    let img = exr(&dir.path("out/x.exr"));
    assert_eq!((img.width, img.height), (32, 24));
    let png = image::open(dir.path("y.png")).unwrap();
    assert_eq!((png.width(), png.height()), (32, 24));

    // `-o` alone: the PNG goes beside the EXR. Another size to tell the files apart.
    let out = render(
        &dir,
        &[SUNSTONE, "-o", "out/z.exr", "--size", "20x10", "--spp", "2"],
    );
    ok(&out);
    let png = image::open(dir.path("out/z.png")).unwrap();
    assert_eq!((png.width(), png.height()), (20, 10));

    // `--no-png`: an EXR only, and no PNG anywhere.
    let mut args = vec![SUNSTONE, "-o", "n.exr", "--no-png"];
    args.extend(SMALL);
    let summary = ok(&render(&dir, &args));
    assert!(
        summary.contains("n.exr") && !summary.contains(".png"),
        "{summary}"
    );
    assert_eq!(dir.files(), ["n.exr", "out", "y.png"]);
    let mut args = vec![SUNSTONE, "--no-png"];
    args.extend(SMALL);
    ok(&render(&dir, &args));
    assert_eq!(dir.files(), ["n.exr", "out", "sunstone.exr", "y.png"]);

    // `--no-png` and `--png` contradict each other.
    let out = render(&dir, &[SUNSTONE, "--no-png", "--png", "w.png"]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    assert!(!dir.path("w.png").exists());
}

#[test]
fn threads_do_not_change_the_image_but_seed_and_sampler_do() {
    let dir = Scratch::new("cli-render", "determinism");
    let run = |out: &str, extra: &[&str]| {
        let mut args = vec![SUNSTONE, "-o", out, "--no-png"];
        args.extend(SMALL);
        args.extend(extra);
        ok(&render(&dir, &args));
        exr(&dir.path(out))
    };
    let one = run("t1.exr", &["--threads", "1", "--seed", "7"]);
    let two = run("t2.exr", &["--threads", "2", "--seed", "7"]);
    assert_eq!(attribute(&one, "lapidary.seed"), "7");
    // Every channel bit for bit, not only colour and variance.
    for name in CHANNELS {
        assert!(
            bits(channel(&one, name)) == bits(channel(&two, name)),
            "{name} differs between 1 and 2 threads"
        );
    }
    // And all the metadata but the time.
    let meta = |img: &ExrImage| -> Vec<(String, String)> {
        img.attributes
            .iter()
            .filter(|(k, _)| k.starts_with("lapidary.") && k != "lapidary.render_time")
            .cloned()
            .collect()
    };
    assert_eq!(meta(&one), meta(&two));

    let colour = |img: &ExrImage| -> Vec<u32> {
        ["R", "G", "B"]
            .iter()
            .flat_map(|c| bits(channel(img, c)))
            .collect()
    };
    let s1 = run("s1.exr", &["--seed", "1"]);
    let s2 = run("s2.exr", &["--seed", "2"]);
    assert_eq!(attribute(&s2, "lapidary.seed"), "2");
    assert_ne!(
        colour(&s1),
        colour(&s2),
        "seeds 1 and 2 give the same image"
    );
    let ind = run("i1.exr", &["--seed", "1", "--sampler", "independent"]);
    assert_eq!(attribute(&ind, "lapidary.sampler"), "independent");
    assert_eq!(attribute(&s1, "lapidary.sampler"), "sobol");
    assert_ne!(
        colour(&s1),
        colour(&ind),
        "independent and sobol give the same image"
    );
}

#[test]
fn a_failed_run_never_replaces_a_good_file() {
    let dir = Scratch::new("cli-render", "atomic");
    let mut args = vec![SUNSTONE, "-o", "good.exr", "--no-png"];
    args.extend(SMALL);
    ok(&render(&dir, &args));
    let good = std::fs::read(dir.path("good.exr")).unwrap();
    std::fs::write(dir.path("good.png"), b"previous png").unwrap();

    std::fs::write(
        dir.path("bad.ron"),
        "(\n  materials: { \"a\": (base: Lambert(albedo: Gray(0.5))) },\n  surface: Voronoi(scale: 0.1, entries: [(1.0, Material(\"b\"))]),\n)\n",
    )
    .unwrap();
    let bad = dir.arg("bad.ron");
    let mut args = vec![bad.as_str(), "-o", "good.exr"];
    args.extend(SMALL);
    let out = render(&dir, &args);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.starts_with("error:"), "{err}");
    assert!(
        err.contains("bad.ron:3:48") && err.contains("unknown material \"b\""),
        "{err}"
    );
    assert_eq!(text(&out.stdout), "", "no summary for a failed run");
    assert_eq!(std::fs::read(dir.path("good.exr")).unwrap(), good);
    assert_eq!(
        std::fs::read(dir.path("good.png")).unwrap(),
        b"previous png"
    );
    assert_eq!(
        dir.files(),
        ["bad.ron", "good.exr", "good.png"],
        "stray files"
    );

    // An output directory that does not exist: an error naming it, before any rendering (the
    // render asked for would take minutes), and nothing written anywhere.
    for (exr_arg, png_arg, missing) in [
        ("missing/x.exr", None, "missing"),
        ("x.exr", Some("nowhere/x.png"), "nowhere"),
    ] {
        let mut args = vec![SUNSTONE, "-o", exr_arg];
        if let Some(p) = png_arg {
            args.extend(["--png", p]);
        }
        // If it did render, the time limit keeps a failure of this test short.
        args.extend(LONG);
        args.extend(["--time-limit", "10"]);
        let start = Instant::now();
        let out = render(&dir, &args);
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(
            err.starts_with("error:") && err.contains(&format!("directory {missing} ")),
            "{err}"
        );
        assert!(
            start.elapsed() < Duration::from_secs(5),
            "it rendered first"
        );
        assert_eq!(text(&out.stdout), "");
        assert_eq!(dir.files(), ["bad.ron", "good.exr", "good.png"], "{err}");
    }
}

#[test]
fn bad_arguments_name_the_allowed_values() {
    let dir = Scratch::new("cli-render", "args");
    for (args, wanted) in [
        (&["--size", "0x10"][..], "1..=16384"),
        (&["--size", "16384x8192"], "at most 67108864 pixels"),
        (&["--size", "16385x10"], "1..=16384"),
        (&["--size", "abc"], "WxH"),
        (&["--size", "32x"], "WxH"),
        (&["--spp", "0"], "1..=1048576"),
        (&["--spp", "many"], "--spp"),
        (&["--time-limit=-1"], "(0, 1e7]"),
        (&["--time-limit", "0"], "(0, 1e7]"),
        (&["--time-limit", "nan"], "(0, 1e7]"),
        (&["--threads", "0"], "1..=1024"),
        (&["--max-depth", "0"], "1..=1024"),
        (&["--exposure", "-31"], "-30..=30"),
        (&["--sampler", "halton"], "sobol"),
    ] {
        let mut all = vec![SUNSTONE];
        all.extend(args);
        let out = render(&dir, &all);
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains(wanted),
            "{args:?}: {wanted:?} missing from {err}"
        );
    }
    // A negative exposure is a value, not an option.
    let mut args = vec![SUNSTONE, "--exposure", "-1", "--no-png", "-q"];
    args.extend(SMALL);
    ok(&render(&dir, &args));
    std::fs::remove_file(dir.path("sunstone.exr")).unwrap();

    let missing = dir.arg("no-such-gem.ron");
    let out = render(&dir, &[missing.as_str()]);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.starts_with("error:") && err.contains(&missing), "{err}");
    assert_eq!(dir.files(), Vec::<String>::new(), "nothing written");
}

/// `--time-limit -1` (value as a separate word) is reported like `--time-limit=-1` and
/// `--exposure -31`, naming the range (it once said "unexpected argument '-1' found").
#[test]
fn negative_time_limit_as_a_separate_word_names_the_range() {
    let dir = Scratch::new("cli-render", "negative-time");
    let out = render(&dir, &[SUNSTONE, "--time-limit", "-1"]);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("(0, 1e7]"), "{err}");
}

#[test]
fn time_limit_stops_early_and_writes_a_partial_image() {
    let dir = Scratch::new("cli-render", "time-limit");
    // (The limit covers setup too, which takes about a second in the test build on an idle
    // machine and more under the load of the other tests.)
    let mut args = vec![SUNSTONE, "--time-limit", "6"];
    args.extend(LONG);
    let start = Instant::now();
    let out = render(&dir, &args);
    let elapsed = start.elapsed();
    let summary = ok(&out);
    assert!(elapsed < Duration::from_secs(20), "took {elapsed:?}");
    assert!(
        summary.contains("partial") && summary.contains("time limit"),
        "{summary}"
    );
    assert_eq!(dir.files(), ["sunstone.exr", "sunstone.png"]);
    let img = exr(&dir.path("sunstone.exr"));
    assert_eq!((img.width, img.height), (200, 150));
    assert_eq!(attribute(&img, "lapidary.partial"), "true");
    assert_eq!(attribute(&img, "lapidary.spp"), "4096");
    let complete: u32 = attribute(&img, "lapidary.spp_complete").parse().unwrap();
    assert!(complete < 4096, "{complete}");
    // Every pixel has at least the complete passes, none more than asked.
    let samples = channel(&img, "samples.Y");
    assert!(
        samples.iter().all(|&s| s >= complete as f32 && s < 4096.0),
        "samples.Y out of [{complete}, 4096)"
    );
    assert!(
        summary.contains(&format!("{complete} of 4096 spp")),
        "{summary}"
    );
    for name in CHANNELS {
        assert!(
            channel(&img, name).iter().all(|v| v.is_finite()),
            "{name} has non-finite values"
        );
    }
}

/// User plus system CPU time of a process in seconds (`/proc/PID/stat` fields 14 and 15, in
/// clock ticks of 1/100 s on Linux); `None` without `/proc`.
#[cfg(unix)]
fn cpu_seconds(pid: u32) -> Option<f64> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    // The command name (field 2) is in parentheses and may hold spaces: count after it.
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

#[cfg(unix)]
#[test]
fn ctrl_c_writes_a_partial_image_and_exits_130() {
    let dir = Scratch::new("cli-render", "ctrl-c");
    let mut args = vec!["render", SUNSTONE, "-o", "c.exr"];
    args.extend(LONG);
    let child = Command::new(env!("CARGO_BIN_EXE_lapidary"))
        .args(&args)
        .current_dir(&dir.0)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("binary runs");
    let pid = child.id();
    let start = Instant::now();
    while !handler_installed(pid, start) {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "the render never started"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    // Let it set up (about half a second of CPU) and render some passes (0.07 s each): wait for
    // CPU time rather than wall time, so a loaded machine cannot make the signal land in setup.
    while cpu_seconds(pid).is_some_and(|s| s < 3.0) {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "the render used less than 3 s of CPU in 120 s"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    let kill = Command::new("kill")
        .args(["-INT", &pid.to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let sent = Instant::now();
    let out = child.wait_with_output().unwrap();
    assert!(
        sent.elapsed() < Duration::from_secs(20),
        "took {:?} to stop",
        sent.elapsed()
    );
    let summary = text(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(130),
        "{:?}\nstdout:\n{summary}\nstderr:\n{}",
        out.status,
        text(&out.stderr)
    );
    assert!(
        summary.contains("Ctrl-C") && summary.contains("partial"),
        "{summary}"
    );
    assert_eq!(dir.files(), ["c.exr", "c.png"]);
    let img = exr(&dir.path("c.exr"));
    assert_eq!(attribute(&img, "lapidary.partial"), "true");
    let complete: u32 = attribute(&img, "lapidary.spp_complete").parse().unwrap();
    assert!(complete < 4096, "{complete}");
    assert!(
        channel(&img, "R").iter().all(|v| v.is_finite()),
        "non-finite colour"
    );
}
