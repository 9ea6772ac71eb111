//! Spatially varying platelet density (issue 18, `sunstone-patterned`: "the scattering function is
//! no longer homogeneous"): a scalar field over object space whose value, clamped to `[0, 1]`,
//! multiplies a population's density at each point.
//!
//! The field is the recipe's field description (the one a `Switch` compares with its thresholds,
//! [`crate::texture::field`]), compiled into a table of its own. Both forms of a population follow
//! it:
//!
//! - **Explicit** platelets are *thinned* (independent thinning of a Poisson process, Lewis &
//!   Shedler 1979): the point process is generated at the full density, every attribute of every
//!   platelet is drawn as before, and platelet `i` of cell `c` is kept iff a uniform number drawn
//!   from its own `(seed, c, i)` stream ([`thinning_uniform`]) is below the modulation at its
//!   centre. The kept set is a pure function of `(seed, c)`, a subset of the unmodulated set with
//!   the same seed, and a dropped platelet leaves the indices of the others unchanged. The kept
//!   centres form a Poisson process of intensity `density · m(x)`.
//! - The **statistical** form's collision rate becomes `σ(d) · m(p)` at the point `p` of the ray:
//!   sampled by delta tracking ([`super::statistical`]).
//!
//! The explicit form modulates whole discs by their centre, the statistical one the rate at each
//! point: the two agree where the field changes little over a platelet's diameter.

use crate::sampler::{hash_words, to_unit_f32};
use crate::texture::{FieldId, FieldTable};
use glam::Vec3;

/// Tag of the thinning streams (kept apart from the cell streams that draw the attributes).
const THINNING: u64 = 0x7468_696e;

/// A density modulation: a field and the node of its table that gives the value.
#[derive(Clone, Debug, PartialEq)]
pub struct Modulation {
    fields: FieldTable,
    root: FieldId,
}

impl Modulation {
    /// The modulation `fields[root]`; `None` if `root` is not a node of the table.
    pub fn new(fields: FieldTable, root: FieldId) -> Option<Modulation> {
        ((root as usize) < fields.len()).then_some(Modulation { fields, root })
    }

    /// A modulation of constant value `c` (clamped like any other).
    pub fn constant(c: f32) -> Modulation {
        let mut fields = FieldTable::default();
        let root = fields
            .add(crate::texture::FieldNode::Constant(c))
            .unwrap_or(0);
        Modulation { fields, root }
    }

    /// The factor on the density at object-space point `p`: the field's value clamped to
    /// `[0, 1]` (dimensionless; non-finite field values read 0, see [`FieldTable::eval`]).
    #[inline]
    pub fn at(&self, p: Vec3) -> f32 {
        self.fields.eval(self.root, p).clamp(0.0, 1.0)
    }

    /// A conservative interval holding every value of the field before clamping
    /// ([`FieldTable::bounds`]).
    pub fn bounds(&self) -> (f32, f32) {
        self.fields.bounds(self.root)
    }

    /// The field table and the root node (for inspection).
    pub fn field(&self) -> (&FieldTable, FieldId) {
        (&self.fields, self.root)
    }
}

/// The uniform number in `[0, 1)` that decides whether platelet `index` of cell `c` of the
/// population with `seed` survives thinning: a stream of its own, so the decision does not depend
/// on the other platelets, on the order cells are visited in, or on the attribute draws.
#[inline]
pub fn thinning_uniform(seed: u64, c: [i32; 3], index: u32) -> f32 {
    to_unit_f32(hash_words(&[
        seed,
        c[0] as u32 as u64,
        c[1] as u32 as u64,
        c[2] as u32 as u64,
        u64::from(index),
        THINNING,
    ]))
}

/// Whether a platelet centred where the modulation reads `m` survives, given its thinning uniform
/// `u`: `u < m`. `m ≥ 1` always keeps and `m ≤ 0` always drops, which the comparison gives too;
/// the shortcut lets a caller skip drawing `u` in those cases.
#[inline]
pub fn survives(m: f32, u: impl FnOnce() -> f32) -> bool {
    m >= 1.0 || (m > 0.0 && u() < m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_are_clamped_and_uniforms_are_independent_of_each_other() {
        assert_eq!(Modulation::constant(3.0).at(Vec3::ZERO), 1.0);
        assert_eq!(Modulation::constant(-2.0).at(Vec3::ONE), 0.0);
        assert_eq!(Modulation::constant(0.25).at(Vec3::X), 0.25);
        assert!(Modulation::new(FieldTable::default(), 0).is_none());
        // Uniform in [0, 1): the mean of many and their spread.
        let n = 100_000;
        let mut sum = 0.0f64;
        for i in 0..n {
            let u = thinning_uniform(5, [i % 7 - 3, i / 7, -4], i as u32 % 3);
            assert!((0.0..1.0).contains(&u));
            sum += f64::from(u);
        }
        let mean = sum / f64::from(n);
        assert!((mean - 0.5).abs() < 4.0 * (1.0 / 12.0f64 / f64::from(n)).sqrt());
        assert!(survives(1.0, || unreachable!()) && !survives(0.0, || unreachable!()));
        assert!(survives(0.5, || 0.49) && !survives(0.5, || 0.5));
    }
}
