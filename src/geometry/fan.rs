//! Rays from one origin against the stone ([`Fan`]), and the cabochon placed in the world
//! ([`PlacedCabochon`]): the stone's intersection with the work that depends only on the
//! placement done once per stone, and the work that depends only on the origin done once per
//! fan.
//!
//! A cabochon's ellipsoids are met in their normalised frames, where each is the unit sphere. The
//! placement and the scaling to the upper dome's frame fold into one affine map from world space
//! (so a world ray reaches the frame in one transform instead of two), and the map from a
//! unit-sphere point to the world normal into one matrix. The manifold walks cast many rays from
//! one vertex (every Newton step, every finite difference): a [`Fan`] transforms the vertex and
//! forms the constant term of each quadric once. [`super::Stone::intersect`] is a fan of one
//! ray, so both give the same hits bit for bit.

use super::cabochon::{FrameOrigin, Piece};
use super::hit::valid_direction;
use super::placed::PlacedCabochon;
use super::ray::Ray;
use super::solid::Solid;
use super::stone::{Stone, StoneHit};
use glam::{Mat3A, Vec3, Vec3A};

/// How a [`Fan`] meets the stone.
#[derive(Clone, Copy, Debug)]
enum Kind<'a> {
    /// The origin is not finite: every ray misses.
    Invalid,
    /// A placed cabochon, with the origin's part of the query.
    Cabochon(&'a PlacedCabochon, FrameOrigin),
    /// Any other solid, with the origin in object space.
    Solid(Vec3),
}

/// Rays from one world-space origin against the stone: [`Fan::intersect`] along a direction is
/// [`Stone::intersect`] of the ray from the origin, bit for bit.
#[derive(Clone, Copy, Debug)]
pub struct Fan<'a> {
    stone: &'a Stone,
    kind: Kind<'a>,
}

impl<'a> Fan<'a> {
    /// The fan of rays from world point `origin`.
    #[inline]
    pub(crate) fn new(stone: &'a Stone, origin: Vec3) -> Self {
        let kind = if !origin.is_finite() {
            Kind::Invalid
        } else if let Some(c) = stone.placed() {
            let o = c.to_frame.transform_point3(origin);
            if o.is_finite() {
                Kind::Cabochon(c, c.shape.frame_origin(o))
            } else {
                Kind::Invalid
            }
        } else {
            Kind::Solid(stone.to_object().transform_point3(origin))
        };
        Fan { stone, kind }
    }

    /// Closest hit with `0 < t < t_max` along the world direction `dir` (unit, so `t` is a
    /// distance), as [`Stone::intersect`] documents.
    #[inline]
    pub fn intersect(&self, dir: Vec3, t_max: f32) -> Option<StoneHit> {
        match self.kind {
            Kind::Invalid => None,
            Kind::Cabochon(c, org) => {
                if !valid_direction(dir, t_max) {
                    return None;
                }
                let d = c.to_frame.transform_vector3(dir);
                let (t, piece) = c.shape.first_hit(&org, d, t_max)?;
                let ng = match piece {
                    Piece::Base(_) => c.base_normal,
                    Piece::Upper(u) => (c.upper_normal * u).normalize_or_zero(),
                    Piece::Lower(u) => (c.lower_normal * u).normalize_or_zero(),
                };
                let p_object = c.shape.point(piece);
                self.finish(t, p_object, ng, ng, None)
            }
            Kind::Solid(o) => {
                let ray = Ray::new(o, self.stone.to_object().transform_vector3(dir));
                let h = self.stone.solid().intersect(&ray, t_max)?;
                let nw = self.stone.normal_to_world();
                let ng = (nw * h.ng).normalize_or_zero();
                // An analytic shape's shading normal is its geometric one: transformed once.
                let ns = if h.ns == h.ng {
                    ng
                } else {
                    (nw * h.ns).normalize_or(ng)
                };
                self.finish(h.t, h.p, ng, ns, h.facet)
            }
        }
    }

