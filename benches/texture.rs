//! Texture cost: nanoseconds per lookup of the Voronoi basis (F1 + id, and F1 + F2 + edge), of our
//! hashed-lattice Perlin noise and its fBm next to the `noise` crate's permutation-table `Perlin`
//! and `Fbm` (`src/texture/perlin.rs` says why we do not use them), of a marble field, and of whole
//! map trees: a glitter map over a surface map, and the Lavender Lepidolite recipe
//! (`gems/lepidolite.ron`: a marble switch between nested Voronoi maps, under glitter with a facet
//! bump). `docs/cost.md` holds the measured tables.
//!
//! Every timed iteration runs one lookup per point of a fixed batch of `BATCH` pseudo-random points
//! uniform in the box `[−4, 4]³` (the same points for every benchmark, in random order), so the
//! per-lookup time is the iteration time / `BATCH` (criterion's throughput line reports it as
//! elements per second). Positions are in the units each function takes: cell units for the bare
//! Voronoi basis, lattice units for the noise, object units for fields and maps (whose scales then
//! set how many cells the box spans).
//!
//! Times are the benchmark thread's CPU time on 64-bit Linux (`CLOCK_THREAD_CPUTIME_ID`, as in
//! `benches/bsdf.rs`), so builds and tests running at the same time on a small machine do not
//! inflate them; elsewhere, and on a quiet machine, they are wall time.
//!
//! Run with `cargo bench --bench texture` (about half a minute); a filter narrows it, e.g.
//! `cargo bench --bench texture -- perlin`. No number here is asserted anywhere.

use criterion::{BenchmarkGroup, Criterion, Throughput};
use glam::Vec3;
use lapidary::recipe::GemRecipe;
use lapidary::sampler::Rng;
use lapidary::texture::{
    Entry, FacetBump, FieldNode, FieldTable, Map, MapNode, NodeId, Octaves, Tilt, Voronoi,
    VoronoiNode, perlin,
};
use noise::{MultiFractal, NoiseFn};
use std::hint::black_box;
use std::time::Duration;

/// Clocks shared with `benches/bsdf.rs` (the benchmark thread's CPU time on 64-bit Linux).
#[path = "common/clock.rs"]
mod clock;

use clock::Clock;

/// Lookups per timed iteration.
const BATCH: usize = 1024;

/// Half the side of the box the points fill.
const HALF_SIDE: f32 = 4.0;

/// `BATCH` points uniform in `[−HALF_SIDE, HALF_SIDE]³`.
fn points() -> Vec<Vec3> {
    let mut rng = Rng::new(0x7e_0001);
    (0..BATCH)
        .map(|_| (Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - 1.0) * HALF_SIDE)
        .collect()
}

/// One random number in `[0, 1)` per point, for the stochastic switch bands of map lookups.
fn switch_numbers() -> Vec<f32> {
    let mut rng = Rng::new(0x7e_0002);
    (0..BATCH).map(|_| rng.uniform()).collect()
}

/// Times `f` over the whole batch, one call per point.
fn bench_each<T, R>(g: &mut BenchmarkGroup<'_, Clock>, id: &str, xs: &[T], f: impl Fn(T) -> R)
where
    T: Copy,
{
    g.bench_function(id, |bn| {
        bn.iter(|| {
            for &x in xs {
                black_box(f(black_box(x)));
            }
        })
    });
}

/// A group whose every benchmark processes one batch per iteration.
fn group<'a>(c: &'a mut Criterion<Clock>, name: &str) -> BenchmarkGroup<'a, Clock> {
    let mut g = c.benchmark_group(name);
    g.throughput(Throughput::Elements(BATCH as u64));
    g
}

/// The Voronoi basis at full and half jitter: the nearest point only (what maps use to pick a
/// cell) and the full lookup (F2 and the exact edge distance as well).
fn voronoi(c: &mut Criterion<Clock>) {
    let xs = points();
    let mut g = group(c, "voronoi");
    for jitter in [1.0f32, 0.5] {
        let v = Voronoi::new(0x5eed, jitter);
        let v = &v;
        bench_each(&mut g, &format!("nearest/jitter_{jitter:.1}"), &xs, |p| {
            black_box(v).nearest(p)
        });
        bench_each(&mut g, &format!("full/jitter_{jitter:.1}"), &xs, |p| {
            black_box(v).sample(p)
        });
    }
    g.finish();
}

/// The classic fBm parameters: 6 octaves, gain ½, lacunarity 2.
const FBM: Octaves = Octaves {
    octaves: 6,
    gain: 0.5,
    lacunarity: 2.0,
    seed: 17,
};

