//! BSDF cost: nanoseconds per `eval` and per `sample` for every component and for every material of
//! the course catalogue under each evaluation model, the cost of compiling a stack's tables, and the
//! layered-over-single ratio that the course quotes (§3.4.2: 195 vs 83 cycles, ≈2.3×, with
//! precomputed Fresnel). `docs/cost.md` holds the measured tables.
//!
//! Every timed iteration runs one call per entry of a fixed batch of `BATCH` pre-generated inputs
//! (directions uniform over the hemisphere in solid angle, random order), so branches are as
//! unpredictable as they are in a renderer and the per-call time is the iteration time / `BATCH`
//! (criterion's throughput line reports it as elements per second).
//!
//! Per-call times are the benchmark thread's CPU time on 64-bit Linux (`CLOCK_THREAD_CPUTIME_ID`),
//! so that builds and tests running at the same time on a small machine do not inflate them by
//! preempting the benchmark (on a quiet machine it equals wall time); table builds, which run in
//! parallel, are timed by the wall clock and by the process's CPU time. Elsewhere everything is wall
//! time.
//!
//! Run with `cargo bench --bench bsdf` (release profile, about six minutes on two cores); a filter
//! narrows it, e.g. `cargo bench --bench bsdf -- ratio` or `-- vertex` (a path vertex's light
//! sample and continuation sample, separately and sharing their work). No number here is asserted anywhere.

use criterion::{BenchmarkGroup, Criterion, SamplingMode, Throughput};
use glam::{Vec2, Vec3};
use lapidary::bsdf::layered::lobes::WeightsMemo;
use lapidary::bsdf::{
    Base, BsdfSample, Bxdf, Coat, Distribution, Fresnel, FresnelMode, Lambert, LayeredBsdf,
    LobeFlags, Metal, MicrofacetDistribution, Model, OrenNayar, ReferenceParams, RoughDielectric,
    StackDesc, TorranceSparrow, TransportMode,
};
use lapidary::color::Rgb;
use lapidary::recipe::MaterialLibrary;
use lapidary::sampler::Rng;
use lapidary::spectrum::RgbSample;
use std::hint::black_box;
use std::time::Duration;

#[path = "common/clock.rs"]
mod clock;

use clock::Clock;

/// Calls per timed iteration.
const BATCH: usize = 1024;

/// One pre-generated call: the directions for `eval`, the random numbers for `sample`.
#[derive(Clone, Copy)]
struct Input {
    wo: Vec3,
    wi: Vec3,
    uc: f32,
    u: Vec2,
}

/// A direction uniform in solid angle over the upper hemisphere (`z ∈ (0, 1]`, grazing included).
fn uniform_hemisphere(rng: &mut Rng) -> Vec3 {
    let z = 1.0 - rng.uniform();
    let phi = std::f32::consts::TAU * rng.uniform();
    let r = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// `BATCH` inputs with `wo`, `wi` both above the surface; with `transmission`, every second `wi`
/// is mirrored below it (for interfaces that transmit).
fn batch(key: u64, transmission: bool) -> Vec<Input> {
    let mut rng = Rng::new(key);
    (0..BATCH)
        .map(|i| {
            let wo = uniform_hemisphere(&mut rng);
            let mut wi = uniform_hemisphere(&mut rng);
            if transmission && i % 2 == 1 {
                wi.z = -wi.z;
            }
            Input {
                wo,
                wi,
                uc: rng.uniform(),
                u: rng.uniform2(),
            }
        })
        .collect()
}

/// The rough dielectric as the renderer calls it: radiance transport, both lobes (its own
/// [`Bxdf`] implementation, behind the same wrapper as before so the benchmark ids stay).
struct Interface(RoughDielectric);

impl Bxdf for Interface {
    #[inline]
    fn flags(&self) -> LobeFlags {
        self.0.flags()
    }
    #[inline]
    fn eval_mode(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> RgbSample {
        self.0.eval_mode(wo, wi, mode)
    }
    #[inline]
    fn sample_mode(&self, wo: Vec3, uc: f32, u: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        self.0.sample_mode(wo, uc, u, mode)
    }
    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.0.pdf(wo, wi)
    }
}

/// Which call a benchmark times.
#[derive(Clone, Copy)]
enum Op {
    Eval,
    Sample,
}

impl Op {
    fn name(self) -> &'static str {
        match self {
            Op::Eval => "eval",
            Op::Sample => "sample",
        }
    }
}

/// Times `op` of `b` over the whole batch, one call per input.
fn bench_op<B: Bxdf>(g: &mut BenchmarkGroup<'_, Clock>, id: &str, b: &B, op: Op, xs: &[Input]) {
    match op {
        Op::Eval => g.bench_function(id, |bn| {
            bn.iter(|| {
                let b = black_box(b);
                for x in xs {
                    black_box(b.eval(black_box(x.wo), black_box(x.wi)));
                }
            })
        }),
        Op::Sample => g.bench_function(id, |bn| {
            bn.iter(|| {
                let b = black_box(b);
                for x in xs {
                    black_box(b.sample(black_box(x.wo), black_box(x.uc), black_box(x.u)));
                }
            })
        }),
    };
}

