//! A doubly refractive crystal at one wavelength, uniaxial or biaxial: what the boundary
//! ([`super::boundary`]) and the camera path's crystal steps ([`super::crystal`]) ask of it — its
//! two waves' names, indices, rays, fields and absorption weights.

use super::biaxial::Biaxial;
use super::cvec::cv as complex;
use super::uniaxial::Uniaxial;
use glam::DVec3;

/// A wave's kind: s or p on the isotropic side, ordinary or extraordinary in the crystal.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Isotropic side, electric field across the plane of incidence.
    S,
    /// Isotropic side, electric field in the plane of incidence.
    P,
    /// Crystal, ordinary wave.
    O,
    /// Crystal, extraordinary wave.
    E,
    /// Biaxial crystal, the fast wave (the index surface's inner sheet, the smaller index).
    Fast,
    /// Biaxial crystal, the slow wave (the outer sheet, the larger index).
    Slow,
}

/// A crystal's optics at one wavelength.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Optics {
    /// One optic axis: the ordinary and extraordinary waves.
    Uniaxial(Uniaxial),
    /// Two optic axes: the fast and slow waves.
    Biaxial(Biaxial),
}

impl Optics {
    /// Its two waves, in the order the boundary returns them (outputs 2 and 3).
    pub fn modes(&self) -> [Mode; 2] {
        match self {
            Optics::Uniaxial(_) => [Mode::O, Mode::E],
            Optics::Biaxial(_) => [Mode::Fast, Mode::Slow],
        }
    }

    /// The boundary's output slot (2 or 3) of the crystal wave `mode`.
    pub fn slot(&self, mode: Mode) -> usize {
        if mode == self.modes()[0] { 2 } else { 3 }
    }

    /// The phase index of the wave `mode` with unit wave normal `dir`.
    pub fn index(&self, dir: DVec3, mode: Mode) -> f64 {
        match self {
            Optics::Uniaxial(x) => match mode {
                Mode::O => x.no,
                _ => x.extraordinary_index(dir),
            },
            Optics::Biaxial(x) => x.indices(dir)[usize::from(mode == Mode::Slow)],
        }
    }

    /// The unit ray (energy direction) of the wave `mode` with unit wave normal `dir`.
    pub fn ray(&self, dir: DVec3, mode: Mode) -> DVec3 {
        match self {
            Optics::Uniaxial(x) => match mode {
                Mode::E => x.ray(dir * x.extraordinary_index(dir)),
                _ => dir,
            },
            Optics::Biaxial(x) => x.ray(dir * self.index(dir, mode)),
        }
    }

    /// The unit wave normal of the wave `mode` whose energy travels along the unit `ray`.
    pub fn wave_of_ray(&self, ray: DVec3, mode: Mode) -> DVec3 {
        match self {
            // k ∝ n_o² (r·c) c + n_e² (r − (r·c) c), inverting `Uniaxial::ray`.
            Optics::Uniaxial(x) => match mode {
                Mode::E => {
                    let c = x.axis;
                    let along = ray.dot(c) * c;
                    (x.no * x.no * along + x.ne * x.ne * (ray - along)).normalize()
                }
                _ => ray,
            },
            Optics::Biaxial(x) => x.wave_of_ray(ray, mode == Mode::Slow),
        }
    }

    /// The unit electric field of the wave `mode` travelling along the unit `ray` (across the
    /// ray; any direction across it where the two waves coincide).
    pub fn field(&self, ray: DVec3, mode: Mode) -> DVec3 {
        match self {
            Optics::Uniaxial(x) => {
                let across = ray.cross(x.axis).try_normalize();
                match (mode, across) {
                    (_, None) => ray.any_orthonormal_vector(),
                    (Mode::O, Some(a)) => a,
                    // In the plane of ray and axis, across the ray.
                    (_, Some(a)) => a.cross(ray).normalize(),
                }
            }
            Optics::Biaxial(_) => self.field_of_normal(self.wave_of_ray(ray, mode), ray, mode),
        }
    }

    /// [`Optics::field`] of the wave `mode` with unit wave normal `s` and ray `ray` (a biaxial
    /// crystal's; a uniaxial crystal's field needs only the ray).
    pub fn field_of_normal(&self, s: DVec3, ray: DVec3, mode: Mode) -> DVec3 {
        match self {
            Optics::Uniaxial(_) => self.field(ray, mode),
            Optics::Biaxial(x) => {
                let k = self.index(s, mode) * s;
                let reference = ray.any_orthonormal_vector();
                let e = x.field(complex(k), reference, mode == Mode::Slow);
                let e = DVec3::new(e[0].re, e[1].re, e[2].re);
                (e - ray * e.dot(ray)).try_normalize().unwrap_or(reference)
            }
        }
    }

    /// The shares of the principal absorptions a biaxial crystal's wave `mode` along the unit
    /// `ray` takes: `(D̂·X)², (D̂·Y)², (D̂·Z)²` of its unit displacement, so that its absorption is
    /// `Σ wᵢ σᵢ` — the absorbing crystal's quadratic form (Born & Wolf §15.6), which for a
    /// uniaxial crystal gives `σ_ω cos² θ + σ_ε sin² θ`. `None` for a uniaxial crystal (its
    /// renderer keeps that closed form).
    pub fn absorption_weights(&self, ray: DVec3, mode: Mode) -> Option<[f64; 3]> {
        self.absorption_weights_of(self.wave_of_ray(ray, mode), ray, mode)
    }

    /// [`Optics::absorption_weights`] of the wave with unit wave normal `s`.
    pub fn absorption_weights_of(&self, s: DVec3, ray: DVec3, mode: Mode) -> Option<[f64; 3]> {
        let Optics::Biaxial(x) = self else {
            return None;
        };
        let d = x.displacement(self.field_of_normal(s, ray, mode));
        Some(x.axes.map(|a| a.dot(d).powi(2)))
    }
}
