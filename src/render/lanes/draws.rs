//! A lane packet's random numbers and the map values it evaluates side by side, ahead of the
//! per-lane phases of a bounce (docs/design.md §13).

use super::simd::{L, M};
use crate::render::integrator::RR_DEPTH;
use crate::render::path::PathState;
use crate::render::world::{Hit, World};
use crate::sampler::{PixelSampler, pairs_side_by_side, slots};
use crate::spectrum::RgbSample;
use crate::texture::field::FieldId;
use glam::Vec2;

/// A lane's numbers for one bounce: the slots `slots::bounce(depth) + 0 ..= 5` in the order the
/// scalar integrator draws them (a 1-D number is its slot pair's first coordinate).
#[derive(Clone, Copy, Default)]
pub(super) struct Draws {
    /// The map's switch between layered BSDFs.
    pub(super) switch: f32,
    /// The light's choice and the point on it.
    pub(super) light: f32,
    pub(super) point: Vec2,
    /// The BSDF sample's lobe choice and direction.
    pub(super) uc: f32,
    pub(super) u: Vec2,
    /// Russian roulette (drawn from [`RR_DEPTH`] on).
    pub(super) roulette: f32,
    /// The map's leading field at the lane's stone hit, when evaluated side by side.
    pub(super) known: Option<(FieldId, f32)>,
}

/// The numbers of the bounce of every lane in `active`, drawn side by side (the scrambles as
/// vector instructions); the other lanes' numbers are meaningless.
#[inline(always)]
pub(super) fn bounce_draws(
    samplers: &mut [PixelSampler; L],
    paths: &[PathState<RgbSample>; L],
    active: M,
) -> [Draws; L] {
    if !active.any() {
        return [Draws::default(); L];
    }
    let first: [u32; L] = std::array::from_fn(|i| slots::bounce(paths[i].depth));
    let mut at = |k: u32| pairs_side_by_side(samplers, first.map(|f| f + k), active.0);
    let (switch, light, point, uc, u) = (at(0), at(1), at(2), at(3), at(4));
    // Roulette follows the scattering, which counts one more bounce.
    let roulette = if active.lanes().any(|i| paths[i].depth + 1 >= RR_DEPTH) {
        at(5)
    } else {
        [Vec2::ZERO; L]
    };
    std::array::from_fn(|i| Draws {
        switch: switch[i].x,
        light: light[i].x,
        point: point[i],
        uc: uc[i].x,
        u: u[i],
        roulette: roulette[i].x,
        known: None,
    })
}

/// The map's leading field at every live lane's stone hit, evaluated side by side (the noise as
/// vector instructions), when two or more lanes met the stone; other lanes' values are
/// meaningless and not read (their `shade` does not look the map up).
#[inline(always)]
pub(super) fn leading_field(
    world: &World,
    field: Option<FieldId>,
    found: &[Option<Hit>; L],
    alive: M,
) -> Option<(FieldId, [f32; L])> {
    let field = field?;
    let mut points = [glam::Vec3::ZERO; L];
    let mut stones = 0;
    for i in alive.lanes() {
        if let Some(Hit::Stone(h)) = &found[i] {
            points[i] = h.p_object;
            stones += 1;
        }
    }
    (stones >= 2).then(|| (field, world.map.fields.eval_side_by_side(field, &points)))
}
