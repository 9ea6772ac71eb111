//! The chains of specular events a manifold walk solves for, and the refraction into the body
//! that a chain through the stone starts with (module docs in [`super`]).

use crate::bsdf::refract;
use crate::geometry::{Fan, StoneHit, offset_origin};
use glam::Vec3;

/// The chain of specular events between the vertex and the light that the walk solves for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Chain {
    /// From a vertex inside the body (a platelet, a medium point): one refraction out.
    Out,
    /// From a surface outside the body (the floor): a refraction into the body, then one out —
    /// the light a small lamp focuses through the stone (a caustic).
    Through,
}

impl Chain {
    /// How many times the chain crosses the boundary (each a specular transmission).
    pub fn crossings(self) -> u8 {
        match self {
            Chain::Out => 1,
            Chain::Through => 2,
        }
    }
}

/// Where a [`Chain::Through`] path enters the body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Entry {
    /// The boundary point, world space.
    pub p: Vec3,
    /// Object-space point (for the surface map).
    pub p_object: Vec3,
    /// Distance from the vertex, world units.
    pub t: f32,
    /// Cosine between the direction outside and the shading normal (> 0).
    pub cos_outside: f32,
    /// The refracted direction inside (unit).
    pub inside: Vec3,
    /// Origin of the segment inside (the point moved off the boundary, inward).
    pub origin: Vec3,
}

/// The refraction into the body along direction `d` of the rays `from` the vertex outside; `None`
/// if the ray misses the body or does not enter it there.
pub(super) fn entry(from: &Fan, d: Vec3, eta: f32) -> Option<Entry> {
    entry_at(from.intersect(d, f32::INFINITY)?, d, eta)
}

/// The refraction into the body at the boundary hit `h` of the ray along direction `d` from a
/// vertex outside; `None` if it does not enter there.
pub(super) fn entry_at(h: StoneHit, d: Vec3, eta: f32) -> Option<Entry> {
    let c = -h.ns.dot(d);
    if !(h.ng.dot(d) < 0.0 && c > 0.0) {
        return None;
    }
    let inside = refract(-d, h.ns, eta)?;
    if inside.dot(h.ng) >= 0.0 {
        return None;
    }
    Some(Entry {
        p: h.p,
        p_object: h.p_object,
        t: h.t,
        cos_outside: c,
        inside,
        origin: offset_origin(h.p, h.ng, inside),
    })
}
