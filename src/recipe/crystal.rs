//! Serde description of a doubly refractive body's `crystal` (part of [`super::body`]): uniaxial
//! or biaxial indices and axes, and the pleochroic absorption per wave. Compiles into
//! [`crate::scene::body::Crystal`].
//!
//! ```ron
//! crystal: Uniaxial(ne: 1.640, axis: (0.0, 0.0, 1.0),     // ω is the body's `ior`
//!     pleochroism: Some((ordinary: Srgb(0.2, 0.3, 0.1), extraordinary: Srgb(0.5, 0.8, 0.4),
//!                        distance: 1.0))),
//! crystal: Biaxial(beta: 1.542, gamma: 1.546,            // n_α is the body's `ior`
//!     x_axis: (1.0, 0.0, 0.0), z_axis: (0.0, 0.0, 1.0),  // the vibration directions of α, γ
//!     pleochroism: Some((alpha: …, beta: …, gamma: …, distance: 1.0))),
//! crystal: Uniaxial(ne: 1.553, axis: (1.0, 0.0, 0.0),    // a quartz plate …
//!     thin_section: Some((unit_nm: 15000.0))),          // … 15 µm per object unit, coherent
//! crystal: Uniaxial(ne: 1.5534, axis: (0.0, 1.0, 0.0),   // each index its own dispersion
//!     ne_dispersion: Some(Abbe(68.5))),                 // (ω's is the body's `dispersion`)
//! ```

use super::dispersion::DispersionDesc;
pub use super::pleochroism::{PleochroismDesc, TrichroismDesc};
use crate::bsdf::dispersion::Ior;
use crate::color::Rgb;
use serde::{Deserialize, Deserializer, Serialize};

ranged!(ne_range, "crystal.ne", 1.0001, 4.0);
ranged!(beta_range, "crystal.beta", 1.0001, 4.0);
ranged!(gamma_range, "crystal.gamma", 1.0001, 4.0);
ranged!(unit_nm_range, "thin_section.unit_nm", open 0.0, 1e7);

/// The optics of a doubly refractive body.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum CrystalDesc {
    /// A uniaxial crystal (quartz, calcite, tourmaline, zircon, corundum, beryl): waves across
    /// the optic axis polarised along it meet the extraordinary index `ne` (ε), every other
    /// polarisation the ordinary `ior` (ω).
    Uniaxial {
        /// Extraordinary index ε, 1.0001 ..= 4 (at the d line when there is dispersion).
        #[serde(deserialize_with = "ne_range")]
        ne: f32,
        /// ε's own dispersion law (as the body's `dispersion`, through `ne` at the d line);
        /// default: the birefringence ε − ω at the d line kept at every wavelength.
        #[serde(default)]
        ne_dispersion: Option<DispersionDesc>,
        /// The optic axis in the stone's object space (relative to the cut), any non-zero
        /// length.
        #[serde(deserialize_with = "super::surface::axis_check")]
        axis: (f32, f32, f32),
        /// Dichroism: absorption that depends on the wave (default none).
        #[serde(default)]
        pleochroism: Option<PleochroismDesc>,
        /// A thin plate or section whose two waves add coherently (default: a gem, incoherent).
        #[serde(default)]
        thin_section: Option<ThinSectionDesc>,
    },
    /// A biaxial crystal (cordierite — iolite —, the feldspars, peridot, topaz): light vibrating
    /// along the principal axis X meets the body's `ior` (n_α), along Y `beta` (n_β), along Z
    /// `gamma` (n_γ), with `ior ≤ beta ≤ gamma`.
    Biaxial {
        /// n_β, 1.0001 ..= 4, at least the body's `ior` (at the d line when there is
        /// dispersion).
        #[serde(deserialize_with = "beta_range")]
        beta: f32,
        /// n_γ, 1.0001 ..= 4, at least `beta`.
        #[serde(deserialize_with = "gamma_range")]
        gamma: f32,
        /// n_β's own dispersion law (through `beta` at the d line); default: n_β − n_α at the
        /// d line kept at every wavelength.
        #[serde(default)]
        beta_dispersion: Option<DispersionDesc>,
        /// n_γ's own dispersion law (through `gamma`); default: n_γ − n_α kept likewise.
        #[serde(default)]
        gamma_dispersion: Option<DispersionDesc>,
        /// The X axis (n_α's vibration direction) in the stone's object space, any non-zero
        /// length.
        #[serde(deserialize_with = "super::surface::axis_check")]
        x_axis: (f32, f32, f32),
        /// The Z axis (n_γ's), at least 5° from `x_axis`; made orthogonal to it (Y = Z × X).
        #[serde(deserialize_with = "super::surface::axis_check")]
        z_axis: (f32, f32, f32),
        /// Trichroism: absorption that depends on the vibration direction (default none).
        #[serde(default)]
        pleochroism: Option<TrichroismDesc>,
        /// A thin plate or section whose two waves add coherently (default: a gem, incoherent).
        #[serde(default)]
        thin_section: Option<ThinSectionDesc>,
    },
}

