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
use lapidary::render::{Control, World, render_scene};
use lapidary::scene::{Accuracy, Effect, Scene};

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
    let world = World::new(scene).expect("world");
    let r = render_scene(&world, scene, &Control::default());
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

#[test]
fn white_furnace_stays_white_and_unpolarised() {
    for ior in [1.5, 2.42] {
        for analyser in [None, Some(0.0), Some(45.0), Some(100.0)] {
            let a = analyser.map_or(String::new(), |a: f64| format!("analyser: {a},"));
            let s = compile(&format!(
                r#"(materials: {{}}, body: (ior: {ior}), surface: Body,
                    stage: (shape: Sphere(radius: 1.0), ground: Off,
                            environment: Constant(Gray(1.0)), lights: [],
                            camera: Orthographic(from: (0.0, 0.0, 5.0), to: (0.0, 0.0, 0.0),
                                                 height: 2.0),
                            {a}
                            render: (width: 32, height: 32, spp: 64, max_depth: 64)))"#
            ));
            let s = forced(&s, true);
            let want = if analyser.is_some() { 0.5 } else { 1.0 };
            let (got, se) = mean(&s);
            eprintln!("IOR {ior}, analyser {analyser:?}: {got:.5} ± {se:.5}");
            assert!(
                got <= want + 5.0 * se && got >= want * 0.99 - 5.0 * se,
                "IOR {ior}, analyser {analyser:?}: {got} ± {se} vs {want}"
            );
        }
    }
}
