//! Compiling gem recipes: determinism of the runtime tables, the effects set and what turns each
//! effect on, stage overrides over the studio, included materials.

use lapidary::recipe::GemRecipe;
use lapidary::scene::stage::{Environment, Projection, Shape};
use lapidary::scene::{Effect, Scene};
use std::path::Path;

fn shipped() -> Vec<std::path::PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("gems");
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    v.sort();
    v
}

fn compile(text: &str) -> Scene {
    GemRecipe::parse("t.ron", text)
        .and_then(|r| r.compile())
        .unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn compiling_twice_gives_identical_tables() {
    let gems = shipped();
    assert_eq!(gems.len(), 19, "{gems:?}");
    let mut hashes = vec![];
    for path in gems {
        let a = GemRecipe::load(&path).unwrap().compile().unwrap();
        let b = GemRecipe::load(&path).unwrap().compile().unwrap();
        assert_eq!(a, b, "{}", path.display());
        hashes.push(a.hash);
    }
    hashes.sort_unstable();
    hashes.dedup();
    assert_eq!(hashes.len(), 19, "every recipe hashes differently");
}

#[test]
fn effects_follow_what_the_recipe_uses() {
    const M: &str = r#"materials: {
        "plain": (coats: [(ior: 1.5, roughness: 2.0)], base: Lambert(albedo: Gray(0.5))),
        "tinted": (coats: [(ior: 1.5, roughness: 2.0, thickness: 1.0, tint: Gray(0.5))],
                   base: Lambert(albedo: Gray(0.5))),
        "course": (coats: [(ior: 1.5, roughness: 2.0)], base: Lambert(albedo: Gray(0.5)), model: Course),
    },"#;
    // Only "plain" is used: nothing is on, whatever the unused materials would need.
    let s = compile(&format!("({M} surface: Material(\"plain\"))"));
    assert_eq!(s.effects.iter().count(), 0, "{:?}", s.effects);
    assert_eq!(s.surface.unused().collect::<Vec<_>>(), ["tinted", "course"]);

    let s = compile(&format!("({M} surface: Material(\"tinted\"))"));
    let (why, _) = s.effects.reason(Effect::Absorption).unwrap();
    assert!(
        why.contains("\"tinted\" coats[0]") && why.contains("t.ron:3:"),
        "{why}"
    );
    assert!(!s.effects.on(Effect::TTerm));

    let s = compile(&format!(
        "({M} surface: Switch(by: Perlin(scale: 1.0), stops: [(0.0, Material(\"plain\")), (0.5, Material(\"course\"))], blend: 0.1))"
    ));
    assert!(s.effects.on(Effect::TTerm) && s.effects.on(Effect::StochasticSwitch));
    assert!(!s.effects.on(Effect::FacetBump) && !s.effects.on(Effect::GlitterOverlay));
    // blend 0: a hard switch is no stochastic switch.
    let s = compile(&format!(
        "({M} surface: Switch(by: Perlin(scale: 1.0), stops: [(0.0, Material(\"plain\")), (0.5, Material(\"course\"))]))"
    ));
    assert!(!s.effects.on(Effect::StochasticSwitch));
    // A zero-degree bump tilts nothing.
    let s = compile(&format!(
        "({M} surface: Voronoi(scale: 0.1, entries: [(1.0, Material(\"plain\"))], bump: Cone(half_angle: 0.0)))"
    ));
    assert!(!s.effects.on(Effect::FacetBump));
}

