//! What spectral transport costs (issue 19): every shipped gem rendered by the RGB variant and,
//! forced with `--effect spectral=on`, by the spectral one (four hero wavelengths per path), at
//! 64 × 48 pixels, 16 spp, Sobol', max depth 8 (`LAPIDARY_BENCH_SIZE=W` renders W × 3W/4), on one
//! worker thread; worlds are built and the RGB-to-spectrum table is warmed up outside the timed
//! closure, so the figures are per-sample cost. The target is at most 1.2× the RGB time
//! (Mitsuba 3's `scalar_spectral` costs about 1.18× `scalar_rgb`).
//!
//! Times are the process's CPU time on 64-bit Linux (benches/common/clock.rs). Run with
//! `cargo bench --bench spectral` (about three minutes); a filter narrows it, e.g.
//! `cargo bench --bench spectral -- sunstone`. No number here is asserted anywhere.
//!
//! **Paired ratios.** On a shared VM the machine's speed drifts by 10–20 % between criterion's
//! groups, more than the effect measured. `LAPIDARY_BENCH_PAIRS=N cargo bench --bench spectral`
//! instead renders each gem N times in each variant, alternating (RGB first, then spectral first,
//! …), and prints per gem the median of the N per-pair ratios spectral / RGB with its quartiles:
//! drift slower than one pair cancels out. `LAPIDARY_BENCH_GEMS=sunstone,milky` keeps the gems
//! whose names contain one of the words.

use criterion::Criterion;
use lapidary::recipe::GemRecipe;
use lapidary::render::{Control, Film, World, render};
use lapidary::scene::{Accuracy, Effect, Scene};
use std::hint::black_box;
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

/// A shipped gem at the bench's size, spp, depth and sampler, spectral or not.
fn gem(path: &std::path::Path, spectral: bool) -> Scene {
    let mut s = GemRecipe::load(path)
        .and_then(|r| r.compile())
        .unwrap_or_else(|e| panic!("{} compiles: {e}", path.display()));
    let mut acc = Accuracy::default();
    acc.force(Effect::Spectral, spectral);
    s.set_accuracy(&acc, "benches/spectral.rs")
        .expect("spectral can be forced");
    let r = &mut s.stage.render;
    r.width = width();
    r.height = width() * 3 / 4;
    r.spp = 16;
    r.max_depth = 8;
    r.sampler = lapidary::sampler::SamplerKind::Sobol;
    s
}

fn run(world: &World, scene: &Scene) -> Film {
    render(
        world,
        &scene.stage.camera,
        scene.effects.on(Effect::DepthOfField),
        &scene.stage.render,
        &Control {
            threads: Some(1),
            ..Control::default()
        },
    )
    .film
}

/// The paired measurement (module docs): `pairs` alternating renders per gem and variant.
fn paired(gems: &[std::path::PathBuf], pairs: usize) {
    use criterion::measurement::Measurement;
    let clock = clock::measurement();
    println!(
        "| gem | RGB (median) | spectral (median) | ratio: median of {pairs} pairs | quartiles |"
    );
    println!("|---|---:|---:|---:|---|");
    for path in gems {
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        let setups: Vec<(Scene, World)> = [false, true]
            .iter()
            .map(|&spectral| {
                let scene = gem(path, spectral);
                let world = World::new(&scene).expect("world builds");
                (scene, world)
            })
            .collect();
        for (scene, world) in &setups {
            black_box(run(world, scene)); // warm
        }
        let (mut ratios, mut times) = (Vec::new(), [Vec::new(), Vec::new()]);
        for k in 0..pairs {
            let order = if k % 2 == 0 { [0, 1] } else { [1, 0] };
            let mut t = [0.0f64; 2];
            for v in order {
                let (scene, world) = &setups[v];
                let start = clock.start();
                black_box(run(world, scene));
                t[v] = clock.end(start).as_secs_f64();
                times[v].push(t[v]);
            }
            ratios.push(t[1] / t[0]);
        }
        let q = |v: &mut Vec<f64>, p: f64| {
            v.sort_by(f64::total_cmp);
            v[((v.len() - 1) as f64 * p).round() as usize]
        };
        println!(
            "| {name} | {:.1} ms | {:.1} ms | {:.3} | {:.3}–{:.3} |",
            1e3 * q(&mut times[0], 0.5),
            1e3 * q(&mut times[1], 0.5),
            q(&mut ratios, 0.5),
            q(&mut ratios, 0.25),
            q(&mut ratios, 0.75)
        );
    }
}

fn bench(c: &mut Criterion<Clock>) {
    clock::select(clock::Kind::Process);
    lapidary::spectrum::rgb2spec::warm_up();
    lapidary::spectrum::basis::warm_up();
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("gems");
    let mut gems: Vec<_> = std::fs::read_dir(&dir)
        .expect("gems/")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    gems.sort();
    if let Some(pairs) = std::env::var("LAPIDARY_BENCH_PAIRS")
        .ok()
        .and_then(|s| s.parse::<usize>().ok())
        .filter(|&n| (1..=1000).contains(&n))
    {
        let filter: Vec<String> = std::env::var("LAPIDARY_BENCH_GEMS")
            .unwrap_or_default()
            .split(',')
            .filter(|s| !s.is_empty())
            .map(str::to_string)
            .collect();
        gems.retain(|p| {
            let n = p.file_stem().unwrap().to_string_lossy();
            filter.is_empty() || filter.iter().any(|f| n.contains(f.as_str()))
        });
        paired(&gems, pairs);
        return;
    }
    bookkeeping(c);
    for path in gems {
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        let mut group = c.benchmark_group(format!("spectral/{name}"));
        group.sample_size(15);
        group.warm_up_time(Duration::from_millis(500));
        group.measurement_time(Duration::from_secs(4));
        for (label, spectral) in [("rgb", false), ("spectral", true)] {
            let scene = gem(&path, spectral);
            let world = World::new(&scene).expect("world builds");
            assert_eq!(world.spectral, spectral);
            group.bench_function(label, |b| b.iter(|| black_box(run(&world, &scene))));
        }
        group.finish();
    }
}

/// A spectral path's fixed costs, per path: drawing its four wavelengths (the tabulated visible
/// density, `src/spectrum/wavelengths.rs`) and projecting its estimate onto the film
/// (`HeroSample::to_rgb`), each over a batch of 1024 stratified wavelength numbers.
fn bookkeeping(c: &mut Criterion<Clock>) {
    use lapidary::spectrum::wavelengths::HeroWavelengths;
    use lapidary::spectrum::{HeroSample, Spectral};
    let us: Vec<f32> = (0..1024).map(|i| (i as f32 + 0.5) / 1024.0).collect();
    let lambdas: Vec<HeroWavelengths> = us.iter().map(|&u| HeroWavelengths::sample(u)).collect();
    let mut group = c.benchmark_group("spectral/bookkeeping");
    group.sample_size(20);
    group.bench_function("wavelengths ×1024", |b| {
        b.iter(|| {
            for &u in &us {
                black_box(HeroWavelengths::sample(black_box(u)));
            }
        })
    });
    let l = HeroSample([0.3, 0.5, 0.7, 0.2]);
    group.bench_function("to_rgb ×1024", |b| {
        b.iter(|| {
            for w in &lambdas {
                black_box(black_box(l).to_rgb(w));
            }
        })
    });
    group.finish();
}

fn config() -> Criterion<Clock> {
    Criterion::default()
        .with_measurement(clock::measurement())
        .without_plots()
}

criterion::criterion_group! {
    name = benches;
    config = config();
    targets = bench
}
criterion::criterion_main!(benches);
