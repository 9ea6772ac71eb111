//! Polarised transport in renders ([`lapidary::polarisation::transport`]), against closed forms:
//!
//! - **Malus's law**: a camera looking straight at a polarised light box through an analyser sees
//!   `½ L cos² Δ`, `Δ` the angle between the two axes, written here from the recipe's documented
//!   conventions (the light's horizontal edge, the image's right): exact per pixel (the paths
//!   reach the light directly).
//! - **Brewster's angle**: a black glass slab (IOR 1.5, its interior absorbing everything)
//!   reflecting a white sky into a camera at angle θ through an analyser passes `½ R_s(θ)` across
//!   the plane of incidence and `½ R_p(θ)` in it — at Brewster's angle nothing — with `R_s`, `R_p`
//!   the Fresnel power reflectances written out below (Born & Wolf §1.5.2), within 5 standard
//!   errors of the render's mean (the reflect/refract choice is the only noise).
//! - **White furnace**: lossless glass and diamond spheres in a white, unpolarised sky; in
//!   equilibrium the light everywhere is that sky, unpolarised, so the camera reads 1 without an
//!   analyser and ½ behind one at any angle (within 5 standard errors; paths still trapped by
//!   total internal reflection at the depth limit lose a little, bounded below).
//!
//! Renders are small (≤ 64 × 64) at fixed seeds, so every number is reproducible.

use lapidary::recipe::GemRecipe;
use lapidary::render::{Control, Strategy, World, render_scene};
use lapidary::scene::{Accuracy, Effect, Scene};

/// Biaxial crystals and trichroism.
#[path = "polarisation/biaxial.rs"]
mod biaxial;

/// Bare conductors: Fresnel's Mueller matrix for a complex index.
#[path = "polarisation/conductor.rs"]
mod conductor;

/// Rough dielectric boundaries: each facet's Fresnel matrices.
#[path = "polarisation/rough_dielectric.rs"]
mod rough_dielectric;

/// Energy balance across a crystal's boundary: the radiance invariant.
#[path = "polarisation/etendue.rs"]
mod etendue;

/// The crystal events' one solve against the physical problem's own (reciprocity).
#[path = "polarisation/reciprocity.rs"]
mod reciprocity;

/// Platelets inside a crystal reflect by the conductor's matrix.
#[path = "polarisation/crystal_platelets.rs"]
mod crystal_platelets;

/// Pleochroism given as spectra, read per wavelength.
#[path = "polarisation/measured_pleochroism.rs"]
mod measured_pleochroism;

fn compile(text: &str) -> Scene {
    GemRecipe::parse("polarisation.ron", text)
        .unwrap_or_else(|e| panic!("{e}"))
        .compile()
        .unwrap_or_else(|e| panic!("{e}"))
}

/// `scene` with polarised transport forced on or off (as `--polarised on|off`).
fn forced(scene: &Scene, on: bool) -> Scene {
    let mut acc = Accuracy::default();
    acc.force(Effect::Polarisation, on);
    let mut s = scene.clone();
    s.set_accuracy(&acc, "--polarised").expect("knob applies");
    s
}

/// Mean radiance (channel 0) over the image and its standard error (from the pixels' spread).
fn mean(scene: &Scene) -> (f64, f64) {
    mean_by(scene, Control::default().strategy)
}

/// [`mean`] with light found by `strategy` (light sampling alone, BSDF sampling alone, or both).
fn mean_by(scene: &Scene, strategy: Strategy) -> (f64, f64) {
    let world = World::new(scene).expect("world");
    let control = Control {
        strategy,
        ..Control::default()
    };
    let r = render_scene(&world, scene, &control);
    let v: Vec<f64> = r.film.rgb().iter().map(|p| f64::from(p[0])).collect();
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0);
    (m, (var / n).sqrt())
}

