//! The Weidlich–Wilkie layer stack (course §3.1–3.2; docs/design.md §5.2): rough dielectric coats with
//! absorbing varnish over one opaque base, evaluated by one of three [`Model`]s.
//!
//! - [`Model::Course`] — eqs. 3.1–3.3 exactly as published ([`course`]).
//! - [`Model::Corrected`] — the default: the same structure with the `1/η²` solid-angle compression,
//!   albedo-coupled transmission `T = 1 − E_top` and a multiple-internal-reflection lobe
//!   ([`corrected`]).
//! - [`Model::Reference`] — a position-free Monte Carlo random walk through the same stack
//!   ([`reference`](mod@reference)), the yardstick for the other two.
//!
//! Directions below the top coat are obtained by refracting through the **macro (shading) normal**
//! ([`super::refract_macro`]), not through a sampled micro-normal. This is a deliberate choice: the
//! map `w ↦ w'` is then a fixed bijection between the outside hemisphere and the inner cone, so
//! `eval`, `sample` and `pdf` of the analytic models describe one and the same density, the lower
//! lobes' pdf carries the exact Jacobian `|dωi'/dωi| = cos θi / (η² cos θi')`, and chi-square tests
//! apply. Inner directions outside the cone (beyond the critical angle) cannot leave: a sample that
//! lands there fails, and its energy is what the multiple-reflection lobe (Corrected) or the `t`
//! term (Course) stands in for.

pub mod adding;
pub mod calibrate;
pub mod corrected;
pub mod course;
mod desc;
pub mod fluorescent;
pub mod interface;
pub mod joint;
pub mod ladder;
pub(crate) mod level_tables;
pub mod lobes;
pub mod reference;

pub use desc::{Base, Coat, ConductorIor, Model, ReferenceParams, StackDesc, StackError, validate};

use super::table::Table;
use super::{
    Bsdf, BsdfSample, Bxdf, Distribution, Fresnel, FresnelMode, Lambert, LobeFlags, Masking,
    MicrofacetDistribution, OrenNayar, RoughDielectric, TorranceSparrow, TransportMode,
};
use crate::spectrum::RgbSample;
use glam::{Vec2, Vec3};
use interface::CoatInterface;

/// Runtime data of one coat as seen from above.
#[derive(Clone, Debug)]
pub(crate) struct Level {
    /// Relative IOR below / above.
    pub eta: f32,
    /// The interface's reflection lobe, with the material's Fresnel mode.
    pub top: TorranceSparrow,
    /// Macro-normal Fresnel for the Course model's `T12`, `T21`.
    pub fresnel: Fresnel,
    /// The interface with transmission (exact Fresnel), for the Reference walk.
    pub interface: CoatInterface,
    /// `η = 1` exactly: the interface is invisible and does not deflect light.
    pub index_matched: bool,
    /// A perfectly smooth interface: its reflection is a Dirac delta (reached only by sampling,
    /// flagged specular), refraction follows the macro normal exactly, `T = 1 − F`. `top` and
    /// `interface` then hold a placeholder roughness that is never evaluated as a lobe.
    pub smooth: bool,
    /// Optical depth `α·d` at normal incidence, per channel.
    pub od: RgbSample,
    /// Whether the absorption code runs for this coat: when `od` is non-zero, or when the
    /// absorption effect is forced on (then a clear coat's factor is exactly 1).
    pub absorbing: bool,
    /// Directional albedo of `top`, over `cos θo` outside.
    pub e_top: Table,
    /// `A(μ') = ∫ a(w',wi') f_rest(w',wi') cos θi' dωi'` over the inner `cos θ'`.
    pub albedo_rest: Table,
    /// `Q(μ') = ∫ (1 − T_out(wi')) a f_rest cos θi' dωi'`: what the interface sends back down.
    pub trapped: Table,
    /// `M / N`: the multiple-reflection lobe's scale (see [`corrected`]).
    pub multi_scale: RgbSample,
    /// Fraction of `q` that leaves after the inner bounces: `ρ̄ (1 − r_int) / (1 − ρ̄ r_int)`.
    pub multi_albedo: RgbSample,
    /// The interface's multiple-scattering lobe, when a Corrected stack compensates: its
    /// reflection part joins the top lobe, as in the Reference walk ([`corrected`]).
    pub top_energy: Option<std::sync::Arc<crate::bsdf::interface_energy::InterfaceEnergy>>,
}

impl Level {
    /// Transmission into the layer, `T(w) = 1 − E_top(w)`.
    #[inline]
    pub fn t(&self, cos: f32) -> f32 {
        (1.0 - self.e_top.at(cos)[0]).clamp(0.0, 1.0)
    }