#[test]
fn the_stage_overrides_the_studio_part_by_part() {
    let dir = std::env::temp_dir().join(format!("lapidary-stage-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("sky.exr"), b"not read at compile time").unwrap();
    let recipe = dir.join("g.ron");
    std::fs::write(
        &recipe,
        r#"(materials: { "a": (base: Lambert(albedo: Gray(0.5))) }, surface: Material("a"),
           stage: (shape: Sphere(radius: 0.8),
                   environment: Map(file: "sky.exr", intensity: 2.0),
                   camera: Perspective(from: (0.0, 1.0, 5.0), to: (0.0, 0.0, 0.0), aperture: 0.05),
                   render: (spp: 16)))"#,
    )
    .unwrap();
    let s = GemRecipe::load(&recipe).unwrap().compile().unwrap();
    let studio = lapidary::scene::Stage::studio();
    assert_eq!(s.stage.shape, Shape::Sphere { radius: 0.8 });
    assert!(matches!(
        s.stage.environment,
        Environment::Map { intensity: 2.0, .. }
    ));
    assert_eq!(
        s.stage.lights, studio.lights,
        "lights not given: the studio's"
    );
    assert_eq!(s.stage.render.spp, 16);
    assert_eq!(s.stage.render.width, studio.render.width);
    let Projection::Perspective { focus_distance, .. } = s.stage.camera.projection else {
        panic!()
    };
    assert!((focus_distance - 26f32.sqrt()).abs() < 1e-5);
    assert!(s.effects.on(Effect::DepthOfField) && s.effects.on(Effect::EnvironmentImportance));
    // The studio itself turns neither on.
    let plain = compile(
        r#"(materials: { "a": (base: Lambert(albedo: Gray(0.5))) }, surface: Material("a"))"#,
    );
    assert!(!plain.effects.on(Effect::DepthOfField));
    assert!(!plain.effects.on(Effect::EnvironmentImportance));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn included_materials_follow_the_recipes_own_in_first_use_order() {
    let course = Path::new(env!("CARGO_MANIFEST_DIR")).join("materials/course.ron");
    let text = format!(
        r#"(include: [{:?}], materials: {{ "own": (base: Lambert(albedo: Gray(0.5))) }},
           surface: Voronoi(scale: 0.1, entries: [(1.0, Material("brass")), (1.0, Material("own")), (1.0, Material("sugar"))]))"#,
        course.display().to_string()
    );
    let s = compile(&text);
    assert_eq!(s.surface.names, ["own", "brass", "sugar"]);
    assert!(s.surface.used.iter().all(|u| *u));
    assert!(
        s.effects.on(Effect::Absorption),
        "brass has a tinted varnish"
    );
}

#[test]
fn every_shipped_file_checks_clean() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = shipped();
    for entry in std::fs::read_dir(root.join("materials")).unwrap() {
        files.push(entry.unwrap().path());
    }
    assert!(files.len() >= 8);
    for path in files {
        let report = lapidary::cli::check::check_file(&path);
        assert!(
            report.errors.is_empty() && report.warnings.is_empty(),
            "{}: {:?} {:?}",
            path.display(),
            report.errors,
            report.warnings
        );
        assert!(report.summary.contains("materials"), "{}", report.summary);
    }
}

#[test]
fn info_prints_materials_map_statistics_stage_and_effects() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_lapidary"))
        .arg("info")
        .arg(root.join("gems/lepidolite.ron"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    for expected in [
        "materials (20, 20 used)",
        "dark_silver",
        "map: 32 nodes (Voronoi 5, Overlay 1, Switch 1, Material 25)",
        "nesting depth 5 nodes; a lookup visits at most 3 Voronoi cells",
        "cells/unit",
        "surface.over ",
        "stage:",
        "render       640×480, 64 spp",
        "on   facet-bump               surface.over.bump = Cone { half_angle: 25.0 }",
        "on   stochastic-switch",
        "off  depth-of-field",
        "off  transmission             needs a recipe `body`",
    ] {
        assert!(text.contains(expected), "missing {expected:?} in\n{text}");
    }
    // Shares of the stone's surface add up to 100 %.
    let total: f64 = text
        .lines()
        .skip_while(|l| !l.starts_with("materials"))
        .skip(2)
        .take(20)
        .map(|l| {
            let pct = l.split_whitespace().nth(2).unwrap();
            pct.trim_end_matches('%').parse::<f64>().unwrap()
        })
        .sum();
    assert!((total - 100.0).abs() < 0.2, "{total}");
    // A recipe with an error: exit 1 and the positioned message.
    let bad = std::env::temp_dir().join(format!("lapidary-info-{}.ron", std::process::id()));
    std::fs::write(&bad, "(materials: {}, surface: Material(\"x\"))").unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_lapidary"))
        .arg("info")
        .arg(&bad)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains(":1:26: unknown material \"x\""), "{err}");
    let _ = std::fs::remove_file(&bad);
}

