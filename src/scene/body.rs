//! A translucent stone's compiled body (issue 17): the boundary interface and the interior
//! medium, in **object units** (the world converts the coefficients with the stage's scale).

use crate::bsdf::dispersion::{Dispersion, Ior};
use crate::bsdf::{Bsdf, Distribution, Masking, MicrofacetDistribution, RoughDielectric};
use crate::bsdf::{SmoothDielectric, StackDesc};
use crate::color::Rgb;
use crate::medium::{HenyeyGreenstein, Homogeneous, Medium};
use crate::platelet::Population;
use crate::spectrum::measured::Measured;

/// Stratification grid of a rough boundary's energy tables (`64² · 4` samples per entry): light
/// meets a stone's boundary many times (total internal reflection), so the tables' noise adds up;
/// at the coats' 32 a rough η 2.4 sphere in a white furnace reads 1.0035 ± 0.0009, at 64
/// (measured in tests/translucent/furnace.rs, `furnace_default_tables_full`) it is within noise.
pub const BOUNDARY_GRID: usize = 64;

/// The body of a translucent stone.
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    /// Absolute IOR of the stone (the outside is air, IOR 1); for a dispersive body its index at
    /// the d line (587.56 nm), which RGB paths use.
    pub ior: f32,
    /// The index as a function of the wavelength, for spectral paths (`None`: not dispersive).
    pub dispersion: Option<Ior>,
    /// Boundary roughness `α` (0: a smooth, specular boundary).
    pub alpha: f32,
    /// Micro-facet distribution of a rough boundary.
    pub distribution: Distribution,
    /// Masking of a rough boundary.
    pub masking: Masking,
    /// Whether a rough boundary has its multiple-scattering compensation (see
    /// [`Body::boundary`]); `false` matches peers whose rough dielectric has none.
    pub compensation: bool,
    /// The interior, coefficients per object unit; `None` is clear.
    pub medium: Option<Interior>,
    /// Platelet populations (object space); their entries index [`Body::platelet_materials`]
    /// offset by `Surface::body_index() + 1`.
    pub platelets: Vec<Population>,
    /// The layered materials of platelet faces, by name, each with the body's IOR as its outside
    /// medium.
    pub platelet_materials: Vec<(String, StackDesc)>,
    /// A doubly refractive crystal (`ior` is then its ordinary index); `None`: isotropic.
    pub crystal: Option<Crystal>,
}

/// The optics of a doubly refractive body (object space).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crystal {
    /// Its indices beyond the body's `ior` and its axes.
    pub indices: Indices,
    /// Own dispersion laws of the indices beyond the body's (uniaxial `[ε, —]`, biaxial
    /// `[n_β, n_γ]`); `None`: that index keeps its difference from the body's index at the d
    /// line at every wavelength.
    pub laws: [Option<Ior>; 2],
    /// Absorption per object unit on top of the medium's, per principal wave: uniaxial
    /// `[ω, ε across the axis, 0]`; biaxial `[α, β, γ]` (light vibrating along X, Y, Z).
    pub sigma: [Rgb; 3],
    /// `sigma`'s spectra where the recipe gave a spectrum (`sigma` is then the coefficient of
    /// its colour's projection), read per wavelength by spectral transport.
    pub sigma_measured: [Option<&'static Measured>; 3],
    /// A thin section ([`crate::recipe::crystal::ThinSectionDesc`]): nanometres of crystal per
    /// object unit; its two waves add coherently. `None`: a gem, incoherent.
    pub thin_nm: Option<f32>,
}

/// A crystal's principal indices and axes; the first index is the body's `ior`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Indices {
    /// One optic axis.
    Uniaxial {
        /// Extraordinary index ε at the d line (the ordinary one, ω, is the body's `ior`).
        ne: f32,
        /// Unit optic axis.
        axis: glam::Vec3,
    },
    /// Two optic axes.
    Biaxial {
        /// n_β at the d line (n_α is the body's `ior`).
        beta: f32,
        /// n_γ at the d line.
        gamma: f32,
        /// Orthonormal principal axes X, Y, Z (the vibration directions of n_α, n_β, n_γ).
        axes: [glam::Vec3; 3],
    },
}

