//! Metal platelets suspended in a translucent body (issue 18): aventurescence in depth.
//!
//! A [`Population`] is a 3-D jittered point process on a cubic grid of cells (object space): the
//! platelets of a cell are a pure function of `(seed, cell)` — a Poisson number of discs, each with a
//! centre uniform in the cell, radius, normal and material entry drawn from a stream keyed by the
//! cell — generated when a ray visits the cell and never stored for the whole stone ([`grid`]).
//! Cells are at least `2.2 r_max` wide, so a disc reaches at most into the 26 neighbours of its
//! cell. A ray walks the cells in order (a 3-D DDA, Amanatides & Woo, "A Fast Voxel Traversal
//! Algorithm for Ray Tracing", Eurographics 1987); at each cell it tests the discs of that cell and
//! of the neighbours its segment comes within `r_max` of (each cell generated once per walk), and
//! stops at the first cell whose exit lies beyond the nearest hit found. Discs are two-sided and
//! hit exactly (ray–plane, then the radius); the boundary clips them, since only the segment
//! inside the body is walked.
//! (An earlier version kept each disc inside its own cell instead: that leaves slabs near the
//! cell faces with fewer platelets, visible as stripes.)
//!
//! Orientation: uniform over the sphere (goldstone's randomly oriented copper crystals), or
//! aligned — the normal uniform in a cone of half-angle `spread` about an axis (Oregon sunstone's
//! platelets parallel to one crystal plane). A platelet's face is a layered material evaluated
//! relative to the host (the stack's `outside_ior` is the body's IOR: metal under glass reflects
//! with `(n + ik)/n_host`).
//!
//! Density: uniform, or modulated by a field over object space ([`modulation`]): the platelets are
//! generated at the full density and thinned, each kept with probability `m(centre)`.

mod block;
mod discs;
pub mod grid;
pub mod modulation;
pub mod statistical;
pub mod table;

pub use modulation::Modulation;
pub use table::Prepared;

use crate::sampler::{Rng, hash_words};
use glam::Vec3;

/// Most platelets one cell may hold (the recipe compiler keeps the mean well below it).
pub const MAX_PER_CELL: u32 = 64;
/// Largest mean number of platelets per cell a population may ask for.
pub const MAX_MEAN_PER_CELL: f32 = 16.0;
/// Mean platelets per cell the grid aims at when the platelets are small.
const TARGET_PER_CELL: f32 = 2.0;

/// How platelet normals are distributed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Orientation {
    /// Uniform over the sphere.
    Uniform,
    /// Uniform in the cone of half-angle `spread` (radians, 0 ..= π/2) about the unit `axis`.
    Aligned {
        /// The common normal (object space, unit).
        axis: Vec3,
        /// Half-angle of the cone, radians.
        spread: f32,
    },
}

/// One population of platelets, in object space.
#[derive(Clone, Debug, PartialEq)]
pub struct Population {
    /// Mean number of platelets per unit volume (object units⁻³).
    pub density: f32,
    /// Smallest and largest radius (object units); radii are uniform between them.
    pub radius: (f32, f32),
    /// Normal distribution.
    pub orientation: Orientation,
    /// Cumulative entry weights (last = 1) and the material index of each entry.
    pub entries: Vec<(f32, u32)>,
    /// Seed of the point process.
    pub seed: u64,
    /// Cell edge (object units).
    pub cell: f32,
    /// Mean platelets per cell before thinning, `density · cell³`.
    pub mean_per_cell: f32,
    /// The density's modulation, a factor in `[0, 1]` at each point; `None`: uniform density
    /// (the generation is then exactly that of an unmodulated population).
    pub modulation: Option<Modulation>,
    /// The platelets of the stone's cells drawn once for the grid walk ([`Population::prepare`],
    /// [`table`]): a cache, ignored by equality and by a copy whose seed, cell or radii differ.
    pub table: Prepared,
}

/// One platelet: a disc.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Platelet {
    /// Centre, object space.
    pub center: Vec3,
    /// Unit normal (either side is a face).
    pub normal: Vec3,
    /// Radius, object units.
    pub radius: f32,
    /// Material index of its faces.
    pub material: u32,
}