/// A crystal thin enough — much thinner than white light's coherence length, a few tens of
/// micrometres — that its two waves leave it together and interfere: a petrographic thin section,
/// a quartz wedge, a mica plate. Its boundary then refracts as an isotropic one of index `ior`
/// and its interior acts as a linear retarder of retardation `d (n₂ − n₁)` along each ray (the
/// Michel-Lévy interference colours between crossed polars; Born & Wolf §15.4.4), the walk-off
/// neglected. Turns spectral transport on.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ThinSectionDesc {
    /// Nanometres of crystal per object unit, 0 <..= 1e7 (a 2-unit slab with `unit_nm: 15000`
    /// is a 30 µm section).
    #[serde(deserialize_with = "unit_nm_range")]
    pub unit_nm: f32,
}

/// Sin² of the smallest angle allowed between a biaxial crystal's `x_axis` and `z_axis` (5°).
const MIN_AXES_SIN2: f32 = 0.007_596;

/// A biaxial crystal's checks the fields cannot make alone: the keyword the error is at and what
/// is wrong, or the orthonormal axes X, Y, Z.
pub fn biaxial_axes(
    ior: f32,
    beta: f32,
    gamma: f32,
    x: (f32, f32, f32),
    z: (f32, f32, f32),
) -> Result<[glam::Vec3; 3], (&'static str, String)> {
    if !(ior <= beta && beta <= gamma) {
        return Err((
            "beta",
            format!(
                "body.crystal: the indices must satisfy ior ≤ beta ≤ gamma (n_α ≤ n_β ≤ n_γ), \
                 got {ior} / {beta} / {gamma}"
            ),
        ));
    }
    let xv = glam::Vec3::new(x.0, x.1, x.2).normalize();
    let zv = glam::Vec3::new(z.0, z.1, z.2).normalize();
    if xv.cross(zv).length_squared() < MIN_AXES_SIN2 {
        return Err((
            "z_axis",
            format!(
                "body.crystal.z_axis = {z:?} is within 5° of x_axis = {x:?}: the principal \
                 axes must be at least 5° apart (z_axis is then made orthogonal to x_axis)"
            ),
        ));
    }
    let zv = (zv - xv * zv.dot(xv)).normalize();
    Ok([xv, zv.cross(xv), zv])
}

/// Largest principal index a crystal's dispersion law may reach.
const N_MAX: f32 = 4.0;

/// Wavelengths (nm) at which a crystal's laws are checked against each other: the visible range
/// the spectral variant samples, every 5 nm.
fn checked_wavelengths() -> impl Iterator<Item = f32> {
    (360..=830).step_by(5).map(|l| l as f32)
}

/// The index `d + offset` at `lambda` when `law` is `None` (the d line's difference kept).
fn index_at(law: Option<Ior>, body: Option<Ior>, n_d: f32, ior: f32, lambda: f32) -> f32 {
    match (law, body) {
        (Some(l), _) => l.at(lambda),
        (None, Some(b)) => b.at(lambda) + (n_d - ior),
        (None, None) => n_d,
    }
}

