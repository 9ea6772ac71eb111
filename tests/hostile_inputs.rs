//! Inputs that used to be silently wrong are refused or handled, each with a clear message: a
//! translucent body on a mesh wound inside-out, contradictory flags, and the render summary that
//! hid its setup time.

use std::process::{Command, Output, Stdio};

#[path = "common/scratch.rs"]
mod scratch;
use scratch::{Scratch, text};

fn lapidary(dir: &Scratch, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lapidary"))
        .args(args)
        .current_dir(&dir.0)
        .stdin(Stdio::null())
        .output()
        .expect("binary runs")
}

/// A unit cube as OBJ, its faces wound counter-clockwise seen from outside (or all reversed).
fn cube(inside_out: bool) -> String {
    let mut s =
        String::from("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n");
    for f in [
        [1, 4, 3],
        [1, 3, 2],
        [5, 6, 7],
        [5, 7, 8],
        [1, 2, 6],
        [1, 6, 5],
        [4, 8, 7],
        [4, 7, 3],
        [1, 5, 8],
        [1, 8, 4],
        [2, 3, 7],
        [2, 7, 6],
    ] {
        let [a, b, c] = if inside_out { [f[0], f[2], f[1]] } else { f };
        s += &format!("f {a} {b} {c}\n");
    }
    s
}

const GLASS: &str = r#"(
    materials: {},
    body: (ior: 1.5, medium: (colour: Srgb(0.9, 0.6, 0.5), distance: 1.0)),
    surface: Body,
    stage: (shape: Mesh(file: "cube.obj"), ground: Off),
)"#;

#[test]
fn a_translucent_body_on_an_inside_out_mesh_is_refused() {
    let s = Scratch::new("hostile", "inside-out");
    std::fs::write(s.path("glass.ron"), GLASS).unwrap();
    let args = [
        "render",
        "glass.ron",
        "-o",
        "g.exr",
        "--size",
        "8x6",
        "--spp",
        "1",
    ];
    std::fs::write(s.path("cube.obj"), cube(false)).unwrap();
    let ok = lapidary(&s, &args);
    assert!(ok.status.success(), "{}", text(&ok.stderr));
    std::fs::write(s.path("cube.obj"), cube(true)).unwrap();
    std::fs::remove_file(s.path("g.exr")).unwrap();
    std::fs::remove_file(s.path("g.png")).unwrap();
    let out = lapidary(&s, &args);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("wound inside-out") && err.contains("-1.0000e0"),
        "the message names the fault and the signed volume:\n{err}"
    );
    assert!(!s.path("g.exr").exists() && !s.path("g.png").exists());
}

#[test]
fn contradictory_flags_are_refused_before_anything_is_written() {
    let s = Scratch::new("hostile", "contradictions");
    std::fs::write(
        s.path("gem.ron"),
        GLASS.replace("Mesh(file: \"cube.obj\")", "Sphere(radius: 1.0)"),
    )
    .unwrap();
    for (flags, first, second) in [
        (
            &["--effect", "spectral=on", "--spectral", "off"][..],
            "`--spectral off`",
            "`--effect spectral=on`",
        ),
        (
            &["--effect", "medium=on", "--effect", "medium=off"][..],
            "`--effect medium=off`",
            "`--effect medium=on`",
        ),
        (
            &["--bump", "on", "--effect", "facet-bump=off"][..],
            "`--effect facet-bump=off`",
            "`--bump on`",
        ),
    ] {
        for cmd in [
            &[
                "render", "gem.ron", "-o", "x.exr", "--size", "8x6", "--spp", "1",
            ][..],
            &["info", "gem.ron"][..],
            &["tradeoff", "gem.ron", "--out", "t", "--budget", "0.1"][..],
        ] {
            let out = lapidary(&s, &[cmd, flags].concat());
            let err = text(&out.stderr);
            assert_eq!(out.status.code(), Some(1), "{cmd:?} {flags:?}: {err}");
            assert!(
                err.contains(first) && err.contains(second) && err.contains("contradicts"),
                "{cmd:?} {flags:?}:\n{err}"
            );
        }
    }
    assert_eq!(s.files(), ["gem.ron"], "nothing written");
    // One value given twice is no contradiction.
    let out = lapidary(
        &s,
        &[
            "info",
            "gem.ron",
            "--effect",
            "medium=off",
            "--effect",
            "medium=off",
        ],
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
}

#[test]
fn the_summary_gives_setup_and_rendering_apart() {
    let s = Scratch::new("hostile", "summary");
    std::fs::write(
        s.path("gem.ron"),
        GLASS.replace("Mesh(file: \"cube.obj\")", "Sphere(radius: 1.0)"),
    )
    .unwrap();
    let out = lapidary(&s, &["render", "gem.ron", "--size", "8x6", "--spp", "1"]);
    let said = text(&out.stdout);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let first = said.lines().next().unwrap();
    // "… in T s: setup S s, rendering R s" with T = S + R (to the printed rounding).
    let num = |after: &str| -> f64 {
        let rest = &first[first.find(after).unwrap() + after.len()..];
        rest.split(' ').next().unwrap().parse().unwrap()
    };
    let (total, setup, rendering) = (num(" in "), num("setup "), num("rendering "));
    assert!((total - setup - rendering).abs() <= 0.1 + 1e-9, "{first}");
}

#[test]
fn a_file_where_a_folder_goes_is_named_as_one() {
    let s = Scratch::new("hostile", "folders");
    std::fs::write(
        s.path("gem.ron"),
        GLASS.replace("Mesh(file: \"cube.obj\")", "Sphere(radius: 1.0)"),
    )
    .unwrap();
    std::fs::create_dir(s.path("f")).unwrap();
    std::fs::write(s.path("f/parts"), "x").unwrap();
    let out = lapidary(
        &s,
        &[
            "farm", "slurm", "gem.ron", "--parts", "2", "--spp", "4", "--dir", "f",
        ],
    );
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("f/parts: is a regular file; an output folder must be a directory"),
        "the message names the file in the way and what it should be:\n{err}"
    );
    std::fs::write(s.path("t"), "x").unwrap();
    let out = lapidary(
        &s,
        &["tradeoff", "gem.ron", "--out", "t/sub", "--budget", "0.1"],
    );
    let err = text(&out.stderr);
    assert!(
        err.contains("directory t is not a directory (a file is in the way)"),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(s.path("f/parts")).unwrap(), "x");
}
