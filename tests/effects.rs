//! Effects on demand: for each effect, a scene that does not call for it renders **bit-identically**
//! with the effect's code forced on or off (`Accuracy::force` through `Scene::set_accuracy`, the
//! `--bump off`-style knobs), so the renderer's skip of an unused effect changes nothing but speed.
//! `benches/effects.rs` times the same three variants.
//!
//! For every effect, the scenes that do not call for it are chosen to exercise the code next to the
//! effect: clear and zero-depth coats for `absorption`, uncoated and Reference-model coated stacks
//! for `t-term`, Voronoi maps without a bump or with a 0° bump for `facet-bump`, maps without an
//! `Overlay` for `glitter-overlay`, hard and single-stop switches for `stochastic-switch`, a pinhole
//! and an orthographic camera for `depth-of-field`, constant and gradient skies for
//! `environment-importance`. A film is compared field by field through `to_bits` (radiance sums,
//! squared sums, AOV sums, counts, material ids, ray counts), which `PartialEq` on `f64` would not
//! (it takes `-0.0 == 0.0`).
//!
//! Translucent bodies (issue 17): `transmission` (a body the surface shows) and `medium` (a body
//! whose interior absorbs or scatters) are checked on the shipped opaque Sunstone (and, with every
//! other effect, on the bare scene), each forced on and off alone and both together, on a recipe whose `body` the
//! surface never shows, and — for `medium` — on clear bodies (no medium, a zero medium, a white
//! colour), whose paths cross the boundary but need no free flight. Platelets (issue 18): a gem
//! without them — the opaque Sunstone and the clear tinted glass sphere — renders bit-identically
//! with the `platelets` code forced on or off (`benches/effects.rs` times it).
//!
//! Negative controls show the toggles are live: in a scene that calls for an effect, forcing it off
//! changes the image (absorption, facet bump, glitter overlay, stochastic switch, depth of field,
//! environment importance, transmission and medium on the translucent pink Sunstone), and forcing
//! the `t` term on in a coated Corrected scene changes it too — `t-term` is a model knob, not an
//! on-demand effect, so its "scene that does not call for it" has no coats (or Reference-model
//! coats). Fluorescence (issue 20) forced on or off leaves every scene without a fluorescent base
//! bit-identical, RGB and spectral. The medium's knobs (`medium-depth`, `medium-scattering`) change a scattering body and
//! leave an opaque gem bit-identical.
//!
//! Scenes are 48 × 36 pixels at 16 spp (Sobol') on the studio stage unless a test says otherwise.
//! The camera's and the sky's effects and fluorescence are in [`stage`]; the translucent bodies' effects (issues 17 and 18) in [`translucent`].

use lapidary::recipe::GemRecipe;
use lapidary::render::{Control, Film, PixelSums, World, render};
use lapidary::scene::{Accuracy, Effect, Knobs, Scene};
use std::path::Path;

#[path = "effects/stage.rs"]
mod stage;
#[path = "effects/translucent.rs"]
mod translucent;

/// Compiles recipe text and shrinks the render to 48 × 36 at 16 spp.
fn scene(text: &str) -> Scene {
    let mut s = GemRecipe::parse("effects.ron", text)
        .unwrap_or_else(|e| panic!("{e}"))
        .compile()
        .unwrap_or_else(|e| panic!("{e}"));
    small(&mut s);
    s
}

/// A shipped gem from `gems/`, shrunk like [`scene`].
fn gem(name: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("gems")
        .join(name);
    let mut s = GemRecipe::load(&path)
        .and_then(|r| r.compile())
        .unwrap_or_else(|e| panic!("{e}"));
    small(&mut s);
    s
}

fn small(s: &mut Scene) {
    let r = &mut s.stage.render;
    r.width = 48;
    r.height = 36;
    r.spp = 16;
}

/// Renders `scene` as `lapidary render` does: the world built from the scene's effects, the lens
/// used when depth of field is on.
fn film(scene: &Scene) -> Film {
    let world = World::new(scene).expect("world");
    let r = render(
        &world,
        &scene.stage.camera,
        scene.effects.on(Effect::DepthOfField),
        &scene.stage.render,
        &Control::default(),
    );
    assert_eq!(r.stats.dropped, 0);
    r.film
}

/// Field names of [`bits`].
const FIELDS: [&str; 18] = [
    "sum[0]",
    "sum[1]",
    "sum[2]",
    "sum_sq[0]",
    "sum_sq[1]",
    "sum_sq[2]",
    "albedo[0]",
    "albedo[1]",
    "albedo[2]",
    "normal[0]",
    "normal[1]",
    "normal[2]",
    "depth",
    "n",
    "dropped",
    "depth_n",
    "material",
    "rays",
];

