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
    assert_eq!(
        stdout.lines().filter(|l| l.ends_with(" pass")).count(),
        2,
        "{stdout}"
    );
    // Each row is followed by its per-scale verdicts; a summary closes the table.
    assert_eq!(
        stdout
            .matches("    bias (tiles) |z|/limit: image (1) ")
            .count(),
        2,
        "{stdout}"
    );
    let scales = [", 16x16 (4) ", ", 8x8 (12) ", ", material (2) "];
    assert!(scales.iter().all(|s| stdout.contains(s)), "{stdout}");
    assert!(
        stdout.contains("summary: 2 passed, 0 failed, 0 unusable"),
        "{stdout}"
    );

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
    assert!(stdout.contains("    fails: "), "{stdout}");
    assert!(
        stdout.contains("summary: 1 passed, 1 failed, 0 unusable (failures by test: "),
        "{stdout}"
    );
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

/// Multiplies `img`'s R, G, B by `gain` where the stone is (`material.Y` ≥ 0; the sky behind
/// it is noise-free, so the per-pixel test would see any change there).
fn brighten(img: &mut lapidary::image::ExrImage, gain: f32) {
    let stone: Vec<bool> = img
        .channel("material.Y")
        .unwrap()
        .iter()
        .map(|&m| m >= 0.0)
        .collect();
    for c in img
        .channels
        .iter_mut()
        .filter(|c| ["R", "G", "B"].contains(&&*c.name))
    {
        for (v, _) in c.data.iter_mut().zip(&stone).filter(|(_, s)| **s) {
            *v *= gain;
        }
    }
}

#[test]
fn a_bias_below_the_pixel_noise_fails_and_the_table_says_at_which_scale() {
    use lapidary::image::{read_exr, write_exr};
    let s = Scratch::new("regress", "bias");
    let suite = s.path("suite");
    std::fs::create_dir_all(&suite).unwrap();
    std::fs::write(suite.join("coated.ron"), RECIPE).unwrap();
    let out = regress(&s.0, &["--update", "--ref-spp", "512", "--size", "32x24"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    // The stone 3 % too dark in the reference: every pixel's z stays small, the whole image's
    // does not.
    let path = suite.join("coated.exr");
    let mut reference = read_exr(&path).unwrap();
    brighten(&mut reference, 0.97);
    write_exr(&path, &reference).unwrap();
    let out = regress(&s.0, &[]);
    let stdout = text(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    assert!(
        stdout.contains("100.00 %"),
        "pixel test should pass: {stdout}"
    );
    assert!(
        stdout.contains("    bias (tiles) |z|/limit: image (1) "),
        "{stdout}"
    );
    assert!(stdout.contains(" FAIL, 16x16 (4) "), "{stdout}");
    assert!(
        stdout.contains("    fails: bias at image: |z| "),
        "{stdout}"
    );
    assert!(
        stdout.contains("(failures by test: pixel z-test 0, bias image 1"),
        "{stdout}"
    );

    // Without variance in the reference, a 1 % bias fails on the mean ratio (relMSE passes),
    // and passes with a looser --mean-tolerance.
    let mut reference = read_exr(&path).unwrap();
    brighten(&mut reference, 1.01 / 0.97);
    reference
        .channels
        .retain(|c| !c.name.starts_with("variance."));
    write_exr(&path, &reference).unwrap();
    let out = regress(&s.0, &[]);
    let stdout = text(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    assert!(
        stdout.contains("z-tests skipped (the reference has no variance"),
        "{stdout}"
    );
    assert!(stdout.contains("outside 1 ± 0.005"), "{stdout}");
    assert!(!stdout.contains("relMSE 1"), "{stdout}");
    let out = regress(&s.0, &["--mean-tolerance", "0.02"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stdout));
    // The tolerance is a bounded fraction.
    for bad in ["2", "-0.1", "nan", "1%"] {
        let out = regress(&s.0, &[&format!("--mean-tolerance={bad}")]);
        assert_eq!(out.status.code(), Some(2));
        let err = text(&out.stderr);
        assert!(err.contains("not a fraction in [0, 1]"), "{err}");
    }
}
