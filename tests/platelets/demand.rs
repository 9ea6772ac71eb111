//! Claim 5, on demand: the platelet walk runs only when a body holds platelets. A gem without
//! them renders bit-identically with the `platelets` effect forced on or off; one with them
//! renders identically with the effect left alone or forced on, changes when it is forced off,
//! and then equals the same gem without platelets.

use super::{differences, gem, render_on, scene};
use lapidary::recipe::GemRecipe;
use lapidary::render::{Film, Strategy, World};
use lapidary::scene::{Accuracy, Effect, Scene};
use std::path::Path;

/// Shrinks the render to 40 × 30 at 8 spp.
fn small(mut s: Scene) -> Scene {
    let r = &mut s.stage.render;
    r.width = 40;
    r.height = 30;
    r.spp = 8;
    s
}

/// `scene` with the platelets effect forced `on` through the accuracy knobs.
fn forced(scene: &Scene, on: bool) -> Scene {
    let mut s = scene.clone();
    let mut acc = Accuracy::default();
    acc.force(Effect::Platelets, on);
    s.set_accuracy(&acc, "tests/platelets")
        .expect("platelets can be forced");
    assert_eq!(s.effects.on(Effect::Platelets), on);
    s
}

/// Renders as `lapidary render` does (2 threads).
fn film(scene: &Scene) -> (Film, usize) {
    let world = World::new(scene).expect("world");
    let r = render_on(&world, scene, 2, Strategy::Mis);
    assert_eq!(r.stats.dropped, 0);
    (r.film, world.platelets.len())
}

/// A scene that does not call for platelets renders the same, bit for bit, with them forced on
/// and off (and, if `auto`, left alone), and the world walks no population.
fn assert_untouched(what: &str, s: &Scene, auto: bool) {
    assert!(
        !s.effects.called(Effect::Platelets),
        "{what} calls for platelets"
    );
    let (off, n) = film(&forced(s, false));
    assert_eq!(n, 0);
    let (on, n) = film(&forced(s, true));
    assert_eq!(n, 0, "{what}: forced on, the world has populations");
    let (diff, first) = differences(&off, &on);
    assert_eq!(
        diff, 0,
        "{what}: platelets forced on vs off: {diff} pixels differ; first {first:?}"
    );
    if auto {
        let (left, _) = film(s);
        let (diff, first) = differences(&off, &left);
        assert_eq!(
            diff, 0,
            "{what}: forced off vs left alone: {diff} pixels differ; first {first:?}"
        );
    }
}

/// gems/lepidolite.ron (an opaque stone of layered materials and maps, no body) at 40 × 30,
/// 8 spp: bit-identical with platelets forced on or off (two world builds of its 20 materials,
/// ≈ 4 s).
#[test]
fn a_gem_without_a_body_is_untouched() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("gems/lepidolite.ron");
    let s = GemRecipe::load(&path)
        .and_then(|r| r.compile())
        .expect("lepidolite compiles");
    assert!(s.surface.body.is_none());
    assert_untouched("lepidolite", &small(s), false);
}

/// A translucent body without platelets (rough m 5°, absorbing and scattering, on the studio
/// stage), 40 × 30, 8 spp: bit-identical with platelets forced on, forced off and left alone.
#[test]
fn a_body_without_platelets_is_untouched() {
    let s = scene(&gem(
        "(ior: 1.55, roughness: 5.0, medium: (absorption: (0.2, 0.5, 1.0), scattering: (2.0, 2.0, 2.0)))",
        "",
    ));
    assert!(
        s.surface
            .body
            .as_ref()
            .is_some_and(|b| b.platelets.is_empty())
    );
    assert_untouched("a scattering body", &small(s), true);
}

/// A body with copper platelets (uniform D 3000, r 0.01–0.03, and an aligned population) on the
/// studio stage, 40 × 30, 8 spp: forced on it renders as left alone (bit for bit); forced off,
/// more than 20 pixels change, and the film equals the same recipe without `platelets` bit for
/// bit.
#[test]
fn platelets_forced_off_are_gone() {
    let pops = "platelets: [
        (density: 3000.0, radius: (0.01, 0.03), orientation: Uniform, entries: [(1.0, \"copper\")]),
        (density: 500.0, radius: (0.02, 0.05), orientation: Aligned(axis: (0.0, 1.0, 0.2), spread: 8.0),
         entries: [(1.0, \"mirror\")]),
    ]";
    let with = small(scene(&gem(
        &format!("(ior: 1.54, alpha: 0.02, {pops})"),
        "(render: (max_depth: 24))",
    )));
    let without = small(scene(&gem(
        "(ior: 1.54, alpha: 0.02)",
        "(render: (max_depth: 24))",
    )));
    assert!(with.effects.called(Effect::Platelets) && with.effects.on(Effect::Platelets));
    let (auto, n) = film(&with);
    assert_eq!(n, 2);
    let (on, _) = film(&forced(&with, true));
    let (diff, first) = differences(&auto, &on);
    assert_eq!(diff, 0, "forced on: {diff} pixels differ; first {first:?}");
    let (off, n) = film(&forced(&with, false));
    assert_eq!(n, 0);
    let (changed, _) = differences(&auto, &off);
    println!(
        "platelets forced off: {changed} of {} pixels change",
        auto.pixels.len()
    );
    assert!(
        changed > 20,
        "only {changed} pixels change: the toggle looks dead"
    );
    let (bare, _) = film(&without);
    let (diff, first) = differences(&off, &bare);
    assert_eq!(
        diff, 0,
        "forced off vs no platelets: {diff} pixels differ; first {first:?}"
    );
}