/// Our Perlin noise and fBm against the `noise` crate's at the same points and parameters (each
/// given the points in its own input type, converted outside the timing: `f32` for ours, `f64` for
/// `noise`). `noise::Fbm` defaults to lacunarity 2π/3; it is set to 2 here to match.
///
/// Thread safety (checked by hand against `noise` 0.9.0, not asserted here): `noise::Perlin` (a seed
/// and a 256-byte permutation table, `Copy`, 260 bytes) and `noise::Fbm<Perlin>` (parameters and a
/// `Vec<Perlin>` of per-octave sources) are `Send + Sync`, so either could be shared by render
/// threads; it is `noise::Worley` (an `Rc<dyn Fn>` distance function) that is neither `Send` nor
/// `Sync`, and `noise::Cache` (`Cell`, `RefCell`) that is not `Sync`.
fn noise_functions(c: &mut Criterion<Clock>) {
    let xs = points();
    let xs64: Vec<[f64; 3]> = xs.iter().map(|p| p.as_dvec3().to_array()).collect();
    let theirs = noise::Perlin::new(FBM.seed);
    let their_fbm = noise::Fbm::<noise::Perlin>::new(FBM.seed)
        .set_octaves(FBM.octaves as usize)
        .set_frequency(1.0)
        .set_lacunarity(f64::from(FBM.lacunarity))
        .set_persistence(f64::from(FBM.gain));
    let (theirs, their_fbm) = (&theirs, &their_fbm);

    let mut g = group(c, "perlin");
    bench_each(&mut g, "ours", &xs, |p| perlin(p, black_box(FBM.seed)));
    bench_each(&mut g, "noise_crate", &xs64, |p| black_box(theirs).get(p));
    g.finish();

    let mut g = group(c, "fbm");
    bench_each(&mut g, "ours", &xs, |p| black_box(&FBM).fbm(p));
    bench_each(&mut g, "noise_crate", &xs64, |p| {
        black_box(their_fbm).get(p)
    });
    g.finish();
}

/// A marble field as a switch reads it: veins 1.25 per object unit across a slanted axis, bent by
/// 5-octave turbulence of amplitude 1.5 periods.
fn marble(table: &mut FieldTable, seed: u32) -> u32 {
    table
        .add(FieldNode::Marble {
            inv_scale: 1.25,
            axis: Vec3::new(1.0, 0.4, 0.2).normalize(),
            turbulence: 1.5,
            octaves: Octaves {
                octaves: 5,
                gain: 0.5,
                lacunarity: 2.0,
                seed,
            },
        })
        .expect("a marble field has no inputs")
}

fn field(c: &mut Criterion<Clock>) {
    let xs = points();
    let mut table = FieldTable::default();
    let id = marble(&mut table, 3);
    let table = &table;
    let mut g = group(c, "field");
    bench_each(&mut g, "marble", &xs, |p| black_box(table).eval(id, p));
    g.finish();
}

/// Builds map trees node by node (children before parents), with equal-weight entries.
#[derive(Default)]
struct Tree {
    nodes: Vec<MapNode>,
    entries: Vec<Entry>,
    /// Next material index.
    materials: u32,
}

impl Tree {
    fn push(&mut self, node: MapNode) -> NodeId {
        self.nodes.push(node);
        (self.nodes.len() - 1) as NodeId
    }

    /// `n` new materials.
    fn materials(&mut self, n: u32) -> Vec<NodeId> {
        let first = self.materials;
        self.materials += n;
        (first..first + n)
            .map(|m| self.push(MapNode::Material(m)))
            .collect()
    }

    /// A Voronoi map with cells of mean spacing `scale` (object units), whose filled cells pick
    /// one of `children` with equal weights.
    fn voronoi(
        &mut self,
        seed: u64,
        scale: f32,
        fill: f32,
        bump: Option<FacetBump>,
        children: &[NodeId],
    ) -> NodeId {
        let first = self.entries.len() as u32;
        let n = children.len();
        self.entries
            .extend(children.iter().enumerate().map(|(k, &node)| Entry {
                cumulative: if k + 1 == n {
                    1.0
                } else {
                    (k + 1) as f32 / n as f32
                },
                node,
            }));
        self.push(MapNode::Voronoi(VoronoiNode {
            basis: Voronoi::new(seed, 1.0),
            inv_scale: 1.0 / scale,
            first,
            count: n as u32,
            fill,
            bump,
        }))
    }

    /// A sparse glitter map (5 % of cells of spacing 0.05, four glitter materials, facets tilted
    /// uniformly within 15°) over `under`.
    fn glitter_over(&mut self, under: NodeId) -> NodeId {
        let glitter = self.materials(4);
        let bump = FacetBump {
            tilt: Tilt::Cone { half_angle: 15.0 },
        };
        let over = self.voronoi(0x91, 0.05, 0.05, Some(bump), &glitter);
        self.push(MapNode::Overlay { under, over })
    }

    fn build(self, root: NodeId) -> Map {
        Map::new(
            self.nodes,
            self.entries,
            vec![],
            FieldTable::default(),
            root,
        )
        .expect("a valid tree")
    }
}

/// A glitter map over a dense surface map of 9 materials (cells of spacing 0.25).
fn two_level() -> Map {
    let mut t = Tree::default();
    let tiles = t.materials(9);
    let surface = t.voronoi(0x11, 0.25, 1.0, None, &tiles);
    let root = t.glitter_over(surface);
    t.build(root)
}

/// The map tree of the Lavender Lepidolite recipe, compiled from `gems/lepidolite.ron`.
fn lepidolite() -> Map {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/gems/lepidolite.ron");
    let recipe = GemRecipe::load(path.as_ref()).unwrap_or_else(|e| panic!("{e}"));
    recipe
        .compile()
        .unwrap_or_else(|e| panic!("{e}"))
        .surface
        .map
}

/// Whole map lookups (material, facet normal, cell trail).
fn map(c: &mut Criterion<Clock>) {
    let xs: Vec<(Vec3, f32)> = points().into_iter().zip(switch_numbers()).collect();
    let mut g = group(c, "map");
    for (id, map) in [("two_level", two_level()), ("lepidolite", lepidolite())] {
        let map = &map;
        bench_each(&mut g, id, &xs, |(p, u)| black_box(map).lookup(p, u));
    }
    g.finish();
}

/// Short runs: the whole file takes about half a minute.
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
    targets = voronoi, noise_functions, field, map
}
criterion::criterion_main!(benches);
