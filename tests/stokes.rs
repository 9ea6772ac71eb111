//! The Stokes AOVs (`lapidary render --stokes`, [`lapidary::polarisation::stokes`]) against
//! closed forms and against the analyser they replace:
//!
//! - **A polarised light box seen directly**: `S = ½ L (1, cos 2ψ, sin 2ψ, 0)`, `ψ` the
//!   polariser's axis in the image's frame (right, up), written here from the recipe's documented
//!   conventions — exact per pixel, with and without an analyser in front of the camera (the
//!   Stokes vector is measured before it).
//! - **Fresnel reflection**: a black glass slab reflecting a white sky at θ: `S1 / S0 =
//!   (R_s − R_p) / (R_s + R_p)` (s is the image's horizontal), `S2 = S3 = 0` — exact, not only
//!   within noise: every path's rows see the same reflection, so the ratio holds per path.
//! - **The analyser it replaces**: a glass sphere in the polariscope rendered once with the
//!   Stokes AOVs and once behind analysers at α: `I(α) = ½ (S0 + S1 cos 2α + S2 sin 2α)` per
//!   pixel to rounding. The paths are the same (same seed; a depth limit below Russian
//!   roulette's, whose survival would otherwise see the analyser's halving).
//! - **Nothing else changes**: `S0` equals the colour bit for bit where there is no analyser, and
//!   the AOVs are the same for any thread count (a crystal in the path included).

use lapidary::recipe::GemRecipe;
use lapidary::render::{Control, Film, World, render_scene};
use lapidary::scene::{Accuracy, Effect, Scene};

fn compile(text: &str) -> Scene {
    GemRecipe::parse("stokes.ron", text)
        .unwrap_or_else(|e| panic!("{e}"))
        .compile()
        .unwrap_or_else(|e| panic!("{e}"))
}

/// `scene` measuring the Stokes AOVs (as `--stokes`: polarised transport forced on).
fn with_stokes(scene: &Scene) -> Scene {
    let mut acc = Accuracy::default();
    acc.force(Effect::Polarisation, true);
    let mut s = scene.clone();
    s.set_accuracy(&acc, "--stokes").expect("knob applies");
    s.stage.stokes = true;
    s
}

fn film(scene: &Scene, threads: Option<usize>) -> Film {
    let world = World::new(scene).expect("world");
    let control = Control {
        threads,
        ..Control::default()
    };
    render_scene(&world, scene, &control).film
}

/// Per pixel, the mean Stokes vector's channel 0.
fn stokes0(f: &Film) -> Vec<[f64; 4]> {
    assert_eq!(
        f.stokes.len(),
        f.pixels.len(),
        "the film has the Stokes sums"
    );
    f.stokes
        .iter()
        .zip(&f.pixels)
        .map(|(s, p)| s.mean(p.n).map(|c| f64::from(c[0])))
        .collect()
}

#[test]
fn a_polarised_light_box_reads_its_polariser() {
    for polariser in [0.0f32, 30.0, 75.0, 120.0] {
        for analyser in [None, Some(20.0f32)] {
            let a = analyser.map_or(String::new(), |a| format!("analyser: {a},"));
            let s = with_stokes(&compile(&format!(
                r#"(materials: {{}}, body: (ior: 1.5), surface: Body,
                    stage: (shape: Sphere(radius: 0.1), transform: (translate: (40.0, 0.0, 0.0)),
                            ground: Off, environment: Constant(Gray(0.0)),
                            lights: [Rect(center: (0.0, -1.0, 0.0), target: (0.0, 0.0, 0.0),
                                          size: (20.0, 20.0), radiance: Gray(1.0),
                                          polariser: {polariser})],
                            camera: Orthographic(from: (0.0, 5.0, 0.0), to: (0.0, 0.0, 0.0),
                                                 up: (0.0, 0.0, -1.0), height: 1.0),
                            {a}
                            render: (width: 8, height: 8, spp: 4)))"#
            )));
            // The light faces +y: its axis turns from n × x = −z toward −x; the camera looks
            // down with right +x and up −z (the conventions of tests/polarisation.rs).
            let p = f64::from(polariser).to_radians();
            let axis = [-p.sin(), -p.cos()]; // (x, z)
            let (c, sn) = (axis[0], -axis[1]); // along right, along up
            let psi = sn.atan2(c);
            let want = [0.5, 0.5 * (2.0 * psi).cos(), 0.5 * (2.0 * psi).sin(), 0.0];
            let f = film(&s, None);
            for px in stokes0(&f) {
                for k in 0..4 {
                    assert!(
                        (px[k] - want[k]).abs() < 1e-4,
                        "polariser {polariser}°, analyser {analyser:?}: S{k} {} vs {}",
                        px[k],
                        want[k]
                    );
                }
            }
        }
    }
}