impl CrystalDesc {
    /// The crystal of a body of index `ior` (its law `body`, if dispersive), or the keyword the
    /// error is at and what is wrong. Each principal index with its own law must keep its order
    /// against the others at every visible wavelength (a uniaxial ε − ω its sign, at least 10⁻⁴
    /// from zero; biaxial n_α ≤ n_β ≤ n_γ).
    pub fn compile(
        &self,
        ior: f32,
        body: Option<Ior>,
    ) -> Result<crate::scene::body::Crystal, (&'static str, String)> {
        use crate::scene::body::{Crystal, Indices};
        let pleochroism = |m: String| ("pleochroism", format!("body.crystal.{m}"));
        let law = |d: &Option<DispersionDesc>, key: &'static str, n: f32| {
            d.map(|d| d.law_of(&format!("body.crystal.{key}"), n, N_MAX))
                .transpose()
                .map_err(|m| (key, m))
        };
        match self {
            CrystalDesc::Uniaxial {
                ne,
                ne_dispersion,
                axis,
                pleochroism: p,
                thin_section,
            } => {
                let [o, e] = match p.as_ref().map(|p| p.coefficients()) {
                    None => [(Rgb::ZERO, None); 2],
                    Some(r) => r.map_err(pleochroism)?,
                };
                let ne_law = law(ne_dispersion, "ne_dispersion", *ne)?;
                if ne_law.is_some() {
                    let sign = (*ne - ior).signum();
                    for l in checked_wavelengths() {
                        let o = body.map_or(ior, |b| b.at(l));
                        let d = index_at(ne_law, body, *ne, ior, l) - o;
                        if !(d * sign >= 1e-4) {
                            return Err((
                                "ne_dispersion",
                                format!(
                                    "body.crystal.ne_dispersion: ε − ω is {:+.5} at 587.56 nm \
                                     but {d:+.5} at {l} nm: the laws must keep the \
                                     birefringence's sign, at least 0.0001 from zero, over \
                                     360 ..= 830 nm",
                                    *ne - ior
                                ),
                            ));
                        }
                    }
                }
                Ok(Crystal {
                    indices: Indices::Uniaxial {
                        ne: *ne,
                        axis: glam::Vec3::new(axis.0, axis.1, axis.2).normalize(),
                    },
                    laws: [ne_law, None],
                    sigma: [o.0, e.0, Rgb::ZERO],
                    sigma_measured: [o.1, e.1, None],
                    thin_nm: thin_section.as_ref().map(|t| t.unit_nm),
                })
            }
            CrystalDesc::Biaxial {
                beta,
                gamma,
                beta_dispersion,
                gamma_dispersion,
                x_axis,
                z_axis,
                pleochroism: p,
                thin_section,
            } => {
                let axes = biaxial_axes(ior, *beta, *gamma, *x_axis, *z_axis)?;
                let sigma = match p.as_ref().map(|p| p.coefficients()) {
                    None => [(Rgb::ZERO, None); 3],
                    Some(r) => r.map_err(pleochroism)?,
                };
                let laws = [
                    law(beta_dispersion, "beta_dispersion", *beta)?,
                    law(gamma_dispersion, "gamma_dispersion", *gamma)?,
                ];
                if laws.iter().any(Option::is_some) {
                    for l in checked_wavelengths() {
                        let a = body.map_or(ior, |b| b.at(l));
                        let b = index_at(laws[0], body, *beta, ior, l);
                        let g = index_at(laws[1], body, *gamma, ior, l);
                        if !(a <= b && b <= g) {
                            // n_α > n_β can only come of β's law; n_β > n_γ of γ's, or of β's
                            // when γ has none.
                            let key = if a > b || laws[1].is_none() {
                                "beta_dispersion"
                            } else {
                                "gamma_dispersion"
                            };
                            return Err((
                                key,
                                format!(
                                    "body.crystal.{key}: at {l} nm the indices are {a:.5} / \
                                     {b:.5} / {g:.5}: they must keep n_α ≤ n_β ≤ n_γ over \
                                     360 ..= 830 nm"
                                ),
                            ));
                        }
                    }
                }
                Ok(Crystal {
                    indices: Indices::Biaxial {
                        beta: *beta,
                        gamma: *gamma,
                        axes,
                    },
                    laws,
                    sigma: sigma.map(|s| s.0),
                    sigma_measured: sigma.map(|s| s.1),
                    thin_nm: thin_section.as_ref().map(|t| t.unit_nm),
                })
            }
        }
    }

    /// The recipe key of the first principal index given its own dispersion law, if any.
    pub fn own_dispersion(&self) -> Option<&'static str> {
        match self {
            CrystalDesc::Uniaxial { ne_dispersion, .. } => {
                ne_dispersion.is_some().then_some("ne_dispersion")
            }
            CrystalDesc::Biaxial {
                beta_dispersion,
                gamma_dispersion,
                ..
            } => {
                if beta_dispersion.is_some() {
                    Some("beta_dispersion")
                } else {
                    gamma_dispersion.is_some().then_some("gamma_dispersion")
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn biaxial_axes_are_orthonormal_and_checked() {
        let [x, y, z] = biaxial_axes(1.5, 1.55, 1.6, (2.0, 0.0, 0.0), (0.3, 0.0, 1.0)).unwrap();
        assert!((x - glam::Vec3::X).length() < 1e-6 && (z - glam::Vec3::Z).length() < 1e-6);
        assert!((y - glam::Vec3::Y).length() < 1e-6, "{y}");
        let (at, msg) = biaxial_axes(1.5, 1.45, 1.6, (1.0, 0.0, 0.0), (0.0, 0.0, 1.0)).unwrap_err();
        assert!(at == "beta" && msg.contains("ior ≤ beta ≤ gamma"), "{msg}");
        assert!(biaxial_axes(1.5, 1.7, 1.6, (1.0, 0.0, 0.0), (0.0, 0.0, 1.0)).is_err());
        let (at, msg) =
            biaxial_axes(1.5, 1.55, 1.6, (1.0, 0.0, 0.0), (1.0, 0.05, 0.0)).unwrap_err();
        assert!(at == "z_axis" && msg.contains("within 5°"), "{msg}");
    }

    /// An index with its own law keeps it (through its d-line value); laws that would swap the
    /// indices' order somewhere in 360 ..= 830 nm are refused, naming the key and the wavelength.
    #[test]
    fn own_dispersion_laws_are_kept_and_their_order_checked() {
        use crate::bsdf::dispersion::LAMBDA_D;
        let uni = |law: Option<DispersionDesc>| CrystalDesc::Uniaxial {
            ne: 1.553,
            ne_dispersion: law,
            axis: (0.0, 0.0, 1.0),
            pleochroism: None,
            thin_section: None,
        };
        let c = uni(Some(DispersionDesc::Abbe(68.5)))
            .compile(1.544, None)
            .unwrap();
        let law = c.laws[0].unwrap();
        assert!((law.at(LAMBDA_D) - 1.553).abs() < 1e-5 && law.at(450.0) > 1.555);
        assert_eq!(c.laws[1], None);
        assert_eq!(uni(None).compile(1.544, None).unwrap().laws, [None, None]);
        assert_eq!(
            uni(Some(DispersionDesc::Abbe(68.5))).own_dispersion(),
            Some("ne_dispersion")
        );
        // A strongly dispersive ω (Abbe 12) overtakes a weakly dispersive ε in the blue.
        let body = Ior::from_abbe(1.544, 12.0);
        let (key, msg) = uni(Some(DispersionDesc::Abbe(200.0)))
            .compile(1.544, body)
            .unwrap_err();
        assert_eq!(key, "ne_dispersion");
        assert!(msg.contains("sign") && msg.contains(" nm"), "{msg}");
        // A law out of its own range is named with the crystal's key.
        let (key, msg) = uni(Some(DispersionDesc::Abbe(1.0)))
            .compile(1.544, None)
            .unwrap_err();
        assert!(
            key == "ne_dispersion" && msg.contains("body.crystal.ne_dispersion"),
            "{msg}"
        );

        let bi = |b: Option<DispersionDesc>, g: Option<DispersionDesc>| CrystalDesc::Biaxial {
            beta: 1.5480,
            gamma: 1.5600,
            beta_dispersion: b,
            gamma_dispersion: g,
            x_axis: (1.0, 0.0, 0.0),
            z_axis: (0.0, 0.0, 1.0),
            pleochroism: None,
            thin_section: None,
        };
        let ok = bi(None, Some(DispersionDesc::Abbe(40.0)))
            .compile(1.542, None)
            .unwrap();
        assert!(ok.laws[0].is_none() && ok.laws[1].is_some());
        // β dispersing far more than γ crosses it in the blue: γ's order is broken by β's law.
        let (key, msg) = bi(Some(DispersionDesc::Abbe(10.0)), None)
            .compile(1.542, None)
            .unwrap_err();
        assert_eq!(key, "beta_dispersion");
        assert!(msg.contains("n_α ≤ n_β ≤ n_γ"), "{msg}");
        let (key, _) = bi(None, Some(DispersionDesc::Abbe(200.0)))
            .compile(1.542, Ior::from_abbe(1.542, 10.0))
            .unwrap_err();
        assert_eq!(key, "gamma_dispersion");
    }
}
