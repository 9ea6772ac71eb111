//! No run destroys a file: every output path of every command is checked before any work
//! (devices, directories, FIFOs, symlinks, read-only files, outputs that are inputs, names whose
//! extension is another format's), a render writes its EXR and PNG together or not at all, and
//! stale temporary files of killed runs are removed. Every case runs the built binary; stopping
//! early is in `cli_outputs_stop`.

use std::path::Path;
use std::process::{Command, Output};

#[path = "common/scratch.rs"]
mod scratch;
use scratch::{Scratch, text};
#[path = "common/outputs.rs"]
mod run;
use run::{TINY, copy_sunstone, lapidary, ok, refused, render};

#[test]
fn a_directory_is_never_an_output() {
    let s = Scratch::new("outputs", "directory");
    std::fs::create_dir(s.path("d.exr")).unwrap();
    std::fs::create_dir(s.path("d.png")).unwrap();
    refused(&render(&s, &["-o", "d.exr"]), "d.exr: is a directory");
    // The PNG is a directory: refused before anything, so the EXR is not written either.
    refused(
        &render(&s, &["-o", "new.exr", "--png", "d.png"]),
        "d.png: is a directory",
    );
    assert_eq!(s.files(), ["d.exr", "d.png"]);
}

#[cfg(unix)]
#[test]
fn devices_stay_devices_even_for_root() {
    use std::os::unix::fs::FileTypeExt;
    let s = Scratch::new("outputs", "devices");
    for (args, needle) in [
        (
            &["-o", "a.exr", "--png", "/dev/null"][..],
            "/dev/null: is a character device",
        ),
        (
            &["-o", "/dev/null", "--no-png"][..],
            "/dev/null: is a character device",
        ),
        (
            &["-o", "a.exr", "--png", "/dev/stdout"][..],
            "/dev/stdout: is a",
        ),
    ] {
        refused(&render(&s, args), needle);
    }
    std::os::unix::fs::symlink("/dev/null", s.path("null.png")).unwrap();
    refused(
        &render(&s, &["-o", "a.exr", "--png", "null.png"]),
        "null.png: is a symlink to a character device (/dev/null)",
    );
    let null = std::fs::symlink_metadata("/dev/null").unwrap();
    assert!(null.file_type().is_char_device(), "/dev/null was replaced");
    assert_eq!(s.files(), ["null.png"]);
}

#[cfg(unix)]
#[test]
fn a_fifo_is_refused_and_stays_a_fifo() {
    use std::os::unix::fs::FileTypeExt;
    let s = Scratch::new("outputs", "fifo");
    let made = Command::new("mkfifo")
        .arg(s.path("f.png"))
        .status()
        .unwrap();
    assert!(made.success());
    refused(
        &render(&s, &["-o", "a.exr", "--png", "f.png"]),
        "f.png: is a FIFO",
    );
    let meta = std::fs::symlink_metadata(s.path("f.png")).unwrap();
    assert!(meta.file_type().is_fifo(), "the FIFO was replaced");
    assert_eq!(s.files(), ["f.png"], "the EXR was written without its PNG");
}

#[cfg(unix)]
#[test]
fn symlinks_are_written_through_to_their_target() {
    let s = Scratch::new("outputs", "symlink");
    std::fs::write(s.path("target.exr"), b"old").unwrap();
    std::os::unix::fs::symlink("target.exr", s.path("link.exr")).unwrap();
    ok(&render(&s, &["-o", "link.exr", "--no-png"]));
    let link = std::fs::symlink_metadata(s.path("link.exr")).unwrap();
    assert!(
        link.file_type().is_symlink(),
        "the link was replaced by a file"
    );
    let img = lapidary::image::read_exr(&s.path("target.exr")).expect("the target is the render");
    assert_eq!((img.width, img.height), (16, 16));
    // A link to nowhere, and a link to the recipe, are refused.
    std::os::unix::fs::symlink("nowhere.exr", s.path("dangling.exr")).unwrap();
    refused(
        &render(&s, &["-o", "dangling.exr", "--no-png"]),
        "dangling.exr: is a symlink that leads to no file",
    );
    copy_sunstone(&s.path("gem.ron"));
    let gem = std::fs::read(s.path("gem.ron")).unwrap();
    std::os::unix::fs::symlink("gem.ron", s.path("gem.exr")).unwrap();
    let out = lapidary(
        &s,
        &[
            "render", "gem.ron", "-o", "gem.exr", "--size", "16x16", "--spp", "1",
        ],
    );
    refused(&out, "gem.exr: is also an input (the recipe gem.ron)");
    assert_eq!(std::fs::read(s.path("gem.ron")).unwrap(), gem);
    assert_eq!(
        s.files(),
        [
            "dangling.exr",
            "gem.exr",
            "gem.ron",
            "link.exr",
            "target.exr"
        ]
    );
}