/// Every field of a pixel as raw bits (the film's sums are fixed-point integers).
fn bits(p: &PixelSums) -> [u128; 18] {
    let w = |v: i64| u128::from(v as u64);
    [
        p.sum[0] as u128,
        p.sum[1] as u128,
        p.sum[2] as u128,
        p.sum_sq[0],
        p.sum_sq[1],
        p.sum_sq[2],
        w(p.albedo[0]),
        w(p.albedo[1]),
        w(p.albedo[2]),
        w(p.normal[0]),
        w(p.normal[1]),
        w(p.normal[2]),
        p.depth as u128,
        u128::from(p.n),
        u128::from(p.dropped),
        u128::from(p.depth_n),
        u128::from(p.material as u32),
        u128::from(p.rays),
    ]
}

/// Pixels whose bits differ in any field, and a description of the first difference.
fn differences(a: &Film, b: &Film) -> (usize, Option<String>) {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let mut count = 0;
    let mut first = None;
    for (k, (p, q)) in a.pixels.iter().zip(&b.pixels).enumerate() {
        let (bp, bq) = (bits(p), bits(q));
        if let Some(i) = (0..bp.len()).find(|&i| bp[i] != bq[i]) {
            count += 1;
            first.get_or_insert_with(|| {
                format!(
                    "pixel ({}, {}) {}: {p:?} vs {q:?}",
                    k as u32 % a.width,
                    k as u32 / a.width,
                    FIELDS[i]
                )
            });
        }
    }
    (count, first)
}

/// `scene` with `effect` forced `on` through the accuracy knobs.
fn forced(scene: &Scene, effect: Effect, on: bool) -> Scene {
    let mut s = scene.clone();
    let mut acc = Accuracy::default();
    acc.force(effect, on);
    s.set_accuracy(&acc, "tests/effects.rs")
        .unwrap_or_else(|e| panic!("forcing {effect} {on}: {e}"));
    assert_eq!(s.effects.forced(effect), Some(on));
    assert_eq!(s.effects.on(effect), on);
    s
}

/// The claim of the issue for one effect and one scene that does not call for it: the film is
/// bit-identical with the effect's code left alone, forced off and (if it can be) forced on.
fn assert_untouched(effect: Effect, what: &str, scene: &Scene) {
    if let Some(e) = untouched(effect, what, scene) {
        panic!("{e}");
    }
}

/// [`assert_untouched`], returning the failure.
fn untouched(effect: Effect, what: &str, scene: &Scene) -> Option<String> {
    assert!(
        !scene.effects.called(effect),
        "{what}: the scene calls for {effect} ({:?})",
        scene.effects.reason(effect)
    );
    assert!(!scene.effects.on(effect) && scene.effects.forced(effect).is_none());
    let auto = film(scene);
    // `spectral` forced on is not inert code but the other transport variant (its image differs
    // by what spectral rendering changes: tests/spectral_render.rs); forced off it is the RGB
    // renderer the scene gets anyway.
    let states: &[bool] = if effect != Effect::Spectral {
        &[false, true]
    } else {
        &[false]
    };
    for &on in states {
        let s = forced(scene, effect, on);
        assert!(
            !s.effects.called(effect),
            "{what}: forcing {effect} {on} made the scene call for it"
        );
        let (n, first) = differences(&auto, &film(&s));
        if n > 0 {
            return Some(format!(
                "{effect} forced {}: {what} is not bit-identical: {n} of {} pixels differ; first \
                 at {}",
                if on { "on" } else { "off" },
                auto.pixels.len(),
                first.unwrap_or_default()
            ));
        }
    }
    None
}

/// The opposite, for a scene that calls for `effect`: forcing it off changes the image.
fn assert_live(effect: Effect, what: &str, scene: &Scene) {
    assert!(
        scene.effects.called(effect) && scene.effects.on(effect),
        "{what}: the scene does not call for {effect}"
    );
    let auto = film(scene);
    let off = forced(scene, effect, false);
    let (n, _) = differences(&auto, &film(&off));
    eprintln!(
        "{effect} forced off in {what}: {n} of {} pixels change",
        auto.pixels.len()
    );
    assert!(
        n >= 20,
        "{effect} forced off in {what}: only {n} pixels change (the toggle looks dead)"
    );
}

/// A recipe on the studio stage (perspective pinhole camera, gradient sky, floor, three lights).
fn studio(materials: &str, surface: &str) -> String {
    format!("(materials: {{ {materials} }}, surface: {surface})")
}

/// Uncoated materials in a Voronoi: the scene calls for no effect at all.
fn bare() -> Scene {
    scene(&studio(
        r#""clay": (base: Lambert(albedo: Gray(0.6))),
           "gold": (base: Conductor(metal: Gold, roughness: 8.0))"#,
        r#"Voronoi(scale: 0.2, entries: [(1.0, Material("clay")), (1.0, Material("gold"))])"#,
    ))
}