#[test]
fn malus_law_between_a_polarised_light_and_the_analyser() {
    for polariser in [0.0f32, 30.0, 75.0] {
        for step in 0..=12 {
            let analyser = 15.0 * step as f32;
            let s = compile(&format!(
                r#"(materials: {{}}, body: (ior: 1.5), surface: Body,
                    stage: (shape: Sphere(radius: 0.1), transform: (translate: (40.0, 0.0, 0.0)),
                            ground: Off, environment: Constant(Gray(0.0)),
                            lights: [Rect(center: (0.0, -1.0, 0.0), target: (0.0, 0.0, 0.0),
                                          size: (20.0, 20.0), radiance: Gray(1.0),
                                          polariser: {polariser})],
                            camera: Orthographic(from: (0.0, 5.0, 0.0), to: (0.0, 0.0, 0.0),
                                                 up: (0.0, 0.0, -1.0), height: 1.0),
                            analyser: {analyser},
                            render: (width: 8, height: 8, spp: 4)))"#
            ));
            assert!(s.effects.on(Effect::Polarisation));
            // The recipe's conventions, independently: the light faces +y, so its horizontal
            // edge is n × x = −z and the polariser turns from it toward n × (−z) = −x; the camera
            // looks down with up −z, so its right is +x and its up −z.
            let (p, a) = (polariser.to_radians(), analyser.to_radians());
            let light_axis = [-p.sin(), 0.0, -p.cos()];
            let camera_axis = [a.cos(), 0.0, -a.sin()];
            let cos = light_axis[0] * camera_axis[0] + light_axis[2] * camera_axis[2];
            let want = 0.5 * f64::from(cos * cos);
            let (got, _) = mean(&s);
            assert!(
                (got - want).abs() < 1e-4,
                "polariser {polariser}°, analyser {analyser}°: {got} vs ½ cos² = {want}"
            );
            // Ignoring polarisation, the analyser and the polariser each pass half.
            let off = forced(&s, false);
            let (got_off, _) = mean(&off);
            assert!((got_off - 0.25).abs() < 1e-5, "{got_off}");
        }
    }
}

/// Fresnel's power reflectances for light from air onto a dielectric of index `n` at `cos_i`.
fn fresnel_sp(cos_i: f64, n: f64) -> (f64, f64) {
    let sin_t = (1.0 - cos_i * cos_i).sqrt() / n;
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let rs = (cos_i - n * cos_t) / (cos_i + n * cos_t);
    let rp = (n * cos_i - cos_t) / (n * cos_i + cos_t);
    (rs * rs, rp * rp)
}

/// The black slab seen at `theta` degrees from its normal through an analyser at `analyser`
/// degrees from the image's right (which is across the plane of incidence).
fn slab(theta: f64, analyser: Option<f64>) -> Scene {
    let t = theta.to_radians();
    let (y, z) = (5.0 * t.cos(), 5.0 * t.sin());
    let analyser = analyser.map_or(String::new(), |a| format!("analyser: {a},"));
    compile(&format!(
        r#"(materials: {{}}, surface: Body,
            body: (ior: 1.5, medium: (absorption: (10000.0, 10000.0, 10000.0))),
            stage: (shape: Slab(size: (40.0, 1.0, 40.0)), transform: (translate: (0.0, -0.5, 0.0)),
                    ground: Off, environment: Constant(Gray(1.0)), lights: [],
                    camera: Orthographic(from: (0.0, {y}, {z}), to: (0.0, 0.0, 0.0), height: 0.5),
                    {analyser}
                    render: (width: 48, height: 48, spp: 32, max_depth: 4, seed: 3)))"#
    ))
}

#[test]
fn reflection_at_brewster_angle_is_s_polarised() {
    let n = 1.5f64;
    for theta in [n.atan().to_degrees(), 30.0, 70.0] {
        let (rs, rp) = fresnel_sp(theta.to_radians().cos(), n);
        for (analyser, want, what) in [
            (None, 0.5 * (rs + rp), "no analyser"),
            (Some(0.0), 0.5 * rs, "analyser across the plane (s)"),
            (Some(90.0), 0.5 * rp, "analyser in the plane (p)"),
            (Some(45.0), 0.25 * (rs + rp), "analyser at 45°"),
        ] {
            let (got, se) = mean(&slab(theta, analyser));
            eprintln!("θ {theta:.2}°, {what}: {got:.5} ± {se:.5} (closed form {want:.5})");
            assert!(
                (got - want).abs() <= 5.0 * se + 1e-6,
                "θ {theta:.2}°, {what}: {got} ± {se} vs {want}"
            );
        }
    }
}