#[cfg(unix)]
#[test]
fn a_read_only_output_is_refused_not_replaced() {
    use std::os::unix::fs::PermissionsExt;
    let s = Scratch::new("outputs", "read-only");
    std::fs::write(s.path("ro.exr"), b"keep me").unwrap();
    std::fs::set_permissions(s.path("ro.exr"), std::fs::Permissions::from_mode(0o444)).unwrap();
    refused(
        &render(&s, &["-o", "ro.exr", "--no-png"]),
        "ro.exr: is read-only",
    );
    assert_eq!(std::fs::read(s.path("ro.exr")).unwrap(), b"keep me");
    let mode = std::fs::metadata(s.path("ro.exr"))
        .unwrap()
        .permissions()
        .mode();
    assert_eq!(mode & 0o777, 0o444);
    assert_eq!(s.files(), ["ro.exr"]);
}

#[cfg(unix)]
#[test]
fn a_png_that_cannot_be_written_leaves_the_old_exr() {
    use std::os::unix::fs::PermissionsExt;
    let s = Scratch::new("outputs", "png-fails");
    std::fs::write(s.path("a.exr"), b"old exr").unwrap();
    std::fs::create_dir(s.path("locked")).unwrap();
    std::fs::set_permissions(s.path("locked"), std::fs::Permissions::from_mode(0o555)).unwrap();
    for (png, needle) in [
        ("locked/a.png", "directory locked is not writable"),
        ("missing/a.png", "directory missing does not exist"),
    ] {
        refused(&render(&s, &["-o", "a.exr", "--png", png]), needle);
        assert_eq!(std::fs::read(s.path("a.exr")).unwrap(), b"old exr", "{png}");
    }
    assert_eq!(std::fs::read_dir(s.path("locked")).unwrap().count(), 0);
    std::fs::set_permissions(s.path("locked"), std::fs::Permissions::from_mode(0o755)).unwrap();
    assert_eq!(s.files(), ["a.exr", "locked"]);
}

#[test]
fn no_output_is_an_input_or_another_output() {
    let s = Scratch::new("outputs", "inputs");
    copy_sunstone(&s.path("x.ron"));
    let gem = std::fs::read(s.path("x.ron")).unwrap();
    let tiny = |args: &[&str]| {
        let mut all = vec!["render", "x.ron"];
        all.extend(args);
        all.extend(TINY);
        lapidary(&s, &all)
    };
    refused(
        &tiny(&["-o", "x.ron"]),
        "x.ron: is also an input (the recipe x.ron)",
    );
    refused(
        &tiny(&["-o", "./x.ron", "--no-png"]),
        "is also an input (the recipe",
    );
    refused(
        &tiny(&["-o", "a.exr", "--png", "a.exr"]),
        "a.exr: is given for two outputs",
    );
    assert_eq!(std::fs::read(s.path("x.ron")).unwrap(), gem);
    // An environment map the recipe reads is an input too.
    let sky = lapidary::image::ExrImage {
        width: 4,
        height: 2,
        channels: ["R", "G", "B"]
            .map(|n| lapidary::image::Channel::new(n, vec![1.0; 8]))
            .into(),
        attributes: vec![],
    };
    lapidary::image::write_exr(&s.path("sky.exr"), &sky).unwrap();
    let sky_bytes = std::fs::read(s.path("sky.exr")).unwrap();
    std::fs::write(
        s.path("env.ron"),
        r#"(materials: { "a": (base: Lambert(albedo: Gray(0.5))) }, surface: Material("a"),
            stage: (shape: Sphere(radius: 0.8), environment: Map(file: "sky.exr")))"#,
    )
    .unwrap();
    let out = lapidary(
        &s,
        &[
            "render", "env.ron", "-o", "sky.exr", "--size", "16x16", "--spp", "1",
        ],
    );
    refused(&out, "sky.exr: is also an input (the environment map");
    assert_eq!(std::fs::read(s.path("sky.exr")).unwrap(), sky_bytes);
    assert_eq!(s.files(), ["env.ron", "sky.exr", "x.ron"]);
}

#[test]
fn an_extension_of_another_format_is_refused() {
    let s = Scratch::new("outputs", "extension");
    // `-o out.png` would write an EXR under a PNG name, then the PNG over it.
    refused(
        &render(&s, &["-o", "out.png"]),
        "out.png: EXR output, but the name ends in .png",
    );
    refused(
        &render(&s, &["-o", "a.exr", "--png", "x.exr"]),
        "x.exr: PNG output, but the name ends in .exr",
    );
    refused(
        &render(&s, &["-o", "noext", "--no-png"]),
        "noext: EXR output, but the name has no extension",
    );
    assert!(s.files().is_empty(), "{:?}", s.files());
}

