//! The records a BSDF exchanges with an integrator: the transport mode it is asked in, the lobe
//! flags of what it sampled, and the sample itself.

use crate::spectrum::{RgbSample, Spectral};
use glam::Vec3;

/// Which quantity a path carries (Veach 1997, §5.2; pbrt-v4 §9.5.2).
///
/// BSDFs are not symmetric under refraction: a transmission event scales radiance by `1/η'²`
/// (`η'` = IOR of the side `wi` is on over that of `wo`'s side) but importance not at all, so
/// `f_radiance(wo, wi) = f_importance(wi, wo)`. Reflection is the same in both modes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TransportMode {
    /// Radiance: the path starts at the camera and `wo` points back along it.
    #[default]
    Radiance,
    /// Importance: the adjoint, for paths from a light (and for energy tables, which measure flux).
    Importance,
}

/// What kind of scattering a lobe or a sample is, as a set of flags (pbrt-v4's `BxDFFlags`).
///
/// A sample has exactly one of [`LobeFlags::REFLECTION`] / [`LobeFlags::TRANSMISSION`] and exactly
/// one of [`LobeFlags::DIFFUSE`] / [`LobeFlags::GLOSSY`] / [`LobeFlags::SPECULAR`]; a BSDF's
/// [`super::Bxdf::flags`] is the union over its lobes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct LobeFlags(u8);

impl LobeFlags {
    /// No lobe.
    pub const NONE: LobeFlags = LobeFlags(0);
    /// `wi` on the same side of the macro surface as `wo`.
    pub const REFLECTION: LobeFlags = LobeFlags(1);
    /// `wi` on the other side: the path crosses the surface.
    pub const TRANSMISSION: LobeFlags = LobeFlags(2);
    /// Spread over the hemisphere (Lambert, Oren–Nayar, the stack's multiple-reflection lobe).
    pub const DIFFUSE: LobeFlags = LobeFlags(4);
    /// A micro-facet lobe with a density (rough interfaces, the Reference walk).
    pub const GLOSSY: LobeFlags = LobeFlags(8);
    /// A Dirac delta (smooth interfaces): `eval` and `pdf` are 0 and only `sample` reaches it.
    pub const SPECULAR: LobeFlags = LobeFlags(16);

    /// The union of two sets.
    #[inline]
    pub const fn union(self, o: LobeFlags) -> LobeFlags {
        LobeFlags(self.0 | o.0)
    }
    /// True when every flag of `o` is set.
    #[inline]
    pub const fn contains(self, o: LobeFlags) -> bool {
        self.0 & o.0 == o.0
    }
    /// True when any flag of `o` is set.
    #[inline]
    pub const fn intersects(self, o: LobeFlags) -> bool {
        self.0 & o.0 != 0
    }
    /// A transmission lobe.
    #[inline]
    pub const fn is_transmission(self) -> bool {
        self.intersects(LobeFlags::TRANSMISSION)
    }
    /// Only specular lobes: light sampling can never find a direction with `f > 0`.
    #[inline]
    pub const fn is_specular_only(self) -> bool {
        self.is_specular() && !self.intersects(LobeFlags::DIFFUSE.union(LobeFlags::GLOSSY))
    }
    /// A specular (Dirac) lobe: no MIS against light sampling is possible.
    #[inline]
    pub const fn is_specular(self) -> bool {
        self.intersects(LobeFlags::SPECULAR)
    }
}

impl std::ops::BitOr for LobeFlags {
    type Output = LobeFlags;
    #[inline]
    fn bitor(self, o: LobeFlags) -> LobeFlags {
        self.union(o)
    }
}

/// Which part of a BSDF produced a sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LobeKind {
    /// A diffuse (Lambert / Oren–Nayar) reflection.
    Diffuse,
    /// A micro-facet reflection (Torrance–Sparrow, dielectric or conductor).
    Glossy,
    /// A micro-facet transmission through a dielectric interface.
    Transmission,
    /// The layer stack's multiple-internal-reflection lobe (Corrected model).
    Multiple,
    /// A path of the stochastic Reference random walk.
    RandomWalk,
    /// The mirror reflection of a smooth interface.
    SpecularReflection,
    /// The refraction through a smooth interface.
    SpecularTransmission,
}

impl LobeKind {
    /// The flags of a sample from this lobe.
    pub const fn flags(self) -> LobeFlags {
        match self {
            LobeKind::Diffuse | LobeKind::Multiple => {
                LobeFlags::REFLECTION.union(LobeFlags::DIFFUSE)
            }
            LobeKind::Glossy | LobeKind::RandomWalk => {
                LobeFlags::REFLECTION.union(LobeFlags::GLOSSY)
            }
            LobeKind::Transmission => LobeFlags::TRANSMISSION.union(LobeFlags::GLOSSY),
            LobeKind::SpecularReflection => LobeFlags::REFLECTION.union(LobeFlags::SPECULAR),
            LobeKind::SpecularTransmission => LobeFlags::TRANSMISSION.union(LobeFlags::SPECULAR),
        }
    }
}

