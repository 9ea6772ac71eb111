//! Hard cases that must stay finite (docs/design.md §5.3), for every component and for layer stacks under
//! all three models.
//!
//! Two halves share one set of checkers:
//! - table-driven `#[test]`s over the explicit edges (grazing `cos θ = ±1e-7`, `wo == wi`,
//!   `wo == −wi`, mirror pairs, the normal, `wo` below the surface as a bump-tilted facet produces
//!   it, `u`/`uc` exactly 0, 1 and 1 − ε, `m` 0.01° … 89°, IOR 1.0001 … 4, `k` 10, `αd` 1e3, …), so
//!   they always run;
//! - proptest over the full parameter ranges with a fixed ChaCha seed and no failure persistence
//!   (nothing is written into the tree).
//!
//! The same property tests with many more cases:
//! `cargo test --release --test hard_cases -- --ignored`
//!
//! Properties (docs/design.md §4, §5.3; `src/bsdf/mod.rs`):
//! - `eval` finite and non-negative per channel; `pdf` finite and `≥ 0`;
//! - `sample` is `None` or has a unit `wi`, a finite `pdf > 0`, a finite non-negative `f` and
//!   `weight`, `weight == f·|cos θi|/pdf`, `pdf(wo, wi) > 0`, and (exact-pdf models: components,
//!   Course, Corrected) `f == eval(wo, wi)` and `pdf == pdf(wo, wi)` to 1e-3 relative;
//! - exact-pdf models: wherever `eval(wo, wi) > 0`, `pdf(wo, wi) > 0` — on random directions and on
//!   the directions the lobes' samplers produce (rebuilt here from the public samplers, so that a
//!   direction whose `sample` was swallowed by a zero pdf is still seen);
//! - reflection-only BSDFs: a direction strictly below the surface (`wo` or `wi`) has `eval == 0`
//!   and `pdf == 0`, and `sample` from below is `None` (no energy gain);
//! - Fresnel functions in `[0, 1]`; `refract`/`refract_macro` give unit vectors or `None`;
//! - `LayeredBsdf::new` never panics: `Ok` for in-range descriptions, `Err` for out-of-range ones.

use glam::{Vec2, Vec3};
use lapidary::bsdf::dielectric::Lobes;
use lapidary::bsdf::{
    Base, Bsdf, Bxdf, Coat, ConductorIor, Distribution, Fresnel, FresnelMode, Lambert, LayeredBsdf,
    MicrofacetDistribution, Model, OrenNayar, ReferenceParams, RoughDielectric, StackDesc,
    TorranceSparrow, TransportMode, fresnel, reflect, refract, refract_macro,
    sample_cosine_hemisphere, spherical_direction,
};
use lapidary::color::Rgb;
use lapidary::recipe::MaterialLibrary;
use lapidary::spectrum::RgbSample;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestError, TestRng, TestRunner};
use std::f32::consts::TAU;
use std::fmt::Debug;
use std::panic::{AssertUnwindSafe, catch_unwind};

// ------------------------------------------------------------------------------------------------
// Shared vocabulary
// ------------------------------------------------------------------------------------------------

/// The largest `f32` below 1.
const ONE_MINUS_EPS: f32 = 1.0 - f32::EPSILON / 2.0;

/// Edge values of a uniform random number.
const EDGE_U: [f32; 5] = [0.0, 1.0, ONE_MINUS_EPS, 1e-7, 0.5];

/// Tolerance of the `sample`/`eval`/`pdf` agreement.
const REL: f32 = 1e-3;

/// The Reference walk with small parameters, to keep the tests fast.
const REFERENCE: Model = Model::Reference(ReferenceParams {
    samples: 2,
    max_depth: 16,
});

const MODELS: [Model; 3] = [Model::Course, Model::Corrected, REFERENCE];

const FRESNEL_MODES: [FresnelMode; 4] = [
    FresnelMode::Exact,
    FresnelMode::Schlick,
    FresnelMode::Lazanyi,
    FresnelMode::Table,
];

type Check = Result<(), String>;

/// `return Err(format!(..))` unless the condition holds.
macro_rules! ensure {
    ($cond:expr, $($arg:tt)*) => {{
        let holds: bool = $cond;
        if !holds {
            return Err(format!($($arg)*));
        }
    }};
}

/// How much a BSDF promises about its pdf.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    /// Reflection only, `pdf` is the exact density of `sample` (components, Course, Corrected).
    Exact,
    /// Reflection only, the Reference walk (`pdf` an approximation, `f` of a sample stochastic).
    Walk,
}

fn kind_of(model: Model) -> Kind {
    match model {
        Model::Reference(_) => Kind::Walk,
        _ => Kind::Exact,
    }
}

fn close(a: f32, b: f32, rel: f32) -> bool {
    a == b || (a - b).abs() <= rel * a.abs().max(b.abs())
}

fn close_spectrum(a: RgbSample, b: RgbSample, rel: f32) -> bool {
    (0..3).all(|c| close(a[c], b[c], rel))
}

/// `weight == f·|cos θi|/pdf` per channel, to `REL` plus the absolute rounding of subnormal
/// numbers (spacing 1.4e-45), which `f` or the weight may carry into the comparison.
fn weight_matches(weight: RgbSample, f: RgbSample, cos: f32, pdf: f32) -> bool {
    let subnormal_step = f32::from_bits(1);
    (0..3).all(|c| {
        let w = f[c] * (cos / pdf);
        let slack = subnormal_step * (1.0 + cos / pdf);
        (weight[c] - w).abs() <= REL * weight[c].abs().max(w.abs()) + slack
    })
}

fn is_unit(w: Vec3) -> bool {
    w.is_finite() && (w.length() - 1.0).abs() < 1e-4
}

/// A unit direction with the given `cos θ` (not renormalised, so `z` is exactly `z`).
fn from_z_phi(z: f32, phi: f32) -> Vec3 {
    let s = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(s * phi.cos(), s * phi.sin(), z)
}

/// `w` mirrored about the normal: `wo == reflect(wi)`.
fn mirror(w: Vec3) -> Vec3 {
    Vec3::new(-w.x, -w.y, w.z)
}

/// `base` turned by `angle` toward the azimuth `azimuth` of a frame around it.
fn near(base: Vec3, angle: f32, azimuth: f32) -> Vec3 {
    let (t, b) = base.any_orthonormal_pair();
    (base * angle.cos() + (t * azimuth.cos() + b * azimuth.sin()) * angle.sin()).normalize()
}

/// Directions that every table-driven test visits (both hemispheres, grazing, the normal).
fn edge_dirs() -> Vec<Vec3> {
    vec![
        Vec3::Z,
        -Vec3::Z,
        Vec3::new(1.0, 0.0, 1e-7),
        Vec3::new(1.0, 0.0, -1e-7),
        Vec3::new(0.0, 1.0, 1e-7),
        from_z_phi(1e-7, 2.3),
        from_z_phi(-1e-7, 4.0),
        from_z_phi(1e-4, 0.4),
        Vec3::new(0.6, 0.8, 0.0),
        from_z_phi(0.5, 1.0),
        from_z_phi(-0.5, 1.0),
        from_z_phi(ONE_MINUS_EPS, 0.3),
        spherical_direction(89.99f32.to_radians(), 5.5),
    ]
}

/// How `wi` is derived from `wo` in a query.
#[derive(Clone, Copy, Debug)]
enum Rel {
    /// An independent direction.
    Free(Vec3),
    /// `wi == wo`.
    Same,
    /// `wi == −wo` (half vector undefined).
    Opposite,
    /// `wi == reflect(wo)` about the normal (the specular peak).
    Mirror,
    /// Slightly off the mirror direction (inside a very sharp lobe).
    NearMirror(f32, f32),
    /// Slightly off `−wo` (the peak of transmission through a nearly index-matched interface).
    NearOpposite(f32, f32),
}

impl Rel {
    fn wi(self, wo: Vec3) -> Vec3 {
        match self {
            Rel::Free(w) => w,
            Rel::Same => wo,
            Rel::Opposite => -wo,
            Rel::Mirror => mirror(wo),
            Rel::NearMirror(a, phi) => near(mirror(wo), a, phi),
            Rel::NearOpposite(a, phi) => near(-wo, a, phi),
        }
    }
}

const EDGE_RELS: [Rel; 4] = [
    Rel::Same,
    Rel::Opposite,
    Rel::Mirror,
    Rel::NearMirror(1e-4, 1.0),
];

/// One query of a BSDF: an `(wo, wi)` pair for eval/pdf and `(uc, u)` for a sample from `wo`.
#[derive(Clone, Copy, Debug)]
struct Query {
    wo: Vec3,
    rel: Rel,
    uc: f32,
    u: Vec2,
}

impl Query {
    fn wi(&self) -> Vec3 {
        self.rel.wi(self.wo)
    }
}

/// Every query of the table-driven tests: each edge `wo` against every edge `wi` and every
/// relation, with the `u` edges spread over them.
fn edge_queries() -> Vec<Query> {
    let dirs = edge_dirs();
    let mut out = Vec::new();
    let mut k = 0usize;
    for &wo in &dirs {
        let rels = dirs.iter().map(|&w| Rel::Free(w)).chain(EDGE_RELS);
        for rel in rels {
            let uc = EDGE_U[k % EDGE_U.len()];
            let u = Vec2::new(
                EDGE_U[(k / 5) % EDGE_U.len()],
                EDGE_U[(k / 25) % EDGE_U.len()],
            );
            out.push(Query { wo, rel, uc, u });
            k += 1;
        }
    }
    out
}

