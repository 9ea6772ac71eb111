//! Helpers shared by the farm tests (`#[path]`-included by `distributed` and `slurm`).

#![allow(dead_code)] // each test file uses a different part

use std::process::Output;

/// The standard output of a process that must have succeeded (else both streams in the panic).
pub fn ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// A `regress` table without its time column (the one column that differs between runs).
pub fn table(stdout: &str) -> Vec<String> {
    stdout
        .lines()
        .map(|l| match l.rfind(" s  ") {
            Some(i) => l[..l[..i].rfind(' ').unwrap_or(i)].to_string() + &l[i + 3..],
            None => l.to_string(),
        })
        .collect()
}

/// A small coated recipe for regression suites; replace `0.5` for other greys.
pub const RECIPE: &str = r#"(
    materials: { "a": (coats: [(ior: 1.5, roughness: 8.0)], base: Lambert(albedo: Gray(0.5))) },
    surface: Material("a"),
    stage: (ground: Off),
)"#;
