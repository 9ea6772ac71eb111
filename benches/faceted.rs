//! Faceted stones (issue 39): nanoseconds per ray of the exact convex-polytope intersector against
//! the same round brilliant as a triangle mesh with its BVH (`assets/brilliant.obj`, written by
//! `scripts/brilliant-mesh.py` with the same proportions: 89 facets, 174 triangles), and a
//! 58-facet oval and an emerald cut as polytopes.
//!
//! Each timed iteration intersects a fixed batch of `BATCH` rays: three quarters from outside
//! aimed into the stone's bounds (camera-like rays, most of them hit), one quarter from inside
//! the stone in uniform directions (the rays a translucent body traces between its facets). Times
//! are the benchmark thread's CPU time on 64-bit Linux (`benches/common/clock.rs`).
//!
//! Run with `cargo bench --bench faceted` (about ten seconds). No number here is asserted.

use criterion::{Criterion, Throughput};
use glam::Vec3;
use lapidary::cut::{Brilliant, Cut, Outline, Step};
use lapidary::geometry::shape::Shape;
use lapidary::geometry::{Polytope, Ray, Solid};
use lapidary::sampler::Rng;
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

#[path = "common/clock.rs"]
mod clock;
use clock::Clock;

/// Rays per timed iteration.
const BATCH: usize = 1024;

fn rays() -> Vec<Ray> {
    let mut rng = Rng::new(0xfa_ce7);
    let mut u = move || rng.uniform() * 2.0 - 1.0;
    (0..BATCH)
        .map(|i| {
            if i % 4 == 3 {
                // From inside, any direction.
                let o = Vec3::new(u(), u(), u()) * Vec3::new(0.4, 0.2, 0.4);
                let d = Vec3::new(u(), u(), u()).normalize_or(Vec3::Y);
                Ray::new(o, d)
            } else {
                let o = Vec3::new(u(), u(), u()).normalize_or(Vec3::Z) * 4.0;
                let aim = Vec3::new(u(), u() * 0.6, u());
                Ray::new(o, (aim - o).normalize())
            }
        })
        .collect()
}

fn polytope(cut: Cut) -> Solid {
    let f = cut.facets(2.0).unwrap();
    Solid::Polytope(Polytope::new(&f.planes, "bench").unwrap())
}

fn intersect(c: &mut Criterion<Clock>) {
    let rays = rays();
    let mesh = Solid::new(&Shape::Mesh {
        path: Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/brilliant.obj"),
        scale: 1.0,
    })
    .unwrap();
    let round = polytope(Cut::Brilliant(Brilliant {
        girdle: 0.0125,
        girdle_facets: 32,
        ..Brilliant::default()
    }));
    let oval = polytope(Cut::Brilliant(Brilliant {
        outline: Outline::Oval { ratio: 1.35 },
        culet: 0.01,
        ..Brilliant::default()
    }));
    let emerald = polytope(Cut::Step(Step {
        kind: lapidary::cut::step::StepKind::Emerald,
        ratio: 1.4,
        corner: 0.15,
        table: 0.6,
        crown: vec![50.0, 40.0, 30.0],
        pavilion: vec![60.0, 50.0, 42.0],
        girdle: 0.02,
    }));
    let mut g = c.benchmark_group("intersect");
    g.throughput(Throughput::Elements(BATCH as u64));
    for (name, solid) in [
        ("brilliant mesh+BVH (174 triangles)", &mesh),
        ("brilliant polytope (89 planes)", &round),
        ("oval brilliant polytope (123 planes)", &oval),
        ("emerald polytope", &emerald),
    ] {
        g.bench_function(name, |b| {
            b.iter(|| {
                for r in &rays {
                    black_box(solid.intersect(black_box(r), f32::INFINITY));
                }
            })
        });
    }
    g.finish();
}

fn config() -> Criterion<Clock> {
    Criterion::default()
        .with_measurement(clock::measurement())
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .sample_size(30)
        .without_plots()
}

criterion::criterion_group! {
    name = benches;
    config = config();
    targets = intersect
}
criterion::criterion_main!(benches);