#[test]
fn a_scene_that_calls_for_nothing_renders_identically_with_any_effect_forced() {
    let s = bare();
    assert_eq!(s.effects.iter().count(), 0, "{:?}", s.effects);
    for effect in Effect::ALL {
        assert_untouched(effect, "bare Voronoi (Lambert, gold)", &s);
    }
}

#[test]
fn absorption_code_changes_nothing_for_clear_coats() {
    // A clear coat with thickness, a coloured absorption with thickness 0 (optical depth 0), and
    // two clear coats under the Course model: the layered code runs, the absorption code never
    // needs to.
    let s = scene(&studio(
        r#""clear": (coats: [(ior: 1.5, roughness: 3.0, thickness: 1.0)], base: Lambert(albedo: Gray(0.5))),
           "thin": (coats: [(ior: 1.6, roughness: 6.0, absorption: Rgb(0.5, 1.0, 2.0))],
                    base: Conductor(metal: Gold, roughness: 4.0)),
           "double": (coats: [(ior: 1.4, roughness: 2.0, thickness: 2.0, absorption: Gray(0.0)),
                              (ior: 1.7, roughness: 9.0, thickness: 0.5)],
                      base: Lambert(albedo: Rgb(0.2, 0.5, 0.3)), model: Course)"#,
        r#"Voronoi(scale: 0.15, entries: [(1.0, Material("clear")), (1.0, Material("thin")),
                                         (1.0, Material("double"))])"#,
    ));
    assert!(s.effects.called(Effect::TTerm)); // the Course stack; not the effect under test
    assert_untouched(Effect::Absorption, "clear coats", &s);
}

#[test]
fn absorption_forced_off_changes_a_tinted_coat() {
    let s = scene(&studio(
        r#""amber": (coats: [(ior: 1.55, roughness: 2.0, thickness: 1.0, tint: Rgb(0.9, 0.5, 0.2))],
                     base: Lambert(albedo: Gray(0.7)))"#,
        r#"Material("amber")"#,
    ));
    assert_live(Effect::Absorption, "a tinted coat", &s);
    // The knob rewrites the coats: nothing calls for absorption afterwards.
    assert!(
        !forced(&s, Effect::Absorption, false)
            .effects
            .called(Effect::Absorption)
    );
}

#[test]
fn t_term_code_changes_nothing_without_coats_or_under_the_reference_model() {
    assert_untouched(Effect::TTerm, "uncoated materials", &bare());
    // Coats evaluated by the Reference walk, which has no `t` term.
    let s = scene(&studio(
        r#""walk": (coats: [(ior: 1.5, roughness: 8.0)], base: Lambert(albedo: Gray(0.5)),
                    model: Reference(samples: 1, max_depth: 16))"#,
        r#"Material("walk")"#,
    ));
    assert_untouched(Effect::TTerm, "a Reference-model coat", &s);
}

#[test]
fn t_term_is_a_model_knob_for_coated_materials() {
    // A coated Corrected material does not call for the `t` term; forcing it off changes nothing,
    // forcing it on changes the model (and then the scene calls for it): by design, not a leak.
    let s = scene(&studio(
        r#""glaze": (coats: [(ior: 1.5, roughness: 12.0)], base: Lambert(albedo: Gray(0.5)))"#,
        r#"Material("glaze")"#,
    ));
    assert!(!s.effects.called(Effect::TTerm));
    let auto = film(&s);
    let (n, first) = differences(&auto, &film(&forced(&s, Effect::TTerm, false)));
    assert_eq!(n, 0, "t-term forced off: {}", first.unwrap_or_default());
    let on = forced(&s, Effect::TTerm, true);
    assert!(on.effects.called(Effect::TTerm));
    let (n, _) = differences(&auto, &film(&on));
    eprintln!("t-term forced on for a Corrected coat: {n} pixels change");
    assert!(n >= 20, "t-term forced on changed only {n} pixels");
    // And a Course coat with the term switched off in the recipe gets it back when forced on.
    let s = scene(&studio(
        r#""glaze": (coats: [(ior: 1.5, roughness: 12.0)], base: Lambert(albedo: Gray(0.5)),
                     model: Course, t_term: false)"#,
        r#"Material("glaze")"#,
    ));
    assert!(!s.effects.called(Effect::TTerm));
    let (n, _) = differences(&film(&s), &film(&forced(&s, Effect::TTerm, true)));
    assert!(n >= 20, "t-term forced on (Course) changed only {n} pixels");
}

