//! Render throughput (issue 5): camera paths per second and rays per second for every recipe in
//! `gems/` on its stage, and for a plain Lambertian sphere (albedo 0.5) under a constant white
//! environment — all at 256 × 256 pixels, 64 spp, max depth 8, Sobol' sampler, on every core.
//!
//! Criterion's throughput line gives paths/s (one element = one camera path); rays per path are
//! counted in a first, untimed render and printed, so rays/s = paths/s × rays/path. Times are wall
//! time (the render is multi-threaded). Each iteration is a whole render (several seconds), so the
//! group takes criterion's minimum of 10 samples: run with `cargo bench --bench render` (about
//! 15 minutes on 2 cores); `LAPIDARY_BENCH_SIZE=64` renders 64 × 64 for a quick look. A filter
//! narrows it: `cargo bench --bench render -- lambert`. README's "Speed" table holds the figures.

use criterion::{Criterion, Throughput};
use lapidary::recipe::GemRecipe;
use lapidary::render::{Control, World, render};
use lapidary::scene::{Effect, Scene};
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

/// The plain sphere of the issue.
const LAMBERT_SPHERE: &str = r#"(
    materials: { "grey": (base: Lambert(albedo: Gray(0.5))) },
    surface: Material("grey"),
    stage: (shape: Sphere(radius: 1.0), ground: Off, lights: [], environment: Constant(Gray(1.0)),
            camera: Perspective(from: (0.0, 0.0, 4.0), to: (0.0, 0.0, 0.0), fov: 35.0)),
)"#;

fn size() -> u32 {
    std::env::var("LAPIDARY_BENCH_SIZE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(256)
}

fn prepare(mut scene: Scene) -> Scene {
    let r = &mut scene.stage.render;
    r.width = size();
    r.height = size();
    r.spp = 64;
    r.max_depth = 8;
    r.sampler = lapidary::sampler::SamplerKind::Sobol;
    scene
}

fn scenes() -> Vec<(String, Scene)> {
    let mut out = vec![(
        "lambert-sphere".to_string(),
        GemRecipe::parse("lambert-sphere.ron", LAMBERT_SPHERE)
            .and_then(|r| r.compile())
            .expect("the bench scene compiles"),
    )];
    let mut gems: Vec<_> = std::fs::read_dir("gems")
        .expect("run from the crate root")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    gems.sort();
    for p in gems {
        let name = p
            .file_stem()
            .unwrap_or_default()
            .to_string_lossy()
            .into_owned();
        let scene = GemRecipe::load(Path::new(&p))
            .and_then(|r| r.compile())
            .expect("shipped gems compile");
        out.push((name, scene));
    }
    out.into_iter().map(|(n, s)| (n, prepare(s))).collect()
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("render");
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(1));
    group.measurement_time(Duration::from_secs(1));
    for (name, scene) in scenes() {
        let world = World::new(&scene).expect("world builds");
        let dof = scene.effects.on(Effect::DepthOfField);
        let run = || {
            render(
                &world,
                &scene.stage.camera,
                dof,
                &scene.stage.render,
                &Control::default(),
            )
        };
        let first = run();
        let paths = first.stats.paths;
        eprintln!(
            "{name}: {:.2} rays/path, {} paths per render",
            first.stats.rays as f64 / paths as f64,
            paths
        );
        group.throughput(Throughput::Elements(paths));
        group.bench_function(&name, |b| b.iter(|| black_box(run())));
    }
    group.finish();
}

criterion::criterion_group!(benches, bench);
criterion::criterion_main!(benches);
