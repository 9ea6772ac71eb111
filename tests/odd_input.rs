//! Clear words for odd input (issue 14): byte-order marks, CR-only line endings, control
//! characters in names, directories / FIFOs / devices given as input files, OBJ line numbers,
//! integer overflow, absurd radiance, degenerate environment maps, `brdf` directions and counts,
//! and commands piped into `head`.

#[path = "common/scratch.rs"]
mod scratch;

use lapidary::geometry::mesh::Mesh;
use lapidary::image::{Channel, ExrImage, write_exr};
use lapidary::light::EnvironmentLight;
use lapidary::recipe::{GemRecipe, MaterialLibrary, RecipeError, Source};
use lapidary::scene::stage::Environment;
use scratch::{Scratch, text};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).to_path_buf()
}

fn lapidary(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lapidary"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

/// A one-material recipe (line 1: materials; line 2: surface) with `rest` from line 3.
fn recipe(rest: &str) -> String {
    format!(
        "(materials: {{ \"a\": (base: Lambert(albedo: Gray(0.5))) }},\n surface: Material(\"a\"),\n{rest})"
    )
}

/// The first error of checking `text` (named `bad.ron`).
fn first_error(text: &str) -> RecipeError {
    let report = GemRecipe::check_source(Source::new("bad.ron", text), None);
    report
        .errors
        .into_iter()
        .next()
        .unwrap_or_else(|| panic!("no error for:\n{text}"))
}

fn assert_error(text: &str, at: (usize, usize), words: &[&str]) {
    let e = first_error(text);
    assert_eq!((e.line, e.col), at, "{e}");
    for w in words {
        assert!(e.message.contains(w), "`{w}` missing from: {e}");
    }
}

#[test]
fn a_byte_order_mark_is_accepted_and_positions_stay_right() {
    let gem = std::fs::read_to_string(root().join("gems/sunstone.ron")).unwrap();
    assert!(GemRecipe::parse("gems/sunstone.ron", &format!("\u{feff}{gem}")).is_ok());
    let lib = std::fs::read_to_string(root().join("materials/course.ron")).unwrap();
    let with_bom = MaterialLibrary::parse("course.ron", &format!("\u{feff}{lib}")).unwrap();
    assert_eq!(with_bom.len(), MaterialLibrary::course().len());
    // The same error, at the same place, with and without the mark.
    let bad = recipe(" stage: (render: (spp: 0)),\n");
    let plain = first_error(&bad);
    let marked = first_error(&format!("\u{feff}{bad}"));
    assert_eq!((marked.line, marked.col), (plain.line, plain.col));
    assert_eq!((plain.line, plain.col), (3, 24), "{plain}");
    // From a file, through the command line.
    let s = Scratch::new("odd", "bom");
    // The copy reads the gem's spectrum where the gem does.
    let here = gem.replace("\"../data/", &format!("\"{}/data/", root().display()));
    std::fs::write(s.path("bom.ron"), format!("\u{feff}{here}")).unwrap();
    let out = lapidary(&["check", &s.arg("bom.ron")], &s.0);
    assert!(out.status.success(), "{}", text(&out.stderr));
}

#[test]
fn cr_only_line_endings_get_a_positioned_error_showing_them() {
    let text = recipe(" stage: (render: (spp: 4)),\n").replace('\n', "\r");
    // The first line break of line 1 (by LF lines, the whole file is line 1).
    let col = text.find('\r').unwrap() + 1;
    assert_error(&text, (1, col), &["`\\r`", "LF or CRLF"]);
    // CRLF is fine.
    let crlf = recipe(" stage: (render: (spp: 4)),\n").replace('\n', "\r\n");
    assert!(first_error_or_none(&crlf).is_none());
}

fn first_error_or_none(text: &str) -> Option<RecipeError> {
    GemRecipe::check_source(Source::new("ok.ron", text), None)
        .errors
        .into_iter()
        .next()
}

#[test]
fn control_characters_in_names_are_refused_escaped() {
    // A raw BEL in a material name, and the same name through an escape.
    for (name, shown) in [
        ("ab\u{7}c", r#""ab\u{7}c""#),
        (r"ab\u{7}c", r#""ab\u{7}c""#),
    ] {
        let t = format!(
            "(materials: {{\n  \"{name}\": (base: Lambert(albedo: Gray(0.5))) }},\n surface: Material(\"{name}\"))"
        );
        assert_error(&t, (2, 3), &[shown, "control character"]);
    }
    // A map name, and a file name.
    let t = recipe(" maps: {\n   \"m\\x1b\": Material(\"a\") },\n");
    assert_error(&t, (4, 4), &[r#""m\u{1b}""#]);
    let t = recipe(" stage: (shape: Mesh(file: \"x\\t.obj\")),\n");
    assert_error(&t, (3, 28), &[r#""x\t.obj""#]);
    // A raw control character outside any string.
    let t = recipe(" stage: (render: (spp:\u{1} 4)),\n");
    assert_error(&t, (3, 23), &["\\u{1}", "control character"]);
    // In a material library too.
    let lib = "(materials: { \"x\u{7f}\": (base: Lambert(albedo: Gray(0.5))) })";
    let e = MaterialLibrary::parse("lib.ron", lib).unwrap_err();
    assert!(
        (e.line, e.col) == (1, 15) && e.message.contains(r#""x\u{7f}""#),
        "{e}"
    );
    // A control character in a comment is harmless.
    assert!(first_error_or_none(&recipe(" // \u{7}\n")).is_none());
}

#[cfg(unix)]
fn mkfifo(path: &Path) {
    let ok = Command::new("mkfifo").arg(path).status().unwrap().success();
    assert!(ok, "mkfifo {}", path.display());
}

/// Runs `f` on another thread and returns its result; a call that blocks (opening a FIFO waits
/// for a writer) fails the test instead of hanging it.
fn returns<T: Send + 'static>(f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    rx.recv_timeout(std::time::Duration::from_secs(120))
        .expect("the call blocked")
}

#[cfg(unix)]
#[test]
fn directories_fifos_and_devices_are_named_as_such() {
    let s = Scratch::new("odd", "kinds");
    std::fs::create_dir(s.path("dir.obj")).unwrap();
    std::fs::create_dir(s.path("dir.exr")).unwrap();
    mkfifo(&s.path("pipe.obj"));
    mkfifo(&s.path("pipe.exr"));
    let cases = [
        ("dir.obj", "is a directory"),
        ("pipe.obj", "is a FIFO"),
        ("/dev/null", "is a device"),
    ];
    for (name, words) in cases {
        let path = s.path(name);
        let e = returns(move || Mesh::load(&path, 1.0).unwrap_err().to_string());
        assert!(
            e.contains(words) && !e.contains("no such file"),
            "{name}: {e}"
        );
    }
    for (name, words) in [
        ("dir.exr", "is a directory"),
        ("pipe.exr", "is a FIFO"),
        ("/dev/zero", "is a device"),
    ] {
        let env = Environment::Map {
            path: s.path(name),
            intensity: 1.0,
            rotate: 0.0,
        };
        let e = returns(move || EnvironmentLight::new(&env).unwrap_err().to_string());
        assert!(
            e.contains(words) && !e.contains("no such file"),
            "{name}: {e}"
        );
    }
    // A recipe or an included library given as one.
    std::fs::create_dir(s.path("dir.ron")).unwrap();
    mkfifo(&s.path("pipe.ron"));
    let out = lapidary(&["check", "dir.ron", "pipe.ron", "/dev/null"], &s.0);
    let err = text(&out.stderr);
    for words in [
        "dir.ron: is a directory",
        "pipe.ron: is a FIFO",
        "/dev/null: is a device",
    ] {
        assert!(err.contains(words), "{words}: {err}");
    }
    let inc = "(include: [\"pipe.ron\"],\n materials: {}, surface: Material(\"x\"))";
    std::fs::write(s.path("inc.ron"), inc).unwrap();
    let out = lapidary(&["check", "inc.ron"], &s.0);
    let err = text(&out.stderr);
    assert!(
        err.contains("include \"pipe.ron\"") && err.contains("is a FIFO"),
        "{err}"
    );
    // Through a recipe: the stage's file check says the same, at the file name.
    for (stage, words) in [
        ("shape: Mesh(file: \"dir.obj\")", "is a directory"),
        ("shape: Mesh(file: \"pipe.obj\")", "is a FIFO"),
        ("environment: Map(file: \"pipe.exr\")", "is a FIFO"),
    ] {
        std::fs::write(s.path("r.ron"), recipe(&format!(" stage: ({stage}),\n"))).unwrap();
        let out = lapidary(&["check", "r.ron"], &s.0);
        let err = text(&out.stderr);
        assert!(!out.status.success() && err.contains(words), "{err}");
        assert!(err.contains("r.ron:3:"), "{err}");
    }
}

#[test]
fn obj_errors_carry_the_line_number() {
    let s = Scratch::new("odd", "obj");
    let tri = "# a triangle\nv 0 0 0\nv 1 0 0\nv 0 1 0\n";
    let cases = [
        (
            format!("{tri}f 1 2 3\nf 1 2 7\n"),
            "line 6:",
            "vertex index 7",
        ),
        (format!("{tri}f 1 2 -4\n"), "line 5:", "vertex index -4"),
        (format!("{tri}v 1 one 0\nf 1 2 3\n"), "line 5:", "`one`"),
        (format!("{tri}vn 0 0\nf 1 2 3\n"), "line 5:", "normal"),
        (format!("{tri}f 1 2 x\n"), "line 5:", "`x`"),
        (
            "v 0 0 0\nv 1 0 0\nv 0 inf 0\n\nf 1 2 3\n".to_string(),
            "line 3:",
            "`inf`",
        ),
    ];
    for (i, (obj, line, words)) in cases.iter().enumerate() {
        let path = s.path(&format!("bad{i}.obj"));
        std::fs::write(&path, obj).unwrap();
        let e = Mesh::load(&path, 1.0).unwrap_err().to_string();
        assert!(e.contains(line) && e.contains(words), "{obj}\n→ {e}");
    }
    // A scale that overflows a coordinate names the vertex too.
    let path = s.path("big.obj");
    std::fs::write(&path, format!("{tri}v 1e30 0 0\nf 1 2 4\n")).unwrap();
    let e = Mesh::load(&path, 1e9).unwrap_err().to_string();
    assert!(e.contains("line 5:") && e.contains("scale"), "{e}");
}

#[test]
fn integer_overflow_names_the_field_and_its_range() {
    let stage = |render: &str| recipe(&format!(" stage: (render: ({render})),\n"));
    assert_error(
        &stage("spp: 99999999999999999999"),
        (3, 24),
        &["spp", "1 ..= 1048576"],
    );
    assert_error(&stage("spp: -3"), (3, 24), &["spp = -3", "1 ..= 1048576"]);
    assert_error(
        &stage("width: 5e9"),
        (3, 26),
        &["= 5000000000", "1 ..= 16384"],
    );
    assert_error(&stage("seed: -1"), (3, 25), &["seed = -1", "0 ..= 2⁶⁴ − 1"]);
    assert_error(
        &stage("max_depth: 4294967296"),
        (3, 30),
        &["max_depth = 4294967296", "1 ..= 1024"],
    );
    // The recipe's own seed.
    let t = "(seed: 99999999999999999999,\n materials: { \"a\": (base: Lambert(albedo: Gray(0.5))) },\n surface: Material(\"a\"))";
    assert_error(t, (1, 8), &["seed", "0 ..= 2⁶⁴ − 1"]);
    // A seed deep in the map tree, read by the parser itself: named, with its range.
    let t = recipe(
        " maps: { \"v\": Voronoi(scale: 0.1, seed: -1, entries: [(1.0, Material(\"a\"))]) },\n",
    );
    let e = first_error(&t);
    assert!(
        e.line == 3 && e.message.contains("seed = -1") && e.message.contains("2⁶⁴ − 1"),
        "{e}"
    );
}

#[test]
fn absurd_radiance_is_refused_at_parse_with_the_range() {
    for stage in [
        "lights: [Rect(center: (0.0, 4.0, 0.0), size: (1.0, 1.0), radiance: Gray(1e30))]",
        "environment: Constant(Rgb(1.0, 1e30, 1.0))",
        "environment: Gradient(zenith: Gray(1e7), horizon: Gray(0.1), nadir: Gray(0.0))",
    ] {
        let e = first_error(&recipe(&format!(" stage: ({stage}),\n")));
        assert!(
            e.line == 3 && e.message.contains("radiance") && e.message.contains("0 ..= 1e6"),
            "{stage}: {e}"
        );
    }
    // The largest allowed value is accepted.
    let ok = recipe(" stage: (environment: Constant(Gray(1e6))),\n");
    assert!(first_error_or_none(&ok).is_none());
}

fn write_map(path: &Path, value: impl Fn(usize) -> f32) {
    let (w, h) = (8, 4);
    let data: Vec<f32> = (0..w * h).map(value).collect();
    let img = ExrImage {
        width: w as u32,
        height: h as u32,
        channels: ["R", "G", "B"]
            .map(|n| Channel::new(n, data.clone()))
            .into(),
        attributes: vec![],
    };
    write_exr(path, &img).unwrap();
}

#[test]
fn degenerate_environment_maps_are_refused_or_warned_about() {
    let s = Scratch::new("odd", "envmap");
    let map = |name: &str| Environment::Map {
        path: s.path(name),
        intensity: 1.0,
        rotate: 0.0,
    };
    write_map(&s.path("nan.exr"), |_| f32::NAN);
    let e = EnvironmentLight::new(&map("nan.exr"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("every pixel is NaN"), "{e}");
    write_map(
        &s.path("inf.exr"),
        |i| if i == 9 { f32::INFINITY } else { 1.0 },
    );
    let e = EnvironmentLight::new(&map("inf.exr"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("pixel (1, 1) is infinite"), "{e}");
    write_map(&s.path("huge.exr"), |i| if i == 10 { 1e30 } else { 1.0 });
    let e = EnvironmentLight::new(&map("huge.exr"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("pixel (2, 1)") && e.contains("up to 1e12"),
        "{e}"
    );
    write_map(&s.path("zero.exr"), |_| 0.0);
    let zero = EnvironmentLight::new(&map("zero.exr")).unwrap();
    assert!(
        zero.warnings().iter().any(|w| w.contains("renders black")),
        "{:?}",
        zero.warnings()
    );
    write_map(
        &s.path("some-nan.exr"),
        |i| if i < 3 { f32::NAN } else { 1.0 },
    );
    let some = EnvironmentLight::new(&map("some-nan.exr")).unwrap();
    assert!(some.warnings().iter().any(|w| w.contains("3 of 32 pixels")));
    write_map(&s.path("fine.exr"), |_| 0.5);
    assert!(
        EnvironmentLight::new(&map("fine.exr"))
            .unwrap()
            .warnings()
            .is_empty()
    );
    // `render` says so.
    let stage = " stage: (environment: Map(file: \"zero.exr\"), lights: [], render: (width: 4, height: 4, spp: 1)),\n";
    std::fs::write(s.path("black.ron"), recipe(stage)).unwrap();
    let out = lapidary(
        &["render", "black.ron", "-o", "black.exr", "--no-png"],
        &s.0,
    );
    let err = text(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("warning:") && err.contains("renders black"),
        "{err}"
    );
}

fn brdf_eval(dirs: &str) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_lapidary"))
        .args(["brdf", "--material", "silver_paint", "--eval"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(dirs.as_bytes())
        .unwrap();
    child.wait_with_output().unwrap()
}

#[test]
fn brdf_reads_directions_of_any_length() {
    let out = brdf_eval("0.3 0.2 0.9\n3e-30 2e-30 9e-30\n3e30 2e30 9e30\n300 200 900\n");
    assert!(out.status.success(), "{}", text(&out.stderr));
    let lines: Vec<String> = text(&out.stdout).lines().map(str::to_owned).collect();
    assert_eq!(lines.len(), 4);
    let values = |l: &str| -> Vec<f32> { l.split(' ').map(|x| x.parse().unwrap()).collect() };
    let first = values(&lines[0]);
    for l in &lines[1..] {
        for (a, b) in values(l).iter().zip(&first) {
            assert!(
                (a - b).abs() <= 1e-4 * b.abs().max(1.0),
                "{l} vs {:?}",
                first
            );
        }
    }
    for (input, words) in [
        (
            "0 0 1\n\n0 0 0\n",
            "stdin:3: the direction (0 0 0) has zero length",
        ),
        ("0 0 1\n0 nan 1\n", "stdin:2: expected three finite numbers"),
        ("0 0 1e999\n", "stdin:1: expected three finite numbers"),
    ] {
        let out = brdf_eval(input);
        let err = text(&out.stderr);
        assert!(
            !out.status.success() && err.contains(words),
            "{input:?}: {err}"
        );
    }
}

#[test]
fn brdf_counts_have_upper_bounds() {
    let dir = root();
    for (args, words) in [
        (vec!["--walks", "5000"], "1..=4096"),
        (vec!["--walks", "0"], "1..=4096"),
        (
            vec!["-m", "silver_paint", "--sample", "1000000000"],
            "1..=100000000",
        ),
        (vec!["-m", "silver_paint", "--sample", "0"], "1..=100000000"),
        (vec!["--samples", "100000000"], "1..=10000000"),
    ] {
        let mut full = vec!["brdf"];
        full.extend(&args);
        let out = lapidary(&full, &dir);
        let err = text(&out.stderr);
        assert!(
            !out.status.success() && err.contains(words),
            "{args:?}: {err}"
        );
    }
}

/// Runs `args`, reads one line of its standard output, closes the pipe, and returns the exit
/// status and standard error.
fn into_head(args: &[&str]) -> (std::process::ExitStatus, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_lapidary"))
        .args(args)
        .current_dir(root())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    assert!(!first.is_empty(), "{args:?} printed nothing");
    // The reader is dropped here: the pipe is closed.
    let out = child.wait_with_output().unwrap();
    (out.status, text(&out.stderr))
}

#[test]
fn commands_piped_into_head_exit_quietly() {
    let refs = "tests/refs/furnace.exr";
    for args in [
        vec!["brdf", "--list"],
        vec!["brdf", "-m", "silver_paint", "--sample", "100000"],
        vec!["brdf"],
        vec![
            "brdf",
            "-m",
            "silver_paint",
            "--albedo",
            "--samples",
            "2000",
        ],
        vec!["info", "gems/sunstone.ron"],
        vec!["check", "gems/sunstone.ron", "gems/lepidolite.ron"],
        vec!["compare", refs, refs],
    ] {
        let (status, err) = into_head(&args);
        assert_eq!(status.code(), Some(0), "{args:?}: {status:?}\n{err}");
        assert!(
            !err.to_lowercase().contains("broken pipe"),
            "{args:?}: {err}"
        );
    }
}