/// The lobe of a sample and the layer it comes from (0 = the top coat's interface; the base is at
/// the index equal to the number of coats).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Lobe {
    /// What kind of scattering.
    pub kind: LobeKind,
    /// Which layer of a stack (0 for single components).
    pub layer: u8,
}

/// A sampled direction with everything an integrator needs.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample<S: Spectral = RgbSample> {
    /// Sampled direction toward the light, local frame, unit length.
    pub wi: Vec3,
    /// `f(wo, wi)`, sr⁻¹, cosine excluded (for a specular lobe the delta's weight divided by
    /// `|cos θi|`, so that `weight = f · |wi.z| / pdf` still holds).
    pub f: S,
    /// Density of `wi` per steradian (for a specular lobe the discrete probability of choosing
    /// it; for the Reference model proportional only, see [`Self::pdf_is_proportional`]); always
    /// `> 0` in a returned sample.
    pub pdf: f32,
    /// Path weight `f · |wi.z| / pdf` (for the Reference model the unbiased random-walk weight).
    pub weight: S,
    /// Which lobe produced the sample.
    pub lobe: Lobe,
    /// Reflection or transmission; diffuse, glossy or specular ([`LobeKind::flags`]).
    pub flags: LobeFlags,
    /// Relative IOR of a refraction, `η(wi side) / η(wo side)`; 1 for reflection. A path's
    /// Russian roulette divides its throughput by the product of `η²` (pbrt-v4 §14.1.5) so that
    /// the radiance compression of entering a denser medium does not end paths early.
    pub eta: f32,
    /// True when `pdf` is only proportional to the density of `wi` (the Reference walk's, whose
    /// exact density has no closed form): `weight` is unbiased, but `pdf` must not be used for
    /// MIS against another strategy as if it were exact.
    pub pdf_is_proportional: bool,
    /// True when the sample refracted through a dispersive interface with the hero wavelength's
    /// index: the path must keep only its hero wavelength from here on
    /// ([`Spectral::terminate_secondary`]); the secondaries' values in `f` and `weight` are 0.
    /// Always false in the RGB variant.
    pub terminate_secondary: bool,
}

impl<S: Spectral> BsdfSample<S> {
    /// Builds a sample from an evaluated `f` and `pdf`; `None` unless `pdf > 0` and the result is
    /// finite, so a returned sample is always usable. Flags come from the lobe, `eta` is 1 and the
    /// pdf exact: set [`Self::eta`] for a refraction with [`Self::with_eta`].
    #[inline]
    pub fn from_eval(wi: Vec3, f: S, pdf: f32, lobe: Lobe) -> Option<Self> {
        if !(pdf > 0.0 && pdf.is_finite() && f.is_valid()) {
            return None;
        }
        let weight = f * (wi.z.abs() / pdf);
        weight.is_valid().then_some(BsdfSample {
            wi,
            f,
            pdf,
            weight,
            lobe,
            flags: lobe.kind.flags(),
            eta: 1.0,
            pdf_is_proportional: false,
            terminate_secondary: false,
        })
    }

    /// The same sample with the relative IOR of its refraction.
    #[inline]
    pub fn with_eta(mut self, eta: f32) -> Self {
        self.eta = eta;
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_lobe_has_one_side_and_one_spread() {
        use LobeKind::*;
        for k in [
            Diffuse,
            Glossy,
            Transmission,
            Multiple,
            RandomWalk,
            SpecularReflection,
            SpecularTransmission,
        ] {
            let f = k.flags();
            let sides = [LobeFlags::REFLECTION, LobeFlags::TRANSMISSION];
            let spreads = [LobeFlags::DIFFUSE, LobeFlags::GLOSSY, LobeFlags::SPECULAR];
            assert_eq!(sides.iter().filter(|s| f.contains(**s)).count(), 1, "{k:?}");
            assert_eq!(
                spreads.iter().filter(|s| f.contains(**s)).count(),
                1,
                "{k:?}"
            );
        }
        assert!(SpecularTransmission.flags().is_transmission());
        assert!(SpecularTransmission.flags().is_specular());
        assert!(!Glossy.flags().is_transmission());
    }

    #[test]
    fn failed_or_invalid_samples_are_refused() {
        let lobe = Lobe {
            kind: LobeKind::Diffuse,
            layer: 0,
        };
        let wi = Vec3::Z;
        assert!(BsdfSample::from_eval(wi, RgbSample::ONE, 0.0, lobe).is_none());
        assert!(BsdfSample::from_eval(wi, RgbSample::ONE, f32::NAN, lobe).is_none());
        assert!(BsdfSample::from_eval(wi, RgbSample::splat(-1.0), 1.0, lobe).is_none());
        let s = BsdfSample::from_eval(wi, RgbSample::ONE, 2.0, lobe).unwrap();
        assert_eq!(
            (s.weight, s.eta, s.pdf_is_proportional),
            (RgbSample::splat(0.5), 1.0, false)
        );
        assert_eq!(s.with_eta(1.5).eta, 1.5);
    }
}