/// Lossless spheres in the white furnace, polarisation forced on, through analysers: 1 without
/// one and ½ with any — glass and diamond with smooth boundaries, and a rough (20°) glass
/// sphere whose boundary returns its multiply scattered energy — within 5 standard errors
/// below 1 % under (energy still trapped at depth 1 024) and 5 above. The rough one: each
/// facet's reflection and refraction pass the same shares of s and p as a smooth boundary's, so
/// unpolarised light stays unpolarised up to what masking shades differently in the two lobes
/// and what the compensation lobe's matrix — the single facet's, a GUESS — does not conserve.
#[test]
fn white_furnace_stays_white_and_unpolarised() {
    for body in ["(ior: 1.5)", "(ior: 2.42)", "(ior: 1.5, roughness: 20.0)"] {
        for analyser in [None, Some(0.0), Some(45.0), Some(100.0)] {
            let a = analyser.map_or(String::new(), |a: f64| format!("analyser: {a},"));
            let s = compile(&format!(
                r#"(materials: {{}}, body: {body}, surface: Body,
                    stage: (shape: Sphere(radius: 1.0), ground: Off,
                            environment: Constant(Gray(1.0)), lights: [],
                            camera: Orthographic(from: (0.0, 0.0, 5.0), to: (0.0, 0.0, 0.0),
                                                 height: 2.0),
                            {a}
                            render: (width: 32, height: 32, spp: 64, max_depth: 1024)))"#
            ));
            let s = forced(&s, true);
            let want = if analyser.is_some() { 0.5 } else { 1.0 };
            let (got, se) = mean(&s);
            eprintln!("body {body}, analyser {analyser:?}: {got:.5} ± {se:.5}");
            assert!(
                got <= want + 5.0 * se && got >= want * 0.99 - 5.0 * se,
                "body {body}, analyser {analyser:?}: {got} ± {se} vs {want}"
            );
        }
    }
}

/// A calcite slab (n_o 1.6584, n_e 1.4864; Hecht, *Optics*, table 8.1) 3 units thick, its optic
/// axis at 45° to the faces, over a small lamp, seen straight down through an analyser along
/// `analyser` degrees (`None`: none).
fn calcite(analyser: Option<f32>) -> Scene {
    let a = analyser.map_or(String::new(), |a| format!("analyser: {a},"));
    compile(&format!(
        r#"(materials: {{}}, surface: Body,
            body: (ior: 1.6584, crystal: Uniaxial(ne: 1.4864, axis: (1.0, 1.0, 0.0))),
            stage: (shape: Slab(size: (4.0, 3.0, 4.0)), ground: Off,
                    environment: Constant(Gray(0.0)),
                    lights: [Disc(center: (0.0, -2.0, 0.0), target: (0.0, 0.0, 0.0),
                                  radius: 0.05, radiance: Gray(10.0))],
                    camera: Orthographic(from: (0.0, 5.0, 0.0), to: (0.0, 0.0, 0.0),
                                         up: (0.0, 0.0, -1.0), height: 1.2),
                    {a}
                    render: (width: 128, height: 128, spp: 16, max_depth: 16)))"#
    ))
}

/// Total luminance and its centroid along world x (the image's right) over pixels with
/// `x` in `range`.
fn spot(scene: &Scene, range: std::ops::Range<f64>) -> (f64, f64) {
    let world = World::new(scene).expect("world");
    let r = render_scene(&world, scene, &Control::default());
    let (w, h) = (scene.stage.render.width, scene.stage.render.height);
    let rgb = r.film.rgb();
    let (mut sum, mut sx) = (0.0, 0.0);
    for y in 0..h {
        for x in 0..w {
            let wx = (f64::from(x) + 0.5) / f64::from(w) * 1.2 - 0.6;
            if range.contains(&wx) {
                let v = f64::from(rgb[(y * w + x) as usize][1]);
                sum += v;
                sx += v * wx;
            }
        }
    }
    (sum, if sum > 0.0 { sx / sum } else { f64::NAN })
}

