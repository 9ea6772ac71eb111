//! Measured spectra as recipe colours (issue 19): a material's albedo, a coat's tint, a body's
//! colour, inline or from a CSV file.

use super::{at, furnace_ratio};
use lapidary::recipe::GemRecipe;
use lapidary::render::{Control, World, render_scene};
use lapidary::scene::{Accuracy, Effect, Scene};
use lapidary::spectrum::measured::Measured;

/// The furnace scene (a sphere under a constant white sky) with the material's base `base` and
/// optional `coats`.
fn furnace_recipe(base: &str, coats: &str) -> String {
    format!(
        "(materials: {{ \"m\": (coats: [{coats}],\n base: {base}) }},\n surface: Material(\"m\"),\n \
         stage: (shape: Sphere(radius: 1.0), ground: Off, lights: [],\n \
         environment: Constant(Gray(1.0)),\n camera: Orthographic(from: (0.0, 0.0, 5.0), \
         to: (0.0, 0.0, 0.0), height: 2.4), render: (width: 24, height: 24, spp: 16)))"
    )
}

fn compile(file: &str, text: &str) -> Result<Scene, String> {
    GemRecipe::parse(file, text)
        .and_then(|r| r.compile())
        .map_err(|e| e.to_string())
}

/// A reflectance with structure finer than an RGB triple can hold: a green band and a red rise.
const POINTS: [(f32, f32); 6] = [
    (360.0, 0.05),
    (480.0, 0.05),
    (530.0, 0.9),
    (570.0, 0.1),
    (650.0, 0.1),
    (830.0, 0.7),
];

fn inline(points: &[(f32, f32)]) -> String {
    let p: Vec<String> = points.iter().map(|(l, v)| format!("({l}, {v})")).collect();
    format!("[{}]", p.join(", "))
}

/// A coat-less Lambert base with a measured albedo: spectral transport turns on and names the
/// material; in the white furnace each wavelength's radiance over the illuminant is the
/// spectrum's value there (z-test, α 0.01 Šidák over 9 wavelengths, 4000 paths each; a convex
/// Lambert sphere under a uniform sky returns exactly `ρ(λ)`), not the RGB projection's
/// upsampled spectrum (which misses the narrow band by 0.28 at 530 nm: 0.57 for 0.85).
#[test]
fn a_measured_albedo_is_read_per_wavelength() {
    let text = furnace_recipe(
        &format!("Lambert(albedo: Spectrum({}))", inline(&POINTS)),
        "",
    );
    let scene = compile("leaf.ron", &text).unwrap();
    let (why, _) = scene.effects.reason(Effect::Spectral).unwrap();
    assert!(why.contains("material \"m\" base.albedo spectrum"), "{why}");
    let world = World::new(&scene).unwrap();
    assert!(world.spectral);
    let m = Measured::from_points(&POINTS, 1.0).unwrap();
    let lambdas = [
        380.0f32, 450.0, 500.0, 530.0, 550.0, 600.0, 680.0, 750.0, 820.0,
    ];
    let alpha = super::sidak_alpha(0.01, lambdas.len());
    let z = lapidary::image::stats::normal_quantile_two_sided(alpha);
    for l in lambdas {
        let (mean, se) = furnace_ratio(&world, l, 4000);
        let want = f64::from(m.at(l));
        println!("measured albedo at {l} nm: {mean:.4} ± {se:.4} (spectrum {want:.4})");
        assert!(
            (mean - want).abs() <= z * se + 1e-5,
            "{l} nm: {mean} ± {se}, spectrum {want}"
        );
    }
    // The RGB projection's smooth spectrum would not do: it differs at the band's peak.
    let rgb = m.to_rgb();
    let smooth = <lapidary::spectrum::HeroSample as lapidary::spectrum::Spectral>::from_reflectance(
        rgb,
        &at(530.0),
    );
    assert!((smooth.0[0] - m.at(530.0)).abs() > 0.2, "{smooth:?}");
}

