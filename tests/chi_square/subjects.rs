//! What the chi-square suite tests: the BSDF components with their viewing directions, and the
//! course catalogue's stacks under the analytic models.

use glam::{Vec2, Vec3};
use lapidary::bsdf::dielectric::Lobes;
use lapidary::bsdf::measure::direction_deg;
use lapidary::bsdf::{
    Base, Bsdf, BsdfSample, Bxdf, Distribution, Fresnel, FresnelMode, Lambert, LayeredBsdf,
    LobeFlags, Masking, Metal, MicrofacetDistribution, Model, OrenNayar, RoughDielectric,
    TorranceSparrow, TransportMode,
};
use lapidary::recipe::MaterialLibrary;
use lapidary::spectrum::RgbSample;
use std::sync::Arc;

/// A BSDF that can be shared by the worker threads.
pub type SharedBxdf = Arc<dyn Bxdf + Send + Sync>;

/// Viewing directions `(θo, φo)` in degrees: normal incidence, two moderate angles (one with a
/// nonzero azimuth) and a grazing one at 85° with a nonzero azimuth.
pub const WO_DEG: [(f32, f32); 4] = [(0.0, 0.0), (30.0, 40.0), (60.0, 0.0), (85.0, 250.0)];

/// Analytic stack models, the ones with an exact pdf.
pub const MODELS: [(Model, &str); 2] = [(Model::Course, "course"), (Model::Corrected, "corrected")];

/// Number of materials in the course catalogue (checked when the stacks are built).
pub const CATALOGUE_SIZE: usize = 11;

/// Lowest coat or base roughness (degrees) the sphere histogram can resolve (see [`stacks`]).
pub const MIN_RESOLVED_M: f32 = 1.0;

/// One configuration: a BSDF seen from one direction.
#[derive(Clone)]
pub struct Subject {
    /// Name for the report.
    pub name: String,
    /// The BSDF.
    pub bsdf: SharedBxdf,
    /// Viewing direction, local frame.
    pub wo: Vec3,
    /// `(θo, φo)` in degrees for the report (θo > 90° means `wo` below the surface).
    pub wo_deg: (f32, f32),
}

/// Every direction of [`WO_DEG`], above the surface and, when `below`, mirrored below it too.
fn views(below: bool) -> Vec<(Vec3, (f32, f32))> {
    let mut v: Vec<_> = WO_DEG
        .iter()
        .map(|&(t, p)| (direction_deg(t, p), (t, p)))
        .collect();
    if below {
        v.extend(WO_DEG.iter().map(|&(t, p)| {
            let w = direction_deg(t, p);
            (Vec3::new(w.x, w.y, -w.z), (180.0 - t, p))
        }));
    }
    v
}

fn expand(list: Vec<(String, SharedBxdf, bool)>) -> Vec<Subject> {
    let mut out = Vec::new();
    for (name, bsdf, below) in list {
        for (wo, wo_deg) in views(below) {
            out.push(Subject {
                name: name.clone(),
                bsdf: bsdf.clone(),
                wo,
                wo_deg,
            });
        }
    }
    out
}

