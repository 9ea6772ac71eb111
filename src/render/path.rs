//! The state a camera path carries from vertex to vertex (replaces the loose locals of the path
//! loop; the loop itself is [`super::integrator`]).

use super::world::Hit;
use crate::bsdf::{BsdfSample, LobeFlags};
use crate::color::Rgb;
use crate::geometry::MediumId;
use crate::geometry::Ray;
use crate::geometry::ray::OFFSET_SCALE;
use crate::spectrum::Spectral;
use glam::Vec3;

/// Radiance and first-hit data of one camera path.
#[derive(Clone, Copy, Debug, Default)]
pub struct PathSample {
    /// Radiance along the camera ray, as the film stores it (linear Rec.709).
    pub radiance: Rgb,
    /// True when `radiance` is the Rec.709 image of a spectral estimate's CIE XYZ (a linear map of
    /// a non-negative XYZ): one sample of a saturated colour may then have a negative channel,
    /// which the film keeps (the mean is the image of the mean XYZ). A spectral estimate that is
    /// not finite and non-negative at every wavelength has a NaN `radiance` and is dropped.
    pub signed: bool,
    /// Albedo at the first hit (0 where the ray leaves the scene or meets a light).
    pub albedo: Rgb,
    /// World shading normal at the first hit (facet normal on glitter), 0 if none.
    pub normal: Vec3,
    /// Distance to the first hit along the camera ray, if any.
    pub depth: Option<f32>,
    /// Material index at the first hit: ≥ 0 the stone's material, −1 the floor, −2 nothing or a
    /// light.
    pub material: i32,
    /// Rays traced (camera, extension and shadow rays).
    pub rays: u32,
}

/// The scattering event that produced the current ray (for the MIS weight of emission the ray
/// reaches).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrevVertex {
    /// Density per steradian of the sampled direction.
    pub pdf: f32,
    /// The point the ray left.
    pub p: Vec3,
    /// The sampled lobe: a specular lobe has no density, so emission it reaches takes weight 1.
    pub flags: LobeFlags,
    /// Whether next-event estimation ran at the vertex: where it did not (a medium point, a
    /// reflecting surface inside the stone), emission the ray reaches takes weight 1.
    pub nee: bool,
}

/// A vertex where manifold next-event estimation ran, and the BSDF-sampled continuation from it:
/// if the path then crosses the boundary as the walk's chain does and meets a light, that light
/// is weighted against the walk's ([`super::manifold`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ManifoldVertex {
    /// The vertex: the origin of the ray that left it.
    pub p: Vec3,
    /// The sampled direction (unit, world space).
    pub d: Vec3,
    /// Density of the continuation: the direction's per steradian, times the boundary's
    /// probability of refracting at each crossing so far.
    pub pdf: f32,
    /// The chain the walk at the vertex solved for.
    pub chain: crate::render::manifold::Chain,
    /// Specular transmissions through the boundary since the vertex (and nothing else); the
    /// path is the walk's when they number the chain's [`crossings`](crate::render::manifold::Chain::crossings).
    pub crossings: u8,
}

/// Everything a path knows between two vertices, generic over the transported light `S`.
#[derive(Clone, Copy, Debug)]
pub struct PathState<S: Spectral> {
    /// Throughput `β`: the product of `f |cos| / pdf` so far, divided by the roulette
    /// probabilities.
    pub beta: S,
    /// Radiance gathered so far.
    pub l: S,
    /// Per channel, the product along the path of the free-flight densities over the hero
    /// channel's ([`crate::medium`]): contributions are divided by its mean. All ones until the
    /// first medium segment, and unused ([`PathState::hero`] `None`) on paths that meet no medium.
    pub r: S,
    /// The channel free flights are sampled from, picked at the path's first medium segment.
    pub hero: Option<usize>,
    /// The platelet the current ray leaves from (it must not hit it again).
    pub platelet: Option<crate::platelet::PlateletId>,
    /// The product of `η²` of the refractions so far (pbrt-v4 §14.1.5): Russian roulette looks at
    /// `β · eta_scale`, which removes the radiance compression of entering a denser medium.
    pub eta_scale: f32,
    /// The medium the current ray travels through.
    pub medium: MediumId,
    /// The wavelengths the path's light is carried at (zero-sized in the RGB variant); after a
    /// fluorescent re-radiation, the excitation wavelengths that fed `film`.
    pub lambda: S::Wavelengths,
    /// The wavelengths the camera sees, with the densities they were drawn with: what the
    /// radiance `l` is projected onto the film at. The same as `lambda` until the path meets a
    /// fluorescent base.
    pub film: S::Wavelengths,
    /// RGB transport after a fluorescent re-radiation (issue 20): the 3 × 3 map from the
    /// channels the path carries to the film's (`diag(β) · M` at the event, composed over
    /// events); contributions pass through it ([`PathState::gather`]) and `β` restarts at one.
    /// `None` on every path that has not fluoresced and always in spectral transport, which
    /// changes its wavelengths instead.
    pub remap: Option<[[f32; 3]; 3]>,
    /// Scattering events so far (surface and medium; it positions the sampler's slots).
    pub depth: u32,
    /// Of those, scattering events in a medium (bounded by `medium-depth`, not `max-depth`).
    pub medium_events: u32,
    /// The event that produced the current ray; `None` for the camera ray.
    pub prev: Option<PrevVertex>,
    /// The last vertex where manifold next-event estimation ran, while the path since is its
    /// BSDF-sampled continuation toward the boundary.
    pub manifold: Option<ManifoldVertex>,
}