#[test]
fn facet_bump_code_changes_nothing_without_a_bump() {
    // Nested Voronoi maps, none with a bump.
    let s = scene(&studio(
        r#""a": (base: Lambert(albedo: Gray(0.3))),
           "b": (coats: [(ior: 1.5, roughness: 1.0)], base: Conductor(metal: Silver, roughness: 2.0)),
           "c": (base: Lambert(albedo: Rgb(0.6, 0.3, 0.2)))"#,
        r#"Voronoi(scale: 0.4, entries: [
               (1.0, Voronoi(scale: 0.07, entries: [(1.0, Material("a")), (1.0, Material("b"))])),
               (1.0, Material("c"))])"#,
    ));
    assert_untouched(Effect::FacetBump, "nested Voronoi without bump", &s);
}

#[test]
fn facet_bump_code_changes_nothing_for_a_zero_degree_bump() {
    // A bump of 0° tilts nothing and does not call for the effect, but the map still hands out
    // facet normals (exactly +z): forced on, the renderer builds facet frames from them, and
    // `Frame::tilted(Vec3::Z)` renormalises `n` and re-orthogonalises `s`, which moves the frame
    // by rounding (found by this test: about 500 of 1728 pixels differ in the last bits).
    let mut failures = vec![];
    for bump in ["Cone(half_angle: 0.0)", "Beckmann(rms: 0.0)"] {
        let s = scene(&studio(
            r#""a": (coats: [(ior: 1.5, roughness: 1.0)], base: Conductor(metal: Silver, roughness: 2.0)),
               "b": (base: Lambert(albedo: Gray(0.5)))"#,
            &format!(
                r#"Voronoi(scale: 0.1, entries: [(1.0, Material("a")), (1.0, Material("b"))],
                           bump: {bump})"#
            ),
        ));
        failures.extend(untouched(
            Effect::FacetBump,
            &format!("a Voronoi with bump {bump}"),
            &s,
        ));
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn facet_bump_forced_off_flattens_the_facets() {
    let s = scene(&studio(
        r#""flake": (coats: [(ior: 1.5, roughness: 1.0)], base: Conductor(metal: Silver, roughness: 2.0))"#,
        r#"Voronoi(scale: 0.1, entries: [(1.0, Material("flake"))], bump: Cone(half_angle: 30.0))"#,
    ));
    assert_live(Effect::FacetBump, "a bumped Voronoi", &s);
}

/// A hard marble switch between a Voronoi and a material: no Overlay, no blend band.
fn hard_switch() -> Scene {
    scene(&studio(
        r#""a": (base: Lambert(albedo: Gray(0.3))),
           "b": (coats: [(ior: 1.5, roughness: 2.0)], base: Lambert(albedo: Rgb(0.7, 0.4, 0.6))),
           "vein": (base: Lambert(albedo: Gray(0.9)))"#,
        r#"Switch(by: Marble(scale: 0.5, turbulence: 0.6),
                  stops: [(0.0, Voronoi(scale: 0.08, entries: [(1.0, Material("a")), (1.0, Material("b"))])),
                          (0.6, Material("vein"))])"#,
    ))
}

#[test]
fn glitter_overlay_code_changes_nothing_without_an_overlay() {
    assert_untouched(
        Effect::GlitterOverlay,
        "a hard switch over a Voronoi",
        &hard_switch(),
    );
}

#[test]
fn glitter_overlay_forced_off_hides_the_glitter() {
    let s = scene(&studio(
        r#""body": (base: Lambert(albedo: Rgb(0.6, 0.2, 0.1))),
           "glitter": (base: Conductor(metal: Copper, roughness: 2.0))"#,
        r#"Overlay(under: Material("body"),
                   over: Voronoi(scale: 0.06, fill: 0.3, entries: [(1.0, Material("glitter"))]))"#,
    ));
    assert_live(Effect::GlitterOverlay, "a glitter Overlay", &s);
}

#[test]
fn stochastic_switch_code_changes_nothing_for_hard_or_single_stop_switches() {
    assert_untouched(Effect::StochasticSwitch, "a hard switch", &hard_switch());
    // A blend band with one stop has no neighbour to blend with (blend may be anything there).
    let s = scene(&studio(
        r#""a": (base: Lambert(albedo: Gray(0.3))), "b": (base: Lambert(albedo: Gray(0.8)))"#,
        r#"Switch(by: Marble(scale: 0.5), blend: 0.5,
                  stops: [(0.5, Voronoi(scale: 0.1, entries: [(1.0, Material("a")), (1.0, Material("b"))]))])"#,
    ));
    assert_untouched(Effect::StochasticSwitch, "a one-stop switch with blend", &s);
}

#[test]
fn stochastic_switch_forced_off_makes_the_edges_hard() {
    let s = scene(&studio(
        r#""a": (base: Lambert(albedo: Gray(0.1))), "b": (base: Lambert(albedo: Gray(0.9)))"#,
        r#"Switch(by: Marble(scale: 0.5), stops: [(0.0, Material("a")), (0.5, Material("b"))], blend: 0.4)"#,
    ));
    assert_live(Effect::StochasticSwitch, "a blended switch", &s);
}