/// Which platelet: its population, cell and index within the cell (to skip the platelet a ray
/// leaves from). Ordered by population, then cell, then index: of two hits at the same distance
/// the walk keeps the smaller id.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct PlateletId {
    /// Population index.
    pub population: u32,
    /// Cell coordinates.
    pub cell: [i32; 3],
    /// Index within the cell.
    pub index: u32,
}

/// A ray's hit on a platelet (object space).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlateletHit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// Unit normal of the disc (not oriented toward the ray).
    pub normal: Vec3,
    /// Material index of the face.
    pub material: u32,
    /// Which platelet.
    pub id: PlateletId,
}

impl Population {
    /// A population with its grid chosen: cells at least `2.2 r_max` wide (a disc reaches no
    /// further than the next cell) and about [`TARGET_PER_CELL`] platelets per cell where the platelets are small.
    /// `None` if the result would put more than [`MAX_MEAN_PER_CELL`] platelets in a cell on
    /// average (the platelets would overlap heavily; the recipe compiler reports it).
    pub fn new(
        density: f32,
        radius: (f32, f32),
        orientation: Orientation,
        entries: Vec<(f32, u32)>,
        seed: u64,
    ) -> Option<Population> {
        let cell = (2.2 * radius.1).max((TARGET_PER_CELL / density).cbrt());
        let mean_per_cell = density * cell * cell * cell;
        (mean_per_cell <= MAX_MEAN_PER_CELL && cell.is_finite() && cell > 0.0).then_some(
            Population {
                density,
                radius,
                orientation,
                entries,
                seed,
                cell,
                mean_per_cell,
                modulation: None,
                table: Prepared::default(),
            },
        )
    }

    /// The same population with its density multiplied by `modulation` (clamped to `[0, 1]`) at
    /// each platelet's centre; the grid and every platelet's attributes stay those of `self`.
    pub fn with_modulation(self, modulation: Option<Modulation>) -> Population {
        Population { modulation, ..self }
    }

    /// Draws the platelets of every cell the walks inside the object-space box `[lo, hi]` (the
    /// stone's bounds) can visit, once, for the grid walk to read ([`table`]); none if the box
    /// needs more than [`table::MAX_CELLS`] cells or [`table::MAX_DISCS`] discs. No result
    /// changes: the walk reads the numbers it would otherwise draw.
    pub fn prepare(&mut self, lo: Vec3, hi: Vec3) {
        table::prepare(self, lo, hi);
    }

    /// The platelets of cell `c` that survive thinning, in a fixed order (a pure function of the
    /// seed and the cell).
    pub fn cell_platelets(&self, c: [i32; 3], out: &mut Vec<Platelet>) {
        out.clear();
        self.each_in_cell(c, |_, p| {
            out.push(p);
            false
        });
    }

    /// Calls `f(index, platelet)` for the platelets of cell `c` that survive thinning
    /// ([`Population::kept`]), in order, generating them one by one (no allocation); stops early
    /// when `f` returns true. A dropped platelet's index is not reused.
    #[inline]
    pub fn each_in_cell(&self, c: [i32; 3], mut f: impl FnMut(u32, Platelet) -> bool) {
        self.each_drawn(c, |index, p| self.kept(c, index, &p) && f(index, p));
    }

    /// Whether platelet `index` of cell `c` (as [`Population::each_drawn`] gives it) survives
    /// thinning: always without a modulation, else iff its own uniform number
    /// ([`modulation::thinning_uniform`]) is below the modulation at its centre.
    #[inline]
    pub fn kept(&self, c: [i32; 3], index: u32, p: &Platelet) -> bool {
        match &self.modulation {
            None => true,
            Some(m) => modulation::survives(m.at(p.center), || {
                modulation::thinning_uniform(self.seed, c, index)
            }),
        }
    }