impl<S: Spectral> PathState<S> {
    /// A camera path carrying `lambda`, starting in `medium`.
    pub fn new(lambda: S::Wavelengths, medium: MediumId) -> Self {
        PathState {
            beta: S::ONE,
            l: S::ZERO,
            r: S::ONE,
            hero: None,
            platelet: None,
            eta_scale: 1.0,
            medium,
            lambda,
            film: lambda,
            remap: None,
            depth: 0,
            medium_events: 0,
            prev: None,
            manifold: None,
        }
    }

    /// Surface scattering events so far (what `max-depth` bounds).
    #[inline]
    pub fn bounces(&self) -> u32 {
        self.depth - self.medium_events
    }

    /// Takes a scattering event in a medium at `p`: the free-flight weight has been applied; the
    /// phase function's sample has weight 1, so only the vertex is recorded (its density for the
    /// MIS weight of emission the new ray reaches).
    #[inline]
    pub fn scatter_in_medium(&mut self, pdf: f32, p: Vec3) {
        self.depth += 1;
        self.medium_events += 1;
        self.prev = Some(PrevVertex {
            pdf,
            p,
            flags: LobeFlags::DIFFUSE,
            nee: false,
        });
    }

    /// The throughput a contribution is weighted by: `β`, divided by the mean of the channel
    /// ratios once the path has sampled a free flight.
    #[inline]
    pub fn throughput(&self) -> S {
        match self.hero {
            None => self.beta,
            Some(_) => {
                let m = self.r.average();
                if m > 0.0 {
                    self.beta * (1.0 / m)
                } else {
                    S::ZERO
                }
            }
        }
    }

    /// Adds emitted radiance `le` reaching the path with MIS weight `w`; returns what was added
    /// (as [`PathState::gather`]).
    #[inline]
    pub fn add_emission(&mut self, le: S, w: f32) -> S {
        self.gather(self.throughput() * le * w)
    }

    /// Adds a contribution `c` (throughput × radiance, in the channels the path carries) to the
    /// radiance, through the fluorescent remap if the path has one; returns what was added (the
    /// Stokes AOVs weigh it by their rows, [`crate::polarisation::stokes`]).
    #[inline]
    pub fn gather(&mut self, c: S) -> S {
        let added = self.gathered(c);
        self.l += added;
        added
    }

    /// What [`PathState::gather`] would add for `c`, without adding it.
    #[inline]
    pub fn gathered(&self, c: S) -> S {
        match &self.remap {
            None => c,
            Some(m) => c.remix(m),
        }
    }

    /// Takes an RGB re-radiation matrix `m` (rows: outgoing channels, columns: incident):
    /// the film map becomes `remap · diag(β) · m`, and `β` one.
    #[inline]
    pub fn take_remap(&mut self, m: &[[f32; 3]; 3]) {
        let b: [f32; 3] = std::array::from_fn(|c| {
            if c < S::CHANNELS {
                self.beta.channel(c)
            } else {
                0.0
            }
        });
        let local: [[f32; 3]; 3] = std::array::from_fn(|r| std::array::from_fn(|k| b[r] * m[r][k]));
        self.remap = Some(match &self.remap {
            None => local,
            Some(prev) => std::array::from_fn(|r| {
                std::array::from_fn(|k| (0..3).map(|j| prev[r][j] * local[j][k]).sum())
            }),
        });
        self.beta = S::ONE;
    }