/// RGB renders use the projection: a flat measured albedo, tint and body colour render
/// bit-identically to their greys; under a coat a measured albedo does not call for spectral
/// transport (both modes use the projection there).
#[test]
fn flat_spectra_render_as_their_greys_in_rgb() {
    let film = |s: &Scene| render_scene(&World::new(s).unwrap(), s, &Control::default()).film;
    let same = |a: &Scene, b: &Scene| {
        let (a, b) = (film(a), film(b));
        a.pixels
            .iter()
            .zip(&b.pixels)
            .all(|(p, q)| p.mean() == q.mean())
    };
    let rgb_only = |mut s: Scene| {
        let mut acc = Accuracy::default();
        acc.force(Effect::Spectral, false);
        s.set_accuracy(&acc, "test").unwrap();
        s
    };
    let flat = "Spectrum([(360, 0.4), (830, 0.4)])";
    let coat = |tint: &str| format!("(ior: 1.5, roughness: 10, thickness: 1, tint: {tint})");
    // Bare base.
    let measured = compile(
        "a.ron",
        &furnace_recipe(&format!("Lambert(albedo: {flat})"), ""),
    )
    .unwrap();
    let grey = compile("b.ron", &furnace_recipe("Lambert(albedo: Gray(0.4))", "")).unwrap();
    assert!(same(&rgb_only(measured), &grey));
    // Coated base and tint.
    let measured = compile(
        "a.ron",
        &furnace_recipe(
            &format!("OrenNayar(albedo: {flat}, sigma: 0.3)"),
            &coat(flat),
        ),
    )
    .unwrap();
    assert!(!measured.effects.on(Effect::Spectral));
    let grey = compile(
        "b.ron",
        &furnace_recipe(
            "OrenNayar(albedo: Gray(0.4), sigma: 0.3)",
            &coat("Gray(0.4)"),
        ),
    )
    .unwrap();
    assert!(same(&measured, &grey));
    // A body's colour after a distance.
    let body = |colour: &str| {
        format!(
            "(materials: {{}},\n surface: Body,\n body: (ior: 1.5,\n medium: (colour: {colour}, \
             distance: 2.0)),\n stage: (shape: Sphere(radius: 1.0), ground: Off, lights: [],\n \
             environment: Constant(Gray(1.0)),\n camera: Orthographic(from: (0.0, 0.0, 5.0), \
             to: (0.0, 0.0, 0.0), height: 2.4), render: (width: 24, height: 24, spp: 16)))"
        )
    };
    let measured = compile("a.ron", &body(flat)).unwrap();
    assert!(measured.effects.on(Effect::Spectral));
    let grey = compile("b.ron", &body("Gray(0.4)")).unwrap();
    assert!(same(&rgb_only(measured), &grey));
}

/// A CSV file named relative to the recipe's folder, with `scale`; errors name the recipe's
/// place or the CSV's line and what is wrong; stage colours refuse a spectrum.
#[test]
fn spectra_from_csv_files_and_their_errors() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("measured-spectra");
    std::fs::create_dir_all(dir.join("data")).unwrap();
    let mut csv = String::from("# a test reflectance\nwavelength_nm,value\n");
    for (l, v) in POINTS {
        csv.push_str(&format!("{l},{}\n", v / 2.0));
    }
    std::fs::write(dir.join("data/leaf.csv"), csv).unwrap();
    std::fs::write(dir.join("data/bad.csv"), "400,0.5\n500,0.7\n450,0.1\n").unwrap();
    let recipe = dir.join("leaf.ron");
    let file = recipe.to_str().unwrap();
    let from_file = compile(
        file,
        &furnace_recipe(
            "Lambert(albedo: Spectrum((file: \"data/leaf.csv\", scale: 2)))",
            "",
        ),
    )
    .unwrap();
    let inline_scene = compile(
        file,
        &furnace_recipe(
            &format!("Lambert(albedo: Spectrum({}))", inline(&POINTS)),
            "",
        ),
    )
    .unwrap();
    let film = |s: &Scene| render_scene(&World::new(s).unwrap(), s, &Control::default()).film;
    let (a, b) = (film(&from_file), film(&inline_scene));
    assert!(
        a.pixels
            .iter()
            .zip(&b.pixels)
            .all(|(p, q)| p.mean() == q.mean()),
        "the CSV spectrum renders differently from the same points inline"
    );
    for (base, expect) in [
        (
            "Lambert(albedo: Spectrum(\"data/missing.csv\"))",
            "missing.csv",
        ),
        // Wavelengths that go back are refused at the recipe's place.
        (
            "Lambert(albedo: Spectrum(\"data/bad.csv\"))",
            "does not increase",
        ),
        // Above 1 at some wavelength: not an albedo.
        (
            "Lambert(albedo: Spectrum((file: \"data/leaf.csv\", scale: 4)))",
            "0 ..= 1",
        ),
    ] {
        let e = compile(file, &furnace_recipe(base, "")).unwrap_err();
        assert!(e.contains("leaf.ron:") && e.contains(expect), "{base}: {e}");
    }
    let sky = furnace_recipe("Lambert(albedo: Gray(0.5))", "").replace(
        "Constant(Gray(1.0))",
        "Constant(Spectrum([(400, 1), (700, 1)]))",
    );
    let e = compile(file, &sky).unwrap_err();
    assert!(e.contains("leaf.ron:") && e.contains("spectrum"), "{e}");
}