    /// Calls `f(index, platelet)` for every platelet drawn in cell `c` before thinning, in order
    /// (the walk tests a disc first and asks [`Population::kept`] only of the discs it hits);
    /// stops early when `f` returns true.
    #[inline]
    pub fn each_drawn(&self, c: [i32; 3], mut f: impl FnMut(u32, Platelet) -> bool) {
        let mut stream = self.stream(c);
        while let Some((index, center, radius)) = stream.next_disc() {
            let Some((normal, material)) = stream.finish() else {
                return;
            };
            let p = Platelet {
                center,
                normal,
                radius,
                material,
            };
            if f(index, p) {
                return;
            }
        }
    }

    /// The platelets of cell `c` drawn lazily: each disc's centre and radius first, its normal and
    /// material only when asked for (the grid walk skips the normal of a disc whose bounding
    /// sphere misses the ray). The same numbers as [`Population::each_in_cell`].
    #[inline]
    pub fn stream(&self, c: [i32; 3]) -> CellStream<'_> {
        let key = hash_words(&[
            self.seed,
            c[0] as u32 as u64,
            c[1] as u32 as u64,
            c[2] as u32 as u64,
        ]);
        let mut rng = Rng::new(key);
        let count = poisson(self.mean_per_cell, rng.uniform());
        CellStream {
            pop: self,
            rng,
            origin: Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32) * self.cell,
            count,
            next: 0,
            pending: false,
        }
    }
}

impl Population {
    /// A platelet's unit normal and material index, drawn from its cell's stream positioned after
    /// its centre ([`CellStream::finish`]).
    #[inline]
    pub fn finish_disc(&self, rng: &mut Rng) -> (Vec3, u32) {
        let normal = self.orientation.sample(rng.uniform(), rng.uniform());
        let material = pick_entry(&self.entries, rng.uniform());
        (normal, material)
    }
}

/// Numbers a platelet draws after its radius and centre: two for the normal, one for the entry.
const DRAWS_AFTER_CENTRE: u64 = 3;

/// A platelet's radius, drawn from its cell's stream only when asked for.
#[derive(Clone, Debug)]
pub struct LazyRadius {
    /// The stream positioned at the radius's number.
    rng: Rng,
    /// The population's smallest and largest radius.
    range: (f32, f32),
}

impl LazyRadius {
    /// The radius, object units.
    #[inline]
    pub fn draw(mut self) -> f32 {
        let (r0, r1) = self.range;
        r0 + (r1 - r0) * self.rng.uniform()
    }
}

/// One cell's platelets, drawn in order from the cell's stream ([`Population::stream`]).
#[derive(Clone, Debug)]
pub struct CellStream<'a> {
    pop: &'a Population,
    rng: Rng,
    /// The cell's lowest corner (object space).
    origin: Vec3,
    /// Platelets in the cell.
    count: u32,
    /// Index of the next platelet.
    next: u32,
    /// Whether the last platelet's normal and entry are still to be drawn.
    pending: bool,
}

impl CellStream<'_> {
    /// The next platelet's index, centre (object space) and radius (object units); `None` after
    /// the last. Its normal and material follow from [`CellStream::finish`], or are skipped.
    #[inline]
    pub fn next_disc(&mut self) -> Option<(u32, Vec3, f32)> {
        self.next_centre()
            .map(|(index, center, radius)| (index, center, radius.draw()))
    }

    /// [`CellStream::next_disc`] with the radius left undrawn until asked for (the grid walk's
    /// first bounding-sphere test takes the largest radius): the same numbers.
    #[inline]
    pub fn next_centre(&mut self) -> Option<(u32, Vec3, LazyRadius)> {
        if std::mem::take(&mut self.pending) {
            self.rng.skip(DRAWS_AFTER_CENTRE);
        }
        if self.next >= self.count {
            return None;
        }
        // The stream is counter-based: the radius is the next number, the centre the three after.
        let radius = LazyRadius {
            rng: self.rng.clone(),
            range: self.pop.radius,
        };
        self.rng.skip(1);
        let (x, y, z) = (self.rng.uniform(), self.rng.uniform(), self.rng.uniform());
        let center = self.origin + Vec3::new(x, y, z) * self.pop.cell;
        let index = self.next;
        self.next += 1;
        self.pending = true;
        Some((index, center, radius))
    }

    /// The unit normal and material index of the platelet [`CellStream::next_disc`] just gave;
    /// `None` if there is none or they were already drawn.
    #[inline]
    pub fn finish(&mut self) -> Option<(Vec3, u32)> {
        if !std::mem::take(&mut self.pending) {
            return None;
        }
        Some(self.pop.finish_disc(&mut self.rng))
    }

    /// The stream positioned at the normal of the platelet [`CellStream::next_disc`] just gave
    /// (what [`CellStream::finish`] draws from, for [`Population::finish_disc`]).
    #[inline]
    pub fn rest(&self) -> Rng {
        self.rng.clone()
    }
}

