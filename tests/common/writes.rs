//! Every command that writes a file, as a pair of runs over the same outputs (the second makes
//! different content), for the failed-write suites (`write_failures`, `full_disk`).

#![allow(dead_code)]

use super::scratch::Scratch;

/// A small coated recipe that renders in a fraction of a second.
pub const RECIPE: &str = r#"(
    materials: { "a": (coats: [(ior: 1.5, roughness: 8.0)], base: Lambert(albedo: Gray(0.5))) },
    surface: Material("a"),
    stage: (ground: Off),
)"#;

/// One command's outputs, made twice.
pub struct Case {
    /// The test's name.
    pub name: &'static str,
    /// Makes the inputs in the scratch directory.
    pub setup: fn(&Scratch),
    /// The run that makes the old outputs.
    pub first: Vec<String>,
    /// The run that would replace them with different content.
    pub second: Vec<String>,
    /// The files (relative to the scratch directory) both runs write.
    pub outputs: Vec<&'static str>,
    /// Exit codes of a run that wrote its outputs (`compare` and `regress` exit 1 for a failed
    /// comparison that still writes its heatmap).
    pub ok_status: Vec<i32>,
    /// Prefixes of files a failed second run may add (caches written before the failure).
    pub may_add: Vec<&'static str>,
}

fn args(a: &[&str]) -> Vec<String> {
    a.iter().map(|s| s.to_string()).collect()
}

fn recipe(s: &Scratch) {
    std::fs::write(s.path("gem.ron"), RECIPE).unwrap();
}