    /// Whether [`Fan::intersect_curved`] knows the surface's curvature: a placed cabochon's
    /// domes and base, a placed sphere, and the flat faces of a faceted stone or a slab (zero). A
    /// mesh's normals are interpolated: its walks take a finite-difference Jacobian.
    #[inline]
    pub fn has_shape_operator(&self) -> bool {
        match self.kind {
            Kind::Cabochon(..) => true,
            Kind::Solid(_) => matches!(
                self.stone.solid(),
                Solid::Polytope(_) | Solid::Slab(_) | Solid::Sphere(_)
            ),
            Kind::Invalid => false,
        }
    }

    /// [`Fan::intersect`] (the same hit, bit for bit) with the surface's curvature there
    /// ([`Curvature`]); `None` for the curvature where [`Fan::has_shape_operator`] is false.
    #[inline]
    pub fn intersect_curved(&self, dir: Vec3, t_max: f32) -> Option<CurvedHit> {
        let Kind::Cabochon(c, org) = self.kind else {
            let hit = self.intersect(dir, t_max)?;
            let curvature = match self.stone.solid() {
                Solid::Sphere(s) => Some(self.sphere_curvature(s.radius(), &hit)?),
                _ => self.has_shape_operator().then_some(Curvature::FLAT),
            };
            return Some(CurvedHit { hit, curvature });
        };
        if !valid_direction(dir, t_max) {
            return None;
        }
        let d = c.to_frame.transform_vector3(dir);
        let (t, piece) = c.shape.first_hit(&org, d, t_max)?;
        let dome = |g: Vec3, field: Mat3A| {
            let inv_len = g.length().recip();
            (g.normalize_or_zero(), Curvature { field, inv_len })
        };
        let (ng, curvature) = match piece {
            Piece::Base(_) => (c.base_normal, Curvature::FLAT),
            Piece::Upper(u) => dome(c.upper_normal * u, c.upper_shape),
            Piece::Lower(u) => dome(c.lower_normal * u, c.lower_shape),
        };
        let p_object = c.shape.point(piece);
        let hit = self.finish(t, p_object, ng, ng, None)?;
        curvature.inv_len.is_finite().then_some(CurvedHit {
            hit,
            curvature: Some(curvature),
        })
    }

    /// The curvature at `hit` of a sphere of `radius` (object units) centred at the object
    /// origin, placed by the stone's affine map `x = A u + b`: the world normal is `n = g/|g|`
    /// with `g = N u / r` (`N` the normal matrix, `u` the object point), so `g = F x + const`
    /// with `F = N A⁻¹ / r` ([`Curvature`]). `None` where it degenerates.
    #[inline]
    fn sphere_curvature(&self, radius: f32, hit: &StoneHit) -> Option<Curvature> {
        let nw = self.stone.normal_to_world();
        // Formed once with the stone (the same product, so the same bits).
        let field = self.stone.sphere_field()?;
        let inv_len = (nw * (hit.p_object / radius)).length().recip();
        inv_len.is_finite().then_some(Curvature { field, inv_len })
    }

    /// The world hit from the object-space point and the world normals; `None` where they
    /// degenerate (a zero normal, a point overflowing the placement).
    #[inline(always)]
    fn finish(
        &self,
        t: f32,
        p_object: Vec3,
        ng: Vec3,
        ns: Vec3,
        facet: Option<u32>,
    ) -> Option<StoneHit> {
        let p = self.stone.to_world().transform_point3(p_object);
        (ng != Vec3::ZERO && p.is_finite()).then_some(StoneHit {
            t,
            p,
            p_object,
            ng,
            ns,
            facet,
        })
    }

    /// Whether the stone blocks direction `dir` anywhere in `0 < t < t_max`
    /// ([`Stone::occluded`]).
    #[inline]
    pub fn occluded(&self, dir: Vec3, t_max: f32) -> bool {
        match self.kind {
            Kind::Invalid => false,
            Kind::Cabochon(c, org) => {
                valid_direction(dir, t_max)
                    && c.shape
                        .meets(&org, c.to_frame.transform_vector3(dir), t_max)
            }
            Kind::Solid(o) => {
                let ray = Ray::new(o, self.stone.to_object().transform_vector3(dir));
                self.stone.solid().occluded(&ray, t_max)
            }
        }
    }
}