/// A group whose every benchmark processes one batch per iteration.
fn group<'a>(c: &'a mut Criterion<Clock>, name: &str) -> BenchmarkGroup<'a, Clock> {
    let mut g = c.benchmark_group(name);
    g.throughput(Throughput::Elements(BATCH as u64));
    g
}

/// A Blinn micro-facet distribution of RMS slope `m` degrees.
fn blinn(m: f32) -> MicrofacetDistribution {
    MicrofacetDistribution::new(Distribution::Blinn, m)
}

/// Single components, each with the parameters of a typical catalogue layer (m = 12°, η = 1.5,
/// aluminium).
fn components(c: &mut Criterion<Clock>) {
    let (al_n, al_k) = Metal::Aluminium.nk();
    let ts_d = |mode| TorranceSparrow::new(blinn(12.0), Fresnel::dielectric(1.5, mode));
    let ts_c = |mode| {
        TorranceSparrow::new(
            blinn(12.0),
            Fresnel::conductor(al_n.into(), al_k.into(), mode),
        )
    };
    let lambert = Lambert {
        albedo: RgbSample::splat(0.5),
    };
    let oren_nayar = OrenNayar {
        albedo: RgbSample::splat(0.5),
        sigma: 0.3,
    };
    let beckmann = TorranceSparrow::new(
        MicrofacetDistribution::new(Distribution::Beckmann, 12.0),
        Fresnel::dielectric(1.5, FresnelMode::Exact),
    );
    let lobes: [(&str, TorranceSparrow); 9] = [
        ("ts_dielectric_exact", ts_d(FresnelMode::Exact)),
        ("ts_dielectric_schlick", ts_d(FresnelMode::Schlick)),
        ("ts_dielectric_table", ts_d(FresnelMode::Table)),
        (
            "ts_dielectric_exact_compensated",
            ts_d(FresnelMode::Exact).with_compensation(),
        ),
        ("ts_dielectric_exact_beckmann", beckmann),
        ("ts_conductor_exact", ts_c(FresnelMode::Exact)),
        ("ts_conductor_schlick", ts_c(FresnelMode::Schlick)),
        ("ts_conductor_table", ts_c(FresnelMode::Table)),
        (
            "ts_conductor_exact_compensated",
            ts_c(FresnelMode::Exact).with_compensation(),
        ),
    ];
    let interface = Interface(RoughDielectric::new(blinn(12.0), 1.5));

    let above = batch(0xbe_0001, false);
    let both = batch(0xbe_0002, true);
    for op in [Op::Eval, Op::Sample] {
        let mut g = group(c, &format!("component_{}", op.name()));
        bench_op(&mut g, "lambert", &lambert, op, &above);
        bench_op(&mut g, "oren_nayar", &oren_nayar, op, &above);
        for (id, ts) in &lobes {
            bench_op(&mut g, id, ts, op, &above);
        }
        bench_op(&mut g, "rough_dielectric", &interface, op, &both);
        g.finish();
    }
}