fn render_of(s: &Scratch, out: &str, extra: &[&str]) {
    let mut a = vec!["render", "gem.ron", "-o", out, "--size", "8x6", "--quiet"];
    a.extend(extra);
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_lapidary"))
        .args(&a)
        .current_dir(&s.0)
        .env_remove("LAPIDARY_WRITE_FAULT")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// The inputs of `merge` and `compare`: two parts of each of two seeds, and three full renders.
fn parts(s: &Scratch) {
    recipe(s);
    std::fs::create_dir_all(s.path("in")).unwrap();
    for seed in ["1", "2"] {
        for range in ["0..2", "2..4"] {
            let out = format!("in/p{seed}-{}.exr", &range[..1]);
            render_of(s, &out, &["--spp", "4", "--samples", range, "--seed", seed]);
        }
        render_of(
            s,
            &format!("in/full{seed}.exr"),
            &["--spp", "4", "--seed", seed],
        );
    }
    render_of(s, "in/full3.exr", &["--spp", "4", "--seed", "3"]);
}

fn suite(s: &Scratch) {
    std::fs::create_dir_all(s.path("suite")).unwrap();
    std::fs::write(s.path("suite/gem.ron"), RECIPE).unwrap();
}

/// A suite whose reference is of another grey, so that the test fails and writes its render and
/// heatmap.
fn failing_suite(s: &Scratch) {
    suite(s);
    recipe(s);
    let grey = RECIPE.replace("Gray(0.5)", "Gray(0.1)");
    std::fs::write(s.path("other.ron"), grey).unwrap();
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_lapidary"))
        .args([
            "render",
            "other.ron",
            "-o",
            "suite/gem.exr",
            "--no-png",
            "--size",
            "8x6",
        ])
        .args(["--spp", "64", "--quiet"])
        .current_dir(&s.0)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::remove_file(s.path("other.ron")).unwrap();
}

/// Every command that writes a file.
pub fn cases() -> Vec<Case> {
    let render = [
        "render", "gem.ron", "-o", "out.exr", "--size", "8x6", "--spp", "2",
    ];
    vec![
        Case {
            name: "render",
            setup: recipe,
            first: args(&[&render[..], &["--seed", "1"]].concat()),
            second: args(&[&render[..], &["--seed", "2"]].concat()),
            outputs: vec!["out.exr", "out.png"],
            ok_status: vec![0],
            may_add: vec![],
        },
        Case {
            name: "render_part",
            setup: recipe,
            first: args(
                &[
                    &render[..6],
                    &["--spp", "4", "--samples", "0..2", "--seed", "1"],
                ]
                .concat(),
            ),
            second: args(
                &[
                    &render[..6],
                    &["--spp", "4", "--samples", "0..2", "--seed", "2"],
                ]
                .concat(),
            ),
            outputs: vec!["out.exr"],
            ok_status: vec![0],
            may_add: vec![],
        },
        Case {
            name: "merge",
            setup: parts,
            first: args(&["merge", "in/p1-0.exr", "in/p1-2.exr", "-o", "m.exr"]),
            second: args(&["merge", "in/p2-0.exr", "in/p2-2.exr", "-o", "m.exr"]),
            outputs: vec!["m.exr", "m.png"],
            ok_status: vec![0],
            may_add: vec![],
        },
        Case {
            name: "compare_heatmap",
            setup: parts,
            first: args(&[
                "compare",
                "in/full1.exr",
                "in/full2.exr",
                "--heatmap",
                "h.png",
            ]),
            second: args(&[
                "compare",
                "in/full1.exr",
                "in/full3.exr",
                "--heatmap",
                "h.png",
            ]),
            outputs: vec!["h.png"],
            ok_status: vec![0, 1],
            may_add: vec![],
        },
        Case {
            name: "regress_update",
            setup: suite,
            first: args(&[
                "regress",
                "suite",
                "--update",
                "--ref-spp",
                "2",
                "--size",
                "8x6",
            ]),
            second: args(&[
                "regress",
                "suite",
                "--update",
                "--ref-spp",
                "4",
                "--size",
                "8x6",
            ]),
            outputs: vec!["suite/gem.exr"],
            ok_status: vec![0],
            may_add: vec![],
        },
        Case {
            name: "regress_failure",
            setup: failing_suite,
            first: args(&[
                "regress", "suite", "--spp", "4", "--seed", "1", "--out", "o",
            ]),
            second: args(&[
                "regress", "suite", "--spp", "4", "--seed", "2", "--out", "o",
            ]),
            outputs: vec!["o/gem-test.exr", "o/gem-heatmap.png"],
            ok_status: vec![1],
            may_add: vec![],
        },
        Case {
            name: "map",
            setup: recipe,
            first: args(&["map", "gem.ron", "--out", "m.png", "--size", "64"]),
            second: args(&["map", "gem.ron", "--out", "m.png", "--size", "80"]),
            outputs: vec!["m.png"],
            ok_status: vec![0],
            may_add: vec![],
        },
        Case {
            name: "tradeoff",
            setup: recipe,
            first: args(&[
                "tradeoff",
                "gem.ron",
                "--budget",
                "0.05",
                "--size",
                "8x6",
                "--ref-spp",
                "16",
                "--setting",
                "model=course",
                "--out",
                "t",
                "--quiet",
                "--seed",
                "1",
            ]),
            second: args(&[
                "tradeoff",
                "gem.ron",
                "--budget",
                "0.05",
                "--size",
                "8x6",
                "--ref-spp",
                "16",
                "--setting",
                "model=course",
                "--out",
                "t",
                "--quiet",
                "--seed",
                "2",
            ]),
            outputs: vec!["t/tradeoff.csv", "t/tradeoff-curves.csv", "t/tradeoff.png"],
            ok_status: vec![0],
            // The cached reference of the second seed is complete before the tables fail.
            may_add: vec!["t/gem-reference-"],
        },
        Case {
            name: "brdf_plot",
            setup: recipe,
            first: args(&["brdf", "--material", "brass", "--plot", "p.png"]),
            second: args(&["brdf", "--material", "sugar", "--plot", "p.png"]),
            outputs: vec!["p.png"],
            ok_status: vec![0],
            may_add: vec![],
        },
        Case {
            name: "farm_slurm",
            setup: recipe,
            first: args(&[
                "farm", "slurm", "gem.ron", "--parts", "2", "--spp", "4", "--dir", "f",
            ]),
            second: args(&[
                "farm", "slurm", "gem.ron", "--parts", "2", "--spp", "8", "--dir", "f",
            ]),
            outputs: vec!["f/render.sbatch", "f/parts/command.txt"],
            ok_status: vec![0],
            may_add: vec![],
        },
        Case {
            name: "farm_regress",
            setup: suite,
            first: args(&[
                "regress",
                "suite",
                "--farm",
                "slurm",
                "--farm-dir",
                "f",
                "--spp",
                "4",
            ]),
            second: args(&[
                "regress",
                "suite",
                "--farm",
                "slurm",
                "--farm-dir",
                "f",
                "--spp",
                "8",
            ]),
            outputs: vec!["f/regress.sbatch", "f/table.sbatch"],
            ok_status: vec![0],
            may_add: vec![],
        },
    ]
}
