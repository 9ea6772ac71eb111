//! Bounds on what a recipe may ask for (issue 14, "nothing hangs, nothing runs out of memory"):
//! setup linear in the recipe, every count bounded at parse time with its position, inline
//! nesting up to the documented limit, memory estimated before a render allocates.

use std::process::{Command, Output};

#[path = "common/scratch.rs"]
mod scratch;
use scratch::Scratch;

fn lapidary(args: &[&str]) -> Output {
    lapidary_with(&[], args)
}

/// [`lapidary`] with environment variables set.
fn lapidary_with(env: &[(&str, &str)], args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lapidary"))
        .args(args)
        .envs(env.iter().copied())
        .output()
        .expect("binary runs")
}

fn text_of(b: &[u8]) -> String {
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
    let err = text_of(&out.stderr);
    assert!(out.status.success(), "{}", &err[..err.len().min(2000)]);
    assert!(
        text_of(&out.stdout).contains("100000 materials"),
        "{}",
        text_of(&out.stdout)
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
    assert!(out.status.success(), "{}", text_of(&out.stderr));

    // Every one used, through one Voronoi of 100 000 entries.
    std::fs::write(&file, many_materials(100_000, true)).unwrap();
    let out = lapidary(&["check", file.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text_of(&out.stderr));
    assert!(text_of(&out.stdout).contains("100001 map nodes"));
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
    let err = text_of(&out.stderr);
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

/// `n` map nodes nested inline: `n − 1` Switches (each with a Remap field and a second stop),
/// the innermost holding a material.
fn nested_switches(n: usize) -> String {
    let mut s = String::from("Material(\"a\")");
    for _ in 1..n {
        s = format!(
            "Switch(by: Remap(field: Perlin(scale: 1.0), from: (0.0, 1.0), to: (0.0, 1.0)),\n stops: [(0.0, {s}), (0.5, Material(\"a\"))], blend: 0.1)"
        );
    }
    format!("(materials: {{ \"a\": (base: Lambert(albedo: Gray(0.5))) }},\n surface: {s})")
}

/// `n` fields nested inline: `Sum([Sum([… Constant(0.5) …, Constant(0)]), Constant(0)])`.
fn nested_fields(n: usize) -> String {
    let mut f = String::from("Constant(0.5)");
    for _ in 1..n {
        f = format!("Sum([{f}, Constant(0.0)])");
    }
    format!(
        "(materials: {{ \"a\": (base: Lambert(albedo: Gray(0.5))) }},\n surface: Switch(by: {f}, stops: [(0.0, Material(\"a\"))]))"
    )
}

fn check(text: &str) -> Result<lapidary::scene::Scene, lapidary::recipe::RecipeError> {
    lapidary::recipe::GemRecipe::parse("nest.ron", text).and_then(|g| g.compile())
}

/// Inline nesting up to the documented 64 map levels (and 16 field levels) parses and compiles
/// (16 inline Switches used to hit the RON parser's recursion limit); one more is refused at the
/// first node too deep, in the project's words.
#[test]
fn inline_nesting_parses_up_to_the_limit_and_is_refused_beyond() {
    for n in [16, 64] {
        let scene = check(&nested_switches(n)).unwrap_or_else(|e| panic!("{n} levels: {e}"));
        assert_eq!(scene.surface.map.max_trail(scene.surface.map.root), 0);
    }
    let text = nested_switches(65);
    let e = check(&text).expect_err("65 levels");
    assert_eq!(e.message, "map tree nested 65 deep; at most 64", "{e}");
    // At the 65th node: the innermost `Material("a")`, on the last line but the closing ones.
    let at = text.find("Material(\"a\")),").unwrap();
    let line = text[..at].matches('\n').count() + 1;
    assert_eq!(
        (e.line, e.col),
        (line, at - text[..at].rfind('\n').unwrap()),
        "{e}"
    );
    let e = check(&nested_switches(300)).expect_err("300 levels");
    assert_eq!(e.message, "map tree nested 300 deep; at most 64", "{e}");

    check(&nested_fields(16)).unwrap_or_else(|e| panic!("16 fields: {e}"));
    let text = nested_fields(17);
    let e = check(&text).expect_err("17 fields");
    assert_eq!(e.message, "field nested 17 deep; at most 16", "{e}");
    assert_eq!(
        (e.line, e.col),
        (
            2,
            text.find("Constant(0.5)").unwrap() - text.find('\n').unwrap()
        )
    );

    // Brackets of any kind, however deep, get a message before the parser recurses into them.
    let text = format!("(materials: {}{})", "[".repeat(5000), "]".repeat(5000));
    let e = check(&text).expect_err("deep brackets");
    assert_eq!(e.message, "brackets nested 5001 deep; at most 256", "{e}");
    assert_eq!((e.line, e.col), (1, 268), "{e}");
}

/// Every count a recipe gives is bounded where it is written: the message names the field and
/// its limit, at `file:line:col` of the first element too many (or of the number).
#[test]
fn every_count_in_a_recipe_is_bounded_at_its_position() {
    let mat = |extra: &str| format!("(base: Lambert(albedo: Gray(0.5)){extra})");
    let gem = |extra: &str, surface: &str, stage: &str| {
        format!(
            "(materials: {{ \"a\": {} }},\n surface: {surface}{stage})",
            mat(extra)
        )
    };
    let list = |item: &str, n: usize| vec![item; n].join(", ");
    let light = "Rect(center: (0.0, 5.0, 0.0), target: (0.0, 0.0, 0.0), size: (1.0, 1.0), radiance: Gray(1.0))";
    let cases: Vec<(&str, String, String, &str)> = vec![
        (
            "Reference samples",
            gem(", model: Reference(samples: 100000)", "Material(\"a\")", ""),
            "samples: 100000".into(),
            "samples = 100000 is out of range: allowed 1 ..= 256",
        ),
        (
            "Reference max_depth",
            gem(", model: Reference(max_depth: 5000)", "Material(\"a\")", ""),
            "max_depth: 5000".into(),
            "max_depth = 5000 is out of range: allowed 1 ..= 4096",
        ),
        (
            "coats",
            gem(
                &format!(", coats: [{}]", list("(ior: 1.5, roughness: 3.0)", 17)),
                "Material(\"a\")",
                "",
            ),
            "".into(),
            "coats: more than 16 elements; at most 16",
        ),
        (
            "Sum inputs",
            gem(
                "",
                &format!(
                    "Switch(by: Sum([{}]), stops: [(0.0, Material(\"a\"))])",
                    list("Constant(1.0)", 65)
                ),
                "",
            ),
            "".into(),
            "inputs: more than 64 elements; at most 64",
        ),
        (
            "lights",
            gem(
                "",
                "Material(\"a\")",
                &format!(", stage: (lights: [{}])", list(light, 65)),
            ),
            "".into(),
            "lights: more than 64 elements; at most 64",
        ),
        (
            "Voronoi octaves",
            gem(
                "",
                "Switch(by: Perlin(scale: 1.0, octaves: 17), stops: [(0.0, Material(\"a\"))])",
                "",
            ),
            "octaves: 17".into(),
            "octaves = 17 is out of range: allowed 1 ..= 16",
        ),
    ];
    for (what, text, at, message) in cases {
        let e = check(&text).expect_err(what);
        assert!(e.message.contains(message), "{what}: {e}");
        assert!(e.line > 0 && e.col > 0, "{what}: {e}");
        if !at.is_empty() {
            let p = text.find(&at).unwrap();
            let line = text[..p].matches('\n').count() + 1;
            let col = p - text[..p].rfind('\n').map_or(0, |n| n + 1) + 1;
            let value = at.split(": ").next().unwrap().len() + 2;
            assert_eq!((e.line, e.col), (line, col + value), "{what}: {e}");
        }
    }

    // A list one element within its bound is accepted.
    let ok = gem(
        &format!(", coats: [{}]", list("(ior: 1.5, roughness: 3.0)", 16)),
        &format!(
            "Switch(by: Sum([{}]), stops: [(0.0, Material(\"a\"))])",
            list("Constant(1.0)", 64)
        ),
        &format!(", stage: (lights: [{}])", list(light, 64)),
    );
    check(&ok).unwrap_or_else(|e| panic!("{e}"));

    // 100 001 materials: refused at the first one too many (in its name).
    let mut text = String::from("(materials: {\n");
    for i in 0..100_001 {
        text += &format!("  \"m{i}\": (base: Lambert(albedo: Gray(0.5))),\n");
    }
    text += "}, surface: Material(\"m0\"))";
    let e = check(&text).expect_err("too many materials");
    assert_eq!(
        (e.line, e.col, e.message.as_str()),
        (
            100_002,
            4,
            "materials: more than 100000 definitions; at most 100000"
        ),
        "{e}"
    );
}

/// `--time-limit` covers setup: a recipe whose material tables take far longer than the limit
/// stops while they are built, says so, and writes nothing.
#[test]
fn a_time_limit_that_ends_during_setup_stops_it_and_writes_nothing() {
    let dir = Scratch::new("bounds", "setup-limit");
    let mut text = String::from("(materials: {\n");
    for i in 0..400 {
        text += &format!(
            "  \"m{i}\": (coats: [(ior: {:.4}, roughness: 5.0, thickness: 0.5), (ior: 1.6, roughness: 10.0)], base: Lambert(albedo: Gray(0.5))),\n",
            1.3 + f64::from(i) * 0.001
        );
    }
    text += "}, surface: Voronoi(scale: 0.1, entries: [";
    for i in 0..400 {
        text += &format!("(1.0, Material(\"m{i}\")),");
    }
    text += "]), stage: (lights: []))";
    std::fs::write(dir.path("slow.ron"), text).unwrap();
    let start = std::time::Instant::now();
    // The tables measured every run: a table cache that kept them from an earlier run of this
    // test would end setup sooner.
    let out = lapidary_with(
        &[("LAPIDARY_CACHE_DIR", "off")],
        &[
            "render",
            &dir.arg("slow.ron"),
            "-o",
            &dir.arg("slow.exr"),
            "--size",
            "8x8",
            "--spp",
            "1",
            "--time-limit",
            "0.5",
        ],
    );
    let err = text_of(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("stopped during setup: nothing rendered, nothing written"),
        "{err}"
    );
    assert_eq!(dir.files(), ["slow.ron"]);
    // (Building all 400 materials' tables takes tens of seconds; not asserted, just printed.)
    println!("stopped after {:?}", start.elapsed());
}

/// A render too big for the memory allowed is refused before anything is allocated, with the
/// figure; one that fits renders.
#[test]
fn a_render_needing_more_memory_than_allowed_is_refused_with_the_figure() {
    let dir = Scratch::new("bounds", "memory");
    std::fs::write(
        dir.path("g.ron"),
        "(materials: { \"a\": (base: Lambert(albedo: Gray(0.5))) }, surface: Material(\"a\"), stage: (lights: []))",
    )
    .unwrap();
    let render = |extra: &[&str]| {
        let mut args = vec!["render", "g.ron", "-o", "g.exr", "--spp", "1", "-q"];
        args.extend_from_slice(extra);
        Command::new(env!("CARGO_BIN_EXE_lapidary"))
            .args(&args)
            .current_dir(&dir.0)
            .output()
            .unwrap()
    };
    let out = render(&["--size", "8192x8192", "--max-memory", "8G"]);
    let err = text_of(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("the render needs 25.0 GiB, 8.0 GiB allowed (film 25.0 GiB)"),
        "{err}"
    );
    // Beyond the largest image (2^26 pixels) the size itself is refused, with the range.
    let out = render(&["--size", "16384x16384"]);
    let err = text_of(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("at most 67108864 pixels"), "{err}");
    assert_eq!(dir.files(), ["g.ron"]);
    let out = render(&["--size", "1024x1024", "--max-memory", "200M"]);
    let err = text_of(&out.stderr);
    assert!(
        err.contains("the render needs 416.0 MiB, 200.0 MiB allowed"),
        "{err}"
    );
    let out = render(&["--size", "64x64", "--max-memory", "200M"]);
    assert!(out.status.success(), "{}", text_of(&out.stderr));
    let out = render(&["--size", "64x64", "--max-memory", "1X"]);
    assert!(!out.status.success());
    assert!(text_of(&out.stderr).contains("expected a memory size"));
}
