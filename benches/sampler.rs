//! The pixel sampler (issue 37): the numbers of one camera path (the camera's two slots and two
//! bounces of six), drawn from a sampler made for each sample, from one sampler restarted for each
//! sample of its pixel (the render loop's way: the slot seeds are kept), and for eight pixels side
//! by side (the lane loop's way). `cargo bench --bench sampler`; docs/design.md §13 holds the
//! render-level figures measured with callgrind.

use criterion::{Criterion, Throughput};
use lapidary::sampler::{PixelSampler, SamplerKind, pairs_side_by_side};
use std::hint::black_box;

/// Slots a path of two surface bounces draws: film and lens, then two blocks of six.
const SLOTS: u32 = 14;
/// Samples per pixel in one iteration.
const SAMPLES: u32 = 64;

/// The lane loop's draws, compiled like its kernel for the widest instruction set at run time.
struct SideBySide(SamplerKind);

impl pulp::WithSimd for SideBySide {
    type Output = f32;
    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) -> f32 {
        let mut acc = 0.0f32;
        let mut p: [PixelSampler; 8] =
            std::array::from_fn(|k| PixelSampler::new(self.0, 7, black_box(1234 + k as u64), 0));
        for s in 0..SAMPLES {
            for q in p.iter_mut() {
                q.restart(s);
            }
            for slot in 0..SLOTS {
                let u = pairs_side_by_side(&mut p, [slot; 8], [true; 8]);
                acc += u.iter().map(|v| v.x).sum::<f32>();
            }
        }
        black_box(acc)
    }
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("sampler");
    for kind in [SamplerKind::Sobol, SamplerKind::Independent] {
        g.throughput(Throughput::Elements(u64::from(SAMPLES * SLOTS)));
        g.bench_function(format!("{} new per sample", kind.name()), |b| {
            b.iter(|| {
                let mut acc = 0.0f32;
                for s in 0..SAMPLES {
                    let mut p = PixelSampler::new(kind, 7, black_box(1234), s);
                    for _ in 0..SLOTS {
                        acc += p.get2d().x;
                    }
                }
                black_box(acc)
            })
        });
        g.bench_function(format!("{} restarted per sample", kind.name()), |b| {
            b.iter(|| {
                let mut acc = 0.0f32;
                let mut p = PixelSampler::new(kind, 7, black_box(1234), 0);
                for s in 0..SAMPLES {
                    p.restart(s);
                    for _ in 0..SLOTS {
                        acc += p.get2d().x;
                    }
                }
                black_box(acc)
            })
        });
        g.throughput(Throughput::Elements(u64::from(8 * SAMPLES * SLOTS)));
        g.bench_function(format!("{} 8 pixels side by side", kind.name()), |b| {
            b.iter(|| pulp::Arch::new().dispatch(SideBySide(kind)))
        });
    }
    g.finish();
}

criterion::criterion_group!(benches, bench);
criterion::criterion_main!(benches);
