//! The statistical form of a platelet population (issue 18's `platelets: statistical` knob): the
//! same platelets as a participating medium of oriented flakes, after the microflake models
//! (Jakob, Arbree, Moon, Bala & Marschner, "A radiative transfer framework for rendering materials
//! with anisotropic structure", SIGGRAPH 2010; Heitz, Dupuy, Crassin & Dachsbacher, "The SGGX
//! Microflake Distribution", SIGGRAPH 2015).
//!
//! A ray in direction `d` meets discs of radius `r` and normal `n` at the rate
//! `σ(d) = N · π⟨r²⟩ · E_n[|d·n|]` per unit length (`N` the density); `σ` is constant along a
//! straight ray, so the collision distance is exponential. At a collision the platelet's normal
//! has density `∝ |d·n| p(n)` (the discs a ray sees are tilted toward it) and its face is the
//! population's layered material, as for an explicit platelet. What this form drops is the
//! correlation between platelets: a ray never meets the same disc twice and sparkle averages out
//! — cheap at a distance, wrong up close.

use super::{Orientation, Population};
use crate::sampler::{Rng, hash_words};
use glam::{Affine3A, Vec3};

/// Entries of the `E[|d·n|]` table of an aligned population (over `cos` of the angle between
/// `d` and the axis).
const PROJECTION_ENTRIES: usize = 65;
/// Normals drawn per rejection attempt before giving up on a collision's normal.
const MAX_REJECTIONS: u32 = 256;

/// One population as flakes in world space.
#[derive(Clone, Debug, PartialEq)]
struct Flakes {
    /// `N · π⟨r²⟩` in world units⁻¹.
    area_density: f32,
    /// The orientation distribution with its axis in world space.
    orientation: Orientation,
    /// `E[|d·n|]` against `|cos|` of the angle to the axis (aligned populations).
    projection: Vec<f32>,
    /// Cumulative entry weights and material indices.
    entries: Vec<(f32, u32)>,
}

/// The populations of a body as one statistical medium of flakes (world space).
#[derive(Clone, Debug, PartialEq)]
pub struct FlakeMedium {
    flakes: Vec<Flakes>,
}

/// A collision with a statistical platelet.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlakeCollision {
    /// Distance along the ray (world units).
    pub t: f32,
    /// The flake's unit normal (world space), facing the ray's origin.
    pub normal: Vec3,
    /// Material index of its face.
    pub material: u32,
}

impl FlakeMedium {
    /// The statistical form of `pops` (object space) under the object-to-world map `to_world`
    /// (uniform scale).
    pub fn new(pops: &[Population], to_world: Affine3A) -> FlakeMedium {
        let scale = to_world.matrix3.x_axis.length();
        let flakes = pops
            .iter()
            .map(|p| {
                let (r0, r1) = (f64::from(p.radius.0), f64::from(p.radius.1));
                // ⟨r²⟩ for r uniform in [r0, r1].
                let r2 = (r0 * r0 + r0 * r1 + r1 * r1) / 3.0;
                let area_density =
                    (f64::from(p.density) * std::f64::consts::PI * r2 / f64::from(scale)) as f32;
                let orientation = match p.orientation {
                    Orientation::Uniform => Orientation::Uniform,
                    Orientation::Aligned { axis, spread } => Orientation::Aligned {
                        axis: to_world.transform_vector3(axis).normalize(),
                        spread,
                    },
                };
                let projection = match orientation {
                    Orientation::Uniform => vec![],
                    Orientation::Aligned { axis, .. } => (0..PROJECTION_ENTRIES)
                        .map(|i| {
                            let c = i as f32 / (PROJECTION_ENTRIES - 1) as f32;
                            let s = (1.0 - c * c).max(0.0).sqrt();
                            let frame = crate::geometry::Frame::from_normal(axis);
                            let d = frame.to_world(Vec3::new(s, 0.0, c));
                            mean_projection(&orientation, d)
                        })
                        .collect(),
                };
                Flakes {
                    area_density,
                    orientation,
                    projection,
                    entries: p.entries.clone(),
                }
            })
            .collect();
        FlakeMedium { flakes }
    }

    fn sigma_of(f: &Flakes, d: Vec3) -> f32 {
        let e = match f.orientation {
            Orientation::Uniform => 0.5,
            Orientation::Aligned { axis, .. } => {
                let x = d.dot(axis).abs().min(1.0) * (PROJECTION_ENTRIES - 1) as f32;
                let i = (x as usize).min(PROJECTION_ENTRIES - 2);
                let w = x - i as f32;
                f.projection[i] * (1.0 - w) + f.projection[i + 1] * w
            }
        };
        f.area_density * e
    }