#[test]
fn fresnel_reflection_polarises_across_the_plane_of_incidence() {
    let n = 1.5f64;
    for theta in [30.0, n.atan().to_degrees(), 70.0] {
        let t = f64::to_radians(theta);
        let (y, z) = (5.0 * t.cos(), 5.0 * t.sin());
        let s = with_stokes(&compile(&format!(
            r#"(materials: {{}}, surface: Body,
                body: (ior: 1.5, medium: (absorption: (10000.0, 10000.0, 10000.0))),
                stage: (shape: Slab(size: (40.0, 1.0, 40.0)), transform: (translate: (0.0, -0.5, 0.0)),
                        ground: Off, environment: Constant(Gray(1.0)), lights: [],
                        camera: Orthographic(from: (0.0, {y}, {z}), to: (0.0, 0.0, 0.0), height: 0.5),
                        render: (width: 16, height: 16, spp: 16, max_depth: 4, seed: 3)))"#
        )));
        let cos_i = t.cos();
        let sin_t = (1.0 - cos_i * cos_i).sqrt() / n;
        let cos_t = (1.0 - sin_t * sin_t).sqrt();
        let rs = ((cos_i - n * cos_t) / (cos_i + n * cos_t)).powi(2);
        let rp = ((n * cos_i - cos_t) / (n * cos_i + cos_t)).powi(2);
        let f = film(&s, None);
        let sum = stokes0(&f).iter().fold([0.0; 4], |mut a, px| {
            for k in 0..4 {
                a[k] += px[k];
            }
            a
        });
        let dop = sum[1] / sum[0];
        let want = (rs - rp) / (rs + rp);
        eprintln!("θ {theta:.2}°: S1/S0 {dop:.6} (closed form {want:.6})");
        assert!(sum[0] > 0.0);
        assert!((dop - want).abs() < 1e-4, "θ {theta}: {dop} vs {want}");
        assert!((sum[2] / sum[0]).abs() < 1e-4 && (sum[3] / sum[0]).abs() < 1e-4);
    }
}

/// The polariscope's glass sphere without its analyser (the light box still polarised).
fn sphere(analyser: Option<f32>) -> Scene {
    let a = analyser.map_or(String::new(), |a| format!("analyser: {a},"));
    compile(&format!(
        r#"(materials: {{}}, body: (ior: 1.5), surface: Body,
            stage: (preset: Polariscope(crossed: true), shape: Sphere(radius: 0.8),
                    transform: (translate: (0.0, 0.802, 0.0)), {a}
                    render: (width: 24, height: 24, spp: 8, max_depth: 3, seed: 5)))"#
    ))
}

#[test]
fn the_stokes_vector_predicts_every_analyser() {
    // The preset's own analyser is replaced: with none, the Stokes render; then each angle.
    let mut bare = sphere(None);
    bare.stage.analyser = None;
    let st = stokes0(&film(&with_stokes(&bare), None));
    let mut checked = 0;
    for alpha in [0.0f32, 45.0, 90.0, 150.0] {
        let s = sphere(Some(alpha));
        assert_eq!(s.stage.analyser, Some(alpha.to_radians()));
        checked += predicts(&st, &film(&s, None), alpha);
    }
    // The sphere turns the light's polarisation: some pixels pass every analyser.
    assert!(checked > 100, "{checked}");
}

/// The same with the light sampled off a rough bare conductor (a polarising vertex in next-event
/// estimation as well as in BSDF sampling): the Stokes rows read each light sample by their own
/// Fresnel correction, and a polarising lamp's light after it.
#[test]
fn the_stokes_vector_predicts_every_analyser_off_a_rough_conductor() {
    let metal = r#"materials: { "metal": (base: Conductor(metal: Complex(n: (1.5, 0.4, 0.4),
                                                                    k: (0.5, 2.0, 2.0)),
                                                       roughness: 8.0)) },
                   surface: Material("metal"),"#;
    for polariser in ["", ", polariser: 30.0"] {
        stokes_off(metal, polariser, 0.2, 3);
    }
}

/// The same off and through a clear rough dielectric slab (reflection and refraction at its
/// facets, light samples through the boundary from inside as well). Two bounces: Russian
/// roulette (from the third) reads the sensor row's corrected throughput, so an analyser's
/// render ends other paths than the Stokes render does — both unbiased, no longer pixel for
/// pixel the same.
#[test]
fn the_stokes_vector_predicts_every_analyser_through_a_rough_dielectric() {
    let glass = "materials: {}, body: (ior: 1.5, roughness: 8.0), surface: Body,";
    for polariser in ["", ", polariser: 30.0"] {
        stokes_off(glass, polariser, 0.05, 2);
    }
}