#[test]
fn info_names_the_body_and_the_recipe_line_that_turned_transmission_and_medium_on() {
    // The translucent gems: `transmission` and `medium` on, each naming the `body` line of the
    // recipe, and the body's row in the material table; a forced effect names who forced it.
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let info = |args: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_lapidary"))
            .arg("info")
            .args(args)
            .current_dir(root)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    };
    for gem in [
        "sunstone-pink",
        "sunstone-patterned",
        "aventurine-glass",
        "oregon-sunstone",
        "tinted-glass-sphere",
        "milky-stone",
    ] {
        let file = format!("gems/{gem}.ron");
        let source = std::fs::read_to_string(root.join(&file)).unwrap();
        // The line of the recipe's `body:` key (comments mention bodies too: skip them).
        let line = 1 + source
            .lines()
            .position(|l| l.trim_start().starts_with("body:"))
            .unwrap_or_else(|| panic!("{file} has no body"));
        let text = info(&[&file]);
        let transmission = format!("on   transmission             body ({file}:{line})");
        // The medium effect names the line of `body.medium`'s key.
        let medium_line = line
            + 1
            + source
                .lines()
                .skip(line)
                .position(|l| l.trim_start().starts_with("medium:"))
                .unwrap_or_else(|| panic!("{file} has no body.medium"));
        let medium = format!("on   medium                   body.medium ({file}:{medium_line})");
        for expected in [
            transmission.as_str(),
            medium.as_str(),
            "Body ",
            "body: IOR ",
            "manifold walks: halvings per step 1, continuation off",
        ] {
            assert!(
                text.contains(expected),
                "{file}: missing {expected:?} in\n{text}"
            );
        }
    }
    // Forced off on the command line: `info` says who forced it.
    let text = info(&[
        "gems/milky-stone.ron",
        "--effect",
        "medium=off",
        "--effect",
        "transmission=off",
    ]);
    for effect in ["transmission", "medium"] {
        let row = text
            .split("\neffects:")
            .nth(1)
            .expect("an effects section")
            .lines()
            .find(|l| l.contains(&format!(" {effect} ")))
            .unwrap_or_else(|| panic!("no {effect} row in\n{text}"));
        assert!(
            row.trim_start().starts_with("off") && row.contains("forced"),
            "{effect}: {row}"
        );
    }
}

#[test]
fn render_accuracy_knobs_rewrite_materials_and_force_effects() {
    use lapidary::bsdf::{FresnelMode, Model};
    const M: &str = r#"materials: {
        "tinted": (coats: [(ior: 1.5, roughness: 2.0, thickness: 1.0, tint: Gray(0.5))],
                   base: Lambert(albedo: Gray(0.5))),
    },
    surface: Voronoi(scale: 0.1, entries: [(1.0, Material("tinted"))], bump: Cone(half_angle: 20.0)),"#;
    let plain = compile(&format!("({M})"));
    assert!(plain.effects.on(Effect::Absorption) && plain.effects.on(Effect::FacetBump));
    assert!(plain.accuracy.is_default());

    let s = compile(&format!(
        "({M} stage: (render: (accuracy: (model: Course, fresnel: Table, absorption: false, \
         bump: false, effects: {{\"depth-of-field\": true}}))))"
    ));
    let stack = &s.surface.stacks[0];
    assert_eq!(
        (stack.model, stack.fresnel),
        (Model::Course, FresnelMode::Table)
    );
    assert_eq!(stack.coats[0].absorption.max_channel(), 0.0);
    // Absorption is gone from what the scene calls for; the Course model turned the t term on.
    assert!(!s.effects.called(Effect::Absorption) && !s.effects.on(Effect::Absorption));
    assert!(s.effects.on(Effect::TTerm));
    // The bump is still called for by the map, but forced off; depth of field forced on.
    assert!(s.effects.called(Effect::FacetBump) && !s.effects.on(Effect::FacetBump));
    assert!(!s.effects.called(Effect::DepthOfField) && s.effects.on(Effect::DepthOfField));
    let by = s.effects.forced_by(Effect::FacetBump).unwrap();
    assert!(
        by.contains("render.accuracy") && by.contains("t.ron:"),
        "{by}"
    );
    assert_eq!(
        s.accuracy.to_string(),
        "model=course,fresnel=table,absorption=off,bump=off,depth-of-field=on"
    );

    // Bad knobs: an unknown effect names the allowed ones at its line; an unknown field is a
    // parse error with its position; an effect this version cannot simulate cannot be forced on.
    let err = |text: String| match GemRecipe::parse("t.ron", &text).and_then(|r| r.compile()) {
        Ok(_) => panic!("accepted: {text}"),
        Err(e) => e.to_string(),
    };
    let e = err(format!(
        "({M} stage: (render: (accuracy: (effects: {{\"sparkle\": true}}))))"
    ));
    assert!(
        e.contains("t.ron:")
            && e.contains("unknown effect \"sparkle\"")
            && e.contains("facet-bump"),
        "{e}"
    );
    let e = err(format!("({M} stage: (render: (accuracy: (speed: 2))))"));
    assert!(e.contains("t.ron:") && e.contains("speed"), "{e}");
    // Every effect may be forced (fluorescence became the last simulated one in issue 20).
    assert!(
        GemRecipe::parse(
            "t.ron",
            &format!("({M} stage: (render: (accuracy: (effects: {{\"fluorescence\": true}}))))")
        )
        .and_then(|r| r.compile())
        .is_ok()
    );
}