/// The three evaluation models, with the names used as benchmark ids.
fn models() -> [(&'static str, Model); 3] {
    [
        ("course", Model::Course),
        ("corrected", Model::Corrected),
        ("reference", Model::Reference(ReferenceParams::default())),
    ]
}

/// Every catalogue material under every model (tables built once, outside the timing).
fn materials(c: &mut Criterion<Clock>) {
    let lib = MaterialLibrary::course();
    let xs = batch(0xbe_0003, false);
    for (model_name, model) in models() {
        let built: Vec<(&str, LayeredBsdf)> = lib
            .names()
            .map(|n| (n, lib.build(n, Some(model)).expect("catalogue builds")))
            .collect();
        for op in [Op::Eval, Op::Sample] {
            let mut g = group(c, &format!("material_{}_{model_name}", op.name()));
            if matches!(model, Model::Reference(_)) {
                // A batch of random walks takes milliseconds: equal-sized samples, more time.
                g.sampling_mode(SamplingMode::Flat)
                    .measurement_time(Duration::from_secs(2));
            }
            for (name, stack) in &built {
                bench_op(&mut g, name, stack, op, &xs);
            }
            g.finish();
        }
    }
}

/// A path vertex's scattering work on every catalogue material under the Corrected model:
/// next-event estimation's value and density toward a light, then the continuation sample — as
/// two calls and a sample, and as one joint call and a sample that share the vertex's lobe
/// weights (`LayeredBsdf::eval_pdf_memo`, `sample_memo`; bit for bit the same numbers, tested in
/// `bsdf::layered::joint`). A fresh memo per vertex, as a path makes one.
fn vertex(c: &mut Criterion<Clock>) {
    let lib = MaterialLibrary::course();
    let xs = batch(0xbe_0005, false);
    let mut g = group(c, "vertex_corrected");
    for name in lib.names() {
        let stack = lib
            .build(name, Some(Model::Corrected))
            .expect("catalogue builds");
        g.bench_function(format!("{name} separate"), |bn| {
            bn.iter(|| {
                let b = black_box(&stack);
                for x in &xs {
                    black_box(b.eval(black_box(x.wo), black_box(x.wi)));
                    black_box(b.pdf(black_box(x.wo), black_box(x.wi)));
                    black_box(b.sample(black_box(x.wo), black_box(x.uc), black_box(x.u)));
                }
            })
        });
        g.bench_function(format!("{name} joint"), |bn| {
            bn.iter(|| {
                let b = black_box(&stack);
                for x in &xs {
                    let memo = WeightsMemo::default();
                    let r = TransportMode::Radiance;
                    black_box(b.eval_pdf_memo(black_box(x.wo), black_box(x.wi), r, &memo));
                    black_box(b.sample_memo(black_box(x.wo), black_box(x.uc), x.u, r, &memo));
                }
            })
        });
    }
    g.finish();
}

/// What a compiled scene pays once per material: validating the description and building the
/// stack's tables (`LayeredBsdf::new`). Course and Corrected build the same tables; a compensated
/// Reference stack also builds its interfaces' energy tables. Table builds run in parallel (rayon),
/// so these are timed by the wall clock (latency) and, for Corrected, by the process's CPU time
/// (total work over all threads).
fn build(c: &mut Criterion<Clock>) {
    let lib = MaterialLibrary::course();
    let mut cases = vec![
        ("corrected", Model::Corrected, clock::Kind::Wall),
        (
            "reference",
            Model::Reference(ReferenceParams::default()),
            clock::Kind::Wall,
        ),
    ];
    if clock::CPU_CLOCKS {
        cases.push(("corrected_cpu", Model::Corrected, clock::Kind::Process));
    }
    for (label, model, kind) in cases {
        clock::select(kind);
        let mut g = c.benchmark_group(format!("material_build_{label}"));
        g.sampling_mode(SamplingMode::Flat)
            .sample_size(10)
            .measurement_time(Duration::from_secs(2));
        for name in lib.names() {
            let mut desc = lib.stack(name).expect("catalogue validates");
            desc.model = model;
            g.bench_function(name, |bn| {
                bn.iter(|| LayeredBsdf::new(black_box(&desc)).expect("catalogue builds"))
            });
        }
        g.finish();
    }
    clock::select(clock::Kind::Thread);
}

/// The course's comparison (§3.4.2): a one-coat stack — a tinted dielectric Torrance–Sparrow coat
/// (η = 1.5, m = 12°; the course's cost includes the Lambert–Beer term) over a Lambert base —
/// against the coat's Torrance–Sparrow lobe alone, with precomputed (table) and exact Fresnel.
fn ratio(c: &mut Criterion<Clock>) {
    let coat = Coat {
        ior: 1.5,
        roughness: 12.0,
        absorption: Rgb::new(0.1, 0.2, 0.4),
        thickness: 1.0,
    };
    let base = Base::Lambert {
        albedo: Rgb::splat(0.5),
    };
    let xs = batch(0xbe_0004, false);
    let mut singles = Vec::new();
    let mut stacks = Vec::new();
    for (mode_name, mode) in [("table", FresnelMode::Table), ("exact", FresnelMode::Exact)] {
        singles.push((
            format!("single_ts_{mode_name}"),
            TorranceSparrow::new(blinn(coat.roughness), Fresnel::dielectric(coat.ior, mode)),
        ));
        for (model_name, model) in [("course", Model::Course), ("corrected", Model::Corrected)] {
            let mut desc = StackDesc::new(vec![coat], base).with_model(model);
            desc.fresnel = mode;
            stacks.push((
                format!("layered_{model_name}_{mode_name}"),
                LayeredBsdf::new(&desc).expect("valid stack"),
            ));
        }
    }
    for op in [Op::Eval, Op::Sample] {
        let mut g = group(c, &format!("ratio_{}", op.name()));
        for (id, ts) in &singles {
            bench_op(&mut g, id, ts, op, &xs);
        }
        for (id, stack) in &stacks {
            bench_op(&mut g, id, stack, op, &xs);
        }
        g.finish();
    }
}

/// Short runs: the whole file takes about five minutes on two cores.
fn config() -> Criterion<Clock> {
    Criterion::default()
        .with_measurement(clock::measurement())
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(1))
        .sample_size(20)
        .without_plots()
}

criterion::criterion_group! {
    name = benches;
    config = config();
    targets = ratio, components, materials, vertex, build
}
criterion::criterion_main!(benches);
