//! `lapidary regress DIR` end to end: making references with `--update`, a passing suite, a
//! failing recipe (one IOR changed) with its evidence written, and unusable input.

use std::path::Path;
use std::process::{Command, Output};

#[path = "common/scratch.rs"]
mod scratch;
use scratch::{Scratch, text};

const RECIPE: &str = r#"(
    materials: { "a": (coats: [(ior: 1.5, roughness: 8.0)], base: Lambert(albedo: Gray(0.5))) },
    surface: Material("a"),
    stage: (ground: Off),
)"#;

fn regress(dir: &Path, extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lapidary"))
        .arg("regress")
        .arg(dir.join("suite"))
        .args(extra)
        .current_dir(dir)
        .output()
        .expect("run lapidary")
}

#[test]
fn a_suite_passes_fails_and_reports_unusable_input() {
    let s = Scratch::new("regress", "suite");
    let suite = s.path("suite");
    std::fs::create_dir_all(&suite).unwrap();
    std::fs::write(suite.join("coated.ron"), RECIPE).unwrap();
    std::fs::write(
        suite.join("bright.ron"),
        RECIPE.replace("Gray(0.5)", "Gray(0.8)"),
    )
    .unwrap();

    // Make the references.
    let out = regress(&s.0, &["--update", "--ref-spp", "512", "--size", "32x24"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(suite.join("coated.exr").exists() && suite.join("bright.exr").exists());

    // The same recipes at 64 spp and another seed pass.
    let out = regress(&s.0, &[]);
    let stdout = text(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}{}", text(&out.stderr));
    assert!(
        stdout.contains("coated") && stdout.contains("bright"),
        "{stdout}"
    );
    assert_eq!(stdout.matches(" pass").count(), 2, "{stdout}");

    // One IOR changed: that recipe fails, its render and heatmap are written.
    std::fs::write(
        suite.join("coated.ron"),
        RECIPE.replace("ior: 1.5", "ior: 1.9"),
    )
    .unwrap();
    let out = regress(&s.0, &[]);
    let stdout = text(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    assert!(stdout.contains("FAIL"), "{stdout}");
    assert!(
        s.path("regress-out/coated-heatmap.png").exists(),
        "{stdout}"
    );
    assert!(s.path("regress-out/coated-test.exr").exists());

    // A recipe without a reference is unusable input: exit 2, and it says how to make one.
    std::fs::write(suite.join("new.ron"), RECIPE).unwrap();
    let out = regress(&s.0, &[]);
    let stdout = text(&out.stdout);
    assert_eq!(out.status.code(), Some(2), "{stdout}");
    assert!(
        stdout.contains("new") && stdout.contains("--update"),
        "{stdout}"
    );
}

#[test]
fn an_empty_or_missing_folder_is_an_error() {
    let s = Scratch::new("regress", "empty");
    std::fs::create_dir_all(s.path("suite")).unwrap();
    let out = regress(&s.0, &[]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out.stderr).contains("no recipes"),
        "{}",
        text(&out.stderr)
    );
    std::fs::remove_dir_all(s.path("suite")).unwrap();
    let out = regress(&s.0, &[]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("suite"));
}