/// The components (docs/design.md §5.1) with the parameters of the issue. The flag says whether `wo`
/// below the surface is tested too (only the rough dielectric scatters from there).
pub fn component_bsdfs() -> Vec<(String, SharedBxdf, bool)> {
    let ts = |kind, m, fresnel: Fresnel| {
        TorranceSparrow::new(MicrofacetDistribution::new(kind, m), fresnel)
    };
    let diel = Fresnel::dielectric(1.5, FresnelMode::Exact);
    let (gn, gk) = Metal::Gold.nk();
    let gold = Fresnel::conductor(gn.into(), gk.into(), FresnelMode::Exact);
    let shared = |b: Bsdf| -> SharedBxdf { Arc::new(b) };
    let mut v: Vec<(String, SharedBxdf, bool)> = vec![
        (
            "lambert".into(),
            shared(Bsdf::Lambert(Lambert {
                albedo: RgbSample::rgb(0.2, 0.5, 0.9),
            })),
            false,
        ),
        (
            "oren_nayar s=0.3".into(),
            shared(Bsdf::OrenNayar(OrenNayar {
                albedo: RgbSample::rgb(0.8, 0.6, 0.3),
                sigma: 0.3,
            })),
            false,
        ),
        (
            "oren_nayar s=1.0".into(),
            shared(Bsdf::OrenNayar(OrenNayar {
                albedo: RgbSample::splat(0.9),
                sigma: 1.0,
            })),
            false,
        ),
    ];
    for (kind, m, label) in [
        (Distribution::Blinn, 5.0, "blinn m=5"),
        (Distribution::Blinn, 20.0, "blinn m=20"),
        (Distribution::Beckmann, 10.0, "beckmann m=10"),
    ] {
        v.push((
            format!("ts dielectric eta=1.5 {label}"),
            shared(Bsdf::TorranceSparrow(ts(kind, m, diel.clone()))),
            false,
        ));
    }
    for m in [3.0, 30.0] {
        let plain = ts(Distribution::Blinn, m, gold.clone());
        v.push((
            format!("ts gold blinn m={m}"),
            shared(Bsdf::TorranceSparrow(plain.clone())),
            false,
        ));
        v.push((
            format!("ts gold compensated blinn m={m}"),
            shared(Bsdf::TorranceSparrow(plain.with_compensation())),
            false,
        ));
    }
    // Smith masking (issue 16): every distribution × both Smith forms, with their own
    // samplers (GGX visible normals, D·cos for Beckmann and Blinn), dielectric and gold Fresnel,
    // and the smooth-ish and rough ends.
    for (kind, m) in [
        (Distribution::Ggx, 5.0),
        (Distribution::Ggx, 30.0),
        (Distribution::Beckmann, 20.0),
        (Distribution::Blinn, 20.0),
    ] {
        for masking in [Masking::Smith, Masking::SmithSeparable] {
            let dist = MicrofacetDistribution::new(kind, m).with_masking(masking);
            v.push((
                format!("ts dielectric eta=1.5 {kind:?} {masking:?} m={m}"),
                shared(Bsdf::TorranceSparrow(TorranceSparrow::new(
                    dist,
                    diel.clone(),
                ))),
                false,
            ));
        }
        let dist = MicrofacetDistribution::new(kind, m).with_masking(Masking::Smith);
        v.push((
            format!("ts gold compensated {kind:?} Smith m={m}"),
            shared(Bsdf::TorranceSparrow(
                TorranceSparrow::new(dist, gold.clone()).with_compensation(),
            )),
            false,
        ));
    }
    v.push((
        "ts dielectric eta=1.5 Ggx VCavity m=20".into(),
        shared(Bsdf::TorranceSparrow(ts(
            Distribution::Ggx,
            20.0,
            diel.clone(),
        ))),
        false,
    ));
    for m in [10.0, 30.0] {
        v.push((
            format!("rough dielectric eta=1.5 blinn m={m}"),
            shared(Bsdf::Dielectric(RoughDielectric::new(
                MicrofacetDistribution::new(Distribution::Blinn, m),
                1.5,
            ))),
            true,
        ));
    }
    v
}

/// Every component at every viewing direction.
pub fn components() -> Vec<Subject> {
    expand(component_bsdfs())
}

/// Number of component configurations, without building anything heavy.
pub fn component_count() -> usize {
    // 10 + 13 (Smith, GGX) components above the surface only, 2 rough dielectrics on both sides.
    23 * WO_DEG.len() + 2 * 2 * WO_DEG.len()
}

