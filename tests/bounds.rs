//! Bounds on what a recipe may ask for (issue 14, "nothing hangs, nothing runs out of memory"):
//! setup linear in the recipe, every count bounded at parse time with its position, inline
//! nesting up to the documented limit, memory estimated before a render allocates.

use std::process::{Command, Output};

#[path = "common/scratch.rs"]
mod scratch;
use scratch::Scratch;

fn lapidary(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lapidary"))
        .args(args)
        .output()
        .expect("binary runs")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// A recipe with `n` materials, each on its own line; the surface uses material 0 only, or every
/// material (through one Voronoi) when `all`.
fn many_materials(n: usize, all: bool) -> String {
    let mut s = String::from("(\n materials: {\n");
    for i in 0..n {
        s += &format!("  \"m{i}\": (base: Lambert(albedo: Gray(0.5))), // m{i}\n");
    }
    s += " },\n";
    if all {
        s += " surface: Voronoi(scale: 0.1, entries: [";
        for i in 0..n {
            s += &format!("(1.0, Material(\"m{i}\")),");
        }
        s += "]),\n)\n";
    } else {
        s += " surface: Material(\"m0\"),\n)\n";
    }
    s
}

/// 100 000 materials, 99 999 of them unused (one warning each, with its position): `check`
/// finishes (this took minutes while each warning searched the whole text) and `info` too.
#[test]
fn a_hundred_thousand_materials_check() {
    let dir = Scratch::new("bounds", "many");
    let file = dir.path("many.ron");
    std::fs::write(&file, many_materials(100_000, false)).unwrap();
    let out = lapidary(&["check", file.to_str().unwrap()]);
    let err = text(&out.stderr);
    assert!(out.status.success(), "{}", &err[..err.len().min(2000)]);
    assert!(
        text(&out.stdout).contains("100000 materials"),
        "{}",
        text(&out.stdout)
    );
    let warnings: Vec<&str> = err.lines().filter(|l| l.starts_with("warning:")).collect();
    assert_eq!(warnings.len(), 99_999);
    // Each warning points at its own key: material m{i} is defined on line i + 3.
    let last = warnings.last().unwrap();
    assert!(
        last.contains("many.ron:100002:3:") && last.contains("\"m99999\""),
        "{last}"
    );
    let out = lapidary(&["info", file.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out.stderr));

    // Every one used, through one Voronoi of 100 000 entries.
    std::fs::write(&file, many_materials(100_000, true)).unwrap();
    let out = lapidary(&["check", file.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("100001 map nodes"));
}

/// 100 000 unknown material names: each reported once at its own use (the first few with a
/// did-you-mean), without comparing every name with every other.
#[test]
fn a_hundred_thousand_unknown_names_are_each_reported() {
    let dir = Scratch::new("bounds", "unknown");
    let file = dir.path("unknown.ron");
    let src = many_materials(100_000, true).replace("Material(\"m", "Material(\"x");
    std::fs::write(&file, src).unwrap();
    let out = lapidary(&["check", file.to_str().unwrap()]);
    assert!(!out.status.success());
    let err = text(&out.stderr);
    let errors: Vec<&str> = err.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(errors.len(), 100_000, "{}", &err[..err.len().min(2000)]);
    assert!(
        errors[0].contains("unknown material \"x0\""),
        "{}",
        errors[0]
    );
    let last = errors.last().unwrap();
    assert!(last.contains("\"x99999\""), "{last}");
}

/// An 8192 × 4096 environment map (33.5 M texels, one bright patch): its sampling tables take at
/// most half of the image's own `f32` RGB size (they took 8 bytes a texel, f32 weights and CDF,
/// plus a grid-sized copy of the weights while building), and what it samples has exactly the
/// density it reports, down to the smallest texels.
#[test]
fn a_large_environment_map_keeps_its_tables_small() {
    use lapidary::image::exr::RgbImage;
    use lapidary::light::EnvironmentLight;
    let (w, h) = (8192u32, 4096u32);
    let mut pixels = vec![[0.25f32, 0.5, 0.75]; (w * h) as usize];
    for y in 1000..1040 {
        for x in 3000..3040 {
            pixels[(y * w + x) as usize] = [5e3; 3];
        }
    }
    // A dim corner far below the f32 resolution of its row's CDF.
    pixels[(h as usize - 1) * w as usize] = [1e-12; 3];
    let image_bytes = pixels.len() * 12;
    let light = EnvironmentLight::from_rgb(
        RgbImage {
            width: w,
            height: h,
            pixels,
        },
        1.0,
        0.0,
    );
    let tables = light.table_bytes();
    println!(
        "{w}x{h} map: tables {tables} bytes = {:.2} bytes per texel; image {image_bytes} bytes",
        tables as f64 / f64::from(w * h)
    );
    assert!(
        tables > 0 && tables * 2 <= image_bytes,
        "{tables} > {image_bytes}/2"
    );
    let (mut hits, mut sampled) = (0, 0);
    for i in 0..2000u32 {
        let u = glam::Vec2::new(
            (i as f32 + 0.5) / 2000.0,
            ((i * 7919) % 2000) as f32 / 2000.0,
        );
        // (A sample exactly at a pole has an infinite density and is refused.)
        let Some(s) = light.sample(u) else {
            continue;
        };
        sampled += 1;
        let pdf = light.pdf(s.wi);
        assert!(
            (pdf - s.pdf).abs() <= 1e-3 * s.pdf,
            "sample pdf {} but pdf() {pdf}",
            s.pdf
        );
        hits += usize::from(s.radiance.0[0] > 1e3);
    }
    assert!(sampled > 1990, "{sampled}");
    // The patch holds most of the light (~ 1600 · 5e3 against 33.5 M · 0.5).
    assert!(hits > 500, "{hits} of 2000 samples on the bright patch");
}