    /// [`absorption`] in this coat, or 1 when its absorption code is off.
    #[inline]
    pub fn absorb(&self, cos_a: f32, cos_b: f32) -> RgbSample {
        if self.absorbing {
            absorption(self.od, cos_a, cos_b)
        } else {
            RgbSample::ONE
        }
    }

    /// [`transmittance`] of one leg in this coat, or 1 when its absorption code is off.
    #[inline]
    pub fn transmit(&self, cos: f32) -> RgbSample {
        if self.absorbing {
            transmittance(self.od, cos)
        } else {
            RgbSample::ONE
        }
    }
}

/// Absorption along the two inner legs, `exp(−α d (1/cos θi' + 1/cos θo'))` (course eq. 3.2); 0
/// (never NaN) when the optical depth is huge or a leg is grazing, and exactly 1 for `α d = 0`
/// (the path length is at most `2·10¹²`, so `0 · path = 0`).
#[inline]
pub fn absorption(od: RgbSample, cos_a: f32, cos_b: f32) -> RgbSample {
    let path = 1.0 / cos_a.abs().max(1e-12) + 1.0 / cos_b.abs().max(1e-12);
    od.map(|o| (-o * path).exp())
}

/// Transmittance of one inner leg, `exp(−α d / |cos θ|)`; exactly 1 for `α d = 0`.
#[inline]
pub fn transmittance(od: RgbSample, cos: f32) -> RgbSample {
    let path = 1.0 / cos.abs().max(1e-12);
    od.map(|o| (-o * path).exp())
}

/// A compiled layer stack: the material interface of lapidary.
#[derive(Clone, Debug)]
pub struct LayeredBsdf {
    pub(crate) levels: Box<[Level]>,
    /// The base as used by Corrected and Reference (compensated when asked).
    pub(crate) base: Bsdf,
    /// The base as the course defines it (never compensated), used by Course.
    pub(crate) base_plain: Bsdf,
    pub(crate) model: Model,
    /// The recipe's explicit `t_term`, if any (the default depends on the current model).
    pub(crate) t_term: Option<bool>,
    pub(crate) compensation: bool,
    /// The Corrected model's albedo calibration `c(μ)` of the outermost body ([`calibrate`]);
    /// `None` until a Corrected stack without the `t` term is prepared, or when switched off.
    pub(crate) calibration: Option<std::sync::Arc<Table>>,
    /// Whether the Corrected model is calibrated ([`StackDesc::calibration`]).
    pub(crate) calibrate: bool,
    pub(crate) fresnel: FresnelMode,
    pub(crate) distribution: Distribution,
    pub(crate) masking: Masking,
    /// A diffuse base's measured albedo spectrum ([`StackDesc::base_spectrum`]).
    pub(crate) base_spectrum: Option<&'static crate::spectrum::measured::Measured>,
    /// The base's fluorescent colorant ([`fluorescent`]).
    pub(crate) fluorescence: Option<std::sync::Arc<crate::spectrum::fluorescence::Fluorescence>>,
    /// A measured diffuse base's albedo ladder for spectral paths ([`ladder`]), when the world
    /// renders spectrally and it applies.
    pub(crate) ladder: Option<std::sync::Arc<ladder::AlbedoLadder>>,
}

/// Roughness (degrees) of the placeholder micro-facet lobes a smooth coat carries.
const SMOOTH_PLACEHOLDER: f32 = 0.01;

/// Table entries are measured on a stratified `TABLE_GRID²` grid of directions, each with
/// `UC_STRATA` lobe choices.
const TABLE_GRID: usize = 16;

impl LayeredBsdf {
    /// [`Bxdf::eval_pdf_mode`] with the top level's lobe weights kept in `memo` (a path
    /// vertex's, [`lobes::WeightsMemo`]); the same results bit for bit.
    #[inline]
    pub fn eval_pdf_memo(
        &self,
        wo: Vec3,
        wi: Vec3,
        mode: TransportMode,
        memo: &lobes::WeightsMemo,
    ) -> (RgbSample, f32) {
        match self.model {
            Model::Corrected => {
                let (f, p) = joint::eval_pdf_memo(self, wo, wi, memo);
                (super::flush_tiny(f), p)
            }
            _ => self.eval_pdf_mode(wo, wi, mode),
        }
    }

    /// [`Bxdf::sample_mode`] with the top level's lobe weights kept in `memo`; the same sample
    /// bit for bit.
    #[inline]
    pub fn sample_memo(
        &self,
        wo: Vec3,
        uc: f32,
        u: Vec2,
        mode: TransportMode,
        memo: &lobes::WeightsMemo,
    ) -> Option<BsdfSample> {
        match self.model {
            Model::Corrected => corrected::sample_memo(self, wo, uc, u, memo),
            _ => self.sample_mode(wo, uc, u, mode),
        }
    }