/// The calcite rhomb's double image: the ordinary ray goes straight through, the extraordinary
/// one walks off by `ρ`, `tan ρ = ½ n(θ)² (1/n_e² − 1/n_o²) sin 2θ` (Yariv & Yeh eq. 4.3-14,
/// written here independently of the renderer), so the lamp shows twice, `d tan ρ` apart; an
/// analyser across the axis's plane keeps only the ordinary image, one along it only the
/// extraordinary — the two images are polarised at right angles. Centroids within a pixel.
#[test]
fn calcite_doubles_and_polarises_the_image() {
    let (no, ne) = (1.6584f64, 1.4864f64);
    let theta = std::f64::consts::FRAC_PI_4;
    let n2 = 1.0 / (theta.cos().powi(2) / (no * no) + theta.sin().powi(2) / (ne * ne));
    let tan_rho = 0.5 * n2 * (1.0 / (ne * ne) - 1.0 / (no * no)) * (2.0 * theta).sin();
    let shift = 3.0 * tan_rho.abs();
    let pixel = 1.2 / 128.0;
    let s = calcite(None);
    assert!(s.effects.on(Effect::Polarisation));
    let (o, xo) = spot(&s, -0.15..0.15);
    let (e_left, xl) = spot(&s, -0.6..-0.15);
    let (e_right, xr) = spot(&s, 0.15..0.6);
    let (e, xe) = if e_left > e_right {
        (e_left, xl)
    } else {
        (e_right, xr)
    };
    eprintln!("o image at {xo:.4} ({o:.1}), e image at {xe:.4} ({e:.1}); d tan ρ = {shift:.4}");
    assert!(xo.abs() < pixel, "ordinary image at {xo}");
    assert!(
        (xe.abs() - shift).abs() < pixel,
        "extraordinary image at {xe}, want ±{shift}"
    );
    assert!(
        e_left.min(e_right) < 1e-3 * e,
        "one extraordinary image only"
    );
    // Each image carries about half the light (their transmittances differ by a few %).
    assert!((o / e - 1.0).abs() < 0.15, "o/e {}", o / e);
    // The axis lies in the x–y plane: the extraordinary field along x, the ordinary along z.
    for (a, keeps_o) in [(0.0, false), (90.0, true)] {
        let s = calcite(Some(a));
        let (o2, _) = spot(&s, -0.15..0.15);
        let (e2, _) = spot(&s, -0.6..-0.15);
        let (e3, _) = spot(&s, 0.15..0.6);
        let e2 = e2 + e3;
        eprintln!("analyser {a}°: o {o2:.2}, e {e2:.2}");
        let (kept, gone) = if keeps_o { (o2, e2) } else { (e2, o2) };
        assert!(gone < 1e-3 * kept, "analyser {a}°: {o2} {e2}");
    }
}

/// A lossless calcite sphere in a white unpolarised furnace reads 1 (equilibrium), within 5
/// standard errors and 0.1 % for the light still trapped at depth 1 024: a wave converted on
/// reflection can circle the sphere under total internal reflection for hundreds of bounces (at
/// depth 64 the sphere read 0.996). A furnace does not test the radiance invariant (a path's
/// radiance scalings telescope from sky to sky whatever they are); the energy balance in
/// `polarisation/etendue.rs` does.
#[test]
fn calcite_sphere_in_a_white_furnace() {
    for axis in ["(0.0, 1.0, 0.0)", "(1.0, 1.0, 0.3)"] {
        let (got, se) = furnace_sphere(&format!(
            "(ior: 1.6584, crystal: Uniaxial(ne: 1.4864, axis: {axis}))"
        ));
        eprintln!("calcite sphere, axis {axis}: {got:.5} ± {se:.5}");
        assert!(
            (got - 1.0).abs() < 1e-3 + 5.0 * se,
            "axis {axis}: {got} ± {se}"
        );
    }
}

/// A plate cut parallel to its optic axis between the polariscope's crossed polars, turned by
/// `rotation` degrees (quartz, n_o 1.544, n_e 1.553; or glass with `crystal: false`).
fn plate(rotation: f64, crystal: bool) -> Scene {
    let optics = if crystal {
        "ior: 1.544, crystal: Uniaxial(ne: 1.553, axis: (1.0, 0.0, 0.0))"
    } else {
        "ior: 1.544"
    };
    compile(&format!(
        r#"(materials: {{}}, surface: Body, body: ({optics}),
            stage: (preset: Polariscope(crossed: true, rotation: {rotation}),
                    shape: Slab(size: (2.0, 0.5, 2.0)), transform: (translate: (0.0, 0.3, 0.0)),
                    render: (width: 40, height: 40, spp: 16, max_depth: 16, seed: 5)))"#
    ))
}

