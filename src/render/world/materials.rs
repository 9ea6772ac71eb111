//! The material table of a world: every used layer stack built once (identical stacks share one
//! build, in parallel, at most one material per task so that a stop is noticed soon), then the
//! translucent body's boundary and its platelets' faces; with each, its albedo for the AOV.

use super::{PROGRESS_AFTER, Setup, WorldError};
use crate::bsdf::layered::ladder::AlbedoLadder;
use crate::bsdf::{Bsdf, Bxdf, LayeredBsdf, StackDesc};
use crate::color::Rgb;
use crate::scene::{Effect, Scene};
use crate::spectrum::RgbSample;
use crate::spectrum::prefilter::Prefilter;
use glam::{Vec2, Vec3};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// The materials of `scene` (its `stacks`, reduced under `prefilter` when given) and their
/// albedos, indexed like the surface's leaves (an unused material is `None`), then the
/// translucent body's boundary and its platelets' faces.
pub(super) fn build(
    scene: &Scene,
    stacks: &[StackDesc],
    prefilter: Option<&Prefilter>,
    setup: &Setup,
) -> Result<(Vec<Option<Bsdf>>, Vec<Rgb>), WorldError> {
    // Tables take tens of milliseconds per material: build them in parallel (the result is
    // the same in any order), at most one material per task, so a stop is noticed soon.
    // Materials whose stacks are identical share one build (the first of them builds).
    let mut seen: std::collections::HashMap<String, usize> = std::collections::HashMap::new();
    let twin: Vec<usize> = (0..stacks.len())
        .map(|k| {
            if scene.surface.used[k] {
                let key = format!("{:?}", stacks[k]);
                *seen.entry(key).or_insert(k)
            } else {
                k
            }
        })
        .collect();
    let distinct = seen.len() as u64;
    let bar = ProgressBar::with_draw_target(Some(distinct), ProgressDrawTarget::hidden());
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {wide_bar} {pos}/{len} material tables ETA {eta}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let start = Instant::now();
    let shown = AtomicBool::new(false);
    let built: Vec<Result<Option<(Bsdf, Rgb)>, WorldError>> = stacks
        .par_iter()
        .with_max_len(1)
        .enumerate()
        .map(|(k, desc)| {
            if !scene.surface.used[k] || twin[k] != k {
                return Ok(None);
            }
            setup.check()?;
            if setup.progress
                && start.elapsed() > PROGRESS_AFTER
                && !shown.swap(true, Ordering::Relaxed)
            {
                // A terminal draw target draws nothing when standard error is not a terminal.
                bar.set_draw_target(ProgressDrawTarget::stderr());
            }
            bar.inc(1);
            let material = |source| WorldError::Material {
                name: scene.surface.names[k].clone(),
                source,
            };
            let absorption = scene.effects.forced(Effect::Absorption);
            let spectral = scene.effects.on(Effect::Spectral);
            let build = || {
                let mut stack = LayeredBsdf::new(desc).map_err(material)?;
                stack.force_absorption(absorption);
                if spectral
                    && let Some(l) = AlbedoLadder::build(desc, absorption).map_err(material)?
                {
                    stack.set_albedo_ladder(l);
                }
                let bsdf = Bsdf::from(stack);
                let albedo = Rgb::from(normal_albedo(&bsdf));
                Ok((bsdf, albedo))
            };
            match setup.cache {
                // Everything the build reads: the stack, the absorption switch and whether the
                // spectral ladder is built.
                Some(cache) => cache
                    .get_or_build(format!("{desc:?}|{absorption:?}|{spectral}"), build)
                    .map(Some),
                None => build().map(Some),
            }
        })
        .collect();
    bar.finish_and_clear();
    let mut materials: Vec<Option<Bsdf>> = Vec::with_capacity(built.len());
    let mut albedo = Vec::with_capacity(built.len());
    for (k, b) in built.into_iter().enumerate() {
        match b? {
            Some((bsdf, a)) => {
                materials.push(Some(bsdf));
                albedo.push(a);
            }
            // A used twin of an earlier material (built before it: `twin[k] < k`).
            None if scene.surface.used[k] => {
                let first = twin[k];
                materials.push(materials[first].clone());
                albedo.push(albedo[first]);
            }
            None => {
                materials.push(None);
                albedo.push(Rgb::ZERO);
            }
        }
    }
    // The translucent body's boundary is material `body_index`, one past the stacks.
    let body = scene.surface.body.as_ref();
    if let Some(b) = body {
        debug_assert_eq!(materials.len(), scene.surface.body_index() as usize);
        materials.push(Some(b.boundary()));
        // A lossless boundary: everything that arrives leaves, reflected or refracted.
        albedo.push(Rgb::ONE);
        // Platelet faces, under the body's IOR, from `body_index + 1`.
        for (name, desc) in &b.platelet_materials {
            setup.check()?;
            let desc = match &prefilter {
                Some(p) => &crate::render::prefilter::stack(p, desc),
                None => desc,
            };
            let absorption = scene.effects.forced(Effect::Absorption);
            let build = || {
                let mut stack = LayeredBsdf::new(desc).map_err(|source| WorldError::Material {
                    name: format!("platelet:{name}"),
                    source,
                })?;
                stack.force_absorption(absorption);
                let bsdf = Bsdf::from(stack);
                let a = Rgb::from(normal_albedo(&bsdf));
                Ok::<_, WorldError>((bsdf, a))
            };
            let (bsdf, a) = match setup.cache {
                Some(cache) => {
                    cache.get_or_build(format!("platelet|{desc:?}|{absorption:?}"), build)?
                }
                None => build()?,
            };
            albedo.push(a);
            materials.push(Some(bsdf));
        }
    }
    Ok((materials, albedo))
}

/// Directional albedo at normal incidence, from a fixed stratified set of 256 samples (for the
/// albedo AOV only).
fn normal_albedo(bsdf: &Bsdf) -> RgbSample {
    let n = 16;
    let mut sum = RgbSample::ZERO;
    for i in 0..n {
        for j in 0..n {
            let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
            let uc = ((i * n + j) as f32 + 0.5) / (n * n) as f32;
            if let Some(s) = bsdf.sample(Vec3::Z, uc, u) {
                sum += s.weight;
            }
        }
    }
    (sum * (1.0 / (n * n) as f32)).map(|v| v.clamp(0.0, 1.0))
}