    /// The collision rate for unit direction `d`, world units⁻¹.
    pub fn sigma(&self, d: Vec3) -> f32 {
        self.flakes.iter().map(|f| Self::sigma_of(f, d)).sum()
    }

    /// Samples the first collision along a ray in unit direction `d` before `t_max`.
    ///
    /// # Arguments
    /// * `u` – two uniform numbers: the distance, and the key of the normal's and entry's draws.
    pub fn collide(&self, d: Vec3, t_max: f32, u: glam::Vec2) -> Option<FlakeCollision> {
        let sigma = self.sigma(d);
        if !(sigma > 0.0) {
            return None;
        }
        let t = -(1.0 - u.x).ln() / sigma;
        if !(t < t_max) {
            return None;
        }
        let mut rng = Rng::new(hash_words(&[u64::from(u.y.to_bits()), 0x666c_616b]));
        // The population, in proportion to its share of the rate.
        let mut pick = rng.uniform() * sigma;
        let mut flakes = &self.flakes[0];
        for f in &self.flakes {
            flakes = f;
            let s = Self::sigma_of(f, d);
            if pick < s {
                break;
            }
            pick -= s;
        }
        // The normal: p(n) |d·n| by rejection (accepted with probability |d·n|).
        let mut normal = None;
        for _ in 0..MAX_REJECTIONS {
            let n = flakes.orientation.sample(rng.uniform(), rng.uniform());
            if rng.uniform() < n.dot(d).abs() {
                normal = Some(n);
                break;
            }
        }
        let n = normal?;
        let n = if n.dot(d) < 0.0 { n } else { -n };
        let material = super::pick_entry(&flakes.entries, rng.uniform());
        Some(FlakeCollision {
            t,
            normal: n,
            material,
        })
    }
}

/// `E[|d·n|]` over the orientation distribution, by a fixed stratified quadrature.
fn mean_projection(o: &Orientation, d: Vec3) -> f32 {
    let k = 128;
    let mut sum = 0.0f64;
    for i in 0..k {
        for j in 0..k {
            let n = o.sample((i as f32 + 0.5) / k as f32, (j as f32 + 0.5) / k as f32);
            sum += f64::from(n.dot(d).abs());
        }
    }
    (sum / f64::from(k * k)) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pop(orientation: Orientation) -> Population {
        Population::new(500.0, (0.01, 0.02), orientation, vec![(1.0, 7)], 1).unwrap()
    }

    /// Uniform orientation: `σ = N π⟨r²⟩ / 2` in every direction; aligned flakes are seen edge-on
    /// along the plane and face-on along the axis.
    #[test]
    fn rates_follow_the_projected_area() {
        let m = FlakeMedium::new(&[pop(Orientation::Uniform)], Affine3A::IDENTITY);
        let expect = 500.0 * std::f32::consts::PI * (1e-4 + 2e-4 + 4e-4) / 3.0 * 0.5;
        for d in [Vec3::X, Vec3::new(0.3, 0.4, 0.866).normalize()] {
            assert!(
                (m.sigma(d) - expect).abs() < 1e-4 * expect,
                "{}",
                m.sigma(d)
            );
        }
        let a = FlakeMedium::new(
            &[pop(Orientation::Aligned {
                axis: Vec3::Y,
                spread: 0.0,
            })],
            Affine3A::from_scale(Vec3::splat(2.0)),
        );
        let face = a.sigma(Vec3::Y);
        assert!(
            (face - expect).abs() < 1e-3 * expect,
            "face-on {face}, half the scale"
        );
        assert!(a.sigma(Vec3::X) < 1e-3 * face, "edge-on");
    }

    /// Collision distances are exponential with the rate; normals face the ray.
    #[test]
    fn collisions_are_exponential_and_face_the_ray() {
        let m = FlakeMedium::new(&[pop(Orientation::Uniform)], Affine3A::IDENTITY);
        let d = Vec3::new(0.0, 0.6, 0.8);
        let sigma = m.sigma(d);
        let n = 20_000;
        let mut sum = 0.0f64;
        for i in 0..n {
            let u = glam::Vec2::new((i as f32 + 0.5) / n as f32, (i as f32 * 0.618).fract());
            let c = m.collide(d, f32::INFINITY, u).expect("a collision");
            assert!(c.normal.dot(d) < 0.0 && c.material == 7);
            sum += f64::from(c.t);
        }
        let mean = sum / f64::from(n);
        assert!(
            (mean * f64::from(sigma) - 1.0).abs() < 0.01,
            "mean t·σ {}",
            mean * f64::from(sigma)
        );
    }
}