/// The `(uc, u)` edges, all 125 combinations.
fn edge_us() -> Vec<(f32, Vec2)> {
    let mut out = Vec::new();
    for &a in &EDGE_U {
        for &b in &EDGE_U {
            for &c in &EDGE_U {
                out.push((a, Vec2::new(b, c)));
            }
        }
    }
    out
}

// ------------------------------------------------------------------------------------------------
// Checkers
// ------------------------------------------------------------------------------------------------

/// eval/pdf of a reflection-only BSDF at one pair of directions.
fn check_pair(b: &impl Bxdf, kind: Kind, wo: Vec3, wi: Vec3) -> Check {
    let f = b.eval(wo, wi);
    ensure!(
        f.is_valid(),
        "eval(wo {wo:?}, wi {wi:?}) = {f:?} is not finite and non-negative"
    );
    let p = b.pdf(wo, wi);
    ensure!(
        p.is_finite() && p >= 0.0,
        "pdf(wo {wo:?}, wi {wi:?}) = {p} is not finite and non-negative"
    );
    if wo.z < 0.0 || wi.z < 0.0 {
        ensure!(
            f.is_black() && p == 0.0,
            "below the surface: eval(wo {wo:?}, wi {wi:?}) = {f:?}, pdf = {p} (must be 0)"
        );
    }
    if f.max_channel() > 0.0 {
        ensure!(
            p > 0.0,
            "eval(wo {wo:?}, wi {wi:?}) = {f:?} > 0 but pdf = {p}: energy that is never sampled \
             ({kind:?})"
        );
    }
    Ok(())
}

/// One sample of a reflection-only BSDF.
fn check_sample(b: &impl Bxdf, kind: Kind, wo: Vec3, uc: f32, u: Vec2) -> Check {
    let Some(s) = b.sample(wo, uc, u) else {
        return Ok(());
    };
    let at = format!("sample(wo {wo:?}, uc {uc:?}, u {u:?}) = {s:?}");
    ensure!(
        wo.z >= 0.0,
        "{at}: a sample from below the surface (energy gain)"
    );
    ensure!(is_unit(s.wi), "{at}: wi is not a unit vector");
    ensure!(
        s.wi.z > 0.0,
        "{at}: a reflection BSDF sampled a direction below the surface"
    );
    ensure!(
        s.pdf > 0.0 && s.pdf.is_finite(),
        "{at}: pdf not finite and > 0"
    );
    ensure!(s.f.is_valid(), "{at}: f not finite and non-negative");
    ensure!(
        s.weight.is_valid(),
        "{at}: weight not finite and non-negative"
    );
    ensure!(
        weight_matches(s.weight, s.f, s.wi.z.abs(), s.pdf),
        "{at}: weight != f·cos/pdf = {:?}",
        s.f * (s.wi.z.abs() / s.pdf)
    );
    if s.flags.is_specular() {
        // A delta (a smooth top coat's mirror reflection): its pdf is the probability of the
        // choice and `f` carries F/cos; neither `pdf` nor `eval` can see it (their values at the
        // mirror direction are the other lobes' alone, and must stay finite).
        ensure!(s.pdf <= 1.0 + 1e-6, "{at}: a delta's pdf is a probability");
        let (p, f) = (b.pdf(wo, s.wi), b.eval(wo, s.wi));
        ensure!(
            p.is_finite() && p >= 0.0 && f.is_valid(),
            "{at}: pdf {p} / eval {f:?} at the delta's direction"
        );
        return Ok(());
    }
    let p = b.pdf(wo, s.wi);
    ensure!(p > 0.0, "{at}: pdf(wo, s.wi) = {p} for a sampled direction");
    ensure!(close(s.pdf, p, REL), "{at}: s.pdf != pdf(wo, s.wi) = {p}");
    if kind == Kind::Exact {
        let f = b.eval(wo, s.wi);
        ensure!(
            close_spectrum(s.f, f, REL),
            "{at}: s.f != eval(wo, s.wi) = {f:?}"
        );
    }
    check_pair(b, kind, wo, s.wi).map_err(|e| format!("{at}: at the sampled direction: {e}"))
}

/// Below-surface `wo` (a bump-tilted facet): nothing may come back.
fn check_below(b: &impl Bxdf, wo: Vec3, wi: Vec3, uc: f32, u: Vec2) -> Check {
    debug_assert!(wo.z < 0.0);
    let f = b.eval(wo, wi);
    let p = b.pdf(wo, wi);
    ensure!(
        f.is_black() && p == 0.0,
        "wo {wo:?} below the surface: eval(wo, wi {wi:?}) = {f:?}, pdf = {p}"
    );
    let s = b.sample(wo, uc, u);
    ensure!(
        s.is_none(),
        "wo {wo:?} below the surface: sample(uc {uc:?}, u {u:?}) = {s:?} (energy gain)"
    );
    Ok(())
}

/// A full query: the pair, the sample, the sampler-produced candidate directions, and (for `wo`
/// below the surface) the no-energy-gain rule.
fn check_query(b: &impl Bxdf, kind: Kind, q: &Query, candidates: &[Vec3]) -> Check {
    let (wo, wi) = (q.wo, q.wi());
    check_pair(b, kind, wo, wi)?;
    check_sample(b, kind, wo, q.uc, q.u)?;
    if wo.z < 0.0 {
        check_below(b, wo, wi, q.uc, q.u)?;
    }
    for &c in candidates {
        check_pair(b, kind, wo, c).map_err(|e| format!("at a lobe-sampled direction: {e}"))?;
    }
    Ok(())
}

/// The directions a micro-facet reflection sampler can produce for `u`: `sample_h(u)` draws `h`
/// from `D cos`, the V-cavity visible-normal sampler keeps `h` or its cavity partner
/// `(−hx, −hy, hz)` (chosen by `uc`); both are reflected about `wo` like the Torrance–Sparrow
/// sampler does.
fn glossy_candidates(d: &MicrofacetDistribution, wo: Vec3, u: Vec2) -> Vec<Vec3> {
    cavity_normals(d, u)
        .into_iter()
        .filter(|h| wo.dot(*h) > 0.0)
        .map(|h| reflect(wo, h).normalize())
        .filter(|wi| wi.z > 0.0)
        .collect()
}

/// The two facets of the V-cavity whose normal `sample_h(u)` draws.
fn cavity_normals(d: &MicrofacetDistribution, u: Vec2) -> Vec<Vec3> {
    d.sample_h(u)
        .map(|h| vec![h, Vec3::new(-h.x, -h.y, h.z)])
        .unwrap_or_default()
}

// ------------------------------------------------------------------------------------------------
// Components
// ------------------------------------------------------------------------------------------------

#[derive(Clone, Copy, Debug)]
enum FresnelDesc {
    Dielectric(f32, FresnelMode),
    Conductor(RgbSample, RgbSample, FresnelMode),
    Perfect,
}

impl FresnelDesc {
    fn build(self) -> Fresnel {
        match self {
            FresnelDesc::Dielectric(eta, mode) => Fresnel::dielectric(eta, mode),
            FresnelDesc::Conductor(n, k, mode) => Fresnel::conductor(n, k, mode),
            FresnelDesc::Perfect => Fresnel::Perfect,
        }
    }
}

#[derive(Clone, Copy, Debug)]
enum Component {
    Lambert(RgbSample),
    OrenNayar(RgbSample, f32),
    Torrance {
        distribution: Distribution,
        m: f32,
        fresnel: FresnelDesc,
        compensation: bool,
    },
}

impl Component {
    fn build(self) -> Bsdf {
        match self {
            Component::Lambert(albedo) => Bsdf::Lambert(Lambert { albedo }),
            Component::OrenNayar(albedo, sigma) => Bsdf::OrenNayar(OrenNayar { albedo, sigma }),
            Component::Torrance {
                distribution,
                m,
                fresnel,
                compensation,
            } => {
                let ts = TorranceSparrow::new(
                    MicrofacetDistribution::new(distribution, m),
                    fresnel.build(),
                );
                Bsdf::TorranceSparrow(if compensation {
                    ts.with_compensation()
                } else {
                    ts
                })
            }
        }
    }

    /// Directions this component's sampler produces for `u`.
    fn candidates(self, wo: Vec3, u: Vec2) -> Vec<Vec3> {
        if wo.z <= 0.0 {
            return Vec::new();
        }
        match self {
            Component::Lambert(_) | Component::OrenNayar(..) => {
                sample_cosine_hemisphere(u).into_iter().collect()
            }
            Component::Torrance {
                distribution, m, ..
            } => glossy_candidates(&MicrofacetDistribution::new(distribution, m), wo, u),
        }
    }
}

fn check_component(c: Component, bsdf: &Bsdf, q: &Query) -> Check {
    check_query(bsdf, Kind::Exact, q, &c.candidates(q.wo, q.u))
}

