//! How one generation of the preview is rendered: a quick quarter-resolution frame, then sample
//! ranges that merge exactly into one film until the budget (or the rock motion's frames), each
//! published as it completes; the worker pauses while no page asks.

use super::state::{Image, Phase, ROCK_AMPLITUDE, ROCK_PERIOD, Request, Shared};
use crate::render::world::Setup;
use crate::render::{Control, Film, World, render};
use crate::scene::view::{MAX_TILT, View};
use crate::scene::{Knobs, Scene};
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

/// Renders samples `range` of `scene` at `1/scale` of its size; `None` when stopped part way.
fn render_range(
    shared: &Shared,
    world: &World,
    scene: &Scene,
    range: std::ops::Range<u32>,
    scale: u32,
) -> Option<(Film, u64, f64)> {
    let mut settings = scene.stage.render;
    settings.width = settings.width.div_ceil(scale).max(1);
    settings.height = settings.height.div_ceil(scale).max(1);
    let control = Control {
        threads: shared.threads,
        cancel: Some(&shared.restart),
        samples: Some(range),
        ..Control::default()
    };
    let r = render(
        world,
        &scene.stage.camera,
        scene.effects.on(crate::scene::Effect::DepthOfField),
        &settings,
        &control,
    );
    (!r.stats.partial).then_some((r.film, r.stats.paths, r.stats.elapsed.as_secs_f64()))
}

/// Refines the image of one generation until its budget or a change.
pub(super) fn refine(
    shared: &Shared,
    scene: Arc<Scene>,
    world: Arc<World>,
    view: View,
    knobs: &Knobs,
) {
    let (w, h) = (scene.stage.render.width, scene.stage.render.height);
    let budget = scene.stage.render.spp;
    // A quick quarter-resolution frame first (a sixteenth of one pass), unless the image is
    // small already.
    if w >= 160 && h >= 120 && !quick_frame(shared, (&scene, &world, view, knobs), 1, 4) {
        return;
    }
    let mut film = Film::new(w, h);
    let mut done = 0u32;
    let mut rate = 0.0f64; // pixel samples per second
    let seconds = shared.lock().request.seconds;
    let mut spent = 0.0f64;
    while done < budget && seconds.is_none_or(|b| spent < b) {
        if shared.restart.load(Ordering::SeqCst) || !wait_for_a_client(shared) {
            return;
        }
        // Ranges of about a third of a second once the rate is known (1 spp first).
        let pixels = f64::from(w) * f64::from(h);
        let want = if rate > 0.0 {
            (rate * 0.33 / pixels).floor().clamp(1.0, 256.0) as u32
        } else {
            1
        };
        let end = done.saturating_add(want).min(budget);
        let Some((part, paths, secs)) = render_range(shared, &world, &scene, done..end, 1) else {
            return;
        };
        for (acc, p) in film.pixels.iter_mut().zip(&part.pixels) {
            acc.merge(p);
        }
        if film.stokes.is_empty() {
            film.stokes.clone_from(&part.stokes);
        } else {
            for (acc, s) in film.stokes.iter_mut().zip(&part.stokes) {
                acc.merge(s);
            }
        }
        rate = paths as f64 / secs.max(1e-6);
        spent += secs;
        done = end;
        publish_image(
            shared,
            (&scene, &world, view, knobs),
            film.clone(),
            done,
            1,
            paths,
            secs,
        );
    }
    let s = shared.lock();
    shared.publish(s, |s| s.phase = Phase::Done);
}

/// Pauses while no page has asked for anything for [`Shared::idle`]; `false` when a change
/// or quit ends the wait.
fn wait_for_a_client(shared: &Shared) -> bool {
    let mut s = shared.lock();
    if s.last_client.elapsed() < shared.idle {
        return true;
    }
    let resume = s.phase;
    let since = Instant::now();
    s.phase = Phase::Paused;
    s.pauses += 1;
    shared.publish(s, |_| {});
    let mut s = shared.lock();
    let go_on = loop {
        if s.last_client.elapsed() < shared.idle {
            break true;
        }
        if s.quit || shared.restart.load(Ordering::SeqCst) {
            break false;
        }
        s = match shared.wake.wait_timeout(s, Duration::from_millis(500)) {
            Ok((g, _)) => g,
            Err(p) => p.into_inner().0,
        };
    };
    s.paused_seconds += since.elapsed().as_secs_f64();
    if go_on {
        s.phase = resume;
    }
    go_on
}