impl Orientation {
    /// A normal from two uniform numbers.
    pub fn sample(&self, u1: f32, u2: f32) -> Vec3 {
        let (cos_max, frame) = match *self {
            Orientation::Uniform => (-1.0, None),
            Orientation::Aligned { axis, spread } => (spread.cos(), Some(axis)),
        };
        let z = 1.0 - u1 * (1.0 - cos_max);
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = std::f32::consts::TAU * u2;
        let local = Vec3::new(r * phi.cos(), r * phi.sin(), z);
        match frame {
            None => local,
            Some(axis) => crate::geometry::Frame::from_normal(axis)
                .to_world(local)
                .normalize(),
        }
    }
}

/// The material of the entry `u ∈ [0, 1)` falls in, from cumulative weights (last = 1).
#[inline]
pub fn pick_entry(entries: &[(f32, u32)], u: f32) -> u32 {
    entries
        .iter()
        .find(|(w, _)| u < *w)
        .or(entries.last())
        .map_or(0, |e| e.1)
}

/// A Poisson-distributed count with mean `lambda` by inversion of the CDF at `u`, capped at
/// [`MAX_PER_CELL`].
pub fn poisson(lambda: f32, u: f32) -> u32 {
    let lambda = f64::from(lambda);
    let mut p = (-lambda).exp();
    let mut cdf = p;
    let mut k = 0u32;
    while f64::from(u) >= cdf && k < MAX_PER_CELL {
        k += 1;
        p *= lambda / f64::from(k);
        cdf += p;
    }
    k
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn poisson_mean_and_variance() {
        let n = 100_000;
        for lambda in [0.3f32, 2.0, 9.0] {
            let (mut s, mut s2) = (0.0f64, 0.0f64);
            for i in 0..n {
                let k = f64::from(poisson(lambda, (i as f32 + 0.5) / n as f32));
                s += k;
                s2 += k * k;
            }
            let m = s / n as f64;
            let v = s2 / n as f64 - m * m;
            assert!((m - f64::from(lambda)).abs() < 0.01, "λ {lambda}: mean {m}");
            assert!((v - f64::from(lambda)).abs() < 0.05, "λ {lambda}: var {v}");
        }
    }

    #[test]
    fn centres_lie_in_their_cell_and_are_reproducible() {
        let pop = Population::new(
            50.0,
            (0.01, 0.05),
            Orientation::Uniform,
            vec![(0.5, 3), (1.0, 4)],
            7,
        )
        .unwrap();
        let mut a = vec![];
        let mut b = vec![];
        for c in [[0, 0, 0], [-3, 5, 2], [100, -100, 7]] {
            pop.cell_platelets(c, &mut a);
            pop.cell_platelets(c, &mut b);
            assert_eq!(a, b);
            let lo = Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32) * pop.cell;
            for p in &a {
                assert!((p.center - lo).min_element() >= -1e-5);
                assert!((lo + pop.cell - p.center).min_element() >= -1e-5);
                assert!(p.radius >= 0.01 && p.radius <= 0.05);
                assert!((p.normal.length() - 1.0).abs() < 1e-4);
                assert!(p.material == 3 || p.material == 4);
            }
        }
    }

    #[test]
    fn aligned_normals_stay_in_the_cone() {
        let axis = Vec3::new(0.0, 1.0, 1.0).normalize();
        let o = Orientation::Aligned {
            axis,
            spread: 10f32.to_radians(),
        };
        for i in 0..1000 {
            let n = o.sample((i as f32 + 0.5) / 1000.0, (i as f32 * 0.618).fract());
            assert!(n.dot(axis) >= 10f32.to_radians().cos() - 1e-5);
        }
    }
}
