//! The platelet grid walk (issue 18): `platelet::grid::intersect` on the shipped gems'
//! populations, rays through a 2-unit stone (the studio cabochon is 2 units across).
//!
//! Each iteration intersects a fixed set of 2 048 rays: origins uniform on the unit sphere, each
//! looking inward (a uniform direction in the inner hemisphere), `t_max` the chord to the far side
//! of the sphere — the segments a path walks inside the body. Two questions per population:
//!
//! - `first` — the nearest platelet along each chord (what the integrator asks per segment);
//! - `all` — every platelet along each chord, by repeated nearest hits from the last one,
//!   skipping the platelet it is on (the longest walks: to the far side when the last disc is
//!   passed).
//!
//! Populations: `aventurine-glass` (8 000 / unit³, r 0.01–0.04, uniform orientation) and
//! `oregon-sunstone` (800 / unit³, r 0.015–0.04, aligned to y with a 4° spread), each drawn cell
//! by cell as the walk goes and (`…-table`) from the lists a render prepares over the stone's box
//! (`Population::prepare`). Times are the
//! benchmark thread's CPU time on 64-bit Linux (wall time elsewhere). Run with
//! `cargo bench --bench platelets` (about 40 s); a filter narrows it, e.g.
//! `cargo bench --bench platelets -- aventurine/first`.
//!
//! `manifold/…`: 512 manifold walks (`render::manifold::solve`, one refraction out) from random
//! points inside a glass unit sphere (IOR 1.5) to random points on a disc light above it —
//! `exact` with the sphere described as a cabochon (two hemispherical domes: the walk's
//! Jacobian in closed form), `differences` with the sphere as a `Sphere` (a finite-difference
//! Jacobian and Broyden's updates). The same geometry, so the ratio is the Jacobian's cost.

use criterion::{Criterion, Throughput};
use glam::Vec3;
use lapidary::platelet::grid::intersect;
use lapidary::platelet::{Orientation, Population};
use lapidary::recipe::GemRecipe;
use lapidary::render::World;
use lapidary::render::manifold::{Chain, solve};
use lapidary::sampler::Rng;
use std::hint::black_box;
use std::time::Duration;

#[path = "common/clock.rs"]
mod clock;

use clock::Clock;

/// Rays per iteration.
const RAYS: usize = 2048;

/// A uniform direction.
fn unit(rng: &mut Rng) -> Vec3 {
    let z = 1.0 - 2.0 * rng.uniform();
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * rng.uniform();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Chords of the unit sphere: origin, unit direction, length.
fn chords(seed: u64) -> Vec<(Vec3, Vec3, f32)> {
    let mut rng = Rng::new(seed);
    (0..RAYS)
        .map(|_| {
            let o = unit(&mut rng);
            let mut d = unit(&mut rng);
            if d.dot(o) > 0.0 {
                d = -d;
            }
            // |o + t d| = 1 again at t = −2 o·d.
            let len = -2.0 * o.dot(d);
            (o, d, len)
        })
        .collect()
}

fn populations() -> Vec<(&'static str, Population)> {
    let aventurine = Population::new(
        8000.0,
        (0.01, 0.04),
        Orientation::Uniform,
        vec![(1.0, 0)],
        7,
    )
    .expect("aventurine-glass population");
    let oregon = Population::new(
        800.0,
        (0.015, 0.04),
        Orientation::Aligned {
            axis: Vec3::Y,
            spread: 4f32.to_radians(),
        },
        vec![(1.0, 0)],
        9,
    )
    .expect("oregon-sunstone population");
    vec![("aventurine", aventurine), ("oregon", oregon)]
}

/// A glass unit sphere described as `shape`, under a disc light of radius 0.5 at height 4.
fn sphere_world(shape: &str) -> World {
    let text = format!(
        "(materials: {{ \"m\": (coats: [], base: Lambert(albedo: Gray(0.5))) }},
          body: (ior: 1.5), surface: Body,
          stage: (shape: {shape},
                  lights: [Disc(center: (0.0, 4.0, 0.0), target: (0.0, 0.0, 0.0), radius: 0.5,
                                radiance: Gray(20.0))]))"
    );
    let scene = GemRecipe::parse("bench.ron", &text)
        .and_then(|r| r.compile())
        .expect("bench recipe");
    World::new(&scene).expect("bench world")
}

/// Manifold walks on the same sphere with the exact and the finite-difference Jacobian.
fn walks(c: &mut Criterion<Clock>) {
    let mut rng = Rng::new(0x3a1f);
    let pairs: Vec<(Vec3, Vec3)> = (0..512)
        .map(|_| {
            let x0 = unit(&mut rng) * (0.9 * rng.uniform().cbrt());
            let (r, phi) = (
                0.5 * rng.uniform().sqrt(),
                std::f32::consts::TAU * rng.uniform(),
            );
            (x0, Vec3::new(r * phi.cos(), 4.0, r * phi.sin()))
        })
        .collect();
    let mut group = c.benchmark_group("manifold");
    group.throughput(Throughput::Elements(pairs.len() as u64));
    for (name, shape) in [
        (
            "exact",
            "Cabochon(radius: (1.0, 1.0), height: 1.0, base: 1.0)",
        ),
        ("differences", "Sphere(radius: 1.0)"),
    ] {
        let world = sphere_world(shape);
        group.bench_function(name, |b| {
            b.iter(|| {
                let mut found = 0u32;
                for &(x0, x2) in &pairs {
                    found +=
                        u32::from(solve(&world, x0, x2, Vec3::NEG_Y, 1.5, Chain::Out).is_some());
                }
                black_box(found)
            })
        });
    }
    group.finish();
}

fn bench(c: &mut Criterion<Clock>) {
    walks(c);
    let rays = chords(0x18);
    let mut cases = Vec::new();
    for (name, pop) in populations() {
        // The same population with its cells drawn once over the stone's box (what a render
        // walks: the lists of `platelet::table`).
        let mut table = pop.clone();
        table.prepare(Vec3::splat(-1.0), Vec3::splat(1.0));
        cases.push((name.to_string(), pop));
        cases.push((format!("{name}-table"), table));
    }
    for (name, pop) in cases {
        let pops = std::slice::from_ref(&pop);
        let mut group = c.benchmark_group(format!("platelets/{name}"));
        group.throughput(Throughput::Elements(RAYS as u64));
        group.bench_function("first", |b| {
            b.iter(|| {
                let mut n = 0u32;
                for &(o, d, len) in &rays {
                    n += u32::from(intersect(pops, o, d, 0.0, len, None).is_some());
                }
                black_box(n)
            })
        });
        group.bench_function("all", |b| {
            b.iter(|| {
                let mut n = 0u32;
                for &(o, d, len) in &rays {
                    let (mut t, mut skip) = (0.0, None);
                    while let Some(h) = intersect(pops, o, d, t, len, skip) {
                        n += 1;
                        (t, skip) = (h.t, Some(h.id));
                    }
                }
                black_box(n)
            })
        });
        group.finish();
    }
}

fn config() -> Criterion<Clock> {
    Criterion::default()
        .with_measurement(clock::measurement())
        .without_plots()
        .sample_size(20)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3))
}

criterion::criterion_group! {
    name = benches;
    config = config();
    targets = bench
}
criterion::criterion_main!(benches);
