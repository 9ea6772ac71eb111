//! Scalar fields over object space: the functions a `Switch` compares with its thresholds.
//!
//! A [`FieldTable`] is a flat array of [`FieldNode`]s; composite nodes name their inputs by index
//! into the same table, so evaluating a field walks indices and never allocates.
//!
//! | node | value | range |
//! |---|---|---|
//! | `Constant(c)` | `c` | — |
//! | `Fbm` | fBm of [`perlin`](super::perlin::perlin) at `p / scale` | ≈ −1 … 1 |
//! | `Turbulence` | `Σ gainᵏ·|noise|` (Perlin 1985) | 0 … 1 |
//! | `Marble` | `½ + ½ sin(2π (a·p/scale + turbulence · turb(p/scale)))` (Perlin 1985's marble) | 0 … 1 |
//! | `Sum`, `Product` | of the inputs | — |
//! | `Remap` | `to.0 + (v − from.0)/(from.1 − from.0)·(to.1 − to.0)`, optionally clamped | — |
//!
//! `scale` is a length in object units: the lattice spacing of the first octave (Perlin) or the
//! stripe spacing (Marble).

use super::perlin::Octaves;
use glam::Vec3;
use std::f32::consts::TAU;

/// Index of a field in its [`FieldTable`].
pub type FieldId = u32;

/// One field node (see the module table).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FieldNode {
    /// A constant.
    Constant(f32),
    /// Fractional Brownian motion of Perlin noise.
    Fbm {
        /// `1 / scale` (object units⁻¹).
        inv_scale: f32,
        /// Octave parameters.
        octaves: Octaves,
    },
    /// Turbulence: the fBm of `|noise|`.
    Turbulence {
        /// `1 / scale` (object units⁻¹).
        inv_scale: f32,
        /// Octave parameters.
        octaves: Octaves,
    },
    /// Marble veins: a sine of an axis coordinate perturbed by turbulence.
    Marble {
        /// `1 / scale`: veins per object unit along `axis`.
        inv_scale: f32,
        /// Unit vector across the veins.
        axis: Vec3,
        /// Amplitude of the turbulence, in vein periods.
        turbulence: f32,
        /// Octave parameters of the turbulence.
        octaves: Octaves,
    },
    /// Sum of `count` inputs listed from `first` in the table's argument list.
    Sum {
        /// First argument slot.
        first: u32,
        /// Number of inputs.
        count: u32,
    },
    /// Product of `count` inputs listed from `first`.
    Product {
        /// First argument slot.
        first: u32,
        /// Number of inputs.
        count: u32,
    },
    /// Linear remap of one input from `from` to `to`.
    Remap {
        /// The input field.
        input: FieldId,
        /// Source interval (distinct ends).
        from: [f32; 2],
        /// Target interval.
        to: [f32; 2],
        /// Clamp the result to the target interval.
        clamp: bool,
    },
}

/// A flat table of fields.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FieldTable {
    nodes: Vec<FieldNode>,
    args: Vec<FieldId>,
}

impl FieldTable {
    /// Appends a node and returns its id. Inputs of composite nodes must already be in the table
    /// (children before parents), which makes cycles impossible; [`FieldTable::add`] checks it.
    pub fn add(&mut self, node: FieldNode) -> Result<FieldId, String> {
        let id = self.nodes.len() as FieldId;
        let ok = |f: FieldId| f < id;
        let valid = match node {
            FieldNode::Sum { first, count } | FieldNode::Product { first, count } => self
                .args
                .get(first as usize..(first + count) as usize)
                .is_some_and(|a| a.iter().all(|&f| ok(f))),
            FieldNode::Remap { input, from, .. } => ok(input) && from[0] != from[1],
            _ => true,
        };
        if !valid {
            return Err(format!("field {id}: inputs must be earlier fields"));
        }
        self.nodes.push(node);
        Ok(id)
    }

