//! Lane types: `L` values side by side (structure of arrays), with the arithmetic written as
//! loops over the lanes that the compiler turns into SIMD instructions. Every operation is
//! `#[inline(always)]`, so that inside the kernel that [`super::dispatch`] compiles for the
//! machine's widest instruction set (AVX-512, AVX2 + FMA, or the baseline) the loops become
//! single vector instructions on registers rather than calls.
//!
//! No operation depends on the other lanes (no horizontal sums inside arithmetic), and none is
//! contracted (no fused multiply-add unless written as [`F::mul_add`], which is exact in every
//! instruction set), so a lane computes bit for bit what it would alone: results do not depend
//! on the lane width or on the instruction set.

use glam::Vec3;
use std::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, MulAssign, Neg, Not, Sub};

/// Lanes per packet: eight `f32` fill an AVX2 register, half an AVX-512 one (which then runs
/// two packets' worth of work per instruction pair); eight camera paths of one pixel keep the
/// lanes coherent (same pixel, nearby directions).
pub const L: usize = 8;

/// `L` floats.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct F(pub [f32; L]);

/// `L` booleans: which lanes an operation applies to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct M(pub [bool; L]);

/// `L` unsigned integers (indices: material, light, pixel sample).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct U(pub [u32; L]);

/// `L` three-vectors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct V3 {
    /// The `x` components.
    pub x: F,
    /// The `y` components.
    pub y: F,
    /// The `z` components.
    pub z: F,
}

impl F {
    /// Every lane `v`.
    #[inline(always)]
    pub const fn splat(v: f32) -> F {
        F([v; L])
    }

    /// Lane `i` is `f(i)`.
    #[inline(always)]
    pub fn from_fn(f: impl FnMut(usize) -> f32) -> F {
        F(std::array::from_fn(f))
    }

    /// `f` applied to every lane.
    #[inline(always)]
    pub fn map(self, f: impl Fn(f32) -> f32) -> F {
        F(self.0.map(f))
    }

    /// `f` applied lane by lane to `self` and `o`.
    #[inline(always)]
    pub fn zip(self, o: F, f: impl Fn(f32, f32) -> f32) -> F {
        F(std::array::from_fn(|i| f(self.0[i], o.0[i])))
    }

    /// Square roots.
    #[inline(always)]
    pub fn sqrt(self) -> F {
        self.map(f32::sqrt)
    }

    /// Absolute values.
    #[inline(always)]
    pub fn abs(self) -> F {
        self.map(f32::abs)
    }

    /// Lane-wise minimum (as `f32::min`: a NaN lane takes the other value).
    #[inline(always)]
    pub fn min(self, o: F) -> F {
        self.zip(o, f32::min)
    }

    /// Lane-wise maximum (as `f32::max`).
    #[inline(always)]
    pub fn max(self, o: F) -> F {
        self.zip(o, f32::max)
    }

    /// `self · a + b`, rounded once.
    #[inline(always)]
    pub fn mul_add(self, a: F, b: F) -> F {
        F(std::array::from_fn(|i| self.0[i].mul_add(a.0[i], b.0[i])))
    }

    /// Lanes where `self < o`.
    #[inline(always)]
    pub fn lt(self, o: F) -> M {
        M(std::array::from_fn(|i| self.0[i] < o.0[i]))
    }

    /// Lanes where `self <= o`.
    #[inline(always)]
    pub fn le(self, o: F) -> M {
        M(std::array::from_fn(|i| self.0[i] <= o.0[i]))
    }

    /// Lanes where `self > o`.
    #[inline(always)]
    pub fn gt(self, o: F) -> M {
        M(std::array::from_fn(|i| self.0[i] > o.0[i]))
    }

    /// Lanes where `self >= o`.
    #[inline(always)]
    pub fn ge(self, o: F) -> M {
        M(std::array::from_fn(|i| self.0[i] >= o.0[i]))
    }

    /// Lanes that are finite.
    #[inline(always)]
    pub fn finite(self) -> M {
        M(self.0.map(f32::is_finite))
    }

    /// `a` where `m`, else `b`.
    #[inline(always)]
    pub fn select(m: M, a: F, b: F) -> F {
        F(std::array::from_fn(
            |i| if m.0[i] { a.0[i] } else { b.0[i] },
        ))
    }

    /// Lane `i` of the lanes.
    #[inline(always)]
    pub fn at(self, i: usize) -> f32 {
        self.0[i]
    }
}

macro_rules! binary {
    ($t:ident, $f:ident, $op:tt) => {
        impl $t for F {
            type Output = F;
            #[inline(always)]
            fn $f(self, o: F) -> F {
                F(std::array::from_fn(|i| self.0[i] $op o.0[i]))
            }
        }
        impl $t<f32> for F {
            type Output = F;
            #[inline(always)]
            fn $f(self, o: f32) -> F {
                F(self.0.map(|v| v $op o))
            }
        }
        impl $t<F> for f32 {
            type Output = F;
            #[inline(always)]
            fn $f(self, o: F) -> F {
                F(o.0.map(|v| self $op v))
            }
        }
    };
}
binary!(Add, add, +);
binary!(Sub, sub, -);
binary!(Mul, mul, *);
binary!(Div, div, /);

impl Neg for F {
    type Output = F;
    #[inline(always)]
    fn neg(self) -> F {
        self.map(|v| -v)
    }
}

impl AddAssign for F {
    #[inline(always)]
    fn add_assign(&mut self, o: F) {
        *self = *self + o;
    }
}

impl MulAssign for F {
    #[inline(always)]
    fn mul_assign(&mut self, o: F) {
        *self = *self * o;
    }
}