/// Between crossed polars a doubly refractive plate blinks four times per turn: seen straight
/// through, the light splits into the two waves along and across the axis and the analyser
/// passes `¼ sin² 2φ (T_e² + T_o²)` of it (incoherent sum, "high-order white"), so relative to
/// 45° the image follows `sin² 2φ`; a glass plate stays black at every angle.
#[test]
fn a_doubly_refractive_plate_blinks_and_glass_stays_dark() {
    let (bright, se45) = mean(&plate(45.0, true));
    assert!(bright > 0.05, "{bright}");
    for phi in [0.0f64, 15.0, 30.0, 60.0, 90.0, 135.0] {
        let (got, se) = mean(&plate(phi, true));
        let want = bright * (2.0 * phi.to_radians()).sin().powi(2);
        let tol = 5.0 * (se * se + (se45 * want / bright).powi(2)).sqrt() + 1e-6;
        eprintln!("φ {phi}°: {got:.5} ± {se:.5} (sin² 2φ × the 45° image: {want:.5})");
        assert!(
            (got - want).abs() <= tol,
            "φ {phi}°: {got} vs {want} ± {tol}"
        );
        let (glass, _) = mean(&plate(phi, false));
        assert!(glass < 1e-6, "glass at {phi}°: {glass}");
    }
}

/// A dichroic plate (index 1.62 for both waves, so only the absorption differs) 0.5 thick, its
/// axis along x in its faces, on a white light box, seen straight down through an analyser.
fn dichroic(analyser: Option<f32>) -> Scene {
    let a = analyser.map_or(String::new(), |a| format!("analyser: {a},"));
    compile(&format!(
        r#"(materials: {{}}, surface: Body,
            body: (ior: 1.62, crystal: Uniaxial(ne: 1.62, axis: (1.0, 0.0, 0.0),
                   pleochroism: (ordinary: Gray(0.2), extraordinary: Gray(0.8), distance: 0.5))),
            stage: (shape: Slab(size: (3.0, 0.5, 3.0)), ground: Off,
                    environment: Constant(Gray(0.0)),
                    lights: [Rect(center: (0.0, -1.0, 0.0), target: (0.0, 0.0, 0.0),
                                  size: (20.0, 20.0), radiance: Gray(1.0))],
                    camera: Orthographic(from: (0.0, 5.0, 0.0), to: (0.0, 0.0, 0.0),
                                         up: (0.0, 0.0, -1.0), height: 1.0),
                    {a}
                    render: (width: 24, height: 24, spp: 16, max_depth: 16)))"#
    ))
}

/// Pleochroism: through an analyser along the axis the plate shows the extraordinary wave's
/// colour, across it the ordinary's; light crossing the plate once keeps `τ T²` (`τ` the wave's
/// colour after the thickness, `T = 1 − ((n − 1)/(n + 1))²` per face), half of it passing the
/// analyser; internal reflections add `τ³ R² T²`, under 0.3 % here.
#[test]
fn a_dichroic_plate_shows_each_waves_colour() {
    let r = ((1.62f64 - 1.0) / 2.62).powi(2);
    let t2 = (1.0 - r).powi(2);
    for (analyser, tau) in [(0.0f32, 0.8f64), (90.0, 0.2)] {
        let (got, se) = mean(&dichroic(Some(analyser)));
        let want = 0.5 * t2 * (tau + tau.powi(3) * r * r);
        eprintln!("analyser {analyser}°: {got:.5} ± {se:.5} (closed form {want:.5})");
        assert!(
            (got - want).abs() < 1e-3 * want + 5.0 * se,
            "{analyser}°: {got} vs {want}"
        );
    }
    // Without an analyser, the mean of the two.
    let (got, se) = mean(&dichroic(None));
    let want = 0.5 * t2 * (0.8 + 0.2 + (0.8f64.powi(3) + 0.2f64.powi(3)) * r * r);
    eprintln!("no analyser: {got:.5} ± {se:.5} (closed form {want:.5})");
    assert!(
        (got - want).abs() < 1e-3 * want + 5.0 * se,
        "{got} vs {want}"
    );
}