/// Rough dielectric (both sides are legitimate): both transport modes, all lobe selections.
fn check_dielectric(d: &RoughDielectric, q: &Query) -> Check {
    let (wo, wi) = (q.wo, q.wi());
    for mode in [TransportMode::Radiance, TransportMode::Importance] {
        let f = d.value(wo, wi, mode);
        ensure!(
            f.is_finite() && f >= 0.0,
            "eval(wo {wo:?}, wi {wi:?}, {mode:?}) = {f}"
        );
        for lobes in [Lobes::All, Lobes::Reflection, Lobes::Transmission] {
            let p = d.pdf_lobes(wo, wi, lobes);
            ensure!(
                p.is_finite() && p >= 0.0,
                "pdf(wo {wo:?}, wi {wi:?}, {lobes:?}) = {p}"
            );
        }
        if f > 0.0 {
            let p = d.pdf_lobes(wo, wi, Lobes::All);
            ensure!(
                p > 0.0,
                "eval(wo {wo:?}, wi {wi:?}, {mode:?}) = {f} > 0 but pdf(All) = {p}"
            );
        }
        for lobes in [Lobes::All, Lobes::Reflection, Lobes::Transmission] {
            let Some(s) = d.sample_lobes(wo, q.uc, q.u, mode, lobes) else {
                continue;
            };
            let at = format!(
                "sample(wo {wo:?}, uc {:?}, u {:?}, {mode:?}, {lobes:?}) = {s:?}",
                q.uc, q.u
            );
            ensure!(is_unit(s.wi), "{at}: wi not unit");
            ensure!(s.pdf > 0.0 && s.pdf.is_finite(), "{at}: bad pdf");
            ensure!(
                s.f.is_valid() && s.weight.is_valid(),
                "{at}: f or weight invalid"
            );
            let side = s.wi.z * wo.z;
            match lobes {
                Lobes::Reflection => ensure!(side > 0.0, "{at}: reflection crossed the surface"),
                Lobes::Transmission => ensure!(side < 0.0, "{at}: transmission did not cross"),
                Lobes::All => ensure!(side != 0.0, "{at}: wi in the surface plane"),
            }
            let f = d.value(wo, s.wi, mode);
            ensure!(close(s.f[0], f, REL), "{at}: s.f != eval = {f}");
            let p = d.pdf_lobes(wo, s.wi, lobes);
            ensure!(close(s.pdf, p, REL), "{at}: s.pdf != pdf = {p}");
            ensure!(
                weight_matches(s.weight, s.f, s.wi.z.abs(), s.pdf),
                "{at}: weight != f·cos/pdf"
            );
        }
    }
    // Both facets of the sampled V-cavity, reflected and refracted, must have pdf > 0 where f > 0.
    for h in cavity_normals(&d.distribution, q.u) {
        if wo.z == 0.0 || wo.dot(h) * wo.z <= 0.0 {
            continue;
        }
        let mut dirs = vec![reflect(wo, h).normalize()];
        dirs.extend(refract(wo, h, d.eta));
        for c in dirs {
            let f = d.value(wo, c, TransportMode::Radiance);
            let p = d.pdf_lobes(wo, c, Lobes::All);
            ensure!(
                f.is_finite() && f >= 0.0 && p.is_finite() && p >= 0.0,
                "sampled micro-normal {h:?}: eval(wo {wo:?}, {c:?}) = {f}, pdf = {p}"
            );
            ensure!(
                f <= 0.0 || p > 0.0,
                "sampled micro-normal {h:?}: eval(wo {wo:?}, {c:?}) = {f} > 0, pdf = {p}"
            );
        }
    }
    // The closed enum dispatches to the same thing.
    let via_enum = Bsdf::Dielectric(d.clone()).eval(wo, wi);
    ensure!(
        via_enum == RgbSample::splat(d.value(wo, wi, TransportMode::Radiance)),
        "Bsdf::Dielectric disagrees"
    );
    Ok(())
}

// ------------------------------------------------------------------------------------------------
// Stacks
// ------------------------------------------------------------------------------------------------

/// Relative IORs of the coats (`below / above`), top first.
fn etas(desc: &StackDesc) -> Vec<f32> {
    let mut above = 1.0;
    desc.coats
        .iter()
        .map(|c| {
            let eta = c.ior / above;
            above = c.ior;
            eta
        })
        .collect()
}

/// Directions the stack's lobes produce for `wo` and `u`: each interface's glossy lobe and the
/// base's lobe, refracted out through the macro normal, and the cosine (multiple) lobe.
fn stack_candidates(desc: &StackDesc, wo: Vec3, u: Vec2) -> Vec<Vec3> {
    if wo.z <= 0.0 {
        return Vec::new();
    }
    let etas = etas(desc);
    let leave = |mut w: Vec3, level: usize| -> Option<Vec3> {
        for l in (0..level).rev() {
            w = refract_macro(w, 1.0 / etas[l])?;
        }
        Some(w)
    };
    let mut out: Vec<Vec3> = sample_cosine_hemisphere(u).into_iter().collect();
    let mut w = Some(wo);
    for (l, c) in desc.coats.iter().enumerate() {
        let Some(wl) = w else { break };
        let d = MicrofacetDistribution::new(desc.distribution, c.roughness);
        out.extend(
            glossy_candidates(&d, wl, u)
                .into_iter()
                .filter_map(|x| leave(x, l)),
        );
        w = refract_macro(wl, etas[l]);
    }
    if let Some(wb) = w {
        let inner = match desc.base {
            Base::Lambert { .. } | Base::OrenNayar { .. } => {
                let mut v: Vec<Vec3> = sample_cosine_hemisphere(u).into_iter().collect();
                // The same disk point shrunk into the escape cone `sin θ' < 1/η` of the coat
                // above: its rim maps to grazing directions outside.
                if let (Some(d), Some(&eta)) = (sample_cosine_hemisphere(u), etas.last())
                    && eta > 1.0
                {
                    let (x, y) = (d.x / eta, d.y / eta);
                    let z = (1.0 - x * x - y * y).max(0.0).sqrt();
                    if z > 0.0 {
                        v.push(Vec3::new(x, y, z));
                    }
                }
                v
            }
            Base::Conductor { roughness, .. } => glossy_candidates(
                &MicrofacetDistribution::new(desc.distribution, roughness),
                wb,
                u,
            ),
        };
        out.extend(inner.into_iter().filter_map(|x| leave(x, desc.coats.len())));
    }
    out
}

fn check_stack(stack: &LayeredBsdf, desc: &StackDesc, q: &Query) -> Check {
    let kind = kind_of(stack.model());
    check_query(stack, kind, q, &stack_candidates(desc, q.wo, q.u))
        .map_err(|e| format!("{:?}: {e}", stack.model()))
}

/// `eval` is finite and non-negative and `pdf` finite and ≥ 0 for every query.
fn eval_and_pdf_are_finite<'a>(
    stack: &LayeredBsdf,
    queries: impl Iterator<Item = &'a Query>,
) -> Result<(), String> {
    for q in queries {
        let (wo, wi) = (q.wo, q.wi());
        let f = stack.eval(wo, wi);
        let p = stack.pdf(wo, wi);
        ensure!(
            f.is_valid() && p.is_finite() && p >= 0.0,
            "{:?}: eval({wo:?}, {wi:?}) = {f:?}, pdf {p}",
            stack.model()
        );
    }
    Ok(())
}

/// The stack of `desc` under each of the three models.
fn build_all_models(desc: &StackDesc) -> Result<Vec<LayeredBsdf>, String> {
    let built = catch_unwind(AssertUnwindSafe(|| LayeredBsdf::new(desc)))
        .map_err(|_| "LayeredBsdf::new panicked".to_string())?
        .map_err(|e| format!("LayeredBsdf::new rejected an in-range description: {e}"))?;
    Ok(MODELS.iter().map(|&m| built.with_model(m)).collect())
}

fn coat(ior: f32, roughness: f32) -> Coat {
    Coat {
        ior,
        roughness,
        absorption: Rgb::ZERO,
        thickness: 0.0,
    }
}

fn absorbing(ior: f32, roughness: f32, od: f32) -> Coat {
    Coat {
        ior,
        roughness,
        absorption: Rgb::splat(od),
        thickness: 1.0,
    }
}

fn lambert(a: f32) -> Base {
    Base::Lambert {
        albedo: Rgb::splat(a),
    }
}

fn conductor(n: f32, k: f32, roughness: f32) -> Base {
    Base::Conductor {
        ior: ConductorIor::Complex {
            n: Rgb::splat(n),
            k: Rgb::splat(k),
        },
        roughness,
    }
}

fn perfect(roughness: f32) -> Base {
    Base::Conductor {
        ior: ConductorIor::Perfect,
        roughness,
    }
}