/// The catalogue's stacks under Course and Corrected. With `resolvable`, every coat and conductor
/// base roughness below [`MIN_RESOLVED_M`] is raised to it: a near-mirror lobe (e.g.
/// `blue_glossy_ceramic`, coat m = 0.01°, a lobe ~0.03° wide) falls into a single 3.75° bin of the
/// sphere histogram, where a chi-square test cannot see how the samples are spread. Near-mirror
/// sampling is covered elsewhere: the distribution's `sample_h` against `pdf_h` in slope space
/// (down to m = 0.01°, [`super::slope`]) and the weight-consistency check, which runs on the
/// unmodified catalogue.
pub fn stacks(resolvable: bool) -> Vec<Subject> {
    let lib = MaterialLibrary::course();
    let names: Vec<String> = lib.names().map(str::to_string).collect();
    assert_eq!(names.len(), CATALOGUE_SIZE, "the catalogue changed size");
    let mut out = Vec::new();
    for name in &names {
        let mut desc = lib.stack(name).unwrap_or_else(|e| panic!("{e}"));
        let mut label = name.clone();
        if resolvable {
            let mut raised = false;
            for c in desc.coats.iter_mut() {
                if c.roughness < MIN_RESOLVED_M {
                    c.roughness = MIN_RESOLVED_M;
                    raised = true;
                }
            }
            if let Base::Conductor { roughness, .. } = &mut desc.base
                && *roughness < MIN_RESOLVED_M
            {
                *roughness = MIN_RESOLVED_M;
                raised = true;
            }
            if raised {
                label.push_str(" (m>=1)");
            }
        }
        for (model, model_name) in MODELS {
            let stack = LayeredBsdf::new(&desc.clone().with_model(model))
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            let bsdf: SharedBxdf = Arc::new(Bsdf::from(stack));
            out.extend(expand(vec![(
                format!("{label} [{model_name}]"),
                bsdf,
                false,
            )]));
        }
    }
    out
}

/// Number of stack configurations.
pub fn stack_count() -> usize {
    CATALOGUE_SIZE * MODELS.len() * WO_DEG.len()
}

/// A rough dielectric seen through one transport mode and one lobe selection (the [`Bsdf`] enum
/// exposes radiance transport with both lobes only).
pub struct DielectricVariant {
    /// The interface.
    pub interface: RoughDielectric,
    /// Transport mode of `eval` and `sample`.
    pub mode: TransportMode,
    /// Lobes `sample` and `pdf` may use.
    pub lobes: Lobes,
}

impl Bxdf for DielectricVariant {
    fn flags(&self) -> LobeFlags {
        LobeFlags::REFLECTION | LobeFlags::TRANSMISSION | LobeFlags::GLOSSY
    }
    fn eval_mode(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> RgbSample {
        RgbSample::splat(self.interface.value(wo, wi, self.mode))
    }
    fn sample_mode(&self, wo: Vec3, uc: f32, u: Vec2, _mode: TransportMode) -> Option<BsdfSample> {
        self.interface
            .sample_lobes(wo, uc, u, self.mode, self.lobes)
    }
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.interface.pdf_lobes(wo, wi, self.lobes)
    }
}

/// Rough dielectrics in importance transport and with one lobe at a time, on both sides (for the
/// weight-consistency check only: their pdfs are the ones the chi-square suite tests, restricted
/// to one lobe).
pub fn dielectric_variants() -> Vec<Subject> {
    let mut v: Vec<(String, SharedBxdf, bool)> = Vec::new();
    for m in [10.0, 30.0] {
        for (mode, lobes, label) in [
            (
                TransportMode::Importance,
                Lobes::All,
                "importance, both lobes",
            ),
            (
                TransportMode::Radiance,
                Lobes::Reflection,
                "radiance, reflection",
            ),
            (
                TransportMode::Radiance,
                Lobes::Transmission,
                "radiance, transmission",
            ),
        ] {
            v.push((
                format!("rough dielectric m={m} {label}"),
                Arc::new(DielectricVariant {
                    interface: RoughDielectric::new(
                        MicrofacetDistribution::new(Distribution::Blinn, m),
                        1.5,
                    ),
                    mode,
                    lobes,
                }),
                true,
            ));
        }
    }
    expand(v)
}
