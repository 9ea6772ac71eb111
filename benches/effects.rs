//! Effects on demand: for each implemented effect, a scene that does not call for it rendered with
//! the effect's code left alone (`auto`), forced off (`forced-off`) and forced on (`forced-on`).
//! The three renders are bit-identical (checked here before timing, and in `tests/effects.rs`);
//! the issue asks that `auto` be no slower than `forced-off`, and `forced-on` shows what the code
//! of an effect costs when it runs for nothing.
//!
//! Scenes (the same as in `tests/effects.rs`, on the studio stage): clear coats for
//! `absorption`, uncoated materials for `t-term` (forcing it on in a coated Corrected scene would
//! change the model, so that is not an on-demand comparison), nested Voronoi maps without a bump
//! for `facet-bump`, a hard marble switch for `glitter-overlay` and `stochastic-switch`, the
//! studio's pinhole camera for `depth-of-field`, a gradient sky as the only light for
//! `environment-importance`, and the shipped opaque gem `gems/sunstone.ron` for `transmission` and
//! `medium` (issue 17: forced on, the free-flight code runs on every segment through a medium that
//! neither absorbs nor scatters), and the shipped clear body without platelets
//! `gems/tinted-glass-sphere.ron` for `platelets` (issue 18: every path segment inside the body
//! passes the platelet code's test, forced on or off) and for `manifold-nee` (a smooth body
//! where nothing inside scatters: no walk can start), and the rough-bodied `gems/milky-stone.ron`
//! for `manifold-caustics` (the walk through the stone needs a smooth boundary), and the grey-lit
//! `gems/lepidolite.ron` for `light-prefilter` (nothing to reduce). Each is 64 × 48 pixels, 16 spp, Sobol', max depth 8
//! (`LAPIDARY_BENCH_SIZE=W` renders W × 3W/4), on one worker thread; the world is built outside
//! the timed closure. `effects/light-prefilter-build` times the one place the prefilter runs:
//! building the RGB day-glo world (`scenes/dayglo-laser-20.ron --spectral off`) with it on and off.
//!
//! Times are the **process's CPU time** on 64-bit Linux (all render threads), so other builds and
//! tests on a small machine inflate them less than wall time; elsewhere wall time. Run with
//! `cargo bench --bench effects` (about two minutes); a filter narrows it, e.g.
//! `cargo bench --bench effects -- absorption`. No number here is asserted anywhere.

use criterion::Criterion;
use lapidary::recipe::GemRecipe;
use lapidary::render::{Control, Film, World, render};
use lapidary::scene::{Accuracy, Effect, Scene};
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

#[path = "common/clock.rs"]
mod clock;

use clock::Clock;

fn width() -> u32 {
    std::env::var("LAPIDARY_BENCH_SIZE")
        .ok()
        .and_then(|s| s.parse().ok())
        .filter(|w| *w >= 4)
        .unwrap_or(64)
}

fn compile(text: &str) -> Scene {
    let s = GemRecipe::parse("effects-bench.ron", text)
        .and_then(|r| r.compile())
        .unwrap_or_else(|e| panic!("the bench scene compiles: {e}"));
    shrink(s)
}

/// A shipped gem from `gems/`.
fn gem(name: &str) -> Scene {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("gems")
        .join(name);
    let s = GemRecipe::load(&path)
        .and_then(|r| r.compile())
        .unwrap_or_else(|e| panic!("{name} compiles: {e}"));
    shrink(s)
}

/// The bench's size, spp, depth and sampler.
fn shrink(mut s: Scene) -> Scene {
    let r = &mut s.stage.render;
    r.width = width();
    r.height = width() * 3 / 4;
    r.spp = 16;
    r.max_depth = 8;
    r.sampler = lapidary::sampler::SamplerKind::Sobol;
    s
}

/// A recipe on the studio stage.
fn studio(materials: &str, surface: &str) -> String {
    format!("(materials: {{ {materials} }}, surface: {surface})")
}