impl Crystal {
    /// Whether the absorption depends on the wave.
    pub fn pleochroic(&self) -> bool {
        !self.sigma.iter().all(|s| s.is_black())
    }
}

/// A homogeneous interior as the recipe gives it (per object unit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interior {
    /// Absorption coefficient per object unit.
    pub sigma_a: Rgb,
    /// Scattering coefficient per object unit.
    pub sigma_s: Rgb,
    /// Henyey–Greenstein asymmetry.
    pub g: f32,
    /// A measured absorption spectrum per object unit (`sigma_a` is its RGB projection).
    pub sigma_a_measured: Option<Measured>,
    /// A measured scattering spectrum per object unit (`sigma_s` is its RGB projection).
    pub sigma_s_measured: Option<Measured>,
}

impl Body {
    /// The boundary's BSDF: a smooth dielectric, or a rough one (Walter et al. 2007) with its
    /// reciprocal multiple-scattering compensation (`bsdf::interface_energy`), so a lossless body
    /// keeps all the energy that enters it — unless [`Body::compensation`] is off (the plain
    /// interface of Mitsuba 3, pbrt-v4 and Cycles). `eta` is inside over outside.
    pub fn boundary(&self) -> Bsdf {
        let law = self.dispersion.map(|inside| Dispersion {
            inside,
            outside: 1.0,
        });
        if self.alpha == 0.0 {
            let b = SmoothDielectric::new(self.ior);
            Bsdf::SmoothDielectric(match law {
                Some(l) => SmoothDielectric {
                    dispersion: Some(l),
                    ..b
                },
                None => b,
            })
        } else {
            let d = MicrofacetDistribution::from_alpha(self.distribution, self.alpha)
                .with_masking(self.masking);
            let plain = RoughDielectric::new(d, self.ior);
            let mut b = if self.compensation {
                plain.with_energy_tables_at(BOUNDARY_GRID)
            } else {
                plain
            };
            b.dispersion = law;
            Bsdf::Dielectric(b)
        }
    }

    /// The interior as a runtime medium in world units: `scale` is the stage's uniform
    /// object-to-world scale; `scattering: false` is the absorption-only approximation.
    pub fn medium(&self, scale: f32, scattering: bool) -> Medium {
        match self.medium {
            None => Medium::Vacuum,
            Some(m) => {
                let h = Homogeneous {
                    sigma_a: m.sigma_a * (1.0 / scale),
                    sigma_s: m.sigma_s * (1.0 / scale),
                    phase: HenyeyGreenstein::new(m.g),
                    sigma_a_measured: m.sigma_a_measured.map(|s| s.scaled(1.0 / scale).intern()),
                    sigma_s_measured: m.sigma_s_measured.map(|s| s.scaled(1.0 / scale).intern()),
                };
                Medium::Homogeneous(if scattering {
                    h
                } else {
                    h.without_scattering()
                })
            }
        }
    }

    /// Every platelet entry with the material of its faces, in recipe order: population index,
    /// entry index, material name and description. `body_index` is the surface's
    /// (`Surface::body_index`): the populations' material indices start one past it.
    pub fn platelet_entries(
        &self,
        body_index: u32,
    ) -> impl Iterator<Item = (usize, usize, &str, &StackDesc)> {
        self.platelets.iter().enumerate().flat_map(move |(k, pop)| {
            pop.entries
                .iter()
                .enumerate()
                .filter_map(move |(j, &(_, m))| {
                    let i = m.checked_sub(body_index)?.checked_sub(1)? as usize;
                    let (name, stack) = self.platelet_materials.get(i)?;
                    Some((k, j, name.as_str(), stack))
                })
        })
    }

    /// Whether the interior absorbs or scatters at all (the `medium` effect).
    pub fn has_medium(&self) -> bool {
        self.medium.is_some_and(|m| {
            m.sigma_a != Rgb::ZERO
                || m.sigma_s != Rgb::ZERO
                || m.sigma_a_measured.is_some_and(|s| s.max() > 0.0)
                || m.sigma_s_measured.is_some_and(|s| s.max() > 0.0)
        })
    }

    /// Whether the interior is given by a measured spectrum (which turns spectral transport on).
    pub fn has_measured_medium(&self) -> bool {
        self.medium
            .is_some_and(|m| m.sigma_a_measured.is_some() || m.sigma_s_measured.is_some())
    }
}