    /// Validates `desc` and builds its runtime tables (tens of milliseconds per material).
    pub fn new(desc: &StackDesc) -> Result<Self, StackError> {
        validate(desc)?;
        Ok(Self::build_tables_of(desc))
    }

    /// Builds the tables of a valid `desc`.
    fn build_tables_of(desc: &StackDesc) -> Self {
        let mut stack = Self::skeleton(desc);
        if let Bsdf::TorranceSparrow(ts) = &mut stack.base
            && desc.compensation
        {
            *ts = ts.clone().with_compensation();
        }
        for l in (0..stack.levels.len()).rev() {
            level_tables::build_tables(&mut stack, l, TABLE_GRID);
        }
        stack.prepare_model();
        stack
    }

    /// The stack of a valid `desc` with every table still empty: its levels, its base without
    /// compensation, its knobs.
    fn skeleton(desc: &StackDesc) -> Self {
        let mut above = desc.outside_ior;
        let mut levels = Vec::with_capacity(desc.coats.len());
        for c in &desc.coats {
            let eta = c.ior / above;
            above = c.ior;
            let smooth = c.roughness == 0.0;
            let dist = MicrofacetDistribution::new(
                desc.distribution,
                if smooth {
                    SMOOTH_PLACEHOLDER
                } else {
                    c.roughness
                },
            )
            .with_masking(desc.masking);
            levels.push(Level {
                eta,
                top: TorranceSparrow::new(dist, Fresnel::dielectric(eta, desc.fresnel)),
                fresnel: Fresnel::dielectric(eta, desc.fresnel),
                interface: CoatInterface {
                    rough: RoughDielectric::new(dist, eta),
                    smooth,
                },
                index_matched: (eta - 1.0).abs() < 1e-6,
                smooth,
                od: RgbSample::from(c.absorption) * c.thickness,
                absorbing: (RgbSample::from(c.absorption) * c.thickness).max_channel() > 0.0,
                e_top: Table::zero(),
                albedo_rest: Table::zero(),
                trapped: Table::zero(),
                multi_scale: RgbSample::ZERO,
                multi_albedo: RgbSample::ZERO,
                top_energy: None,
            });
        }
        let base = match desc.base {
            Base::Lambert { albedo } => Bsdf::Lambert(Lambert {
                albedo: albedo.into(),
            }),
            Base::OrenNayar { albedo, sigma } => Bsdf::OrenNayar(OrenNayar {
                albedo: albedo.into(),
                sigma,
            }),
            Base::Conductor { ior, roughness } => {
                let fresnel = match ior.rgb() {
                    None => Fresnel::Perfect,
                    Some((n, k)) => Fresnel::conductor(
                        RgbSample::from(n) / above,
                        RgbSample::from(k) / above,
                        desc.fresnel,
                    ),
                };
                let mut lobe = TorranceSparrow::new(
                    MicrofacetDistribution::new(desc.distribution, roughness)
                        .with_masking(desc.masking),
                    fresnel,
                );
                if let ConductorIor::Measured(metal) = ior {
                    lobe.metal =
                        Some(super::torrance_sparrow::SpectralMetal { metal, host: above });
                }
                Bsdf::TorranceSparrow(lobe)
            }
        };
        let base_plain = base.clone();
        let t_term = desc.t_term;
        LayeredBsdf {
            levels: levels.into_boxed_slice(),
            base,
            base_plain,
            model: desc.model,
            t_term,
            compensation: desc.compensation,
            calibration: None,
            calibrate: desc.calibration,
            fresnel: desc.fresnel,
            distribution: desc.distribution,
            masking: desc.masking,
            base_spectrum: match desc.base {
                Base::Lambert { .. } | Base::OrenNayar { .. } => desc.base_spectrum,
                Base::Conductor { .. } => None,
            },
            fluorescence: match desc.base {
                Base::Lambert { .. } => desc.fluorescence.clone(),
                _ => None,
            },
            ladder: None,
        }
    }

    /// Builds what the current model needs beyond the shared tables: the albedo calibration of
    /// Corrected (unless the `t` term is on: the course's own approximation of internal
    /// reflection is then measured as it is), the interfaces' energy tables for a compensated
    /// Reference walk.
    fn prepare_model(&mut self) {
        if self.model == Model::Corrected && self.compensation {
            for lv in self.levels.iter_mut() {
                if lv.top_energy.is_none() && !lv.smooth && !lv.index_matched {
                    lv.top_energy = lv.interface.clone().with_energy_tables().rough.energy;
                }
            }
        }
        if self.model == Model::Corrected
            && self.calibrate
            && !self.t_term()
            && self.calibration.is_none()
            && !self.levels.is_empty()
        {
            // Read back from the table store when an earlier run measured it (same inputs).
            let table =
                crate::bsdf::store::table("calibration", &*self, || calibrate::calibration(self));
            self.calibration = Some(std::sync::Arc::new(table));
        }
        if matches!(self.model, Model::Reference(_)) && self.compensation {
            for lv in self.levels.iter_mut() {
                if lv.interface.rough.energy.is_none() && !lv.index_matched {
                    lv.interface = lv.interface.clone().with_energy_tables();
                }
            }
        }
    }

