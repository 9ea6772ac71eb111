//! The film's exact sums (issue 21): adding one sample to a pixel's fixed-point sums, and merging
//! two part films of 640 × 480 pixels (what `lapidary merge` does per part, reading excluded).
//! `cargo bench --bench film`; docs/farm.md holds the figures and the render-loop cost measured
//! with callgrind.

use criterion::{Criterion, Throughput};
use glam::Vec3;
use lapidary::color::Rgb;
use lapidary::render::{Film, PathSample, PixelSums};
use std::hint::black_box;

fn samples() -> Vec<PathSample> {
    (0..1024)
        .map(|i| {
            let v = ((i * 7919 % 1000) as f32 * 0.013).powf(1.7);
            PathSample {
                radiance: Rgb::new(v, 0.5 * v, 0.25 * v),
                albedo: Rgb::splat(0.5),
                normal: Vec3::Y,
                depth: Some(3.0),
                material: 1,
                rays: 3,
                signed: false,
            }
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let list = samples();
    let mut g = c.benchmark_group("film");
    g.throughput(Throughput::Elements(list.len() as u64));
    g.bench_function("add 1024 samples", |b| {
        b.iter(|| {
            let mut p = PixelSums::EMPTY;
            for s in &list {
                p.add(black_box(s));
            }
            black_box(p)
        })
    });
    let mut a = Film::new(640, 480);
    for (i, p) in a.pixels.iter_mut().enumerate() {
        p.add(&list[i % list.len()]);
    }
    let part = a.clone();
    g.throughput(Throughput::Elements(a.pixels.len() as u64));
    g.bench_function("merge 640x480", |b| {
        b.iter(|| {
            let mut m = a.clone();
            for (x, y) in m.pixels.iter_mut().zip(&part.pixels) {
                x.merge(y);
            }
            black_box(m)
        })
    });
    g.finish();
}

criterion::criterion_group!(benches, bench);
criterion::criterion_main!(benches);
