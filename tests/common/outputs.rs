//! What the `cli_outputs*` suites share: the binary run in a scratch directory, tiny and long
//! renders, and the assertions on a refused run.

#![allow(dead_code)] // each suite uses a different part

use super::scratch::{Scratch, text};
use std::process::{Command, Output, Stdio};

pub const SUNSTONE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/gems/sunstone.ron");
/// Writes a copy of the Sunstone recipe to `dest` whose paths into the repository (its measured
/// spectrum, `../data/…`) stay valid wherever the copy lies.
pub fn copy_sunstone(dest: &std::path::Path) {
    let text = std::fs::read_to_string(SUNSTONE).unwrap();
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/");
    std::fs::write(dest, text.replace("\"../", &format!("\"{root}"))).unwrap();
}

/// A render that takes well under a second.
pub const TINY: [&str; 4] = ["--size", "16x16", "--spp", "1"];
/// A render whose first pass takes far longer than setup; only ever stopped early.
pub const LONG: [&str; 4] = ["--size", "640x480", "--spp", "4096"];

/// Runs `lapidary ARGS…` in `dir`.
pub fn lapidary(dir: &Scratch, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lapidary"))
        .args(args)
        .current_dir(&dir.0)
        .stdin(Stdio::null())
        .output()
        .expect("binary runs")
}

/// Runs `lapidary render SUNSTONE ARGS… TINY`.
pub fn render(dir: &Scratch, args: &[&str]) -> Output {
    let mut all = vec!["render", SUNSTONE];
    all.extend(args);
    all.extend(TINY);
    lapidary(dir, &all)
}

/// Asserts exit status 1 with an `error:` naming `needle` and nothing on stdout (no summary).
pub fn refused(out: &Output, needle: &str) {
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "stderr:\n{err}");
    assert!(
        err.starts_with("error:") && err.contains(needle),
        "wanted `{needle}` in:\n{err}"
    );
    assert_eq!(text(&out.stdout), "", "no summary for a refused run");
}

/// Asserts a successful run.
pub fn ok(out: &Output) {
    assert_eq!(out.status.code(), Some(0), "stderr:\n{}", text(&out.stderr));
}