/// A slab of `surface` (recipe text) under a lamp (behind `polariser`, recipe text) and a dim
/// sky, paths of at most `depth` bounces: its Stokes AOVs predict every analyser's render;
/// `|S1|` is at least `share` of S0.
fn stokes_off(surface: &str, polariser: &str, share: f64, depth: u32) {
    let slab = |analyser: Option<f32>| {
        let a = analyser.map_or(String::new(), |a| format!("analyser: {a},"));
        compile(&format!(
            r#"({surface}
                stage: (shape: Slab(size: (40.0, 1.0, 40.0)),
                        transform: (translate: (0.0, -0.5, 0.0)), ground: Off,
                        environment: Constant(Gray(0.1)),
                        lights: [Rect(center: (0.0, 3.0, -4.0), target: (0.0, 0.0, 0.0),
                                      size: (3.0, 3.0), radiance: Gray(4.0) {polariser})],
                        camera: Orthographic(from: (1.0, 3.2, 3.8), to: (0.0, 0.0, 0.0),
                                             height: 0.5),
                        {a}
                        render: (width: 16, height: 16, spp: 8, max_depth: {depth}, seed: 5)))"#
        ))
    };
    let st = stokes0(&film(&with_stokes(&slab(None)), None));
    // Reflection polarises: S1 is a large share of S0.
    let (s0, s1) = st
        .iter()
        .fold((0.0, 0.0), |a, p| (a.0 + p[0], a.1 + p[1].abs()));
    assert!(s1 > share * s0, "S0 {s0} |S1| {s1}");
    for alpha in [0.0f32, 45.0, 90.0, 150.0] {
        predicts(&st, &film(&slab(Some(alpha)), None), alpha);
    }
}

/// Asserts that the Stokes vectors `st` predict, per pixel, the render `f` through an analyser
/// at `alpha` degrees: `½ (S0 + S1 cos 2α + S2 sin 2α)` to 10⁻⁵. Returns the pixels lit above
/// 10⁻³.
fn predicts(st: &[[f64; 4]], f: &Film, alpha: f32) -> usize {
    let a = 2.0 * f64::from(alpha).to_radians();
    let mut lit = 0;
    for (px, p) in st.iter().zip(&f.pixels) {
        let want = 0.5 * (px[0] + px[1] * a.cos() + px[2] * a.sin());
        let got = f64::from(p.mean()[0]);
        assert!(
            (got - want).abs() <= 1e-5 * (1.0 + want.abs()),
            "analyser {alpha}°: {got} vs ½(S0 + S1 cos 2α + S2 sin 2α) = {want}"
        );
        lit += usize::from(want > 1e-3);
    }
    lit
}

#[test]
fn s0_is_the_colour_and_the_aovs_do_not_depend_on_threads() {
    // A glass sphere in a sky and the dichroic sunstone (a crystal's boundary in the paths).
    let glass = compile(
        r#"(materials: {}, body: (ior: 1.5), surface: Body,
            stage: (shape: Sphere(radius: 1.0), ground: Off,
                    environment: Constant(Gray(1.0)), lights: [],
                    camera: Orthographic(from: (0.0, 0.0, 5.0), to: (0.0, 0.0, 0.0), height: 2.4),
                    render: (width: 16, height: 16, spp: 8, max_depth: 12)))"#,
    );
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("gems/oregon-sunstone-dichroic.ron");
    let mut sun = GemRecipe::load(&path).and_then(|r| r.compile()).unwrap();
    sun.stage.render.width = 24;
    sun.stage.render.height = 18;
    sun.stage.render.spp = 4;
    for (name, scene) in [("glass", glass), ("sunstone", sun)] {
        let s = with_stokes(&scene);
        let one = film(&s, Some(1));
        let two = film(&s, Some(2));
        assert_eq!(one.stokes, two.stokes, "{name}: thread counts differ");
        assert_eq!(one.pixels, two.pixels, "{name}: thread counts differ");
        if s.stage.analyser.is_none() {
            for (st, p) in one.stokes.iter().zip(&one.pixels) {
                let s0 = st.mean(p.n)[0];
                assert_eq!(s0.map(f32::to_bits), p.mean().0.map(f32::to_bits), "{name}");
            }
        }
        // The colour is the render without the AOVs, bit for bit.
        let mut plain = s.clone();
        plain.stage.stokes = false;
        let f = film(&plain, Some(2));
        assert!(f.stokes.is_empty());
        assert_eq!(f.pixels, one.pixels, "{name}: the AOVs changed the colour");
        assert!(
            one.stokes
                .iter()
                .any(|s| s.0[1] != [0; 3] || s.0[2] != [0; 3]),
            "{name}: some light is polarised"
        );
    }
}

#[path = "common/scratch.rs"]
mod scratch;