    /// The evaluation model.
    pub fn model(&self) -> Model {
        self.model
    }

    /// Whether the top coat is perfectly smooth (its reflection is a delta lobe).
    #[inline]
    pub fn smooth_top(&self) -> bool {
        self.levels.first().is_some_and(|l| l.smooth)
    }

    /// Number of coats.
    pub fn coats(&self) -> usize {
        self.levels.len()
    }

    /// Whether the Course `t` term is applied.
    pub fn t_term(&self) -> bool {
        self.t_term.unwrap_or(matches!(self.model, Model::Course))
    }

    /// Every accuracy knob of this stack in one line, so no approximation is silent:
    /// model, Fresnel evaluation, distribution, `t` term and compensation.
    pub fn knobs(&self) -> String {
        let model = match self.model {
            Model::Course => "Course".to_string(),
            Model::Corrected => "Corrected".to_string(),
            Model::Reference(p) => format!("Reference({} walks, depth {})", p.samples, p.max_depth),
        };
        format!(
            "model {model}, fresnel {:?}, distribution {:?}{}, t term {}, compensation {}, \
             calibration {}",
            self.fresnel,
            self.distribution,
            match self.masking {
                Masking::VCavity => String::new(),
                m => format!(", masking {m:?}"),
            },
            if self.t_term() { "on" } else { "off" },
            if self.compensation { "on" } else { "off" },
            if self.calibration.is_some() {
                "on"
            } else {
                "off"
            }
        )
    }

    /// Forces the absorption code of every coat on (`Some(true)`: clear coats multiply by exactly
    /// 1), off (`Some(false)`: for stacks whose absorption was cleared before building, see
    /// [`crate::scene::Accuracy`]) or leaves it to each coat (`None`: on where `α d > 0`).
    pub fn force_absorption(&mut self, forced: Option<bool>) {
        for lv in self.levels.iter_mut() {
            lv.absorbing = forced.unwrap_or(lv.od.max_channel() > 0.0);
        }
    }

    /// Gives spectral paths the stack at the albedo of the measured base at each wavelength
    /// ([`ladder`]).
    pub fn set_albedo_ladder(&mut self, ladder: ladder::AlbedoLadder) {
        self.ladder = Some(std::sync::Arc::new(ladder));
    }

    /// The same compiled stack evaluated by another model (tables are shared by all models).
    pub fn with_model(&self, model: Model) -> Self {
        let mut s = self.clone();
        s.model = model;
        s.prepare_model();
        s
    }
}

impl Bxdf for LayeredBsdf {
    #[inline]
    fn flags(&self) -> LobeFlags {
        // Every lobe of a stack reflects; the Reference walk is glossy, the analytic models
        // mix glossy coats with the base's spread.
        let body = match self.model {
            Model::Reference(_) => LobeFlags::REFLECTION | LobeFlags::GLOSSY,
            _ => self.base.flags() | LobeFlags::GLOSSY,
        };
        if self.smooth_top() {
            body | LobeFlags::SPECULAR
        } else {
            body
        }
    }
    #[inline]
    fn eval_mode(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> RgbSample {
        super::flush_tiny(match self.model {
            Model::Course => course::eval(self, 0, wo, wi),
            Model::Corrected => corrected::eval(self, 0, wo, wi),
            Model::Reference(p) => reference::eval(self, p, wo, wi),
        })
    }
    #[inline]
    fn sample_mode(&self, wo: Vec3, uc: f32, u: Vec2, _mode: TransportMode) -> Option<BsdfSample> {
        match self.model {
            Model::Course => corrected::sample(self, 0, wo, uc, u, false),
            Model::Corrected => corrected::sample(self, 0, wo, uc, u, true),
            Model::Reference(p) => reference::sample(self, p, wo, uc, u),
        }
    }
    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self.model {
            Model::Course => corrected::pdf(self, 0, wo, wi, false),
            Model::Corrected => corrected::pdf(self, 0, wo, wi, true),
            Model::Reference(_) => reference::pdf(self, wo, wi),
        }
    }
    #[inline]
    fn eval_pdf_mode(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> (RgbSample, f32) {
        match self.model {
            Model::Corrected => {
                let (f, p) = joint::eval_pdf(self, 0, wo, wi);
                (super::flush_tiny(f), p)
            }
            _ => (self.eval_mode(wo, wi, mode), self.pdf(wo, wi)),
        }
    }
}