impl M {
    /// Every lane `v`.
    #[inline(always)]
    pub const fn splat(v: bool) -> M {
        M([v; L])
    }

    /// Lane `i` is `f(i)`.
    #[inline(always)]
    pub fn from_fn(f: impl FnMut(usize) -> bool) -> M {
        M(std::array::from_fn(f))
    }

    /// Whether any lane is set.
    #[inline(always)]
    pub fn any(self) -> bool {
        self.0.iter().any(|&b| b)
    }

    /// Whether every lane is set.
    #[inline(always)]
    pub fn all(self) -> bool {
        self.0.iter().all(|&b| b)
    }

    /// The set lanes, in order.
    #[inline(always)]
    pub fn lanes(self) -> impl Iterator<Item = usize> {
        (0..L).filter(move |&i| self.0[i])
    }

    /// `self` and not `o`.
    #[inline(always)]
    pub fn and_not(self, o: M) -> M {
        M(std::array::from_fn(|i| self.0[i] && !o.0[i]))
    }
}

impl BitAnd for M {
    type Output = M;
    #[inline(always)]
    fn bitand(self, o: M) -> M {
        M(std::array::from_fn(|i| self.0[i] && o.0[i]))
    }
}

impl BitOr for M {
    type Output = M;
    #[inline(always)]
    fn bitor(self, o: M) -> M {
        M(std::array::from_fn(|i| self.0[i] || o.0[i]))
    }
}

impl Not for M {
    type Output = M;
    #[inline(always)]
    fn not(self) -> M {
        M(self.0.map(|b| !b))
    }
}

impl U {
    /// Every lane `v`.
    #[inline(always)]
    pub const fn splat(v: u32) -> U {
        U([v; L])
    }

    /// `a` where `m`, else `b`.
    #[inline(always)]
    pub fn select(m: M, a: U, b: U) -> U {
        U(std::array::from_fn(
            |i| if m.0[i] { a.0[i] } else { b.0[i] },
        ))
    }

    /// Lanes equal to `v`.
    #[inline(always)]
    pub fn eq(self, v: u32) -> M {
        M(self.0.map(|x| x == v))
    }
}

impl V3 {
    /// Every lane `v`.
    #[inline(always)]
    pub fn splat(v: Vec3) -> V3 {
        V3 {
            x: F::splat(v.x),
            y: F::splat(v.y),
            z: F::splat(v.z),
        }
    }

    /// Lane `i` is `f(i)`.
    #[inline(always)]
    pub fn from_fn(mut f: impl FnMut(usize) -> Vec3) -> V3 {
        let v: [Vec3; L] = std::array::from_fn(&mut f);
        V3 {
            x: F::from_fn(|i| v[i].x),
            y: F::from_fn(|i| v[i].y),
            z: F::from_fn(|i| v[i].z),
        }
    }

    /// Lane `i` as a vector.
    #[inline(always)]
    pub fn at(&self, i: usize) -> Vec3 {
        Vec3::new(self.x.0[i], self.y.0[i], self.z.0[i])
    }

    /// Sets lane `i`.
    #[inline(always)]
    pub fn set(&mut self, i: usize, v: Vec3) {
        self.x.0[i] = v.x;
        self.y.0[i] = v.y;
        self.z.0[i] = v.z;
    }

    /// Dot products, `x·x + y·y + z·z` in that order (as `glam::Vec3::dot`).
    #[inline(always)]
    pub fn dot(self, o: V3) -> F {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// Squared lengths.
    #[inline(always)]
    pub fn length_squared(self) -> F {
        self.dot(self)
    }

    /// Lengths.
    #[inline(always)]
    pub fn length(self) -> F {
        self.length_squared().sqrt()
    }

    /// `a` where `m`, else `b`.
    #[inline(always)]
    pub fn select(m: M, a: V3, b: V3) -> V3 {
        V3 {
            x: F::select(m, a.x, b.x),
            y: F::select(m, a.y, b.y),
            z: F::select(m, a.z, b.z),
        }
    }

    /// Every component times `s`.
    #[inline(always)]
    pub fn scale(self, s: F) -> V3 {
        V3 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }
}

impl Add for V3 {
    type Output = V3;
    #[inline(always)]
    fn add(self, o: V3) -> V3 {
        V3 {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
}

impl Sub for V3 {
    type Output = V3;
    #[inline(always)]
    fn sub(self, o: V3) -> V3 {
        V3 {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
}

impl Neg for V3 {
    type Output = V3;
    #[inline(always)]
    fn neg(self) -> V3 {
        V3 {
            x: -self.x,
            y: -self.y,
            z: -self.z,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_compute_what_each_lane_would_alone() {
        let a = F::from_fn(|i| i as f32 * 0.37 - 1.0);
        let b = F::from_fn(|i| 2.0 - i as f32 * 0.11);
        let r = (a * b + a / b - 0.5).sqrt().max(F::splat(0.1));
        for i in 0..L {
            let (x, y) = (a.at(i), b.at(i));
            assert_eq!(
                r.at(i).to_bits(),
                (x * y + x / y - 0.5).sqrt().max(0.1).to_bits()
            );
        }
        let v = V3::from_fn(|i| Vec3::new(i as f32, 1.0, -2.0));
        let w = V3::splat(Vec3::new(0.5, -1.0, 0.25));
        for i in 0..L {
            assert_eq!(v.dot(w).at(i), v.at(i).dot(w.at(i)));
        }
        let m = a.lt(F::splat(0.0));
        assert_eq!(m.lanes().count(), (0..L).filter(|&i| a.at(i) < 0.0).count());
        assert!(m.any() && !m.all());
    }
}
