//! Item 2 of tests/smooth_coat.rs: the checks of a smooth top coat's delta bookkeeping for one
//! stack and viewing direction (see the module docs there).

use super::{ODS, chi, coat, gold, lambert};
use glam::{Vec2, Vec3};
use lapidary::bsdf::{
    Base, BsdfSample, Bxdf, Coat, LayeredBsdf, LobeFlags, LobeKind, Model, fresnel,
};
use lapidary::sampler::Rng;
use std::f32::consts::FRAC_1_PI;

/// `(name, coats, base, single coat over Lambert: (ρ, od) for the exact checks)`.
pub type Case = (&'static str, Vec<Coat>, Base, Option<(f32, [f32; 3])>);

pub fn cases() -> Vec<Case> {
    let two = vec![coat(1.5, 0.0, [0.0; 3]), coat(1.7, 15.0, [0.3, 0.0, 0.1])];
    vec![
        (
            "η 1.5 od 0/0.5/2 / Lambert 0.8",
            vec![coat(1.5, 0.0, ODS)],
            lambert(0.8),
            Some((0.8, ODS)),
        ),
        (
            "η 2 / Lambert 1",
            vec![coat(2.0, 0.0, [0.0; 3])],
            lambert(1.0),
            Some((1.0, [0.0; 3])),
        ),
        (
            "η 1.5 / gold 10°",
            vec![coat(1.5, 0.0, [0.0, 0.2, 0.5])],
            gold(10.0),
            None,
        ),
        ("η 1.5 / η 1.7 m 15° / Lambert 0.5", two, lambert(0.5), None),
    ]
}

pub fn close(a: f32, b: f32, rel: f32) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()) + 1e-30
}

/// The mean of `g` at four directions `delta` radians from `w`.
fn neighbours(w: Vec3, delta: f32, g: impl Fn(Vec3) -> [f32; 3]) -> [f32; 3] {
    let (t1, t2) = w.any_orthonormal_pair();
    let mut sum = [0.0; 3];
    for d in [t1, -t1, t2, -t2] {
        let v = g((w + d * delta).normalize());
        (0..3).for_each(|c| sum[c] += v[c] / 4.0);
    }
    sum
}

/// Course's body for one smooth coat over Lambert, exactly.
fn course_body(wo: Vec3, wi: Vec3, eta: f32, rho: f32, od: [f32; 3]) -> [f32; 3] {
    let inner = |w: Vec3| (1.0 - (1.0 - w.z * w.z) / (eta * eta)).sqrt();
    let t = (1.0 - fresnel::dielectric(wo.z, eta)) * (1.0 - fresnel::dielectric(wi.z, eta));
    let path = 1.0 / inner(wo) + 1.0 / inner(wi);
    od.map(|o| t * rho * FRAC_1_PI * (-o * path).exp())
}