/// The stone's ray queries, all through a [`Fan`].
impl Stone {
    /// The rays from world point `origin`: for many rays from one point (the manifold walks'
    /// Newton steps), [`Fan::intersect`] is [`Stone::intersect`] with the origin's share of the
    /// work done once.
    #[inline]
    pub fn fan(&self, origin: Vec3) -> Fan<'_> {
        Fan::new(self, origin)
    }

    /// Closest hit with `0 < t < t_max` along a world ray (unit direction, so `t` is a distance).
    ///
    /// The world point is `to_world(p_object)`, with `p_object` projected onto the surface in
    /// object space, rather than `ray.at(t)`: its error is then a few ulps of the coordinates
    /// wherever the ray came from, while `ray.at(t)` carries the error of `t`, which grows with
    /// the distance the ray travelled (a far camera) and puts the point off the surface.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<StoneHit> {
        self.fan(ray.origin).intersect(ray.dir, t_max)
    }

    /// Whether world point `p` lies inside the stone: the first surface a ray from `p` meets is
    /// seen from its back (the surface's own normals point outward on a closed, consistently
    /// wound stone). Tried along three fixed directions; the majority decides, so a ray grazing an
    /// edge cannot flip the answer alone.
    pub fn contains(&self, p: Vec3) -> bool {
        let dirs = [
            Vec3::new(0.267, 0.534, 0.802),
            Vec3::new(-0.577, -0.211, 0.789),
            Vec3::new(0.123, -0.911, -0.394),
        ];
        let fan = self.fan(p);
        let inside = dirs
            .iter()
            .filter(|d| {
                let d = d.normalize();
                fan.intersect(d, f32::INFINITY)
                    .is_some_and(|h| h.ng.dot(d) > 0.0)
            })
            .count();
        inside >= 2
    }

    /// Whether the stone blocks the world ray anywhere in `0 < t < t_max`.
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.fan(ray.origin).occluded(ray.dir, t_max)
    }
}

/// A hit of [`Fan::intersect_curved`].
#[derive(Clone, Copy, Debug)]
pub struct CurvedHit {
    /// The hit, as [`Fan::intersect`] gives it.
    pub hit: StoneHit,
    /// The surface's curvature there, where the stone knows it.
    pub curvature: Option<Curvature>,
}

/// How the unit normal turns along the surface at a hit (its shape operator `S`, world
/// units⁻¹): `δn = S δx` for a displacement `δx` of the point along the surface. A dome's normal
/// is `n = g/|g|` with `g = F x + const` (`F` the dome's `*_shape` matrix: the normal matrix
/// times the world-to-frame map), so `S δx = (I − n nᵀ) F δx / |g|`; a flat face's is zero.
#[derive(Clone, Copy, Debug)]
pub struct Curvature {
    /// `F`, world units⁻¹ (zero on the flat base).
    field: Mat3A,
    /// `1 / |g|`.
    inv_len: f32,
}

impl Curvature {
    /// A flat face's: the normal does not turn.
    pub const FLAT: Curvature = Curvature {
        field: Mat3A::ZERO,
        inv_len: 0.0,
    };

    /// `δn = S δx` at the hit whose unit normal is `n`.
    #[inline]
    pub fn turn(&self, n: Vec3, dx: Vec3) -> Vec3 {
        self.turn_a(n.into(), dx.into()).into()
    }

    /// [`Curvature::turn`] on [`Vec3A`]s (the same operations, so the same bits).
    #[inline]
    pub fn turn_a(&self, n: Vec3A, dx: Vec3A) -> Vec3A {
        let w = self.field * dx;
        (w - n * n.dot(w)) * self.inv_len
    }
}