/// Stacks at the edges of every parameter (each with the default options; variants of options
/// are added by [`edge_stacks`]).
fn edge_stack_shapes() -> Vec<(Vec<Coat>, Base)> {
    let on = |sigma| Base::OrenNayar {
        albedo: Rgb::new(1.0, 0.5, 0.0),
        sigma,
    };
    vec![
        (vec![], lambert(1.0)),
        (vec![], perfect(0.01)),
        (vec![coat(1.5, 5.0)], lambert(1.0)),
        (vec![coat(1.0001, 0.01)], lambert(1.0)),
        (vec![coat(4.0, 0.01)], lambert(1.0)),
        (vec![coat(4.0, 45.0)], on(1.0)),
        (vec![coat(1.0001, 45.0)], on(0.0)),
        (vec![coat(1.7, 7.0)], perfect(10.0)),
        (vec![coat(1.5, 0.01)], perfect(0.01)),
        (vec![coat(4.0, 0.01)], conductor(0.01, 10.0, 0.01)),
        (vec![coat(1.0001, 45.0)], conductor(4.0, 10.0, 45.0)),
        (vec![coat(1.3, 12.0)], conductor(0.01, 0.0, 3.0)),
        // A conductor index-matched to the varnish above it (relative n = 1, k = 0).
        (vec![coat(1.5, 10.0)], conductor(1.5, 0.0, 10.0)),
        (vec![], conductor(1.0, 0.0, 10.0)),
        (vec![absorbing(1.5, 10.0, 1e3)], lambert(1.0)),
        (vec![absorbing(1.5, 0.01, 1e3)], perfect(0.01)),
        (
            vec![coat(1.5, 10.0), absorbing(1.7, 3.0, 1e3)],
            conductor(0.2, 3.0, 5.0),
        ),
        // Index-matched inner interface (the course's light blue house paint).
        (vec![coat(1.3, 30.0), coat(1.3, 7.0)], on(0.34)),
        // Descending IORs: relative η < 1 inside, total internal reflection from above.
        (vec![coat(4.0, 5.0), coat(1.0001, 0.01)], lambert(1.0)),
        (
            vec![coat(4.0, 45.0), coat(1.0001, 45.0), coat(4.0, 0.01)],
            perfect(0.01),
        ),
        (
            vec![coat(1.0001, 0.01), coat(1.0002, 0.01), coat(1.0003, 0.01)],
            lambert(1.0),
        ),
        (
            vec![
                absorbing(1.5, 2.0, 1e-3),
                absorbing(2.0, 20.0, 1.0),
                absorbing(3.0, 45.0, 1e3),
            ],
            on(0.5),
        ),
        // Spot checks of very rough interfaces beyond the design range (the types allow < 90°).
        (vec![coat(1.5, 60.0)], conductor(0.2, 3.0, 80.0)),
        (vec![coat(1.5, 89.0)], lambert(0.8)),
        (vec![coat(4.0, 89.0), coat(1.5, 89.0)], perfect(89.0)),
    ]
}

/// Every edge shape under a rotation of the options, so that each option value meets many shapes.
fn edge_stacks() -> Vec<StackDesc> {
    edge_stack_shapes()
        .into_iter()
        .enumerate()
        .map(|(i, (coats, base))| {
            let mut d = StackDesc::new(coats, base);
            d.fresnel = FRESNEL_MODES[i % 4];
            d.distribution = [
                Distribution::Blinn,
                Distribution::Beckmann,
                Distribution::Ggx,
            ][(i / 4) % 3];
            d.t_term = [None, Some(true), Some(false)][i % 3];
            d.compensation = (i / 2) % 2 == 0;
            d
        })
        .collect()
}

