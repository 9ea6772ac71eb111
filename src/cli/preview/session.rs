//! The preview's render worker: one thread that loads the recipe, builds its world (reusing the
//! materials an edit did not change, [`crate::render::world::MaterialCache`]) and hands each
//! generation to [`super::progressive`]. A saved file or a new view stops the range in flight and
//! starts a new generation; the last good image stays published until the new one has its first
//! pixels, and a broken recipe publishes its errors beside it.

use super::progressive::{build, draft, refine, rock};
use super::state::{DEBOUNCE, Phase, Rebuild, Request, Shared};
use super::watch::Inputs;
use crate::scene::{Knobs, Scene};
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

/// What one generation works from.
struct Loaded {
    scene: Scene,
    inputs: Inputs,
    knobs: Knobs,
}

/// The worker: runs until [`Shared::quit`]. Never panics out: a panic inside a generation is
/// caught and shown as an error, and the session goes on.
pub fn run_worker(shared: &Shared) {
    let mut loaded: Option<Loaded> = None;
    loop {
        // Wait for something to do.
        let (request, reload) = {
            let mut s = shared.lock();
            loop {
                if s.quit {
                    return;
                }
                let wait = if s.reload {
                    // Debounced: the files must be quiet for a moment.
                    let quiet = s.last_change.elapsed();
                    if quiet >= DEBOUNCE {
                        break;
                    }
                    DEBOUNCE - quiet
                } else {
                    if shared.restart.load(Ordering::SeqCst)
                        || s.request.rock
                        || s.phase_needs_work()
                    {
                        break;
                    }
                    if s.inputs.changed_on_disk() {
                        s.reload = true;
                        s.last_change = Instant::now();
                        continue;
                    }
                    Duration::from_millis(100)
                };
                s = match shared.wake.wait_timeout(s, wait) {
                    Ok((g, _)) => g,
                    Err(p) => p.into_inner().0,
                };
            }
            // The request read here is the one rendered: a later change sets the flag again.
            shared.restart.store(false, Ordering::SeqCst);
            let reload = std::mem::take(&mut s.reload) || loaded.is_none();
            (s.request, reload)
        };
        let run = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            generation(shared, &mut loaded, request, reload)
        }));
        if run.is_err() {
            shared.publish_error(
                "internal error while rendering (a panic); edit the recipe or the view to try \
                 again"
                    .to_string(),
            );
        }
    }
}

/// One generation: reload if asked, build, refine until the budget or a change.
fn generation(shared: &Shared, loaded: &mut Option<Loaded>, request: Request, reload: bool) {
    let start = Instant::now();
    {
        let mut s = shared.lock();
        s.generation += 1;
        s.generation_start = start;
        s.first_pixels = None;
        s.render_seconds = 0.0;
        s.phase = if reload {
            Phase::Loading
        } else {
            Phase::Building
        };
    }
    if reload {
        match load(shared) {
            Ok(l) => {
                let inputs = l.inputs.clone();
                *loaded = Some(l);
                let mut s = shared.lock();
                let before = std::mem::replace(&mut s.inputs, inputs);
                s.error = None;
                // An event that arrived while the files were read, for what was read: nothing
                // new to reload (the files are as their new stamps say), and unless the page
                // changed the request too, nothing to restart.
                if s.reload && !s.inputs.differ_on_disk() {
                    s.reload = false;
                    if s.request == request {
                        shared.restart.store(false, Ordering::SeqCst);
                    }
                }
                if let Ok(mut w) = shared.watcher.lock()
                    && let Some(w) = w.as_mut()
                {
                    super::watch::rewatch(w, &before, &s.inputs);
                }
            }
            Err(message) => {
                shared.publish_error(message);
                return;
            }
        }
    }
    let Some(l) = loaded.as_ref() else { return };
    let mut scene = l.scene.clone();
    let r = &mut scene.stage.render;
    r.width = request.size.0;
    r.height = request.size.1;
    r.spp = request.spp;
    if request.rock {
        rock(shared, &scene, request, &l.knobs);
        return;
    }
    request.view.apply(&mut scene.stage);
    shared.lock().phase = Phase::Building;
    // The session's first world waits for every material's tables: a draft without the
    // Corrected calibration (most of that time) shows the stone first.
    if shared.cache.counts() == (0, 0) {
        draft(shared, &scene, request.view, &l.knobs);
    }
    let (reused0, built0) = shared.cache.counts();
    let Some(world) = build(shared, &scene) else {
        return;
    };
    let (reused1, built1) = shared.cache.counts();
    {
        let mut s = shared.lock();
        s.rebuild = Rebuild {
            reused: reused1 - reused0,
            built: built1 - built0,
            seconds: start.elapsed().as_secs_f64(),
        };
        s.phase = Phase::Rendering;
    }
    refine(shared, Arc::new(scene), world, request.view, &l.knobs);
}

/// Reads and compiles the recipe; the error text is every error `lapidary check` finds.
fn load(shared: &Shared) -> Result<Loaded, String> {
    let path = &shared.recipe;
    let knobs = shared.lock().knobs.clone();
    match crate::cli::load::load_scene(path, &knobs.accuracy, None) {
        Ok(mut l) => {
            knobs.apply_render(&mut l.scene);
            l.scene.stage.stokes = shared.stokes;
            Ok(Loaded {
                inputs: Inputs::of_loaded(path, &l.recipe),
                scene: l.scene,
                knobs,
            })
        }
        Err(e) => {
            let report = crate::cli::check::check_file(path);
            if report.errors.is_empty() {
                Err(format!("{e:#}"))
            } else {
                Err(report
                    .errors
                    .iter()
                    .map(|e| format!("error: {e}"))
                    .collect::<Vec<_>>()
                    .join("\n"))
            }
        }
    }
}
