//! `lapidary tradeoff` end to end on a small coated-gold scene: the table, both CSV files and the
//! plot are written; the Course model's energy gain under a coat shows in the numbers; the
//! reference is cached between runs; bad settings are refused before anything renders.

use std::process::{Command, Output};

#[path = "common/scratch.rs"]
mod scratch;
use scratch::{Scratch, text};

/// Gold under a clear coat of IOR 1.5: the Course model lacks the 1/η² compression of the
/// refracted lobe, so it reflects much more than the Reference walk (course §3; docs/design.md §5.2).
const RECIPE: &str = r#"(
    materials: { "gold": (coats: [(ior: 1.5, roughness: 3.0)],
                          base: Conductor(metal: Gold, roughness: 10.0)) },
    surface: Material("gold"),
    stage: (ground: Off),
)"#;

/// Runs `lapidary tradeoff` on the scratch recipe at 32×24 with a 256-spp reference; `extra` may
/// set `--budget` (default 0.4 s).
fn tradeoff(s: &Scratch, extra: &[&str]) -> Output {
    let budget: &[&str] = if extra.contains(&"--budget") {
        &[]
    } else {
        &["--budget", "0.4"]
    };
    Command::new(env!("CARGO_BIN_EXE_lapidary"))
        .arg("tradeoff")
        .arg(s.arg("gold.ron"))
        .args(["--size", "32x24", "--ref-spp", "256"])
        .args(budget)
        .arg("--out")
        .arg(s.arg("out"))
        .args(extra)
        .output()
        .expect("run lapidary")
}

fn csv(path: &std::path::Path) -> Vec<Vec<String>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| {
            l.split(',')
                .map(|c| c.trim_matches('"').to_string())
                .collect()
        })
        .collect()
}

#[test]
fn tables_plot_energy_gain_and_a_cached_reference() {
    let s = Scratch::new("tradeoff", "run");
    std::fs::write(s.path("gold.ron"), RECIPE).unwrap();
    let settings = ["--setting", "baseline", "--setting", "model=course"];
    let out = tradeoff(&s, &settings);
    let stdout = text(&out.stdout);
    assert!(out.status.success(), "{stdout}{}", text(&out.stderr));
    assert!(
        stdout.contains("baseline") && stdout.contains("model=course"),
        "{stdout}"
    );

    // One row per setting, every column filled where the budget allowed.
    let rows = csv(&s.path("out/tradeoff.csv"));
    assert_eq!(rows.len(), 3, "{rows:?}");
    let header = &rows[0];
    assert_eq!(header.len(), 17, "{header:?}");
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    for r in &rows[1..] {
        assert_eq!(r.len(), header.len(), "{r:?}");
        for name in [
            "equal_spp_time_s",
            "equal_spp_relmse",
            "equal_time_spp",
            "equal_time_flip",
        ] {
            let v: f64 = r[col(name)]
                .parse()
                .unwrap_or_else(|_| panic!("{name}: {r:?}"));
            assert!(v.is_finite(), "{name}: {r:?}");
        }
    }
    let energy = |row: &Vec<String>| row[col("equal_time_energy")].parse::<f64>().unwrap();
    let (base, course) = (energy(&rows[1]), energy(&rows[2]));
    assert!(
        (0.9..1.1).contains(&base),
        "Corrected vs Reference energy {base}"
    );
    assert!(course > 1.15 * base, "Course {course} vs Corrected {base}");
    let relmse = |row: &Vec<String>| row[col("equal_time_relmse")].parse::<f64>().unwrap();
    assert!(relmse(&rows[2]) > 2.0 * relmse(&rows[1]), "{rows:?}");

    // The convergence curves: captures at 4, 8, 16, … spp with growing time.
    let curves = csv(&s.path("out/tradeoff-curves.csv"));
    let base_curve: Vec<&Vec<String>> = curves[1..].iter().filter(|r| r[0] == "baseline").collect();
    assert!(base_curve.len() >= 3, "{curves:?}");
    for (k, r) in base_curve.iter().enumerate() {
        assert_eq!(r[1], (4u32 << k).to_string());
    }
    let png = image::open(s.path("out/tradeoff.png")).unwrap();
    assert_eq!((png.width(), png.height()), (1400, 640));

    // Again: the reference comes from the cache, byte for byte the same file.
    let refs: Vec<String> = std::fs::read_dir(s.path("out"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains("-reference-"))
        .collect();
    assert_eq!(refs.len(), 1, "{refs:?}");
    let before = std::fs::read(s.path(&format!("out/{}", refs[0]))).unwrap();
    let out = tradeoff(&s, &["--setting", "baseline"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(
        text(&out.stderr).contains("(cached)"),
        "{}",
        text(&out.stderr)
    );
    assert_eq!(
        std::fs::read(s.path(&format!("out/{}", refs[0]))).unwrap(),
        before
    );
    assert_eq!(csv(&s.path("out/tradeoff.csv")).len(), 2);
}

#[test]
fn bad_settings_are_refused_before_rendering() {
    let s = Scratch::new("tradeoff", "bad");
    std::fs::write(s.path("gold.ron"), RECIPE).unwrap();
    for (args, expect) in [
        (
            vec!["--setting", "model=fast"],
            "course, corrected, reference",
        ),
        (vec!["--setting", "bump"], "key=value"),
        (vec!["--setting", "fluorescence=maybe"], "on, off"),
        (vec!["--spp", "12"], "power of two"),
        (vec!["--budget", "0"], "0.05..=86400"),
    ] {
        let out = tradeoff(&s, &args);
        assert!(!out.status.success(), "{args:?} accepted");
        let err = text(&out.stderr);
        assert!(err.contains(expect), "{args:?}: {err}");
        assert!(!s.path("out").exists(), "{args:?} wrote output");
    }
}