/// Runs `check` over `items`, collecting every failure (not just the first) into one panic.
fn all_pass<T: Debug>(what: &str, items: impl IntoIterator<Item = T>, check: impl Fn(&T) -> Check) {
    let mut failures = Vec::new();
    let mut n = 0usize;
    for item in items {
        n += 1;
        if let Err(e) = check(&item) {
            failures.push(format!("{item:?}\n    {e}"));
        }
    }
    assert!(
        failures.is_empty(),
        "{what}: {} of {n} cases fail:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

// ------------------------------------------------------------------------------------------------
// Table-driven edges
// ------------------------------------------------------------------------------------------------

const EDGE_COS: [f32; 10] = [0.0, -0.0, 1.0, -1.0, 1e-7, -1e-7, 0.5, -0.5, 0.745, -0.745];

const EDGE_ETA: [f32; 7] = [1.0001, 1.5, 4.0, 1.0 / 1.0001, 1.0 / 1.5, 0.25, 1.0];

const EDGE_NK: [(f32, f32); 8] = [
    (0.01, 0.0),
    (0.01, 10.0),
    (4.0, 10.0),
    (4.0, 0.0),
    (1.0, 0.0),
    (0.2, 3.0),
    (1.0, 10.0),
    (1.5, 1e-7),
];

fn check_fresnel_value(what: &str, v: f32) -> Check {
    ensure!(
        v.is_finite() && (0.0..=1.0).contains(&v),
        "{what} = {v}, outside [0, 1]"
    );
    Ok(())
}

fn check_fresnel(cos: f32, eta: f32, n: f32, k: f32) -> Check {
    check_fresnel_value(
        &format!("dielectric({cos:?}, {eta:?})"),
        fresnel::dielectric(cos, eta),
    )?;
    check_fresnel_value(
        &format!("schlick_dielectric({cos:?}, {eta:?})"),
        fresnel::schlick_dielectric(cos, eta),
    )?;
    check_fresnel_value(
        &format!("conductor({cos:?}, {n:?}, {k:?})"),
        fresnel::conductor(cos, n, k),
    )?;
    check_fresnel_value(
        &format!("lazanyi({cos:?}, {n:?}, {k:?})"),
        fresnel::lazanyi(cos, n, k),
    )?;
    Ok(())
}

fn check_fresnel_objects(cos: f32, eta: f32, n: f32, k: f32) -> Check {
    let nk = (RgbSample::rgb(n, 1.0, 0.2), RgbSample::rgb(k, 0.0, 10.0));
    for mode in FRESNEL_MODES {
        for (what, fr) in [
            ("dielectric", Fresnel::dielectric(eta, mode)),
            ("conductor", Fresnel::conductor(nk.0, nk.1, mode)),
        ] {
            let v = fr.eval(cos);
            for c in 0..3 {
                check_fresnel_value(
                    &format!(
                        "Fresnel::{what}(eta {eta:?} / n {:?} k {:?}, {mode:?}).eval({cos:?})[{c}]",
                        nk.0, nk.1
                    ),
                    v[c],
                )?;
            }
        }
    }
    Ok(())
}

#[test]
fn fresnel_edges_stay_in_unit_interval() {
    let mut cases = Vec::new();
    for &cos in &EDGE_COS {
        for &eta in &EDGE_ETA {
            for &(n, k) in &EDGE_NK {
                cases.push((cos, eta, n, k));
            }
        }
    }
    all_pass(
        "fresnel free functions",
        cases.iter().copied(),
        |&(c, e, n, k)| check_fresnel(c, e, n, k),
    );
    // The Fresnel objects (all modes, including the table built from the exact equations).
    let cases: Vec<_> = EDGE_COS
        .iter()
        .flat_map(|&c| EDGE_ETA.iter().map(move |&e| (c, e)))
        .collect();
    all_pass("Fresnel::eval", cases, |&(c, e)| {
        for &(n, k) in &EDGE_NK {
            check_fresnel_objects(c, e, n, k)?;
        }
        Ok(())
    });
}

#[test]
fn fresnel_known_limits() {
    // Grazing is total reflection for every conductor with k > 0 and every dielectric.
    for &(n, k) in &EDGE_NK {
        if k > 0.0 {
            let r = fresnel::conductor(0.0, n, k);
            assert!((r - 1.0).abs() < 1e-5, "conductor(0, {n}, {k}) = {r}");
        }
    }
    for &eta in &EDGE_ETA {
        if eta != 1.0 {
            let r = fresnel::dielectric(0.0, eta);
            assert!((r - 1.0).abs() < 1e-5, "dielectric(0, {eta}) = {r}");
        }
    }
    // Total internal reflection from inside beyond the critical angle.
    assert_eq!(fresnel::dielectric(-0.5, 1.5), 1.0);
    assert_eq!(fresnel::schlick_dielectric(-0.5, 1.5), 1.0);
}

#[test]
fn refraction_edges_are_unit_or_none() {
    let dirs = edge_dirs();
    let normals = [
        Vec3::Z,
        -Vec3::Z,
        Vec3::new(1.0, 0.0, 1e-7).normalize(),
        from_z_phi(0.3, 2.0),
    ];
    let mut cases = Vec::new();
    for &w in &dirs {
        for &n in &normals {
            for &eta in &EDGE_ETA {
                cases.push((w, n, eta));
            }
        }
    }
    all_pass("refract", cases, |&(w, n, eta)| check_refract(w, n, eta));
    let cases: Vec<_> = dirs
        .iter()
        .filter(|w| w.z > 0.0)
        .flat_map(|&w| EDGE_ETA.iter().map(move |&e| (w, e)))
        .collect();
    all_pass("refract_macro", cases, |&(w, eta)| {
        check_refract_macro(w, eta)
    });
}

fn check_refract(w: Vec3, n: Vec3, eta: f32) -> Check {
    // Sines from the tangential components (accurate near the normal), η relative to the side
    // `n` points into.
    let ci = w.dot(n);
    let si = w.cross(n).length();
    let ratio = if ci >= 0.0 { eta } else { 1.0 / eta };
    let Some(t) = refract(w, n, eta) else {
        ensure!(
            si / ratio > 1.0 - 1e-5,
            "refract({w:?}, {n:?}, {eta:?}) = None without total internal reflection"
        );
        return Ok(());
    };
    ensure!(
        is_unit(t),
        "refract({w:?}, {n:?}, {eta:?}) = {t:?} not unit"
    );
    ensure!(
        ci * t.dot(n) <= 0.0,
        "refract({w:?}, {n:?}, {eta:?}) = {t:?} did not cross the interface"
    );
    let st = t.cross(n).length();
    ensure!(
        (si - ratio * st).abs() < 1e-4,
        "refract({w:?}, {n:?}, {eta:?}) = {t:?} breaks Snell's law: {si} vs {}",
        ratio * st
    );
    Ok(())
}

fn check_refract_macro(w: Vec3, eta: f32) -> Check {
    let s = Vec2::new(w.x, w.y).length();
    let Some(t) = refract_macro(w, eta) else {
        ensure!(
            s / eta > 1.0 - 1e-5,
            "refract_macro({w:?}, {eta:?}) = None without total internal reflection"
        );
        return Ok(());
    };
    ensure!(is_unit(t), "refract_macro({w:?}, {eta:?}) = {t:?} not unit");
    ensure!(
        t.z > 0.0,
        "refract_macro({w:?}, {eta:?}) = {t:?} not upward"
    );
    let st = Vec2::new(t.x, t.y).length();
    ensure!(
        (s - eta * st).abs() < 1e-4,
        "refract_macro({w:?}, {eta:?}) = {t:?} breaks Snell's law: {s} vs {}",
        eta * st
    );
    Ok(())
}

#[test]
fn microfacet_sampler_edges() {
    let ms = [0.01f32, 0.1, 1.0, 10.0, 45.0, 60.0, 80.0, 89.0, 89.99];
    let mut cases = Vec::new();
    for &m in &ms {
        for dist in [
            Distribution::Blinn,
            Distribution::Beckmann,
            Distribution::Ggx,
        ] {
            cases.push((dist, m));
        }
    }
    all_pass("microfacet", cases, |&(dist, m)| {
        let d = MicrofacetDistribution::new(dist, m);
        for &(_, u) in &edge_us() {
            check_microfacet(&d, u)?;
        }
        for h in edge_dirs() {
            let v = d.d(h);
            ensure!(v.is_finite() && v >= 0.0, "D({h:?}) = {v}");
        }
        Ok(())
    });
}

fn check_microfacet(d: &MicrofacetDistribution, u: Vec2) -> Check {
    let Some(h) = d.sample_h(u) else {
        return Ok(());
    };
    ensure!(
        is_unit(h) && h.z > 0.0,
        "sample_h({u:?}) = {h:?} not an upward unit vector"
    );
    let p = d.pdf_h(h);
    ensure!(
        p.is_finite() && p > 0.0,
        "sample_h({u:?}) = {h:?} has pdf_h {p}"
    );
    Ok(())
}

/// Components at the edges of their parameters.
fn edge_components() -> Vec<Component> {
    let mut out = vec![
        Component::Lambert(RgbSample::ONE),
        Component::Lambert(RgbSample::ZERO),
        Component::OrenNayar(RgbSample::ONE, 0.0),
        Component::OrenNayar(RgbSample::ONE, 1.0),
        Component::OrenNayar(RgbSample::rgb(1.0, 0.3, 0.0), 0.5),
    ];
    let fresnels = [
        FresnelDesc::Perfect,
        FresnelDesc::Dielectric(1.0001, FresnelMode::Exact),
        FresnelDesc::Dielectric(4.0, FresnelMode::Schlick),
        FresnelDesc::Dielectric(0.25, FresnelMode::Table),
        FresnelDesc::Dielectric(1.5, FresnelMode::Lazanyi),
        FresnelDesc::Conductor(
            RgbSample::splat(0.01),
            RgbSample::splat(10.0),
            FresnelMode::Exact,
        ),
        FresnelDesc::Conductor(
            RgbSample::splat(4.0),
            RgbSample::splat(0.0),
            FresnelMode::Table,
        ),
        FresnelDesc::Conductor(
            RgbSample::splat(1.0),
            RgbSample::splat(0.0),
            FresnelMode::Table,
        ),
        FresnelDesc::Conductor(
            RgbSample::rgb(0.2, 1.0, 4.0),
            RgbSample::rgb(3.0, 0.0, 10.0),
            FresnelMode::Schlick,
        ),
        FresnelDesc::Conductor(
            RgbSample::rgb(0.2, 1.0, 4.0),
            RgbSample::rgb(3.0, 0.0, 10.0),
            FresnelMode::Lazanyi,
        ),
    ];
    let ms = [0.01f32, 1.0, 20.0, 45.0, 89.0];
    let mut k = 0usize;
    for &m in &ms {
        for &fresnel in &fresnels {
            for distribution in [
                Distribution::Blinn,
                Distribution::Beckmann,
                Distribution::Ggx,
            ] {
                out.push(Component::Torrance {
                    distribution,
                    m,
                    fresnel,
                    compensation: k.is_multiple_of(3),
                });
                k += 1;
            }
        }
    }
    out
}

#[test]
fn component_edges() {
    let queries = edge_queries();
    let us = edge_us();
    all_pass("components", edge_components(), |&c| {
        let b = c.build();
        for q in &queries {
            check_component(c, &b, q).map_err(|e| format!("{q:?}: {e}"))?;
        }
        for wo in edge_dirs() {
            for &(uc, u) in &us {
                let q = Query {
                    wo,
                    rel: Rel::Mirror,
                    uc,
                    u,
                };
                check_component(c, &b, &q)?;
            }
        }
        Ok(())
    });
}

#[test]
fn dielectric_edges() {
    let mut cases = Vec::new();
    for &m in &[0.01f32, 1.0, 20.0, 45.0, 89.0] {
        for &eta in &[1.0001f32, 1.5, 4.0, 1.0 / 1.0001, 0.25] {
            for dist in [
                Distribution::Blinn,
                Distribution::Beckmann,
                Distribution::Ggx,
            ] {
                cases.push((dist, m, eta));
            }
        }
    }
    let queries = edge_queries();
    let extra: Vec<Query> = edge_dirs()
        .into_iter()
        .flat_map(|wo| {
            [Rel::NearOpposite(1e-4, 0.3), Rel::NearOpposite(1e-2, 2.0)].map(|rel| Query {
                wo,
                rel,
                uc: 0.999,
                u: Vec2::new(0.3, 0.6),
            })
        })
        .collect();
    all_pass("rough dielectric", cases, |&(dist, m, eta)| {
        let d = RoughDielectric::new(MicrofacetDistribution::new(dist, m), eta);
        for q in queries.iter().chain(&extra) {
            check_dielectric(&d, q).map_err(|e| format!("{q:?}: {e}"))?;
        }
        Ok(())
    });
}

#[test]
fn stack_edges_under_all_models() {
    let queries = edge_queries();
    let below = [
        Vec3::new(0.6, 0.0, -0.8),
        Vec3::new(1.0, 0.0, -1e-7),
        -Vec3::Z,
    ];
    all_pass("edge stacks", edge_stacks(), |desc| {
        for stack in build_all_models(desc)? {
            for q in queries.iter().step_by(3) {
                check_stack(&stack, desc, q).map_err(|e| format!("{q:?}: {e}"))?;
            }
            for &(uc, u) in edge_us().iter().step_by(4) {
                for wo in [Vec3::Z, Vec3::new(1.0, 0.0, 1e-7), from_z_phi(0.7, 1.0)] {
                    let q = Query {
                        wo,
                        rel: Rel::Mirror,
                        uc,
                        u,
                    };
                    check_stack(&stack, desc, &q)?;
                }
                for wo in below {
                    check_below(&stack, wo, Vec3::Z, uc, u)
                        .map_err(|e| format!("{:?}: {e}", stack.model()))?;
                }
            }
        }
        Ok(())
    });
}

#[test]
fn catalogue_edges_under_all_models() {
    let lib = MaterialLibrary::course();
    let names: Vec<String> = lib.names().map(str::to_owned).collect();
    assert_eq!(names.len(), 11);
    let queries = edge_queries();
    all_pass("catalogue", names, |name| {
        let desc = lib.stack(name).map_err(|e| e.to_string())?;
        let built = lib
            .build(name, Some(Model::Corrected))
            .map_err(|e| e.to_string())?;
        for model in MODELS {
            let stack = built.with_model(model);
            for q in queries.iter().step_by(2) {
                check_stack(&stack, &desc, q).map_err(|e| format!("{q:?}: {e}"))?;
            }
            for &(uc, u) in edge_us().iter().step_by(3) {
                check_below(&stack, Vec3::new(1.0, 0.0, -1e-7), Vec3::Z, uc, u)?;
                let q = Query {
                    wo: Vec3::new(0.0, 1.0, 1e-7),
                    rel: Rel::Same,
                    uc,
                    u,
                };
                check_stack(&stack, &desc, &q)?;
            }
        }
        Ok(())
    });
}

/// With `αd = 1e3` nothing below the top interface survives (underflow to 0, never NaN): the
/// analytic models' `eval` reduces to the top lobe, the Reference walk's (no compensation) to the
/// interface's reflection. (The pdf may still give the dead lower lobes a small floor weight, so it
/// is only held to the general properties.)
fn check_opaque_varnish(desc: &StackDesc) -> Check {
    let c0 = desc.coats[0];
    let eta = c0.ior;
    let dist = MicrofacetDistribution::new(desc.distribution, c0.roughness);
    let top = TorranceSparrow::new(dist, Fresnel::dielectric(eta, desc.fresnel));
    let iface = RoughDielectric::new(dist, eta);
    for stack in build_all_models(desc)? {
        for q in edge_queries() {
            let (wo, wi) = (q.wo, q.wi());
            let f = stack.eval(wo, wi);
            ensure!(
                f.is_valid(),
                "{:?}: eval({wo:?}, {wi:?}) = {f:?}",
                stack.model()
            );
            match stack.model() {
                Model::Reference(_) => {
                    let expect = if wo.z > 0.0 && wi.z > 0.0 {
                        RgbSample::splat(iface.value(wo, wi, TransportMode::Radiance))
                    } else {
                        RgbSample::ZERO
                    };
                    ensure!(
                        close_spectrum(f, expect, REL),
                        "Reference: eval({wo:?}, {wi:?}) = {f:?}, the interface alone gives \
                         {expect:?}"
                    );
                }
                model => {
                    let expect = top.eval(wo, wi);
                    ensure!(
                        close_spectrum(f, expect, REL),
                        "{model:?}: eval({wo:?}, {wi:?}) = {f:?}, the top lobe alone gives \
                         {expect:?}"
                    );
                }
            }
            let kind = kind_of(stack.model());
            check_pair(&stack, kind, wo, wi)
                .and_then(|()| check_sample(&stack, kind, wo, q.uc, q.u))
                .map_err(|e| format!("{:?}: {e}", stack.model()))?;
        }
    }
    Ok(())
}

#[test]
fn huge_optical_depth_underflows_to_the_top_lobe() {
    let mut cases = Vec::new();
    let mut k = 0usize;
    for base in [lambert(1.0), perfect(5.0), conductor(0.2, 3.0, 20.0)] {
        for &(ior, m) in &[(1.5f32, 10.0f32), (1.0001, 0.01), (4.0, 45.0)] {
            let mut d = StackDesc::new(vec![absorbing(ior, m, 1e3)], base);
            d.fresnel = FRESNEL_MODES[k % 4];
            d.compensation = false;
            d.t_term = [None, Some(true)][k % 2];
            d.distribution = [
                Distribution::Blinn,
                Distribution::Beckmann,
                Distribution::Ggx,
            ][(k / 2) % 3];
            k += 1;
            // The same optical depth as an absorption of 1 through 1e3 units, over another coat.
            let mut d2 = d.clone();
            d2.coats[0].absorption = Rgb::ONE;
            d2.coats[0].thickness = 1e3;
            d2.coats.push(coat(2.0, 3.0));
            d2.fresnel = FRESNEL_MODES[(k + 1) % 4];
            cases.push(d);
            cases.push(d2);
        }
    }
    all_pass("opaque varnish", cases, check_opaque_varnish);
}

#[test]
fn below_surface_returns_nothing() {
    let below = [
        Vec3::new(0.6, 0.0, -0.8),
        Vec3::new(1.0, 0.0, -1e-7),
        from_z_phi(-1e-4, 2.0),
        -Vec3::Z,
    ];
    let cases: Vec<(Vec3, Vec3, (f32, Vec2))> = below
        .iter()
        .flat_map(|&wo| {
            [Vec3::Z, -wo, mirror(wo), wo, Vec3::new(0.0, 1.0, 1e-7)]
                .into_iter()
                .flat_map(move |wi| edge_us().into_iter().step_by(7).map(move |u| (wo, wi, u)))
        })
        .collect();
    let comps: Vec<Bsdf> = edge_components()
        .into_iter()
        .map(Component::build)
        .collect();
    all_pass(
        "components below",
        cases.iter().copied(),
        |&(wo, wi, (uc, u))| {
            for b in &comps {
                check_below(b, wo, wi, uc, u).map_err(|e| format!("{b:?}: {e}"))?;
            }
            Ok(())
        },
    );
}

/// Out-of-range descriptions: each must be rejected with `Err`, never a panic, never `Ok`.
fn corruptions() -> Vec<(&'static str, StackDesc)> {
    let good = StackDesc::new(
        vec![coat(1.5, 10.0), absorbing(1.7, 5.0, 0.5)],
        conductor(0.2, 3.0, 10.0),
    );
    let mut out = Vec::new();
    let bad_f = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY];
    let mut push = |what: &'static str, f: &dyn Fn(&mut StackDesc)| {
        let mut d = good.clone();
        f(&mut d);
        out.push((what, d));
    };
    for v in [1.0f32, 0.999, 0.5, 0.0, -0.0, -1.5, 1.00005]
        .into_iter()
        .chain(bad_f)
    {
        push("coat ior", &|d| d.coats[0].ior = v);
        push("inner coat ior", &|d| d.coats[1].ior = v);
    }
    for v in [0.0f32, -0.0, -1.0, 90.0, 90.5, 180.0, 1e30]
        .into_iter()
        .chain(bad_f)
    {
        push("coat roughness", &|d| d.coats[1].roughness = v);
        push("base roughness", &|d| {
            d.base = conductor(0.2, 3.0, v);
        });
        push("perfect base roughness", &|d| d.base = perfect(v));
    }
    for v in [-1e-30f32, -1.0].into_iter().chain(bad_f) {
        push("thickness", &|d| d.coats[0].thickness = v);
        push("absorption", &|d| {
            d.coats[1].absorption = Rgb::new(0.1, v, 0.1)
        });
    }
    for v in [-0.1f32, 1.1].into_iter().chain(bad_f) {
        push("lambert albedo", &|d| {
            d.base = Base::Lambert {
                albedo: Rgb::new(0.5, 0.5, v),
            }
        });
        push("oren-nayar albedo", &|d| {
            d.base = Base::OrenNayar {
                albedo: Rgb::new(v, 0.5, 0.5),
                sigma: 0.3,
            }
        });
    }
    for v in [-0.1f32, 3.0].into_iter().chain(bad_f) {
        push("oren-nayar sigma", &|d| {
            d.base = Base::OrenNayar {
                albedo: Rgb::ONE,
                sigma: v,
            }
        });
    }
    for v in [0.0f32, -1.0].into_iter().chain(bad_f) {
        push("conductor n", &|d| {
            d.base = Base::Conductor {
                ior: ConductorIor::Complex {
                    n: Rgb::new(0.2, v, 0.2),
                    k: Rgb::splat(3.0),
                },
                roughness: 10.0,
            }
        });
    }
    for v in [-1e-3f32, -1.0].into_iter().chain(bad_f) {
        push("conductor k", &|d| {
            d.base = Base::Conductor {
                ior: ConductorIor::Complex {
                    n: Rgb::splat(0.2),
                    k: Rgb::new(3.0, 3.0, v),
                },
                roughness: 10.0,
            }
        });
    }
    push("reference samples 0", &|d| {
        d.model = Model::Reference(ReferenceParams {
            samples: 0,
            max_depth: 16,
        })
    });
    push("reference depth 0", &|d| {
        d.model = Model::Reference(ReferenceParams {
            samples: 2,
            max_depth: 0,
        })
    });
    out
}