    /// Stores an argument list for `Sum`/`Product` and returns `(first, count)`.
    pub fn add_args(&mut self, ids: &[FieldId]) -> (u32, u32) {
        let first = self.args.len() as u32;
        self.args.extend_from_slice(ids);
        (first, ids.len() as u32)
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether the table is empty.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The nodes, in insertion order.
    pub fn nodes(&self) -> &[FieldNode] {
        &self.nodes
    }

    /// Value of field `id` at object-space point `p`; always finite. A node whose value overflows
    /// saturates (+∞ reads `f32::MAX`, −∞ reads `−f32::MAX`), so a switch on a huge field still
    /// takes its last stop; one whose value is undefined (NaN, e.g. marble at |p| ≈ 1e38 or
    /// ∞ − ∞ in a sum) reads 0.
    pub fn eval(&self, id: FieldId, p: Vec3) -> f32 {
        finite_value(self.eval_raw(id, p))
    }

    /// [`FieldTable::eval`] of field `id` at `N` points side by side: the noise fields (fBm,
    /// turbulence, marble) through their side-by-side octaves, which the lane loop's kernel
    /// compiles into vector instructions; the composites point by point. The same bits as `N`
    /// calls (tested).
    #[inline(always)]
    pub fn eval_side_by_side<const N: usize>(&self, id: FieldId, p: &[Vec3; N]) -> [f32; N] {
        let scaled = |inv_scale: f32| {
            let mut q = [Vec3::ZERO; N];
            for k in 0..N {
                q[k] = p[k] * inv_scale;
            }
            q
        };
        let mut v = [0.0f32; N];
        match self.nodes[id as usize] {
            FieldNode::Fbm { inv_scale, octaves } => {
                v = octaves.fbm_side_by_side(&scaled(inv_scale))
            }
            FieldNode::Turbulence { inv_scale, octaves } => {
                v = octaves.turbulence_side_by_side(&scaled(inv_scale));
            }
            FieldNode::Marble {
                inv_scale,
                axis,
                turbulence,
                octaves,
            } => {
                let q = scaled(inv_scale);
                let t = octaves.turbulence_side_by_side(&q);
                for k in 0..N {
                    v[k] = marble(axis.dot(q[k]) + turbulence * t[k]);
                }
            }
            _ => {
                for k in 0..N {
                    v[k] = self.eval_raw(id, p[k]);
                }
            }
        }
        v.map(finite_value)
    }

    /// A conservative interval `(lo, hi)` holding every value [`FieldTable::eval`] can return for
    /// field `id` (field units): Perlin noise is bounded by 2 (each corner term `|u| + |v|` of
    /// offsets within a cell, so fBm lies in `[−2, 2]` and turbulence in `[0, 2]`, though both
    /// stay near `[−1, 1]` in practice), marble in `[0, 1]`, composites by interval arithmetic. An
    /// interval that overflows is `(−∞, ∞)`; an unknown `id` too.
    pub fn bounds(&self, id: FieldId) -> (f32, f32) {
        const ALL: (f32, f32) = (f32::NEG_INFINITY, f32::INFINITY);
        let Some(node) = self.nodes.get(id as usize) else {
            return ALL;
        };
        let args = |first: u32, count: u32| {
            self.args
                .get(first as usize..(first + count) as usize)
                .unwrap_or(&[])
                .iter()
                .map(|&f| self.bounds(f))
        };
        let (lo, hi) = match *node {
            FieldNode::Constant(c) => (c, c),
            FieldNode::Fbm { .. } => (-2.0, 2.0),
            FieldNode::Turbulence { .. } => (0.0, 2.0),
            FieldNode::Marble { .. } => (0.0, 1.0),
            FieldNode::Sum { first, count } => {
                args(first, count).fold((0.0, 0.0), |(a, b), (c, d)| (a + c, b + d))
            }
            FieldNode::Product { first, count } => {
                args(first, count).fold((1.0f32, 1.0f32), |(a, b), (c, d)| {
                    if !(a.is_finite() && b.is_finite() && c.is_finite() && d.is_finite()) {
                        return ALL;
                    }
                    let p = [a * c, a * d, b * c, b * d];
                    (
                        p.into_iter().fold(f32::INFINITY, f32::min),
                        p.into_iter().fold(f32::NEG_INFINITY, f32::max),
                    )
                })
            }
            FieldNode::Remap {
                input,
                from,
                to,
                clamp,
            } => {
                let (a, b) = self.bounds(input);
                let map = |v: f32| {
                    let t = (v - from[0]) / (from[1] - from[0]);
                    let t = if clamp { t.clamp(0.0, 1.0) } else { t };
                    to[0] + t * (to[1] - to[0])
                };
                let (x, y) = (map(a), map(b));
                (x.min(y), x.max(y))
            }
        };
        if lo.is_finite() && hi.is_finite() && lo <= hi {
            (lo, hi)
        } else {
            ALL
        }
    }

    fn eval_raw(&self, id: FieldId, p: Vec3) -> f32 {
        match self.nodes[id as usize] {
            FieldNode::Constant(c) => c,
            FieldNode::Fbm { inv_scale, octaves } => octaves.fbm(p * inv_scale),
            FieldNode::Turbulence { inv_scale, octaves } => octaves.turbulence(p * inv_scale),
            FieldNode::Marble {
                inv_scale,
                axis,
                turbulence,
                octaves,
            } => {
                let q = p * inv_scale;
                marble(axis.dot(q) + turbulence * octaves.turbulence(q))
            }
            FieldNode::Sum { first, count } => self.args[first as usize..(first + count) as usize]
                .iter()
                .map(|&f| self.eval(f, p))
                .sum(),
            FieldNode::Product { first, count } => self.args
                [first as usize..(first + count) as usize]
                .iter()
                .map(|&f| self.eval(f, p))
                .product(),
            FieldNode::Remap {
                input,
                from,
                to,
                clamp,
            } => {
                let t = (self.eval(input, p) - from[0]) / (from[1] - from[0]);
                let t = if clamp { t.clamp(0.0, 1.0) } else { t };
                to[0] + t * (to[1] - to[0])
            }
        }
    }
}

/// A node's value as [`FieldTable::eval`] returns it: overflow saturates, undefined reads 0.
#[inline(always)]
fn finite_value(v: f32) -> f32 {
    if v.is_nan() {
        0.0
    } else {
        v.clamp(-f32::MAX, f32::MAX)
    }
}

/// Marble's veins for the perturbed phase `phase` (vein periods).
#[inline(always)]
fn marble(phase: f32) -> f32 {
    // Reduce the phase first so large coordinates keep the sine accurate.
    0.5 + 0.5 * (TAU * (phase - phase.floor())).sin()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::Rng;

    fn octaves(seed: u32) -> Octaves {
        Octaves {
            octaves: 4,
            gain: 0.5,
            lacunarity: 2.0,
            seed,
        }
    }

    #[test]
    fn side_by_side_is_one_by_one() {
        // Every node kind, a marble, and a sum that overflows (read as f32::MAX).
        let (mut t, ids) = every_kind();
        let marble = t
            .add(FieldNode::Marble {
                inv_scale: 0.4,
                axis: Vec3::new(1.0, 0.35, 0.2),
                turbulence: 0.6,
                octaves: octaves(3),
            })
            .unwrap();
        let big = t.add(FieldNode::Constant(1e38)).unwrap();
        let (first, count) = t.add_args(&[marble, big, big, big, big]);
        let over = t.add(FieldNode::Sum { first, count }).unwrap();
        let mut rng = Rng::new(4);
        let mut point = || Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 50.0 - 25.0;
        for round in 0..2000 {
            let mut p: [Vec3; 8] = std::array::from_fn(|_| point());
            if round == 0 {
                (p[0], p[1], p[2]) = (Vec3::NAN, Vec3::splat(1e30), Vec3::ZERO);
            }
            for id in ids.into_iter().chain([marble, over]) {
                let v = t.eval_side_by_side(id, &p);
                for k in 0..8 {
                    assert_eq!(
                        v[k].to_bits(),
                        t.eval(id, p[k]).to_bits(),
                        "{id} {:?}",
                        p[k]
                    );
                }
            }
        }
    }

    #[test]
    fn composites_combine_their_inputs() {
        let mut t = FieldTable::default();
        let a = t
            .add(FieldNode::Fbm {
                inv_scale: 3.0,
                octaves: octaves(1),
            })
            .unwrap();
        let b = t.add(FieldNode::Constant(0.25)).unwrap();
        let (first, count) = t.add_args(&[a, b]);
        let sum = t.add(FieldNode::Sum { first, count }).unwrap();
        let prod = t.add(FieldNode::Product { first, count }).unwrap();
        let remap = t
            .add(FieldNode::Remap {
                input: a,
                from: [-1.0, 1.0],
                to: [0.0, 1.0],
                clamp: true,
            })
            .unwrap();
        let mut rng = Rng::new(3);
        for _ in 0..1000 {
            let p = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 4.0;
            let va = t.eval(a, p);
            assert!((t.eval(sum, p) - (va + 0.25)).abs() < 1e-6);
            assert!((t.eval(prod, p) - va * 0.25).abs() < 1e-6);
            let r = t.eval(remap, p);
            assert!((0.0..=1.0).contains(&r) && (r - (va + 1.0) / 2.0).abs() < 1e-6);
        }
        // Inputs must come first: a forward reference is rejected.
        let (first, count) = t.add_args(&[99]);
        assert!(t.add(FieldNode::Sum { first, count }).is_err());
        assert!(
            t.add(FieldNode::Remap {
                input: a,
                from: [1.0, 1.0],
                to: [0.0, 1.0],
                clamp: false
            })
            .is_err()
        );
    }

    #[test]
    fn overflow_saturates_so_a_switch_takes_its_last_stop() {
        use crate::texture::map::{Stop, choose_stop};
        let mut t = FieldTable::default();
        let big = t.add(FieldNode::Constant(1e30)).unwrap();
        let (first, count) = t.add_args(&[big, big]);
        let up = t.add(FieldNode::Product { first, count }).unwrap();
        let neg = t.add(FieldNode::Constant(-1e30)).unwrap();
        let (first, count) = t.add_args(&[neg, big]);
        let down = t.add(FieldNode::Product { first, count }).unwrap();
        let (first, count) = t.add_args(&[up, down]);
        let undefined = t.add(FieldNode::Sum { first, count }).unwrap();
        assert_eq!(t.eval(up, Vec3::ZERO), f32::MAX);
        assert_eq!(t.eval(down, Vec3::ZERO), -f32::MAX);
        // MAX + (−MAX) is 0 here; a true ∞ − ∞ inside one node is NaN and reads 0 too.
        assert_eq!(t.eval(undefined, Vec3::ZERO), 0.0);
        let stops = [0.0, 0.5, 0.9].map(|threshold| Stop { threshold, node: 0 });
        let mut u = 0.5;
        assert_eq!(choose_stop(&stops, t.eval(up, Vec3::ZERO), 0.0, &mut u), 2);
        assert_eq!(
            choose_stop(&stops, t.eval(down, Vec3::ZERO), 0.0, &mut u),
            0
        );
    }

    /// A table of every node kind: fBm `a`, turbulence `b`, constant `c`, their sum and product,
    /// and a remap of the sum (in that order of ids).
    fn every_kind() -> (FieldTable, [FieldId; 6]) {
        let mut t = FieldTable::default();
        let a = t
            .add(FieldNode::Fbm {
                inv_scale: 5.0,
                octaves: octaves(3),
            })
            .unwrap();
        let b = t
            .add(FieldNode::Turbulence {
                inv_scale: 2.0,
                octaves: octaves(4),
            })
            .unwrap();
        let c = t.add(FieldNode::Constant(-0.5)).unwrap();
        let (first, count) = t.add_args(&[a, b, c]);
        let sum = t.add(FieldNode::Sum { first, count }).unwrap();
        let prod = t.add(FieldNode::Product { first, count }).unwrap();
        let remap = t
            .add(FieldNode::Remap {
                input: sum,
                from: [1.0, -1.0],
                to: [0.0, 3.0],
                clamp: false,
            })
            .unwrap();
        (t, [a, b, c, sum, prod, remap])
    }

    /// Every value lies in the interval [`FieldTable::bounds`] gives.
    #[test]
    fn bounds_hold_every_value() {
        let (mut t, [a, b, c, sum, prod, remap]) = every_kind();
        assert_eq!(t.bounds(sum), (-2.5, 3.5));
        assert_eq!(t.bounds(remap), (-3.75, 5.25));
        assert_eq!(t.bounds(c), (-0.5, -0.5));
        assert_eq!(t.bounds(99), (f32::NEG_INFINITY, f32::INFINITY));
        let mut rng = Rng::new(5);
        for _ in 0..20_000 {
            let p = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 8.0 - 4.0;
            for id in [a, b, sum, prod, remap] {
                let (lo, hi) = t.bounds(id);
                let v = t.eval(id, p);
                assert!(
                    lo <= v && v <= hi,
                    "field {id} at {p}: {v} not in {lo} ..= {hi}"
                );
            }
        }
        let big = t.add(FieldNode::Constant(3e38)).unwrap();
        let (first, count) = t.add_args(&[big, big]);
        let over = t.add(FieldNode::Product { first, count }).unwrap();
        assert_eq!(t.bounds(over), (f32::NEG_INFINITY, f32::INFINITY));
    }

    #[test]
    fn marble_is_a_turbulent_sine_and_stays_finite_far_out() {
        let mut t = FieldTable::default();
        let plain = t
            .add(FieldNode::Marble {
                inv_scale: 2.0,
                axis: Vec3::X,
                turbulence: 0.0,
                octaves: octaves(2),
            })
            .unwrap();
        let veined = t
            .add(FieldNode::Marble {
                inv_scale: 2.0,
                axis: Vec3::X,
                turbulence: 1.5,
                octaves: octaves(2),
            })
            .unwrap();
        // Without turbulence: ½ + ½ sin(2π·2x), independent of y and z.
        for x in [0.0f32, 0.1, 0.125, 0.3] {
            let want = 0.5 + 0.5 * (TAU * 2.0 * x).sin();
            let got = t.eval(plain, Vec3::new(x, 7.0, -3.0));
            assert!((got - want).abs() < 1e-5, "{x}: {got} vs {want}");
        }
        let mut differs = 0;
        for i in 0..100 {
            let p = Vec3::new(i as f32 * 0.013, i as f32 * 0.07, 0.5);
            let v = t.eval(veined, p);
            assert!((0.0..=1.0).contains(&v));
            differs += usize::from((v - t.eval(plain, p)).abs() > 1e-3);
        }
        assert!(differs > 80, "turbulence bends the veins: {differs}");
        for p in [
            Vec3::splat(1e6),
            Vec3::splat(-1e6),
            Vec3::ZERO,
            Vec3::splat(3e38),
            Vec3::NAN,
            Vec3::INFINITY,
        ] {
            assert!(t.eval(veined, p).is_finite(), "{p:?}");
        }
    }
}
