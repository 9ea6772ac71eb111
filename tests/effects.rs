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
//! coats). The two effects this version does not simulate (spectral, fluorescence) refuse to be
//! forced on, naming "does not simulate" and leaving the scene unchanged, and forcing them off is a
//! no-op. The medium's knobs (`medium-depth`, `medium-scattering`) change a scattering body and
//! leave an opaque gem bit-identical.
//!
//! Scenes are 48 × 36 pixels at 16 spp (Sobol') on the studio stage unless a test says otherwise.

use lapidary::recipe::GemRecipe;
use lapidary::render::{Control, Film, PixelSums, World, render};
use lapidary::scene::{Accuracy, Effect, Knobs, Scene};
use std::path::Path;

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

/// Every field of a pixel as raw bits.
fn bits(p: &PixelSums) -> [u64; 18] {
    let f = |v: f64| v.to_bits();
    [
        f(p.sum[0]),
        f(p.sum[1]),
        f(p.sum[2]),
        f(p.sum_sq[0]),
        f(p.sum_sq[1]),
        f(p.sum_sq[2]),
        f(p.albedo[0]),
        f(p.albedo[1]),
        f(p.albedo[2]),
        f(p.normal[0]),
        f(p.normal[1]),
        f(p.normal[2]),
        f(p.depth),
        u64::from(p.n),
        u64::from(p.dropped),
        u64::from(p.depth_n),
        u64::from(p.material as u32),
        p.rays,
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
    let states: &[bool] = if effect.implemented() {
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

/// A coated sphere seen by `camera`.
fn with_camera(camera: &str) -> Scene {
    scene(&format!(
        r#"(materials: {{ "a": (coats: [(ior: 1.5, roughness: 3.0)], base: Lambert(albedo: Gray(0.5))) }},
            surface: Voronoi(scale: 0.1, entries: [(1.0, Material("a"))]),
            stage: (camera: {camera}))"#
    ))
}

#[test]
fn depth_of_field_code_changes_nothing_for_a_pinhole_or_orthographic_camera() {
    let pinhole = with_camera(
        "Perspective(from: (0.0, 2.6, 4.2), to: (0.0, 0.15, 0.0), fov: 30.0, aperture: 0.0, \
         focus_distance: 2.0)",
    );
    assert_untouched(Effect::DepthOfField, "a pinhole camera", &pinhole);
    let ortho =
        with_camera("Orthographic(from: (0.0, 3.0, 4.0), to: (0.0, 0.2, 0.0), height: 2.6)");
    assert_untouched(Effect::DepthOfField, "an orthographic camera", &ortho);
}

#[test]
fn depth_of_field_forced_off_gives_a_pinhole() {
    let lens = with_camera(
        "Perspective(from: (0.0, 2.6, 4.2), to: (0.0, 0.15, 0.0), fov: 30.0, aperture: 0.2, \
         focus_distance: 2.0)",
    );
    assert_live(Effect::DepthOfField, "a thin lens", &lens);
}

/// The bare scene under `environment` with no lights (the sky is the only light).
fn under_sky(environment: &str) -> Scene {
    scene(&format!(
        r#"(materials: {{ "g": (coats: [(ior: 1.5, roughness: 10.0)], base: Lambert(albedo: Gray(0.5))) }},
            surface: Material("g"),
            stage: (lights: [], environment: {environment}))"#
    ))
}

#[test]
fn environment_importance_code_changes_nothing_for_analytic_skies() {
    for sky in [
        "Constant(Gray(0.8))",
        "Gradient(zenith: Rgb(0.2, 0.4, 1.0), horizon: Gray(1.0), nadir: Rgb(0.5, 0.3, 0.1))",
    ] {
        assert_untouched(Effect::EnvironmentImportance, sky, &under_sky(sky));
    }
}

#[test]
fn environment_importance_forced_off_samples_the_map_uniformly() {
    // A 32 × 16 lat-long sky, dim blue with a bright warm patch.
    let dir = std::env::temp_dir().join(format!("lapidary-effects-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("sky.exr");
    let (w, h) = (32u32, 16u32);
    let mut chans = vec![vec![0.0f32; (w * h) as usize]; 3];
    for y in 0..h {
        for x in 0..w {
            let sun = (8..14).contains(&x) && (3..7).contains(&y);
            let v = if sun {
                [8.0, 6.0, 4.0]
            } else {
                [0.1, 0.2, 0.4]
            };
            for (c, chan) in chans.iter_mut().enumerate() {
                chan[(y * w + x) as usize] = v[c];
            }
        }
    }
    let img = lapidary::image::ExrImage {
        width: w,
        height: h,
        channels: ["R", "G", "B"]
            .iter()
            .zip(chans)
            .map(|(n, data)| lapidary::image::Channel {
                name: n.to_string(),
                data,
            })
            .collect(),
        attributes: vec![],
    };
    lapidary::image::write_exr(&path, &img).unwrap();
    let s = under_sky(&format!(
        "Map(file: {:?}, intensity: 1.0)",
        path.display().to_string()
    ));
    assert_live(Effect::EnvironmentImportance, "an environment map", &s);
    // Forced on, a map that calls for it is unchanged.
    let (n, _) = differences(
        &film(&s),
        &film(&forced(&s, Effect::EnvironmentImportance, true)),
    );
    assert_eq!(n, 0);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn effects_this_version_does_not_simulate_cannot_be_forced_on() {
    // A scene that calls for every implemented effect but environment importance: forcing a
    // later-work slot off touches none of them.
    let busy = scene(
        r#"(materials: {
               "body": (coats: [(ior: 1.5, roughness: 2.0, thickness: 1.0, tint: Rgb(0.9, 0.6, 0.8))],
                        base: Lambert(albedo: Gray(0.6))),
               "vein": (coats: [(ior: 1.5, roughness: 4.0)], base: Lambert(albedo: Gray(0.9)), model: Course),
               "glitter": (base: Conductor(metal: Silver, roughness: 2.0)) },
            body: (ior: 1.55, roughness: 3.0,
                   medium: (colour: Srgb(0.9, 0.7, 0.6), distance: 1.0, scattering: (2.0, 2.0, 2.0))),
            surface: Overlay(
                under: Switch(by: Marble(scale: 0.5),
                              stops: [(0.0, Material("body")), (0.3, Body), (0.6, Material("vein"))],
                              blend: 0.1),
                over: Voronoi(scale: 0.06, fill: 0.1, entries: [(1.0, Material("glitter"))],
                              bump: Cone(half_angle: 20.0))),
            stage: (camera: Perspective(from: (0.0, 2.6, 4.2), to: (0.0, 0.15, 0.0), fov: 30.0,
                                        aperture: 0.05)))"#,
    );
    let called: Vec<Effect> = busy.effects.iter().collect();
    assert_eq!(
        called.len(),
        8,
        "the scene should call for eight effects: {called:?}"
    );
    let auto = film(&busy);
    for effect in Effect::ALL.into_iter().filter(|e| !e.implemented()) {
        let mut s = busy.clone();
        let mut acc = Accuracy::default();
        acc.force(Effect::Absorption, false); // set first: must not be applied either
        acc.force(effect, true);
        let err = s.set_accuracy(&acc, "test").unwrap_err().0;
        assert!(
            err.contains("does not simulate") && err.contains(effect.name()),
            "{effect}: {err}"
        );
        assert_eq!(s, busy, "{effect}: a refused knob changed the scene");
        let knobs: Knobs = format!("{}=on", effect.name()).parse().unwrap();
        let err = knobs.apply(&mut s, "test").unwrap_err().0;
        assert!(err.contains("does not simulate"), "{effect}: {err}");
        assert_eq!(s, busy);

        assert_untouched(effect, "a scene calling for eight other effects", &busy);
        let off = forced(&busy, effect, false);
        assert!(called.iter().all(|e| off.effects.on(*e)));
        let (n, first) = differences(&auto, &film(&off));
        assert_eq!(n, 0, "{effect} forced off: {}", first.unwrap_or_default());
    }
}

/// `scene` with each `(effect, on)` of `states` forced at once.
fn forced_all(scene: &Scene, states: &[(Effect, bool)]) -> Scene {
    let mut s = scene.clone();
    let mut acc = Accuracy::default();
    for &(effect, on) in states {
        acc.force(effect, on);
    }
    s.set_accuracy(&acc, "tests/effects.rs")
        .unwrap_or_else(|e| panic!("forcing {states:?}: {e}"));
    s
}

#[test]
fn transmission_and_medium_code_change_nothing_for_opaque_gems() {
    // The issue's claim for translucent bodies: an opaque gem renders bit-identically with the
    // transmission and medium code forced on or off, alone and together (forced on, the
    // free-flight code runs on every segment through a medium that neither absorbs nor scatters).
    let mut failures = vec![];
    for name in ["sunstone.ron"] {
        let s = gem(name);
        assert!(s.surface.body.is_none(), "{name} has a body");
        for effect in [Effect::Transmission, Effect::Medium] {
            failures.extend(untouched(effect, name, &s));
        }
        let auto = film(&s);
        for on in [false, true] {
            let both = forced_all(&s, &[(Effect::Transmission, on), (Effect::Medium, on)]);
            assert_eq!(both.effects.on(Effect::Medium), on);
            let (n, first) = differences(&auto, &film(&both));
            if n > 0 {
                failures.push(format!(
                    "{name}: transmission and medium both forced {on}: {n} pixels differ; first at {}",
                    first.unwrap_or_default()
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn platelet_code_changes_nothing_for_gems_without_platelets() {
    // Issue 18's claim: a gem without platelets renders bit-identically with the `platelets`
    // code forced on or off — an opaque gem and a clear, absorbing body whose paths run inside it.
    let mut failures = vec![];
    for name in ["sunstone.ron", "tinted-glass-sphere.ron"] {
        let s = gem(name);
        assert!(
            s.surface
                .body
                .as_ref()
                .is_none_or(|b| b.platelets.is_empty()),
            "{name} has platelets"
        );
        failures.extend(untouched(Effect::Platelets, name, &s));
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn manifold_code_changes_nothing_where_no_walk_can_start() {
    // Issue 18: manifold next-event estimation starts only at platelets and medium scattering
    // points inside a smooth boundary. An opaque gem, a smooth clear body (nothing inside
    // scatters) and a rough scattering body render bit-identically with it forced on or off.
    let mut failures = vec![];
    for name in ["sunstone.ron", "tinted-glass-sphere.ron", "milky-stone.ron"] {
        let s = gem(name);
        assert!(
            !s.effects.called(Effect::ManifoldNee),
            "{name} calls for the walk"
        );
        failures.extend(untouched(Effect::ManifoldNee, name, &s));
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn caustic_walk_changes_nothing_where_no_walk_can_start() {
    // Issue 18: the walk through the stone starts only at the floor under a smooth body. An
    // opaque gem and a rough scattering body render bit-identically with it forced on or off.
    let mut failures = vec![];
    for name in ["sunstone.ron", "milky-stone.ron"] {
        let s = gem(name);
        assert!(
            !s.effects.called(Effect::ManifoldCaustics),
            "{name} calls for the walk"
        );
        failures.extend(untouched(Effect::ManifoldCaustics, name, &s));
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn caustic_walk_forced_off_changes_a_gem_that_calls_for_it() {
    let s = gem("tinted-glass-sphere.ron");
    assert!(s.effects.called(Effect::ManifoldCaustics));
    assert_live(Effect::ManifoldCaustics, "tinted-glass-sphere.ron", &s);
}

#[test]
fn manifold_forced_off_changes_a_gem_that_calls_for_it() {
    let s = gem("oregon-sunstone.ron");
    assert!(s.effects.called(Effect::ManifoldNee));
    assert_live(Effect::ManifoldNee, "oregon-sunstone.ron", &s);
}

#[test]
fn a_body_the_surface_never_shows_changes_nothing() {
    // The recipe has a `body` (with an absorbing, scattering medium), but the map never shows
    // `Body`: the stone is opaque (a compile warning says so), nothing calls for transmission or
    // the medium, and forcing either changes nothing.
    let s = scene(&studio(
        r#""clay": (coats: [(ior: 1.5, roughness: 2.0)], base: Lambert(albedo: Gray(0.6)))"#,
        r#"Material("clay"),
           body: (ior: 1.5, medium: (absorption: (1.0, 2.0, 3.0), scattering: (4.0, 4.0, 4.0)))"#,
    ));
    assert!(s.surface.body.is_some());
    for effect in [Effect::Transmission, Effect::Medium] {
        assert_untouched(effect, "a body the map never shows", &s);
    }
}

#[test]
fn medium_code_changes_nothing_for_clear_bodies() {
    // Bodies the paths enter and leave, whose interior neither absorbs nor scatters: no medium,
    // a medium of zero coefficients (a forward phase function that never acts), and a white
    // colour (σa = −ln 1 = 0). Transmission is on; the free-flight code is not needed.
    let mut failures = vec![];
    for medium in [
        "",
        ", medium: (absorption: (0.0, 0.0, 0.0), phase: HenyeyGreenstein(g: 0.6))",
        ", medium: (colour: Gray(1.0), distance: 0.5)",
    ] {
        let s = scene(&studio(
            r#""flake": (coats: [(ior: 1.5, roughness: 3.0)], base: Conductor(metal: Copper, roughness: 4.0))"#,
            &format!(
                r#"Overlay(under: Body,
                           over: Voronoi(scale: 0.08, fill: 0.2, entries: [(1.0, Material("flake"))])),
                   body: (ior: 1.52, roughness: 2.0{medium}),
                   stage: (transform: (translate: (0.0, 0.002, 0.0)))"#
            ),
        ));
        assert!(s.effects.called(Effect::Transmission), "{medium}");
        failures.extend(untouched(
            Effect::Medium,
            &format!("a clear body `{medium}`"),
            &s,
        ));
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn transmission_and_medium_forced_off_change_a_translucent_gem() {
    // The pink Sunstone: glitter over a translucent, absorbing and scattering body. Forced off,
    // transmission makes the boundary reflect only; the medium makes the interior clear.
    let s = gem("sunstone-pink.ron");
    assert_live(Effect::Transmission, "sunstone-pink", &s);
    assert_live(Effect::Medium, "sunstone-pink", &s);
    // Forcing them on where the scene calls for them changes nothing.
    let auto = film(&s);
    let on = forced_all(&s, &[(Effect::Transmission, true), (Effect::Medium, true)]);
    let (n, first) = differences(&auto, &film(&on));
    assert_eq!(n, 0, "forced on: {}", first.unwrap_or_default());
}

#[test]
fn medium_knobs_change_a_scattering_body_and_nothing_else() {
    // `medium-scattering=off` (absorption only) and a short `medium-depth` change the milky
    // stone; on an opaque gem the same knobs change nothing.
    let knobs = |text: &str, s: &Scene| {
        let mut s = s.clone();
        let k: Knobs = text.parse().unwrap();
        k.apply(&mut s, "tests/effects.rs").unwrap();
        s
    };
    let milky = gem("milky-stone.ron");
    assert!(milky.effects.on(Effect::Medium));
    let auto = film(&milky);
    for setting in ["medium-scattering=off", "medium-depth=0", "medium-depth=4"] {
        let (n, _) = differences(&auto, &film(&knobs(setting, &milky)));
        eprintln!(
            "milky stone, {setting}: {n} of {} pixels change",
            auto.pixels.len()
        );
        assert!(
            n >= 20,
            "{setting} changed only {n} pixels of the milky stone"
        );
    }
    let opaque = gem("sunstone.ron");
    let auto = film(&opaque);
    for setting in [
        "medium-scattering=off",
        "medium-depth=0",
        "medium-depth=4096",
    ] {
        let (n, first) = differences(&auto, &film(&knobs(setting, &opaque)));
        assert_eq!(n, 0, "{setting} on sunstone: {}", first.unwrap_or_default());
    }
}