/// The dichroscope: the same plate on the `Dichroscope` stage, its two windows side by side in one
/// image. The left half (analyser along the image's right, the plate's axis) shows the
/// extraordinary wave's colour, the right half the ordinary wave's — the closed forms of
/// [`a_dichroic_plate_shows_each_waves_colour`] — and each half is the whole view: the plate's
/// edges fall on the same columns of both halves.
#[test]
fn the_dichroscope_shows_both_waves_side_by_side() {
    let (w, h) = (48usize, 24usize);
    let s = compile(&format!(
        r#"(materials: {{}}, surface: Body,
            body: (ior: 1.62, crystal: Uniaxial(ne: 1.62, axis: (1.0, 0.0, 0.0),
                   pleochroism: (ordinary: Gray(0.2), extraordinary: Gray(0.8), distance: 0.5))),
            stage: {})"#,
        dichroscope_plate(w, h)
    ));
    assert!(s.stage.dichroscope && s.effects.on(Effect::Polarisation));
    let world = World::new(&s).expect("world");
    let img = render_scene(&world, &s, &Control::default()).film.rgb();
    let r = ((1.62f64 - 1.0) / 2.62).powi(2);
    let t2 = (1.0 - r).powi(2);
    // The plate covers the middle 0.6 of the unit view: columns and rows 6..18 of each half.
    let inside = |x: usize, y: usize| (7..17).contains(&(x % (w / 2))) && (7..17).contains(&y);
    for (half, tau) in [(0usize, 0.8f64), (1, 0.2)] {
        let v: Vec<f64> = (0..h)
            .flat_map(|y| (0..w / 2).map(move |x| (x + half * w / 2, y)))
            .filter(|&(x, y)| inside(x, y))
            .map(|(x, y)| f64::from(img[y * w + x][0]))
            .collect();
        let n = v.len() as f64;
        let m = v.iter().sum::<f64>() / n;
        let se = (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt();
        let want = 0.5 * t2 * (tau + tau.powi(3) * r * r);
        eprintln!("half {half}: {m:.5} ± {se:.5} (closed form {want:.5})");
        assert!(
            (m - want).abs() < 1e-3 * want + 5.0 * se,
            "half {half}: {m} vs {want}"
        );
        // Around the plate both windows see the light box through their analyser: ½.
        for (x, y) in [(1usize, 1usize), (22, 22)] {
            let p = img[y * w + x + half * w / 2][0];
            assert!((p - 0.5).abs() < 1e-4, "half {half} ({x}, {y}): {p}");
        }
    }
}

/// Polarised renders with crystals are deterministic: the pleochroic sunstone renders
/// bit-identically on 1 and 2 threads.
#[test]
fn polarised_crystal_renders_are_thread_count_independent() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("gems/oregon-sunstone-dichroic.ron");
    let mut s = GemRecipe::load(&path).and_then(|r| r.compile()).unwrap();
    s.stage.render.width = 32;
    s.stage.render.height = 24;
    s.stage.render.spp = 8;
    let world = World::new(&s).unwrap();
    let films: Vec<Vec<[f32; 3]>> = [1, 2]
        .map(|t| {
            let c = Control {
                threads: Some(t),
                ..Control::default()
            };
            render_scene(&world, &s, &c).film.rgb()
        })
        .into();
    let bits = |f: &Vec<[f32; 3]>| f.iter().flatten().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&films[0]), bits(&films[1]));
    assert!(films[0].iter().flatten().any(|v| *v > 0.0));
}

/// The dichroscope looking down at a 0.6 × 0.5 × 0.6 plate over a wide white light, `w × h`
/// pixels at 16 spp: the stage of the dichroic plate tests.
fn dichroscope_plate(w: usize, h: usize) -> String {
    format!(
        "(preset: Dichroscope(), shape: Slab(size: (0.6, 0.5, 0.6)),
          transform: (translate: (0.0, 0.3, 0.0)),
          lights: [Rect(center: (0.0, -1.0, 0.0), target: (0.0, 0.0, 0.0),
                        size: (20.0, 20.0), radiance: Gray(1.0))],
          camera: Orthographic(from: (0.0, 5.0, 0.0), to: (0.0, 0.0, 0.0),
                               up: (0.0, 0.0, -1.0), height: 1.0),
          render: (width: {w}, height: {h}, spp: 16, max_depth: 16))"
    )
}

/// A unit sphere of clear `body` in a white furnace (constant sky 1, no floor, no lights), seen
/// whole by an orthographic camera, 32² pixels × 64 spp, depth 1 024: the image's mean and its
/// standard error.
fn furnace_sphere(body: &str) -> (f64, f64) {
    mean(&compile(&format!(
        r#"(materials: {{}}, surface: Body, body: {body},
            stage: (shape: Sphere(radius: 1.0), ground: Off,
                    environment: Constant(Gray(1.0)), lights: [],
                    camera: Orthographic(from: (0.0, 0.0, 5.0), to: (0.0, 0.0, 0.0), height: 2.0),
                    render: (width: 32, height: 32, spp: 64, max_depth: 1024)))"#
    )))
}