/// A draft frame of `scene` with the Corrected model's albedo calibration off (docs/accuracy.md:
/// a few per cent of albedo; most of a first build's time): one sample at a quarter of the size,
/// shown until the calibrated world has its first pixels. Skipped when no material is calibrated.
pub(super) fn draft(shared: &Shared, scene: &Scene, view: View, knobs: &Knobs) {
    let calibrated = |s: &crate::bsdf::StackDesc| {
        s.calibration && s.model == crate::bsdf::Model::Corrected && !s.coats.is_empty()
    };
    if !scene.surface.stacks.iter().any(calibrated) {
        return;
    }
    let mut knobs = knobs.clone();
    knobs.accuracy.calibration = Some(false);
    let mut d = scene.clone();
    if d.set_accuracy(&knobs.accuracy, "preview draft").is_err() {
        return;
    }
    let Some(world) = build(shared, &d) else {
        return;
    };
    quick_frame(shared, (&Arc::new(d), &world, view, &knobs), 1, 4);
}

/// Renders samples `0..spp` at `1/scale` of the size and publishes them; `false` when stopped.
fn quick_frame(
    shared: &Shared,
    what: (&Arc<Scene>, &Arc<World>, View, &Knobs),
    spp: u32,
    scale: u32,
) -> bool {
    let Some((film, paths, secs)) = render_range(shared, what.1, what.0, 0..spp, scale) else {
        return false;
    };
    publish_image(shared, what, film, spp, scale, paths, secs);
    true
}

/// Publishes an image.
fn publish_image(
    shared: &Shared,
    (scene, world, view, knobs): (&Arc<Scene>, &Arc<World>, View, &Knobs),
    film: Film,
    spp: u32,
    scale: u32,
    paths: u64,
    secs: f64,
) {
    let image = Arc::new(Image {
        film,
        spp,
        scale,
        world: Arc::clone(world),
        scene: Arc::clone(scene),
        view,
        knobs: knobs.clone(),
    });
    let s = shared.lock();
    shared.publish(s, |s| {
        if s.first_pixels.is_none() {
            s.first_pixels = Some(s.generation_start.elapsed().as_secs_f64());
        }
        s.paths_per_second = paths as f64 / secs.max(1e-9);
        // A full-resolution range with the session's knobs measures their speed (quick frames
        // and the uncalibrated draft do not).
        if scale == 1 && *knobs == s.knobs {
            let pps = s.paths_per_second;
            s.refined_paths_per_second = Some(pps);
            for c in s.knob_costs.iter_mut().filter(|c| c.knobs == *knobs) {
                c.after = Some(pps);
            }
        }
        s.render_seconds += secs;
        s.image = Some(image);
    });
}

/// Shows the stone rocking: frames at half resolution, 2 spp, each at the tilt of its moment,
/// until the request changes.
pub(super) fn rock(shared: &Shared, base: &Scene, request: Request, knobs: &Knobs) {
    let start = Instant::now();
    shared.lock().phase = Phase::Rocking;
    while !shared.restart.load(Ordering::SeqCst) {
        if !wait_for_a_client(shared) {
            return;
        }
        let t = start.elapsed().as_secs_f64();
        let swing = (std::f64::consts::TAU * t / ROCK_PERIOD).sin() as f32;
        let mut view = request.view;
        view.tilt_x = (view.tilt_x + ROCK_AMPLITUDE * swing).clamp(-MAX_TILT, MAX_TILT);
        let mut scene = base.clone();
        view.apply(&mut scene.stage);
        let Some(world) = build(shared, &scene) else {
            return;
        };
        let scene = Arc::new(scene);
        if !quick_frame(shared, (&scene, &world, view, knobs), 2, 2) {
            return;
        }
        shared.lock().phase = Phase::Rocking;
    }
}

/// Builds the world of `scene`; `None` when stopped by a newer request or failed (the failure
/// is published as the session's error).
pub(super) fn build(shared: &Shared, scene: &Scene) -> Option<Arc<World>> {
    let setup = Setup {
        deadline: None,
        cancel: Some(&shared.restart),
        progress: false,
        cache: Some(&shared.cache),
    };
    match crate::cli::load::build_world(&shared.recipe, scene, &setup) {
        Ok(w) => Some(Arc::new(w)),
        Err(e) if e.stopped() => None,
        Err(e) => {
            shared.publish_error(format!("error: {e}"));
            None
        }
    }
}
