//! `lapidary render --view` (issue 38): the preview's stage moves on the command line, range-checked,
//! refused with `--samples`, and moving the image.

mod preview_common;

use preview_common::scratch;
use std::process::Command;

#[test]
fn render_view_is_range_checked_and_not_taken_by_part_renders() {
    let dir = scratch("view-cli");
    let recipe = dir.join("lepidolite.ron");
    let run = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_lapidary"))
            .arg("render")
            .arg(&recipe)
            .args(["--size", "16x12", "--spp", "1", "--quiet", "--output"])
            .arg(dir.join("v.exr"))
            .args(args)
            .output()
            .unwrap()
    };
    let out = run(&["--view", "pitch=99"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("-85..=85"), "{err}");
    let out = run(&["--view", "yaw=30", "--samples", "0..1"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("part renders do not record the view"));
    assert!(!dir.join("v.exr").exists(), "nothing written");
    let out = run(&["--view", "yaw=30,tilt_x=10,light_yaw=-45"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let moved = lapidary::image::read_exr(&dir.join("v.exr")).unwrap();
    let out = run(&[]);
    assert!(out.status.success());
    let plain = lapidary::image::read_exr(&dir.join("v.exr")).unwrap();
    let r = |i: &lapidary::image::ExrImage| {
        i.channels
            .iter()
            .find(|c| c.name == "R")
            .unwrap()
            .data
            .clone()
    };
    assert_ne!(r(&moved), r(&plain), "the view moves the image");
}
