//! End-to-end tests of `lapidary brdf` through the built binary, and of every command writing to a
//! closed standard output.

use std::io::Write;
use std::process::{Command, Output, Stdio};

fn lapidary(args: &[&str], stdin: Option<&str>) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_lapidary"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("binary runs");
    if let Some(s) = stdin {
        child.stdin.take().unwrap().write_all(s.as_bytes()).unwrap();
    }
    drop(child.stdin.take());
    child.wait_with_output().unwrap()
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

#[test]
fn list_prints_the_catalogue_names() {
    let out = lapidary(&["brdf", "materials/course.ron", "--list"], None);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let names: Vec<String> = text(&out.stdout).lines().map(str::to_owned).collect();
    let expected = [
        "garnet_red_spray_paint",
        "sugar",
        "green_latex",
        "brass",
        "blue_metallic_car_paint",
        "gold_car_paint",
        "blue_metallic_paint",
        "silver_paint",
        "light_blue_house_paint",
        "blue_glossy_ceramic",
        "red_glossy_ceramic",
    ];
    assert_eq!(names, expected);
    // The built-in catalogue is the same file.
    let builtin = lapidary(&["brdf", "--list"], None);
    assert_eq!(text(&builtin.stdout), text(&out.stdout));
}

#[test]
fn eval_matches_sample_for_the_same_direction() {
    let s = lapidary(
        &[
            "brdf",
            "--material",
            "sugar",
            "--wo",
            "40,30",
            "--sample",
            "20",
            "--seed",
            "3",
        ],
        None,
    );
    assert!(s.status.success(), "{}", text(&s.stderr));
    let rows: Vec<Vec<f64>> = text(&s.stdout)
        .lines()
        .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 20);
    assert!(rows.iter().all(|r| r.len() == 7));
    let ok: Vec<&Vec<f64>> = rows.iter().filter(|r| r[6] > 0.0).collect();
    assert!(ok.len() >= 15, "most samples succeed");
    let input: String = ok
        .iter()
        .map(|r| format!("{} {} {}\n", r[0], r[1], r[2]))
        .collect();
    let e = lapidary(
        &["brdf", "--material", "sugar", "--wo", "40,30", "--eval"],
        Some(&input),
    );
    assert!(e.status.success(), "{}", text(&e.stderr));
    for (r, line) in ok.iter().zip(text(&e.stdout).lines()) {
        let v: Vec<f64> = line
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        let (f, pdf) = (&v[..3], v[3]);
        assert!((pdf - r[6]).abs() <= 1e-4 * pdf, "pdf {pdf} vs {}", r[6]);
        for c in 0..3 {
            let w = f[c] * r[2] / pdf;
            assert!(
                (w - r[3 + c]).abs() <= 1e-3 * w.abs().max(1e-6),
                "weight {w} vs {}",
                r[3 + c]
            );
        }
    }
}

#[test]
fn albedo_table_has_ninety_rows_with_errors() {
    let out = lapidary(
        &[
            "brdf",
            "--material",
            "silver_paint",
            "--albedo",
            "--samples",
            "2000",
        ],
        None,
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    let rows: Vec<Vec<f64>> = text(&out.stdout)
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 90);
    for (i, r) in rows.iter().enumerate() {
        assert_eq!(r[0] as usize, i);
        assert!(r[1..4].iter().all(|&a| a > 0.3 && a < 1.05), "{r:?}");
        assert!(r[4..7].iter().all(|&s| s > 0.0 && s < 0.05), "{r:?}");
        assert_eq!(r[7], 2000.0);
    }
}

#[test]
fn bad_input_gives_clear_errors_not_panics() {
    let out = lapidary(&["brdf", "--material", "sugarr", "--albedo"], None);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("did you mean \"sugar\""),
        "{}",
        text(&out.stderr)
    );

    let out = lapidary(
        &["brdf", "--material", "sugar", "--wo", "95", "--albedo"],
        None,
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out.stderr).contains("0 ..< 90"),
        "{}",
        text(&out.stderr)
    );

    let out = lapidary(
        &["brdf", "--material", "sugar", "--eval"],
        Some("0 0 1\n1 2\n"),
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("stdin:2"),
        "{}",
        text(&out.stderr)
    );

    let dir = std::env::temp_dir().join(format!("lapidary-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.ron");
    std::fs::write(&bad, "(materials: {\n  \"x\": (\n    coats: [(ior: 1.5, roughness: 95.0)],\n    base: Lambert(albedo: Gray(0.5)),\n  ),\n})\n").unwrap();
    let out = lapidary(&["brdf", bad.to_str().unwrap(), "--list"], None);
    assert_eq!(out.status.code(), Some(1));
    let err = text(&out.stderr);
    assert!(
        err.contains("bad.ron:3:") && err.contains("roughness") && err.contains("90"),
        "{err}"
    );

    let missing = dir.join("missing.ron");
    let out = lapidary(&["brdf", missing.to_str().unwrap(), "--list"], None);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("cannot read"),
        "{}",
        text(&out.stderr)
    );
}

#[test]
fn plot_writes_a_png_and_a_failed_plot_keeps_the_old_file() {
    let dir = std::env::temp_dir().join(format!("lapidary-plot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let png = dir.join("brass.png");
    let out = lapidary(
        &[
            "brdf",
            "--material",
            "brass",
            "--plot",
            png.to_str().unwrap(),
            "--samples",
            "500",
            "--walks",
            "1",
        ],
        None,
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    // Unknown material: the run fails before writing and the good file stays.
    let out = lapidary(
        &[
            "brdf",
            "--material",
            "nope",
            "--plot",
            png.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(std::fs::read(&png).unwrap(), bytes);
    let leftovers = std::fs::read_dir(&dir).unwrap().count();
    assert_eq!(leftovers, 1, "no temporary files left behind");
}

/// Standard output closed before the command writes (as with `| head`): no panic, whatever the
/// subcommand. `info` and `brdf` write after some work, so the pipe is closed by then.
#[test]
fn a_closed_stdout_ends_output_without_a_panic() {
    let gem = concat!(env!("CARGO_MANIFEST_DIR"), "/gems/lepidolite.ron");
    for args in [
        vec!["info", gem, "--points", "20000"],
        vec!["brdf", "materials/course.ron", "--list"],
        vec!["check", gem],
    ] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_lapidary"))
            .args(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("binary runs");
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        let err = text(&out.stderr);
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
}