fn check_rejected(desc: &StackDesc) -> Check {
    match catch_unwind(AssertUnwindSafe(|| LayeredBsdf::new(desc))) {
        Err(_) => Err("LayeredBsdf::new panicked on an out-of-range description".into()),
        Ok(Ok(_)) => Err("LayeredBsdf::new accepted an out-of-range description".into()),
        Ok(Err(_)) => Ok(()),
    }
}

#[test]
fn construction_rejects_out_of_range() {
    all_pass("out-of-range descriptions", corruptions(), |(_, d)| {
        check_rejected(d)
    });
}

#[test]
fn construction_accepts_range_edges() {
    // The validator's own bounds, inclusive where documented so.
    let shapes = [
        (vec![coat(1.0001, 0.01)], lambert(0.0)),
        (vec![coat(10.0, 89.99)], lambert(1.0)),
        (
            vec![coat(10.0, 0.01), coat(1.0001, 89.99)],
            Base::OrenNayar {
                albedo: Rgb::ONE,
                sigma: 1.5,
            },
        ),
        (vec![coat(1.5, 5.0)], conductor(20.0, 20.0, 89.99)),
        (vec![coat(1.5, 5.0)], conductor(1e-6, 0.0, 0.01)),
        (vec![], perfect(89.99)),
    ];
    all_pass("range edges", shapes, |(coats, base)| {
        let mut d = StackDesc::new(coats.clone(), *base);
        d.fresnel = FresnelMode::Table;
        for stack in build_all_models(&d)? {
            eval_and_pdf_are_finite(&stack, edge_queries().iter().step_by(5))?;
        }
        Ok(())
    });
}

// ------------------------------------------------------------------------------------------------
// Strategies
// ------------------------------------------------------------------------------------------------

/// `10^x` for `x` uniform in `[log10 lo, log10 hi]`, clamped into `[lo, hi]`.
fn log_uniform(lo: f32, hi: f32) -> impl Strategy<Value = f32> {
    (lo.log10()..=hi.log10()).prop_map(move |x| 10f32.powf(x).clamp(lo, hi))
}