/// Every check of item 2 for an analytic model at `wo`; returns the failures.
pub fn bookkeeping(b: &LayeredBsdf, case: &Case, wo: Vec3, n: u64, seed: u64) -> Vec<String> {
    let mut bad = Vec::new();
    let eta = case.1[0].ior;
    let f = fresnel::dielectric(wo.z, eta);
    let mirror = Vec3::new(-wo.x, -wo.y, wo.z);
    let mut rng = Rng::new(seed);
    let top = b
        .sample(wo, 0.0, rng.uniform2())
        .filter(|s| s.flags.is_specular());
    let Some(s0) = top else {
        return vec!["uc = 0 gives no specular sample".into()];
    };
    let p = s0.pdf;
    let delta_ok = |s: &BsdfSample| {
        s.wi == mirror
            && s.flags == LobeFlags::SPECULAR | LobeFlags::REFLECTION
            && s.lobe.kind == LobeKind::SpecularReflection
            && s.pdf == p
            && s.eta == 1.0
            && (0..3).all(|c| close(s.weight[c], f / p, 1e-5) && close(s.f[c], f / wo.z, 1e-5))
    };
    for k in 0..8 {
        let s = b.sample(wo, p * k as f32 / 8.0, rng.uniform2());
        if !s.as_ref().is_some_and(delta_ok) {
            bad.push(format!("uc {}·w_top (w_top {p}): {s:?}", k as f32 / 8.0));
        }
    }
    let above = p + (p * 1e-5).max(1e-6);
    if above < 1.0
        && b.sample(wo, above, rng.uniform2())
            .is_some_and(|s| s.flags.is_specular())
    {
        bad.push(format!("uc just above w_top {p} is still specular"));
    }
    // eval and pdf at the mirror: the body's, continuous with the neighbourhood.
    let at = b.eval(wo, mirror).0;
    let nb = neighbours(mirror, 0.1f32.to_radians(), |w| b.eval(wo, w).0);
    let (pm, pnb) = (
        b.pdf(wo, mirror),
        neighbours(mirror, 0.1f32.to_radians(), |w| [b.pdf(wo, w); 3])[0],
    );
    let cont = |a: f32, n: f32| a.is_finite() && a >= 0.0 && (a - n).abs() <= 2e-3 * n + 1e-6;
    if !(0..3).all(|c| cont(at[c], nb[c])) || !cont(pm, pnb) {
        bad.push(format!(
            "at the mirror eval {at:?} pdf {pm} vs neighbours {nb:?} {pnb}"
        ));
    }
    let exact = |wi: Vec3| match (b.model(), case.3) {
        (Model::Course, Some((rho, od))) => Some(course_body(wo, wi, eta, rho, od)),
        _ => None,
    };
    if let Some(e) = exact(mirror).filter(|e| !(0..3).all(|c| close(at[c], e[c], 2e-4))) {
        bad.push(format!("Course at the mirror: {at:?}, exact body {e:?}"));
    }
    // Random samples.
    let (mut spec, mut ok) = (0u64, 0u64);
    for _ in 0..n {
        let Some(s) = b.sample(wo, rng.uniform(), rng.uniform2()) else {
            continue;
        };
        if s.flags.is_specular() {
            spec += 1;
            if !delta_ok(&s) {
                bad.push(format!("specular sample {s:?}"));
            }
            continue;
        }
        ok += 1;
        let e = b.eval(wo, s.wi);
        let consistent =
            close(b.pdf(wo, s.wi), s.pdf, 1e-5) && (0..3).all(|c| close(e[c], s.f[c], 1e-5));
        if !consistent || exact(s.wi).is_some_and(|x| !(0..3).all(|c| close(e[c], x[c], 2e-4))) {
            bad.push(format!(
                "wi {}: pdf {} eval {e:?} vs sample {s:?}",
                s.wi,
                b.pdf(wo, s.wi)
            ));
        }
    }
    let (nf, pf) = (n as f64, f64::from(p));
    if (spec as f64 - nf * pf).abs() > 5.0 * (nf * pf * (1.0 - pf)).sqrt() + 1.0 {
        bad.push(format!("{spec} specular samples of {n}, w_top {p}"));
    }
    let mass = chi::hemisphere(24, 96).integrate(2, 0.0, 0, |w| f64::from(b.pdf(wo, w)));
    let integral: f64 = mass.iter().sum();
    let frac = ok as f64 / nf;
    if case.3.is_some() && (integral - (1.0 - pf)).abs() > 0.01 {
        bad.push(format!("∫pdf {integral:.5}, 1 − w_top {:.5}", 1.0 - pf));
    }
    if (integral - frac).abs() > 5.0 * (frac * (1.0 - frac) / nf).sqrt() + 0.005 {
        bad.push(format!(
            "∫pdf {integral:.5}, non-specular successes {frac:.5}"
        ));
    }
    bad.truncate(3);
    bad
}

/// The Reference walk's delta: `uc < F` reflects with weight 1; `pdf` at the mirror is the
/// documented mixture of the uncalibrated Corrected pdf, no delta in it.
pub fn reference_checks(
    r: &LayeredBsdf,
    uncal: &LayeredBsdf,
    eta: f32,
    wo: Vec3,
) -> Option<String> {
    let f = fresnel::dielectric(wo.z, eta);
    let mirror = Vec3::new(-wo.x, -wo.y, wo.z);
    let s = r.sample(wo, 0.5 * f, Vec2::new(0.3, 0.7));
    let spec = |s: &BsdfSample| s.flags == LobeFlags::SPECULAR | LobeFlags::REFLECTION;
    if !s
        .as_ref()
        .is_some_and(|s| spec(s) && s.wi == mirror && close(s.weight[0], 1.0, 1e-5))
    {
        return Some(format!("uc = F/2: {s:?}"));
    }
    if r.sample(wo, f * (1.0 + 1e-5) + 1e-6, Vec2::new(0.3, 0.7))
        .is_some_and(|s| spec(&s))
    {
        return Some("uc just above F is specular".into());
    }
    let (pm, want) = (
        r.pdf(wo, mirror),
        0.9 * uncal.pdf(wo, mirror) + 0.1 * mirror.z * FRAC_1_PI,
    );
    let e = r.eval(wo, mirror);
    (!(close(pm, want, 1e-5) && e.is_valid()))
        .then(|| format!("at the mirror pdf {pm} (want {want}), eval {e:?}"))
}
