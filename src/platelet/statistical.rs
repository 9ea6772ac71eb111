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
//!
//! **Modulated density.** A population whose density is modulated ([`super::modulation`]) has the
//! rate `σ(d) · m(p)` at point `p`, which varies along the ray. Its collisions are sampled by delta
//! tracking (Woodcock, Murphy, Hemmings & Longworth 1965; the null-collision view of Galtier et al.
//! 2013 and Kutz et al. 2017): tentative collisions at the unmodulated rate `σ̄(d) = Σ σ_k(d)` (the
//! majorant, since `m ≤ 1`), each given to population `k` with probability `σ_k/σ̄` and made real
//! with probability `m_k(p)`; a null collision goes on from where it happened. This samples the
//! first real collision exactly. At most [`MAX_NULL_COLLISIONS`] null collisions are made per call:
//! past that the flight ends with no collision before `t_max`, as if the rest of the segment held
//! no platelet (a ray meets that many only where the modulation is near 0 over more than
//! `MAX_NULL_COLLISIONS / σ̄` of its length; never on the shipped gems). A medium without
//! modulation samples exactly as before (the same numbers, bit for bit).

use super::modulation::{Modulation, survives};
use super::{Orientation, Population};
use crate::sampler::{Rng, hash_words};
use glam::{Affine3A, Vec3};

/// Entries of the `E[|d·n|]` table of an aligned population (over `cos` of the angle between
/// `d` and the axis).
const PROJECTION_ENTRIES: usize = 65;
/// Normals drawn per rejection attempt before giving up on a collision's normal.
const MAX_REJECTIONS: u32 = 256;
/// Most null collisions one [`FlakeMedium::collide`] makes before it gives up and reports no
/// collision (see the module docs).
pub const MAX_NULL_COLLISIONS: u32 = 4096;

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
    /// The density's modulation (object space), if any.
    modulation: Option<Modulation>,
}

/// Steps of the midpoint rule of [`FlakeMedium::optical_depth`] with a modulated density.
pub const SHADOW_STEPS: u32 = 16;

/// The populations of a body as one statistical medium of flakes (world space).
#[derive(Clone, Debug, PartialEq)]
pub struct FlakeMedium {
    flakes: Vec<Flakes>,
    /// World to object space (where the modulations are defined).
    to_object: Affine3A,
    /// Whether any population is modulated (else the rate is constant along a ray).
    modulated: bool,
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
                    modulation: p.modulation.clone(),
                }
            })
            .collect();
        FlakeMedium {
            modulated: pops.iter().any(|p| p.modulation.is_some()),
            flakes,
            to_object: to_world.inverse(),
        }
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

    /// The unmodulated collision rate for unit direction `d`, world units⁻¹ (the rate itself
    /// without a modulation; the majorant of the modulated rate with one).
    pub fn sigma(&self, d: Vec3) -> f32 {
        self.flakes.iter().map(|f| Self::sigma_of(f, d)).sum()
    }

    /// The largest [`sigma`](Self::sigma) over all directions, world units⁻¹ (an interpolated
    /// projection lies between two of its table's entries).
    pub fn sigma_max(&self) -> f32 {
        self.flakes
            .iter()
            .map(|f| {
                let e = match f.orientation {
                    Orientation::Uniform => 0.5,
                    Orientation::Aligned { .. } => f.projection.iter().copied().fold(0.0, f32::max),
                };
                f.area_density * e
            })
            .sum()
    }

    /// The collision rate at world point `p` for unit direction `d`, world units⁻¹:
    /// `Σ σ_k(d) · m_k(p)`.
    pub fn sigma_at(&self, p: Vec3, d: Vec3) -> f32 {
        let q = self.to_object.transform_point3(p);
        self.flakes
            .iter()
            .map(|f| Self::sigma_of(f, d) * f.modulation.as_ref().map_or(1.0, |m| m.at(q)))
            .sum()
    }

    /// The optical depth `∫ σ(p, d) dt` of the flakes along `o + t d`, `0 ≤ t ≤ t_max` (for a
    /// shadow segment): exact without a modulation; with one, the midpoint rule on
    /// [`SHADOW_STEPS`] steps (a smooth noise field between cells of the modulation; a shadow ray
    /// through the statistical form is itself an approximation knob, so a deterministic estimate
    /// is preferred over a noisy unbiased one such as ratio tracking).
    pub fn optical_depth(&self, o: Vec3, d: Vec3, t_max: f32) -> f32 {
        if !self.modulated {
            return self.sigma(d) * t_max;
        }
        let h = t_max / SHADOW_STEPS as f32;
        (0..SHADOW_STEPS)
            .map(|i| self.sigma_at(o + d * (h * (i as f32 + 0.5)), d))
            .sum::<f32>()
            * h
    }

    /// Whether any population's density is modulated.
    pub fn is_modulated(&self) -> bool {
        self.modulated
    }

    /// Samples the first collision along the ray `o + t d` (world space, `d` unit) before
    /// `t_max`. Without a modulation the distance is exponential with rate [`FlakeMedium::sigma`]
    /// and `o` is not used; with one, delta tracking (module docs).
    ///
    /// # Arguments
    /// * `u` – two uniform numbers: the first tentative distance, and the key of every other draw
    ///   (population, acceptance, further distances, normal, entry).
    pub fn collide(&self, o: Vec3, d: Vec3, t_max: f32, u: glam::Vec2) -> Option<FlakeCollision> {
        let sigma = self.sigma(d);
        if !(sigma > 0.0) {
            return None;
        }
        let mut t = -(1.0 - u.x).ln() / sigma;
        if !(t < t_max) {
            return None;
        }
        let mut rng = Rng::new(hash_words(&[u64::from(u.y.to_bits()), 0x666c_616b]));
        if !self.modulated {
            let flakes = self.pick(d, sigma, &mut rng);
            return Self::finish(flakes, d, t, &mut rng);
        }
        let mut nulls = 0;
        loop {
            let flakes = self.pick(d, sigma, &mut rng);
            let real = match &flakes.modulation {
                None => true,
                Some(m) => {
                    let m = m.at(self.to_object.transform_point3(o + d * t));
                    survives(m, || rng.uniform())
                }
            };
            if real {
                return Self::finish(flakes, d, t, &mut rng);
            }
            nulls += 1;
            if nulls >= MAX_NULL_COLLISIONS {
                return None;
            }
            t += -(1.0 - rng.uniform()).ln() / sigma;
            if !(t < t_max) {
                return None;
            }
        }
    }

    /// The population of a (tentative) collision, in proportion to its share of the rate.
    fn pick(&self, d: Vec3, sigma: f32, rng: &mut Rng) -> &Flakes {
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
        flakes
    }

    /// The collision with `flakes` at distance `t`: its normal and entry.
    fn finish(flakes: &Flakes, d: Vec3, t: f32, rng: &mut Rng) -> Option<FlakeCollision> {
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
            let c = m
                .collide(Vec3::ZERO, d, f32::INFINITY, u)
                .expect("a collision");
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
