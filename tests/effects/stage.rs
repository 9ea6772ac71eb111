//! Effects of the stage — `depth-of-field`, `environment-importance` — and `fluorescence`, free
//! where no base fluoresces, and `light-prefilter`, free where no light has a spectrum and in
//! spectral transport (module docs of tests/effects.rs).

use super::*;

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
fn fluorescence_code_changes_nothing_without_a_fluorescent_base() {
    // A scene that calls for eight effects (not environment importance, spectral or
    // fluorescence): fluorescence forced on or off touches none of them.
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
    assert_untouched(
        Effect::LightPrefilter,
        "a scene calling for eight other effects",
        &busy,
    );
    let called: Vec<Effect> = busy.effects.iter().collect();
    assert_eq!(
        called.len(),
        8,
        "the scene should call for eight effects: {called:?}"
    );
    assert_untouched(
        Effect::Fluorescence,
        "a scene calling for eight other effects",
        &busy,
    );
    // Spectral transport (a dispersive diamond and a measured light): the path keeps its film
    // wavelengths, draws no fluorescence slot and gathers without a remap.
    let diamond = gem("brilliant-diamond.ron");
    assert!(diamond.effects.on(Effect::Spectral));
    assert_untouched(
        Effect::Fluorescence,
        "the spectral brilliant diamond",
        &diamond,
    );
}

/// The day-glo card under the 532 nm laser at 20°, shrunk like the other scenes.
fn dayglo() -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/dayglo-laser-20.ron");
    let mut s = GemRecipe::load(&path)
        .and_then(|r| r.compile())
        .unwrap_or_else(|e| panic!("{e}"));
    small(&mut s);
    s
}

#[test]
fn light_prefilter_runs_only_for_rgb_renders_under_spectral_lights() {
    // Spectral transport reads the spectra themselves: the laser scene (which calls for
    // spectral) renders bit-identically with the prefilter forced either way.
    let spectral = dayglo();
    assert!(spectral.effects.on(Effect::Spectral));
    assert_untouched(
        Effect::LightPrefilter,
        "the spectral day-glo laser scene",
        &spectral,
    );
    // Rendered in RGB, the laser's line calls for it, and forcing it off changes the image
    // (the card's green projected under D65 instead of reflected at 532 nm).
    let rgb = forced(&spectral, Effect::Spectral, false);
    assert_eq!(
        rgb.effects.reason(Effect::LightPrefilter).map(|r| r.1),
        Some(1)
    );
    assert_live(Effect::LightPrefilter, "the RGB day-glo laser scene", &rgb);
}

#[test]
fn polarisation_code_changes_nothing_without_a_polarising_vertex() {
    // Polarised transport forced on: every vertex of these scenes depolarises (Lambert, layered
    // stacks — a varnished metal among them), so the Stokes row stays zero and every throughput
    // correction is exactly 1. (A bare metal polarises: `tests/polarisation/conductor.rs`; so
    // does a body's boundary, smooth or rough: `tests/polarisation/rough_dielectric.rs`.)
    let surface = r#"(materials: {
           "body": (coats: [(ior: 1.5, roughness: 2.0, thickness: 1.0, tint: Rgb(0.9, 0.6, 0.8))],
                    base: Lambert(albedo: Gray(0.6))),
           "glitter": (coats: [(ior: 1.5, roughness: 1.0)],
                       base: Conductor(metal: Silver, roughness: 2.0)) },
        {body}
        surface: Overlay(
            under: Switch(by: Marble(scale: 0.5), stops: [(0.0, Material("body")), (0.4, {under})]),
            over: Voronoi(scale: 0.06, fill: 0.1, entries: [(1.0, Material("glitter"))])))"#;
    let layered = scene(
        &surface
            .replace("{body}", "")
            .replace("{under}", r#"Material("glitter")"#),
    );
    assert!(!layered.effects.called(Effect::Polarisation));
    assert_untouched(
        Effect::Polarisation,
        "layered materials and a varnished metal",
        &layered,
    );
    // A rough translucent body's boundary (with a scattering medium inside) polarises: forced
    // on, its pixels change.
    let rough_body = scene(&surface.replace("{under}", "Body").replace(
        "{body}",
        "body: (ior: 1.55, roughness: 3.0,
                medium: (colour: Srgb(0.9, 0.7, 0.6), distance: 1.0, scattering: (2.0, 2.0, 2.0))),",
    ));
    assert!(!rough_body.effects.called(Effect::Polarisation));
    let (n, _) = differences(
        &film(&rough_body),
        &film(&forced(&rough_body, Effect::Polarisation, true)),
    );
    assert!(n >= 20, "a rough body's boundary: only {n} pixels change");
    assert_untouched(
        Effect::Polarisation,
        "the opaque Sunstone",
        &gem("sunstone.ron"),
    );
    // Live: a smooth glass sphere between crossed polars shows only where its boundary turns
    // the light's polarisation (the dark Maltese cross); forced off, the analyser passes half of
    // every path's light instead.
    let crossed = scene(
        r#"(materials: {}, body: (ior: 1.5), surface: Body,
            stage: (preset: Polariscope(crossed: true), shape: Sphere(radius: 0.8),
                    transform: (translate: (0.0, 0.802, 0.0))))"#,
    );
    assert_live(
        Effect::Polarisation,
        "a glass sphere in the polariscope",
        &crossed,
    );
}