#[test]
fn stale_temporary_files_of_dead_runs_are_removed() {
    let s = Scratch::new("outputs", "stale");
    // Process ids above Linux's maximum (2^22) never exist; this test's own process does.
    let dead = ".a.exr.lapidary-4999999-3.tmp.exr";
    let alive = format!(".a.png.lapidary-{}-0.tmp.png", std::process::id());
    for f in [dead, alive.as_str(), ".unrelated.tmp"] {
        std::fs::write(s.path(f), b"x").unwrap();
    }
    ok(&render(&s, &["-o", "a.exr"]));
    let mut want = vec![
        alive.clone(),
        ".unrelated.tmp".into(),
        "a.exr".into(),
        "a.png".into(),
    ];
    if !Path::new("/proc/self").exists() {
        want.push(dead.into()); // Without /proc nothing can be known dead: kept.
    }
    want.sort();
    assert_eq!(s.files(), want);
}

#[test]
fn map_compare_brdf_and_regress_check_their_outputs() {
    let s = Scratch::new("outputs", "commands");
    copy_sunstone(&s.path("x.ron"));
    let gem = std::fs::read(s.path("x.ron")).unwrap();
    refused(
        &lapidary(&s, &["map", "x.ron", "--out", "x.ron"]),
        "x.ron: is also an input",
    );
    refused(
        &lapidary(&s, &["map", "x.ron", "--out", "/dev/null"]),
        "is a character device",
    );
    assert_eq!(std::fs::read(s.path("x.ron")).unwrap(), gem);
    refused(
        &lapidary(
            &s,
            &["brdf", "--material", "silver_paint", "--plot", "p.exr"],
        ),
        "p.exr: PNG output, but the name ends in .exr",
    );
    // compare: the heatmap may not be one of the images compared (exit 2, unusable).
    ok(&render(&s, &["-o", "a.exr", "--no-png"]));
    let a = std::fs::read(s.path("a.exr")).unwrap();
    let out = lapidary(&s, &["compare", "a.exr", "a.exr", "--heatmap", "a.exr"]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("a.exr: is also an input (the test image"));
    assert_eq!(std::fs::read(s.path("a.exr")).unwrap(), a);
    // regress --update: a reference path that is a FIFO is refused before any render.
    #[cfg(unix)]
    {
        std::fs::create_dir(s.path("suite")).unwrap();
        copy_sunstone(&s.path("suite/g.ron"));
        assert!(
            Command::new("mkfifo")
                .arg(s.path("suite/g.exr"))
                .status()
                .unwrap()
                .success()
        );
        let out = lapidary(
            &s,
            &[
                "regress",
                "suite",
                "--update",
                "--ref-spp",
                "2",
                "--size",
                "8x8",
            ],
        );
        assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
        assert!(
            text(&out.stderr).contains("suite/g.exr: is a FIFO"),
            "{}",
            text(&out.stderr)
        );
        use std::os::unix::fs::FileTypeExt;
        assert!(
            std::fs::symlink_metadata(s.path("suite/g.exr"))
                .unwrap()
                .file_type()
                .is_fifo()
        );
    }
}

/// `lapidary tradeoff x.ron --out out …` at the smallest size and budget.
fn tradeoff(s: &Scratch, extra: &[&str]) -> Output {
    let mut args = vec![
        "tradeoff", "x.ron", "--out", "out", "--size", "8x8", "--budget", "0.05",
    ];
    args.extend(["--ref-spp", "16", "--ref-depth", "2", "--quiet"]);
    args.extend(extra);
    lapidary(s, &args)
}

#[test]
fn tradeoff_refuses_bad_settings_and_outputs_before_rendering() {
    let s = Scratch::new("outputs", "tradeoff");
    copy_sunstone(&s.path("x.ron"));
    for (setting, needle) in [
        ("", "--setting ``: an empty setting"),
        (
            "model=course,model=reference",
            "names the knob `model` twice",
        ),
        (
            "bump=off,facet-bump=on",
            "names the knob `facet-bump` twice",
        ),
        ("max-depth=2,,model=course", "an empty item between commas"),
    ] {
        refused(&tradeoff(&s, &["--setting", setting]), needle);
    }
    assert_eq!(s.files(), ["x.ron"], "nothing may be created");
    // A plot path that is a directory: refused before the reference renders, no CSV written.
    std::fs::create_dir_all(s.path("out/tradeoff.png")).unwrap();
    refused(
        &tradeoff(&s, &["--setting", "baseline"]),
        "tradeoff.png: is a directory",
    );
    let mut left: Vec<String> = std::fs::read_dir(s.path("out"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left, ["tradeoff.png"]);
    // An output folder that is a file.
    std::fs::write(s.path("file"), b"x").unwrap();
    let out = lapidary(
        &s,
        &[
            "tradeoff",
            "x.ron",
            "--out",
            "file",
            "--setting",
            "baseline",
        ],
    );
    refused(
        &out,
        "file: is a regular file; an output folder must be a directory",
    );
}