/// `lo ..= hi`, log-uniform and uniform, with both ends as edges.
fn ranged(lo: f32, hi: f32) -> impl Strategy<Value = f32> {
    prop_oneof![
        4 => log_uniform(lo, hi),
        2 => lo..=hi,
        1 => Just(lo),
        1 => Just(hi),
    ]
}

fn roughness() -> impl Strategy<Value = f32> {
    ranged(0.01, 45.0)
}

fn ior() -> impl Strategy<Value = f32> {
    // 1.5 often, so that neighbouring coats are index-matched now and then.
    prop_oneof![6 => ranged(1.0001, 4.0), 1 => Just(1.5f32)]
}

fn unit_interval() -> impl Strategy<Value = f32> {
    prop_oneof![4 => 0.0f32..=1.0, 1 => Just(0.0f32), 1 => Just(1.0f32)]
}

/// Three independent channels, each drawn from `channel()`.
fn spectrum<S: Strategy<Value = f32>>(channel: impl Fn() -> S) -> impl Strategy<Value = Rgb> {
    (channel(), channel(), channel()).prop_map(|(r, g, b)| Rgb::new(r, g, b))
}

fn conductor_n() -> impl Strategy<Value = f32> {
    prop_oneof![6 => ranged(0.01, 4.0), 1 => Just(1.0f32)]
}

fn conductor_k() -> impl Strategy<Value = f32> {
    prop_oneof![
        3 => 0.0f32..=10.0,
        2 => log_uniform(1e-4, 10.0),
        1 => Just(0.0f32),
        1 => Just(10.0f32),
    ]
}

fn fresnel_mode() -> impl Strategy<Value = FresnelMode> {
    prop::sample::select(FRESNEL_MODES.to_vec())
}

fn distribution() -> impl Strategy<Value = Distribution> {
    prop_oneof![
        Just(Distribution::Blinn),
        Just(Distribution::Beckmann),
        Just(Distribution::Ggx)
    ]
}

/// A uniform number with its edges.
fn unit_u() -> impl Strategy<Value = f32> {
    prop_oneof![
        6 => 0.0f32..1.0,
        1 => Just(0.0f32),
        1 => Just(1.0f32),
        1 => Just(ONE_MINUS_EPS),
        1 => Just(1e-7f32),
    ]
}

fn angle() -> impl Strategy<Value = f32> {
    0.0f32..TAU
}

/// Directions on the whole sphere: uniform, grazing (`|cos θ|` 1e-7 … 0.1, either side), close to
/// the normal, and the edge directions.
fn direction() -> impl Strategy<Value = Vec3> {
    prop_oneof![
        4 => (-1.0f32..=1.0, angle()).prop_map(|(z, phi)| from_z_phi(z, phi)),
        3 => (1.0f32..=7.0, any::<bool>(), angle()).prop_map(|(e, up, phi)| {
            let z = 10f32.powf(-e);
            from_z_phi(if up { z } else { -z }, phi)
        }),
        1 => (1.0f32..=7.0, any::<bool>(), angle()).prop_map(|(e, up, phi)| {
            let z = 1.0 - 10f32.powf(-e);
            from_z_phi(if up { z } else { -z }, phi)
        }),
        1 => prop::sample::select(edge_dirs()),
    ]
}

/// A viewing direction, three times in four above the surface (the rest below, as a bump-tilted
/// facet produces it).
fn view_direction() -> impl Strategy<Value = Vec3> {
    (direction(), 0u8..4).prop_map(|(w, k)| {
        if k == 0 {
            w
        } else {
            Vec3::new(w.x, w.y, w.z.abs())
        }
    })
}

fn relation() -> impl Strategy<Value = Rel> {
    prop_oneof![
        6 => direction().prop_map(Rel::Free),
        1 => Just(Rel::Same),
        1 => Just(Rel::Opposite),
        1 => Just(Rel::Mirror),
        2 => (log_uniform(1e-6, 0.1), angle()).prop_map(|(a, p)| Rel::NearMirror(a, p)),
        1 => (log_uniform(1e-6, 0.1), angle()).prop_map(|(a, p)| Rel::NearOpposite(a, p)),
    ]
}

fn query_with(wo: impl Strategy<Value = Vec3>) -> impl Strategy<Value = Query> {
    (wo, relation(), unit_u(), unit_u(), unit_u()).prop_map(|(wo, rel, uc, a, b)| Query {
        wo,
        rel,
        uc,
        u: Vec2::new(a, b),
    })
}

fn fresnel_desc() -> impl Strategy<Value = FresnelDesc> {
    prop_oneof![
        3 => (
            prop_oneof![ranged(1.0001, 4.0), ranged(1.0001, 4.0).prop_map(|e| 1.0 / e)],
            fresnel_mode()
        )
            .prop_map(|(e, m)| FresnelDesc::Dielectric(e, m)),
        3 => (spectrum(conductor_n), spectrum(conductor_k), fresnel_mode())
            .prop_map(|(n, k, m)| FresnelDesc::Conductor(n.into(), k.into(), m)),
        1 => Just(FresnelDesc::Perfect),
    ]
}

fn component() -> impl Strategy<Value = Component> {
    prop_oneof![
        1 => spectrum(unit_interval).prop_map(|a| Component::Lambert(a.into())),
        2 => (spectrum(unit_interval), unit_interval())
            .prop_map(|(a, s)| Component::OrenNayar(a.into(), s)),
        // Compensation builds a table (milliseconds): one Torrance–Sparrow lobe in eight.
        5 => (distribution(), roughness(), fresnel_desc(), 0u8..8).prop_map(
            |(distribution, m, fresnel, c)| Component::Torrance {
                distribution,
                m,
                fresnel,
                compensation: c == 0,
            }
        ),
    ]
}

/// Optical depth `αd` of one channel: 0, or 1e-3 … 1e3.
fn optical_depth() -> impl Strategy<Value = f32> {
    prop_oneof![2 => Just(0.0f32), 4 => log_uniform(1e-3, 1e3), 1 => Just(1e3f32)]
}

fn coat_strategy() -> impl Strategy<Value = Coat> {
    (
        ior(),
        roughness(),
        spectrum(optical_depth),
        prop_oneof![Just(0.0f32), Just(1.0f32), Just(15.0f32), 0.01f32..15.0],
    )
        .prop_map(|(ior, roughness, od, thickness)| Coat {
            ior,
            roughness,
            // Zero thickness keeps the absorption coefficient but has no optical depth.
            absorption: if thickness > 0.0 {
                od * (1.0 / thickness)
            } else {
                od
            },
            thickness,
        })
}

fn base_strategy() -> impl Strategy<Value = Base> {
    prop_oneof![
        spectrum(unit_interval).prop_map(|albedo| Base::Lambert { albedo }),
        (spectrum(unit_interval), unit_interval())
            .prop_map(|(albedo, sigma)| Base::OrenNayar { albedo, sigma }),
        (
            prop_oneof![
                4 => (spectrum(conductor_n), spectrum(conductor_k))
                    .prop_map(|(n, k)| ConductorIor::Complex { n, k }),
                1 => Just(ConductorIor::Perfect),
            ],
            roughness()
        )
            .prop_map(|(ior, roughness)| Base::Conductor { ior, roughness }),
    ]
}

fn model_strategy() -> impl Strategy<Value = Model> {
    prop::sample::select(MODELS.to_vec())
}

fn stack_desc() -> impl Strategy<Value = StackDesc> {
    (
        prop::collection::vec(coat_strategy(), 1..=3),
        base_strategy(),
        model_strategy(),
        fresnel_mode(),
        distribution(),
        prop_oneof![Just(None), Just(Some(true)), Just(Some(false))],
        any::<bool>(),
        (any::<bool>(), any::<bool>()),
    )
        .prop_map(
            |(mut coats, base, model, fresnel, distribution, t_term, compensation, smooth_top)| {
                StackDesc {
                    // The top coat may be perfectly smooth (a delta reflection).
                    coats: {
                        if smooth_top.0 {
                            coats[0].roughness = 0.0;
                        }
                        coats
                    },
                    base,
                    model,
                    fresnel,
                    distribution,
                    // The candidate directions of these checks are the V-cavity sampler's; Smith
                    // masking has its own tests (tests/chi_square.rs, tests/dielectric.rs).
                    masking: lapidary::bsdf::Masking::VCavity,
                    outside_ior: 1.0,
                    t_term,
                    compensation,
                    calibration: smooth_top.1,
                    base_spectrum: None,
                    fluorescence: None,
                }
            },
        )
}

/// Runs a property with a fixed seed, no persistence and bounded shrinking; panics with the
/// minimal failing input.
fn run_property<S>(name: &str, seed: u8, cases: u32, strategy: S, test: impl Fn(S::Value) -> Check)
where
    S: Strategy,
    S::Value: Debug,
{
    let config = Config {
        cases,
        failure_persistence: None,
        rng_algorithm: RngAlgorithm::ChaCha,
        // Shrinking a stack rebuilds its tables: bound it so a failure still ends in seconds.
        max_shrink_iters: 1000,
        max_shrink_time: 10_000,
        ..Config::default()
    };
    let rng = TestRng::from_seed(RngAlgorithm::ChaCha, &[seed; 32]);
    let mut runner = TestRunner::new_with_rng(config, rng);
    match runner.run(&strategy, |v| test(v).map_err(TestCaseError::fail)) {
        Ok(()) => {}
        Err(TestError::Fail(reason, value)) => {
            panic!("{name}: {reason}\nminimal failing input: {value:#?}")
        }
        Err(e) => panic!("{name}: {e}"),
    }
}

