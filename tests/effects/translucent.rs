//! Effects of translucent bodies (issues 17 and 18): `transmission`, `medium`, `platelets`,
//! `manifold-nee` and `manifold-caustics` — bit-identical where a scene does not call for them,
//! live where it does (module docs of tests/effects.rs).

use super::*;

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
    // stone; on an opaque gem the same knobs change nothing, nor does the manifold walks'
    // continuation (no walk starts there).
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
        "manifold-continuation=on",
        "manifold-continuation=off",
        "manifold-halvings=0",
        "manifold-halvings=8",
    ] {
        let (n, first) = differences(&auto, &film(&knobs(setting, &opaque)));
        assert_eq!(n, 0, "{setting} on sunstone: {}", first.unwrap_or_default());
    }
}
