//! The stone's intersection for a packet: the object-space transform, the solid's test and the
//! world-space normals, lane-wise with exactly the scalar code's operations
//! ([`crate::geometry::Stone::intersect`], [`crate::geometry::Sphere::intersect`],
//! `sphere_interval`), so each lane's hit is bit for bit the scalar one. A sphere is vectorised;
//! the other solids are tested lane by lane with the scalar code.

use super::simd::{F, L, M, V3};
use crate::geometry::{Ray, Solid, Stone, StoneHit};
use glam::{Affine3A, Mat3A, Vec3};

/// `m · v + t` per lane, in glam's order (`x_axis·x + y_axis·y + z_axis·z + t`).
#[inline(always)]
fn affine(m: &Mat3A, t: Vec3, v: V3, point: bool) -> V3 {
    let row = |c: usize| {
        let r = m.x_axis[c] * v.x + m.y_axis[c] * v.y + m.z_axis[c] * v.z;
        if point { r + t[c] } else { r }
    };
    V3 {
        x: row(0),
        y: row(1),
        z: row(2),
    }
}

/// A point transformed by `a` (glam's `transform_point3`).
#[inline(always)]
fn point(a: &Affine3A, v: V3) -> V3 {
    affine(&a.matrix3, Vec3::from(a.translation), v, true)
}

/// A vector transformed by `a` (glam's `transform_vector3`).
#[inline(always)]
fn vector(a: &Affine3A, v: V3) -> V3 {
    affine(&a.matrix3, Vec3::ZERO, v, false)
}

/// `v` normalised where its reciprocal length is finite and positive, else `fallback` (glam's
/// `normalize_or`).
#[inline(always)]
fn normalize_or(v: V3, fallback: V3) -> V3 {
    let rcp = 1.0 / v.length();
    let ok = M::from_fn(|i| rcp.at(i).is_finite() && rcp.at(i) > 0.0);
    V3::select(ok, v.scale(rcp), fallback)
}

/// The stone's hits of the live lanes' rays (unit directions), closest within `(0, ∞)`: which
/// lanes hit, and their hits.
#[inline(always)]
pub fn intersect(stone: &Stone, live: M, o: V3, d: V3) -> (M, [StoneHit; L]) {
    let mut hits = [StoneHit {
        t: f32::INFINITY,
        p: Vec3::ZERO,
        p_object: Vec3::ZERO,
        ng: Vec3::ZERO,
        ns: Vec3::ZERO,
        facet: None,
    }; L];
    let Solid::Sphere(sphere) = stone.solid() else {
        let mut hit = M::splat(false);
        for i in live.lanes() {
            if let Some(h) = stone.intersect(&Ray::new(o.at(i), d.at(i)), f32::INFINITY) {
                hits[i] = h;
                hit.0[i] = true;
            }
        }
        return (hit, hits);
    };
    let r = sphere.radius();
    let to_object = stone.to_object();
    let oo = point(&to_object, o);
    let od = vector(&to_object, d);
    // `valid_query` (t_max = ∞ > 0).
    let valid = M::from_fn(|i| {
        live.0[i] && oo.at(i).is_finite() && od.at(i).is_finite() && od.at(i) != Vec3::ZERO
    });
    // `sphere_interval`.
    let a = od.length_squared();
    let b = oo.dot(od);
    let l = (oo - od.scale(b / a)).length();
    let disc = (F::splat(r) - l) * (F::splat(r) + l);
    let q = -(b + (a * disc).sqrt().zip(b, f32::copysign));
    let len = oo.length();
    let c = (len - r) * (len + r);
    let (t0, t1) = (c / q, q / a);
    let roots = M::from_fn(|i| {
        disc.at(i) >= 0.0 && q.at(i) != 0.0 && t0.at(i).is_finite() && t1.at(i).is_finite()
    });
    let (lo, hi) = (t0.min(t1), t0.max(t1));
    // `first_of_interval` with t_max = ∞.
    let enter = lo.gt(F::splat(0.0)) & lo.lt(F::splat(f32::INFINITY));
    let leave = hi.gt(F::splat(0.0)) & hi.lt(F::splat(f32::INFINITY));
    let t = F::select(enter, lo, hi);
    let found = valid & roots & (enter | leave);
    // The hit: the reprojected normal, then world space (`Stone::intersect`).
    let n = normalize_or(oo + od.scale(t), V3::splat(Vec3::Y));
    let p_object = n.scale(F::splat(r));
    let nw = stone.normal_to_world();
    let n_world = affine(&nw, Vec3::ZERO, n, false);
    let ng = normalize_or(n_world, V3::splat(Vec3::ZERO));
    let ns = normalize_or(n_world, ng);
    let p = point(&stone.to_world(), p_object);
    let mut hit = M::splat(false);
    for i in found.lanes() {
        let (ngi, pi) = (ng.at(i), p.at(i));
        if ngi != Vec3::ZERO && pi.is_finite() {
            hit.0[i] = true;
            hits[i] = StoneHit {
                t: t.at(i),
                p: pi,
                p_object: p_object.at(i),
                ng: ngi,
                ns: ns.at(i),
                facet: None,
            };
        }
    }
    (hit, hits)
}