// ------------------------------------------------------------------------------------------------
// Properties (each run twice: a default size and, ignored, a long one)
// ------------------------------------------------------------------------------------------------

fn fresnel_property(cases: u32) {
    let cos = prop_oneof![
        4 => -1.0f32..=1.0,
        2 => (1.0f32..=7.0, any::<bool>()).prop_map(|(e, s)| if s { 10f32.powf(-e) } else { -10f32.powf(-e) }),
        1 => prop::sample::select(EDGE_COS.to_vec()),
    ];
    let eta = prop_oneof![
        ranged(1.0001, 4.0),
        ranged(1.0001, 4.0).prop_map(|e| 1.0 / e)
    ];
    run_property(
        "fresnel",
        1,
        cases,
        (cos, eta, conductor_n(), conductor_k()),
        |(c, e, n, k)| {
            check_fresnel(c, e, n, k)?;
            check_fresnel_objects(c, e, n, k)
        },
    );
}

fn refract_property(cases: u32) {
    let eta = prop_oneof![
        ranged(1.0001, 4.0),
        ranged(1.0001, 4.0).prop_map(|e| 1.0 / e)
    ];
    let normal = prop_oneof![Just(Vec3::Z), direction()];
    run_property(
        "refract",
        2,
        cases,
        (direction(), normal, eta),
        |(w, n, eta)| {
            check_refract(w, n, eta)?;
            if w.z > 0.0 {
                check_refract_macro(w, eta)?;
            }
            Ok(())
        },
    );
}

fn microfacet_property(cases: u32) {
    let m = prop_oneof![8 => roughness(), 1 => 45.0f32..89.99];
    run_property(
        "microfacet",
        3,
        cases,
        (distribution(), m, unit_u(), unit_u(), direction()),
        |(dist, m, a, b, h)| {
            let d = MicrofacetDistribution::new(dist, m);
            check_microfacet(&d, Vec2::new(a, b))?;
            let v = d.d(h);
            ensure!(v.is_finite() && v >= 0.0, "D({h:?}) = {v}");
            Ok(())
        },
    );
}

fn component_property(cases: u32) {
    run_property(
        "components",
        4,
        cases,
        (
            component(),
            prop::collection::vec(query_with(view_direction()), 8),
        ),
        |(c, queries)| {
            let b = c.build();
            for q in &queries {
                check_component(c, &b, q).map_err(|e| format!("{q:?}: {e}"))?;
            }
            Ok(())
        },
    );
}

fn dielectric_property(cases: u32) {
    let eta = prop_oneof![
        ranged(1.0001, 4.0),
        ranged(1.0001, 4.0).prop_map(|e| 1.0 / e)
    ];
    run_property(
        "rough dielectric",
        5,
        cases,
        (
            distribution(),
            roughness(),
            eta,
            prop::collection::vec(query_with(direction()), 8),
        ),
        |(dist, m, eta, queries)| {
            let d = RoughDielectric::new(MicrofacetDistribution::new(dist, m), eta);
            for q in &queries {
                check_dielectric(&d, q).map_err(|e| format!("{q:?}: {e}"))?;
            }
            Ok(())
        },
    );
}

fn stack_property(cases: u32, queries_per_stack: usize) {
    run_property(
        "stacks",
        6,
        cases,
        (
            stack_desc(),
            prop::collection::vec(query_with(view_direction()), queries_per_stack),
        ),
        |(desc, queries)| {
            for stack in build_all_models(&desc)? {
                for q in &queries {
                    check_stack(&stack, &desc, q).map_err(|e| format!("{q:?}: {e}"))?;
                }
            }
            Ok(())
        },
    );
}

/// Full validator ranges (wider than the design's): never panics, always `Ok`, results finite.
fn construction_property(cases: u32) {
    let wide_coat = (
        1.0001f32..=10.0,
        0.01f32..89.99,
        spectrum(optical_depth),
        0.0f32..=15.0,
    )
        .prop_map(|(ior, roughness, absorption, thickness)| Coat {
            ior,
            roughness,
            absorption,
            thickness,
        });
    let wide_base = prop_oneof![
        spectrum(unit_interval).prop_map(|albedo| Base::Lambert { albedo }),
        (spectrum(unit_interval), 0.0f32..=1.5)
            .prop_map(|(albedo, sigma)| Base::OrenNayar { albedo, sigma }),
        (
            spectrum(|| 1e-6f32..=20.0),
            spectrum(|| 0.0f32..=20.0),
            0.01f32..89.99
        )
            .prop_map(|(n, k, roughness)| Base::Conductor {
                ior: ConductorIor::Complex { n, k },
                roughness,
            }),
    ];
    let desc = (
        prop::collection::vec(wide_coat, 0..=3),
        wide_base,
        fresnel_mode(),
        distribution(),
        any::<bool>(),
    )
        .prop_map(|(coats, base, fresnel, distribution, compensation)| {
            let mut d = StackDesc::new(coats, base);
            d.fresnel = fresnel;
            d.distribution = distribution;
            d.compensation = compensation;
            d
        });
    run_property(
        "construction in range",
        7,
        cases,
        (desc, prop::collection::vec(query_with(view_direction()), 2)),
        |(desc, queries)| {
            for stack in build_all_models(&desc)? {
                eval_and_pdf_are_finite(&stack, queries.iter())?;
            }
            Ok(())
        },
    );
}

/// A valid description with one field made out of range must be rejected.
fn rejection_property(cases: u32) {
    let bad = prop_oneof![
        Just(f32::NAN),
        Just(f32::INFINITY),
        Just(f32::NEG_INFINITY),
        -1e3f32..0.0,
    ];
    let bad_ior = prop_oneof![bad.clone(), -10.0f32..=1.0];
    let bad_m = prop_oneof![bad.clone(), -90.0f32..=0.0, 90.0f32..1e3];
    let corruption = (0u8..7, 0usize..3, 0usize..3, bad_ior, bad_m, bad);
    run_property(
        "construction out of range",
        8,
        cases,
        (stack_desc(), corruption),
        |(mut desc, (which, coat, ch, bad_ior, bad_m, bad))| {
            let c = coat % desc.coats.len();
            match which {
                0 => desc.coats[c].ior = bad_ior,
                1 => desc.coats[c].roughness = bad_m,
                2 => desc.coats[c].thickness = bad,
                3 => {
                    let mut a = desc.coats[c].absorption.0;
                    a[ch] = bad;
                    desc.coats[c].absorption = Rgb(a);
                }
                4 => {
                    desc.base = Base::Conductor {
                        ior: ConductorIor::Perfect,
                        roughness: bad_m,
                    }
                }
                5 => {
                    let mut a = [0.5; 3];
                    a[ch] = bad;
                    desc.base = Base::Lambert { albedo: Rgb(a) }
                }
                _ => {
                    let mut k = [1.0; 3];
                    k[ch] = bad;
                    desc.base = Base::Conductor {
                        ior: ConductorIor::Complex {
                            n: Rgb::ONE,
                            k: Rgb(k),
                        },
                        roughness: 10.0,
                    }
                }
            }
            check_rejected(&desc).map_err(|e| format!("{e}: {desc:?}"))
        },
    );
}

#[test]
fn prop_fresnel() {
    fresnel_property(10_000);
}

#[test]
fn prop_refract() {
    refract_property(50_000);
}

#[test]
fn prop_microfacet() {
    microfacet_property(50_000);
}

#[test]
fn prop_components() {
    component_property(1_000);
}

#[test]
fn prop_dielectric() {
    dielectric_property(5_000);
}

#[test]
fn prop_stacks() {
    stack_property(40, 6);
}

#[test]
fn prop_construction_in_range() {
    construction_property(12);
}

#[test]
fn prop_construction_out_of_range() {
    rejection_property(2_000);
}

// Long versions: `cargo test --release --test hard_cases -- --ignored`

#[test]
#[ignore = "long: cargo test --release --test hard_cases -- --ignored"]
fn prop_fresnel_long() {
    fresnel_property(1_000_000);
}

#[test]
#[ignore = "long: cargo test --release --test hard_cases -- --ignored"]
fn prop_refract_long() {
    refract_property(1_000_000);
}

#[test]
#[ignore = "long: cargo test --release --test hard_cases -- --ignored"]
fn prop_microfacet_long() {
    microfacet_property(1_000_000);
}

#[test]
#[ignore = "long: cargo test --release --test hard_cases -- --ignored"]
fn prop_components_long() {
    component_property(50_000);
}

#[test]
#[ignore = "long: cargo test --release --test hard_cases -- --ignored"]
fn prop_dielectric_long() {
    dielectric_property(50_000);
}

#[test]
#[ignore = "long: cargo test --release --test hard_cases -- --ignored"]
fn prop_stacks_long() {
    stack_property(3_000, 8);
}

#[test]
#[ignore = "long: cargo test --release --test hard_cases -- --ignored"]
fn prop_construction_in_range_long() {
    construction_property(1_000);
}

#[test]
#[ignore = "long: cargo test --release --test hard_cases -- --ignored"]
fn prop_construction_out_of_range_long() {
    rejection_property(50_000);
}