    /// Takes a free flight's `value` and per-channel `pdf` ([`crate::medium::FreeFlight`]):
    /// `β ← β·value/p_hero`, `r ← r·pdf/p_hero`. `hero` is the path's hero channel. A zero hero
    /// density ends the path (its throughput becomes zero).
    #[inline]
    pub fn take_flight(&mut self, hero: usize, value: S, pdf: S) {
        let ph = pdf.channel(hero);
        if ph > 0.0 {
            let inv = 1.0 / ph;
            self.beta *= value * inv;
            self.r *= pdf * inv;
        } else {
            self.beta = S::ZERO;
        }
    }

    /// Takes the scattering event `bs` at `p`: multiplies the throughput, records the vertex and,
    /// for a refraction, its `η²` and the medium crossed into.
    ///
    /// # Arguments
    /// * `inside` – the medium on the far side of the surface when the path crosses it from
    ///   `MediumId::OUTSIDE` (a crossing from any other medium returns to the outside).
    #[inline]
    pub fn scatter(&mut self, bs: &BsdfSample<S>, p: Vec3, inside: MediumId) {
        self.beta *= bs.weight;
        if bs.flags.is_transmission() {
            self.eta_scale *= bs.eta * bs.eta;
            self.medium = if self.medium == MediumId::OUTSIDE {
                inside
            } else {
                MediumId::OUTSIDE
            };
        }
        self.depth += 1;
        self.prev = Some(PrevVertex {
            pdf: bs.pdf,
            p,
            flags: bs.flags,
            nee: true,
        });
    }

    /// The survival probability of Russian roulette, `min(1, max β·eta_scale)`.
    #[inline]
    pub fn survival(&self) -> f32 {
        (self.throughput() * self.eta_scale).max_channel().min(1.0)
    }

    /// False once the throughput is zero or invalid: the path carries nothing more.
    #[inline]
    pub fn alive(&self) -> bool {
        self.beta.is_valid() && !self.beta.is_black() && self.r.is_valid()
    }
}

/// A medium scattering point `p` on `ray`, moved off the surface hit the ray was heading for
/// (`found`) to at least the spawn offset ([`OFFSET_SCALE`]) on the ray's side of its tangent
/// plane. A point sampled within rounding of the boundary would start rays that miss it (the
/// sphere's exit root rounds to ≤ 0) and leave the stone without crossing its surface, then
/// scatter in the interior medium outside the stone until `medium-depth` ends them with nothing
/// (tests/translucent/furnace.rs: one path in ~10⁴–10⁵ at σs 10–100 per unit). The move is
/// below the offset every spawned surface ray gets.
#[inline]
pub(super) fn keep_off_the_boundary(p: Vec3, ray: &Ray, found: Option<&Hit>) -> Vec3 {
    let Some(Hit::Stone(h)) = found else {
        return p;
    };
    let eps = OFFSET_SCALE * h.p.abs().max_element().max(1.0);
    // The normal facing away from the ray's side, and p's distance below the tangent plane.
    let n = if h.ng.dot(ray.dir) > 0.0 { h.ng } else { -h.ng };
    let depth = (h.p - p).dot(n);
    if depth < eps {
        p - n * (eps - depth)
    } else {
        p
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::{Lobe, LobeKind};
    use crate::spectrum::{RgbSample, RgbWavelengths};

    fn sample(kind: LobeKind, weight: f32, eta: f32) -> BsdfSample {
        BsdfSample::from_eval(
            Vec3::Z,
            RgbSample::splat(weight),
            1.0,
            Lobe { kind, layer: 0 },
        )
        .unwrap()
        .with_eta(eta)
    }

    #[test]
    fn refraction_switches_medium_and_keeps_roulette_fair() {
        let inside = MediumId(3);
        let mut p = PathState::<RgbSample>::new(RgbWavelengths, MediumId::OUTSIDE);
        // Entering glass in radiance mode: weight (1 − F)/η² ≈ 0.96/2.25.
        p.scatter(
            &sample(LobeKind::Transmission, 0.96 / 2.25, 1.5),
            Vec3::ZERO,
            inside,
        );
        assert_eq!(p.medium, inside);
        assert!((p.survival() - 0.96).abs() < 1e-5, "{}", p.survival());
        p.scatter(&sample(LobeKind::Glossy, 0.5, 1.0), Vec3::ZERO, inside);
        assert_eq!(p.medium, inside, "a reflection stays inside");
        p.scatter(
            &sample(LobeKind::Transmission, 1.0, 1.0 / 1.5),
            Vec3::ONE,
            inside,
        );
        assert_eq!(p.medium, MediumId::OUTSIDE);
        assert!((p.eta_scale - 1.0).abs() < 1e-6);
        assert_eq!(p.depth, 3);
        assert_eq!(p.prev.unwrap().p, Vec3::ONE);
    }
}
