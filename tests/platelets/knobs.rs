//! Claim 8, the knobs reach the platelets: the faces of a body's platelets are layered materials
//! like the surface's, so the effects they call for are recorded (an absorbing coat turns
//! `absorption` on, credited to `body.platelets[k] entry j`, which `lapidary info` prints) and the
//! accuracy knobs rewrite them (`model=course` changes their model and turns the `t` term on for
//! their coats; `absorption=off` clears their coats) — at compile time and through
//! `Scene::set_accuracy`, which the command line and `lapidary tradeoff` use.

use super::{differences, render_on};
use glam::Vec3;
use lapidary::bsdf::{Bxdf, Model};
use lapidary::recipe::GemRecipe;
use lapidary::render::{Strategy, World};
use lapidary::scene::{Effect, Knobs, Scene};
use std::process::Command;

/// A clear body on a sphere whose surface material is uncoated (it calls for nothing) holding
/// one population of mirror and tinted-coat copper platelets (entry 1 absorbs), with `render`
/// (RON fields of `stage.render`) added.
fn recipe(render: &str) -> String {
    format!(
        r#"(
    materials: {{
        "mirror": (base: Conductor(metal: Perfect, roughness: 0.01)),
        "tinted_flake": (
            coats: [(ior: 1.8, roughness: 3.0, thickness: 1.0, absorption: Rgb(0.5, 1.0, 2.0))],
            base: Conductor(metal: Copper, roughness: 3.0)),
    }},
    body: (ior: 1.54, platelets: [(density: 3000.0, radius: (0.02, 0.04), orientation: Uniform,
        entries: [(1.0, "mirror"), (1.0, "tinted_flake")])]),
    surface: Body,
    stage: (shape: Sphere(radius: 1.0), transform: (translate: (0.0, 1.0, 0.0)),
            render: (width: 32, height: 24, spp: 8, max_depth: 12{render})),
)"#
    )
}

fn compile(text: &str) -> Scene {
    GemRecipe::parse("knobs.ron", text)
        .and_then(|r| r.compile())
        .unwrap_or_else(|e| panic!("{e}"))
}

/// The platelet material `name` of `scene`'s body.
fn face<'a>(scene: &'a Scene, name: &str) -> &'a lapidary::bsdf::StackDesc {
    let body = scene.surface.body.as_ref().expect("a body");
    &body
        .platelet_materials
        .iter()
        .find(|(n, _)| n == name)
        .expect("the platelet material")
        .1
}

#[test]
fn an_absorbing_platelet_coat_turns_absorption_on_and_info_names_it() {
    let text = recipe("");
    let s = compile(&text);
    assert!(s.effects.called(Effect::Absorption), "{:?}", s.effects);
    let (why, n) = s.effects.reason(Effect::Absorption).unwrap();
    assert!(
        why.starts_with("body.platelets[0] entry 1 material \"tinted_flake\" coats[0] (knobs.ron:"),
        "{why}"
    );
    assert_eq!(n, 1);
    // The default (Corrected) model needs no `t` term.
    assert!(!s.effects.called(Effect::TTerm));

    // `lapidary info` prints it.
    let path = std::env::temp_dir().join(format!(
        "lapidary-platelet-knobs-{}.ron",
        std::process::id()
    ));
    std::fs::write(&path, &text).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_lapidary"))
        .arg("info")
        .arg(&path)
        .output()
        .expect("lapidary info runs");
    let _ = std::fs::remove_file(&path);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let line = stdout
        .lines()
        .find(|l| l.contains(" absorption "))
        .unwrap_or_else(|| panic!("no absorption line:\n{stdout}"));
    assert!(
        line.trim_start().starts_with("on")
            && line.contains("body.platelets[0] entry 1 material \"tinted_flake\" coats[0]"),
        "{line}"
    );

    // Without the population (or with the body hidden) nothing calls for absorption.
    let hidden = compile(&text.replace("surface: Body,", r#"surface: Material("mirror"),"#));
    assert!(
        !hidden.effects.called(Effect::Absorption),
        "{:?}",
        hidden.effects.reason(Effect::Absorption)
    );
}

#[test]
fn knobs_rewrite_the_platelet_materials() {
    let s = compile(&recipe(""));
    assert_eq!(face(&s, "tinted_flake").model, Model::Corrected);
    let knobs = |setting: &str| {
        let mut t = s.clone();
        let k: Knobs = setting.parse().unwrap();
        k.apply(&mut t, "tests/platelets").unwrap();
        t
    };

    // `model=course`: every platelet face is evaluated with the course's model, and the coated one
    // now calls for the `t` term, credited to its entry.
    let course = knobs("model=course");
    for name in ["mirror", "tinted_flake"] {
        assert_eq!(face(&course, name).model, Model::Course, "{name}");
    }
    let (why, _) = course.effects.reason(Effect::TTerm).expect("t-term on");
    assert!(
        why.starts_with("body.platelets[0] entry 1 material \"tinted_flake\" (Course model"),
        "{why}"
    );
    assert!(course.effects.called(Effect::Absorption));
    // The runtime face changes with it.
    let (w0, w1) = (World::new(&s).unwrap(), World::new(&course).unwrap());
    let index = s.surface.body_index() as usize + 2;
    let (wo, wi) = (
        Vec3::new(0.3, 0.1, 0.9).normalize(),
        Vec3::new(-0.2, 0.4, 0.8).normalize(),
    );
    let f = |w: &World| w.materials[index].as_ref().map(|b| b.eval(wo, wi));
    assert!(f(&w0).is_some());
    assert_ne!(
        f(&w0),
        f(&w1),
        "model=course left the platelet face's BSDF unchanged"
    );

    // The same knob from the recipe's own `render.accuracy`.
    let from_recipe = compile(&recipe(", accuracy: (model: Course)"));
    assert_eq!(face(&from_recipe, "tinted_flake").model, Model::Course);
    assert!(from_recipe.effects.called(Effect::TTerm));

    // `absorption=off`: the coat is clear, nothing calls for absorption, and the image changes.
    let clear = knobs("absorption=off");
    let coat = face(&clear, "tinted_flake").coats[0];
    assert_eq!(coat.absorption.max_channel(), 0.0);
    assert!(!clear.effects.called(Effect::Absorption));
    assert_eq!(clear.effects.forced(Effect::Absorption), Some(false));
    let before = render_on(&w0, &s, 2, Strategy::Mis).film;
    let after = render_on(&World::new(&clear).unwrap(), &clear, 2, Strategy::Mis).film;
    let (n, _) = differences(&before, &after);
    assert!(n > 0, "absorption=off changed no pixel of the platelet gem");
}
