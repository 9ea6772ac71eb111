//! End-to-end tests of `lapidary map` through the built binary.

use std::path::PathBuf;
use std::process::{Command, Output};

fn lapidary(args: &[&str], threads: Option<usize>) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_lapidary"));
    cmd.args(args);
    if let Some(t) = threads {
        cmd.env("RAYON_NUM_THREADS", t.to_string());
    }
    cmd.output().expect("binary runs")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("lapidary-map-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn map_draws_the_shipped_gems_deterministically_on_any_thread_count() {
    let dir = scratch("ok");
    for gem in ["gems/lepidolite.ron", "gems/sunstone.ron"] {
        let (a, b) = (dir.join("a.png"), dir.join("b.png"));
        let args = |p: &PathBuf| {
            vec![
                "map".to_string(),
                gem.to_string(),
                "--out".into(),
                p.to_str().unwrap().into(),
                "--size".into(),
                "160".into(),
                "--plane".into(),
                "y=0.3".into(),
            ]
        };
        let run = |p: &PathBuf, t| {
            let v = args(p);
            let out = lapidary(&v.iter().map(String::as_str).collect::<Vec<_>>(), Some(t));
            assert!(out.status.success(), "{gem}: {}", text(&out.stderr));
            text(&out.stdout)
        };
        let report = run(&a, 1);
        // Same report (apart from the output name on the first line) and the same bytes.
        let body = |r: &str| r.lines().skip(1).collect::<Vec<_>>().join("\n");
        assert_eq!(body(&run(&b, 2)), body(&report));
        assert_eq!(
            std::fs::read(&a).unwrap(),
            std::fs::read(&b).unwrap(),
            "{gem}"
        );
        let img = image::open(&a).unwrap();
        // The map as asked, the legend beside it as tall as the map, and the summary says so.
        assert_eq!(img.height(), 160, "{gem}");
        assert!(img.width() > 160, "{gem}");
        let first = report.lines().next().unwrap();
        assert!(
            first.contains("map 160×160 px")
                && first.contains(&format!("({}×160 px)", img.width())),
            "{first}"
        );
        // Shares printed per material add up to 100 %.
        let total: f64 = report
            .lines()
            .filter_map(|l| l.trim().split_once(" %  "))
            .map(|(v, _)| v.trim().parse::<f64>().unwrap())
            .sum();
        assert!((total - 100.0).abs() < 0.1, "{gem}: {total}\n{report}");
        assert!(report.contains("glitter cells cover"), "{report}");
        // The albedo preview draws the same pattern in other colours.
        let c = dir.join("c.png");
        let mut v = args(&c);
        v.extend(["--colours".into(), "albedo".into()]);
        let out = lapidary(&v.iter().map(String::as_str).collect::<Vec<_>>(), None);
        assert!(out.status.success(), "{}", text(&out.stderr));
        assert_eq!(body(&text(&out.stdout)), body(&report));
        assert_ne!(std::fs::read(&c).unwrap(), std::fs::read(&a).unwrap());
    }
}

#[test]
fn bad_recipes_and_arguments_fail_cleanly_and_keep_the_old_file() {
    let dir = scratch("bad");
    let out_png = dir.join("keep.png");
    std::fs::write(&out_png, b"previous good output").unwrap();
    let bad = dir.join("bad.ron");
    std::fs::write(
        &bad,
        "(\n  materials: { \"a\": (base: Lambert(albedo: Gray(0.5))) },\n  surface: Voronoi(scale: 0.1, entries: [(1.0, Material(\"b\"))]),\n)\n",
    )
    .unwrap();
    let out = lapidary(
        &[
            "map",
            bad.to_str().unwrap(),
            "--out",
            out_png.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(out.status.code(), Some(1));
    let err = text(&out.stderr);
    assert!(
        err.contains("bad.ron:3:48") && err.contains("unknown material \"b\""),
        "{err}"
    );
    assert_eq!(std::fs::read(&out_png).unwrap(), b"previous good output");

    let out = lapidary(
        &[
            "map",
            "gems/sunstone.ron",
            "--out",
            out_png.to_str().unwrap(),
            "--plane",
            "w=1",
        ],
        None,
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out.stderr).contains("x, y, z"),
        "{}",
        text(&out.stderr)
    );

    let out = lapidary(
        &[
            "map",
            "gems/sunstone.ron",
            "--out",
            out_png.to_str().unwrap(),
            "--size",
            "3",
        ],
        None,
    );
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(std::fs::read(&out_png).unwrap(), b"previous good output");

    // An unwritable destination: an error, no panic.
    let out = lapidary(
        &[
            "map",
            "gems/sunstone.ron",
            "--out",
            "/nonexistent-dir/x.png",
            "--size",
            "16",
        ],
        None,
    );
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
}