/// For each implemented effect, a scene that does not call for it.
fn scenes() -> Vec<(Effect, Scene)> {
    let bare = studio(
        r#""clay": (base: Lambert(albedo: Gray(0.6))),
           "gold": (base: Conductor(metal: Gold, roughness: 8.0))"#,
        r#"Voronoi(scale: 0.2, entries: [(1.0, Material("clay")), (1.0, Material("gold"))])"#,
    );
    let clear_coats = studio(
        r#""clear": (coats: [(ior: 1.5, roughness: 3.0, thickness: 1.0)], base: Lambert(albedo: Gray(0.5))),
           "thin": (coats: [(ior: 1.6, roughness: 6.0, absorption: Rgb(0.5, 1.0, 2.0))],
                    base: Conductor(metal: Gold, roughness: 4.0)),
           "double": (coats: [(ior: 1.4, roughness: 2.0, thickness: 2.0, absorption: Gray(0.0)),
                              (ior: 1.7, roughness: 9.0, thickness: 0.5)],
                      base: Lambert(albedo: Rgb(0.2, 0.5, 0.3)), model: Course)"#,
        r#"Voronoi(scale: 0.15, entries: [(1.0, Material("clear")), (1.0, Material("thin")),
                                         (1.0, Material("double"))])"#,
    );
    let nested = studio(
        r#""a": (base: Lambert(albedo: Gray(0.3))),
           "b": (coats: [(ior: 1.5, roughness: 1.0)], base: Conductor(metal: Silver, roughness: 2.0)),
           "c": (base: Lambert(albedo: Rgb(0.6, 0.3, 0.2)))"#,
        r#"Voronoi(scale: 0.4, entries: [
               (1.0, Voronoi(scale: 0.07, entries: [(1.0, Material("a")), (1.0, Material("b"))])),
               (1.0, Material("c"))])"#,
    );
    let hard_switch = studio(
        r#""a": (base: Lambert(albedo: Gray(0.3))),
           "b": (coats: [(ior: 1.5, roughness: 2.0)], base: Lambert(albedo: Rgb(0.7, 0.4, 0.6))),
           "vein": (base: Lambert(albedo: Gray(0.9)))"#,
        r#"Switch(by: Marble(scale: 0.5, turbulence: 0.6),
                  stops: [(0.0, Voronoi(scale: 0.08, entries: [(1.0, Material("a")), (1.0, Material("b"))])),
                          (0.6, Material("vein"))])"#,
    );
    let sky = r#"(materials: { "g": (coats: [(ior: 1.5, roughness: 10.0)], base: Lambert(albedo: Gray(0.5))) },
                  surface: Material("g"),
                  stage: (lights: [], environment: Gradient(zenith: Rgb(0.2, 0.4, 1.0), horizon: Gray(1.0),
                                                            nadir: Rgb(0.5, 0.3, 0.1))))"#;
    vec![
        (Effect::Absorption, compile(&clear_coats)),
        (Effect::TTerm, compile(&bare)),
        (Effect::FacetBump, compile(&nested)),
        (Effect::GlitterOverlay, compile(&hard_switch)),
        (Effect::StochasticSwitch, compile(&hard_switch)),
        (Effect::DepthOfField, compile(&bare)),
        (Effect::EnvironmentImportance, compile(sky)),
        (Effect::Transmission, gem("sunstone.ron")),
        (Effect::Medium, gem("sunstone.ron")),
        (Effect::Platelets, gem("tinted-glass-sphere.ron")),
        // A smooth clear body under the studio's lights: nothing inside scatters, so the walk
        // has no vertex to start from.
        (Effect::ManifoldNee, gem("tinted-glass-sphere.ron")),
        // A rough boundary: the walk through the stone needs a smooth one.
        (Effect::ManifoldCaustics, gem("milky-stone.ron")),
        // No fluorescent base, in spectral transport (the dispersive diamond): the code is a
        // flag test per hit and the film wavelengths a copy per path.
        (Effect::Fluorescence, gem("brilliant-diamond.ron")),
        // Grey studio lights and sky: the prefilter has nothing to reduce (its only code runs
        // when the world is built).
        (Effect::LightPrefilter, gem("lepidolite.ron")),
    ]
}

/// What the prefilter costs where it runs: building the RGB day-glo world (one material, the
/// floor and the colorant's matrix reduced under the laser) with it on and off.
fn prefilter_build(c: &mut Criterion<Clock>) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/dayglo-laser-20.ron");
    let scene = GemRecipe::load(&path)
        .and_then(|r| r.compile())
        .expect("the day-glo scene compiles");
    let rgb = forced(&scene, Effect::Spectral, false);
    let mut group = c.benchmark_group("effects/light-prefilter-build");
    group.sample_size(20);
    for (name, s) in [
        ("on", rgb.clone()),
        ("off", forced(&rgb, Effect::LightPrefilter, false)),
    ] {
        group.bench_function(name, |b| {
            b.iter(|| black_box(World::new(&s).expect("world builds")))
        });
    }
    group.finish();
}

/// `scene` with `effect` forced `on`.
fn forced(scene: &Scene, effect: Effect, on: bool) -> Scene {
    let mut s = scene.clone();
    let mut acc = Accuracy::default();
    acc.force(effect, on);
    s.set_accuracy(&acc, "benches/effects.rs")
        .expect("implemented effects can be forced");
    s
}

fn run(world: &World, scene: &Scene) -> Film {
    render(
        world,
        &scene.stage.camera,
        scene.effects.on(Effect::DepthOfField),
        &scene.stage.render,
        // One worker: no work stealing or idle spinning between the threads, whose scheduling
        // noise on a 2-core machine was larger (±10 %) than the differences looked for.
        &Control {
            threads: Some(1),
            ..Control::default()
        },
    )
    .film
}

fn bench(c: &mut Criterion<Clock>) {
    clock::select(clock::Kind::Process);
    for (effect, scene) in scenes() {
        assert!(
            !scene.effects.called(effect),
            "the {effect} bench scene must not call for it"
        );
        let variants = [
            ("auto", scene.clone()),
            ("forced-off", forced(&scene, effect, false)),
            ("forced-on", forced(&scene, effect, true)),
        ];
        let worlds: Vec<World> = variants
            .iter()
            .map(|(_, s)| World::new(s).expect("world builds"))
            .collect();
        let reference = run(&worlds[0], &variants[0].1);
        let mut group = c.benchmark_group(format!("effects/{}", effect.name()));
        group.sample_size(20);
        group.warm_up_time(Duration::from_millis(500));
        group.measurement_time(Duration::from_secs(4));
        for ((name, s), world) in variants.iter().zip(&worlds) {
            assert!(
                run(world, s) == reference,
                "{effect} {name}: the film differs from auto"
            );
            group.bench_function(*name, |b| b.iter(|| black_box(run(world, s))));
        }
        group.finish();
    }
}

fn config() -> Criterion<Clock> {
    Criterion::default()
        .with_measurement(clock::measurement())
        .without_plots()
}

criterion::criterion_group! {
    name = benches;
    config = config();
    targets = bench, prefilter_build
}
criterion::criterion_main!(benches);