/// `lapidary render --stokes` writes the four AOVs (and only with the flag), and refuses what
/// cannot measure them, naming the flags.
#[test]
fn the_command_line_writes_the_stokes_channels() {
    use std::process::{Command, Stdio};
    let dir = scratch::Scratch::new("stokes", "cli");
    let recipe = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/polariscope-glass-sphere.ron"
    );
    let run = |extra: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_lapidary"))
            .args([
                "render", recipe, "--size", "24x24", "--spp", "4", "--no-png",
            ])
            .args(["--max-depth", "4"])
            .args(extra)
            .current_dir(&dir.0)
            .stdin(Stdio::null())
            .output()
            .expect("binary runs")
    };
    let out = run(&["-o", "s.exr", "--stokes", "-q"]);
    assert!(out.status.success(), "{}", scratch::text(&out.stderr));
    let img = lapidary::image::read_exr(&dir.path("s.exr")).unwrap();
    let ch = |n: &str| img.channel(n).unwrap_or_else(|| panic!("no {n}"));
    for k in 0..4 {
        for c in ["R", "G", "B"] {
            let v = ch(&format!("S{k}.{c}"));
            assert!(v.iter().all(|x| x.is_finite()), "S{k}.{c}");
        }
    }
    // The crossed polars darken the colour; the light before the analyser is bright.
    let total = |n: &str| ch(n).iter().map(|&x| f64::from(x)).sum::<f64>();
    assert!(
        total("S0.G") > 4.0 * total("G"),
        "{} {}",
        total("S0.G"),
        total("G")
    );
    // The light box's polariser is along the image's right: S1 ≈ S0 around the sphere.
    assert!(ch("S1.G")[0] > 0.9 * ch("S0.G")[0] && ch("S0.G")[0] > 0.0);

    let out = run(&["-o", "plain.exr", "-q"]);
    assert!(out.status.success());
    let plain = lapidary::image::read_exr(&dir.path("plain.exr")).unwrap();
    assert!(plain.channel("S0.R").is_none());
    assert_eq!(
        plain.channel("G"),
        img.channel("G"),
        "the colour is the same"
    );

    let out = run(&["-o", "bad.exr", "--stokes", "--polarised", "off"]);
    let err = scratch::text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("--stokes contradicts --polarised off"),
        "{err}"
    );
    assert!(!dir.path("bad.exr").exists());
}

/// `--stokes` part renders (`--samples`) merge into the whole `--stokes` render bit for bit —
/// the colour, the AOVs and the four Stokes components — whatever the split and thread counts;
/// a part without the Stokes sums does not merge with parts that have them, and nothing is
/// written then.
#[test]
fn stokes_parts_merge_to_the_whole_render_bit_for_bit() {
    use std::process::{Command, Stdio};
    let dir = scratch::Scratch::new("stokes", "parts");
    let recipe = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/polariscope-glass-sphere.ron"
    );
    let run = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_lapidary"))
            .args(args)
            .current_dir(&dir.0)
            .stdin(Stdio::null())
            .output()
            .expect("binary runs");
        (out.status.code(), scratch::text(&out.stderr))
    };
    let render = |extra: &[&str]| {
        let base = [
            "render",
            recipe,
            "--size",
            "20x16",
            "--spp",
            "6",
            "--max-depth",
            "4",
            "-q",
        ];
        let (code, err) = run(&[&base[..], extra].concat());
        assert_eq!(code, Some(0), "{err}");
    };
    render(&["--stokes", "-o", "whole.exr", "--no-png"]);
    for (range, out, threads) in [
        ("0..1", "a.exr", "1"),
        ("1..4", "b.exr", "2"),
        ("4..6", "c.exr", "2"),
    ] {
        render(&[
            "--stokes",
            "--samples",
            range,
            "-o",
            out,
            "--threads",
            threads,
        ]);
    }
    render(&["--samples", "4..6", "-o", "plain.exr"]);
    let (code, err) = run(&[
        "merge",
        "c.exr",
        "a.exr",
        "b.exr",
        "-o",
        "merged.exr",
        "--no-png",
    ]);
    assert_eq!(code, Some(0), "{err}");
    let read = |n: &str| lapidary::image::read_exr(&dir.path(n)).unwrap();
    let (whole, merged) = (read("whole.exr"), read("merged.exr"));
    assert_eq!(whole.channel_names(), merged.channel_names());
    assert!(merged.channel("S3.B").is_some());
    for c in &whole.channels {
        let m = merged.channel(&c.name).unwrap();
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&c.data), bits(m), "channel {}", c.name);
    }
    assert!(
        whole.channel("S1.G").unwrap().iter().any(|&x| x != 0.0),
        "the light is polarised: the comparison is not of zeros"
    );
    let (code, err) = run(&["merge", "a.exr", "b.exr", "plain.exr", "-o", "mixed.exr"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("plain.exr") && err.contains("holds the Stokes sums"),
        "{err}"
    );
    assert!(!dir.path("mixed.exr").exists());
}
