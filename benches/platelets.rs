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
//! `oregon-sunstone` (800 / unit³, r 0.015–0.04, aligned to y with a 4° spread). Times are the
//! benchmark thread's CPU time on 64-bit Linux (wall time elsewhere). Run with
//! `cargo bench --bench platelets` (about 30 s); a filter narrows it, e.g.
//! `cargo bench --bench platelets -- aventurine/first`.

use criterion::{Criterion, Throughput};
use glam::Vec3;
use lapidary::platelet::grid::intersect;
use lapidary::platelet::{Orientation, Population};
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

fn bench(c: &mut Criterion<Clock>) {
    let rays = chords(0x18);
    for (name, pop) in populations() {
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
