//! The preview session's shared state: what the page asked for, what the worker does, the newest
//! image, and the signals between the worker and the server's threads.

use super::watch::Inputs;
use crate::render::world::MaterialCache;
use crate::render::{Film, World};
use crate::scene::view::View;
use crate::scene::{Knobs, Scene};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::{Duration, Instant};

/// Largest image the preview renders (pixels; the film of 1024×768 is about 150 MB).
pub const MAX_PIXELS: u64 = 1024 * 768;
/// Largest refinement budget in samples per pixel.
pub const MAX_SPP: u32 = 65_536;
/// A cycle of the rock motion, and its amplitude in degrees.
pub const ROCK_PERIOD: f64 = 4.0;
/// Amplitude of the rock motion, degrees of tilt about the world `x` axis.
pub const ROCK_AMPLITUDE: f32 = 20.0;
/// How long the worker refines without any page asking, by default (an open page polls at
/// least every [`super::server::LONG_POLL`]); `--idle` sets it.
pub const CLIENT_TIMEOUT: Duration = Duration::from_secs(30);
/// Quiet time after a file event before the recipe is read again (editors save in steps).
pub const DEBOUNCE: Duration = Duration::from_millis(120);

/// What the session renders, as the page last asked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Request {
    /// Camera, stone tilt, lights.
    pub view: View,
    /// Whether the stone rocks (±[`ROCK_AMPLITUDE`] about `x`, [`ROCK_PERIOD`] s a cycle).
    pub rock: bool,
    /// Image size in pixels.
    pub size: (u32, u32),
    /// Refinement budget in samples per pixel.
    pub spp: u32,
    /// Refinement budget in seconds of rendering (`None`: until `spp`).
    pub seconds: Option<f64>,
}

/// What the worker is doing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// Reading and compiling the recipe.
    Loading,
    /// Building the world (material tables, lights).
    Building,
    /// Refining the image.
    Rendering,
    /// The budget is reached; waiting for a change.
    Done,
    /// Showing the stone rocking.
    Rocking,
    /// No page has asked for a while (the tab was closed): waiting for one.
    Paused,
    /// The recipe is broken; waiting for a fix.
    Error,
}

impl Phase {
    /// The name the page shows.
    pub fn name(self) -> &'static str {
        match self {
            Phase::Loading => "loading",
            Phase::Building => "building",
            Phase::Rendering => "rendering",
            Phase::Done => "done",
            Phase::Rocking => "rocking",
            Phase::Paused => "paused",
            Phase::Error => "error",
        }
    }
}

/// A published image: the accumulated film and what it shows.
#[derive(Debug)]
pub struct Image {
    /// The film (at `1/scale` of the requested size while the first pixels come in).
    pub film: Film,
    /// Samples every pixel has.
    pub spp: u32,
    /// Requested size over film size (1, or 4 for the first quick frame).
    pub scale: u32,
    /// The world and scene it was rendered from (the inspector traces them).
    pub world: Arc<World>,
    /// The compiled scene with the view applied.
    pub scene: Arc<Scene>,
    /// The view it shows, rock tilt included.
    pub view: View,
    /// The knobs it was rendered with.
    pub knobs: Knobs,
}

/// What one knob change costs: the paths per second of full-resolution ranges before it and
/// (updated with every range while the knobs stay) after it.
#[derive(Clone, Debug, PartialEq)]
pub struct KnobCost {
    /// The knob (`reset`: back to the command line's knobs).
    pub key: String,
    /// Its new value.
    pub value: String,
    /// Paths per second with the knobs before the change (`None`: none measured yet).
    pub before: Option<f64>,
    /// Paths per second with the knobs after it (`None`: not measured yet).
    pub after: Option<f64>,
    /// The knobs after the change.
    pub knobs: Knobs,
}

/// Most knob changes the status lists (one per knob; the oldest is dropped).
pub const MAX_KNOB_COSTS: usize = 32;

/// How the last world was built.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Rebuild {
    /// Materials taken from the cache.
    pub reused: u64,
    /// Materials built.
    pub built: u64,
    /// Seconds from reading the recipe to a built world.
    pub seconds: f64,
}

/// The session's state, shared by the worker and the server's threads.
#[derive(Debug)]
pub struct State {
    /// What the page asked for.
    pub request: Request,
    /// The recipe's files changed since they were read.
    pub reload: bool,
    /// When a file last changed.
    pub last_change: Instant,
    /// The server is shutting down.
    pub quit: bool,
    /// The number of the newest published image (0: none yet).
    pub frame: u64,
    /// Bumps with every new accumulation (a saved file or a new view).
    pub generation: u64,
    /// When this generation started.
    pub generation_start: Instant,
    /// Seconds from this generation's start to its first image.
    pub first_pixels: Option<f64>,
    /// What the worker does.
    pub phase: Phase,
    /// The recipe's errors (positioned as `lapidary check` prints them), shown over the image.
    pub error: Option<String>,
    /// The newest image.
    pub image: Option<Arc<Image>>,
    /// Paths per second of the newest range.
    pub paths_per_second: f64,
    /// Seconds spent rendering this generation.
    pub render_seconds: f64,
    /// How the last world was built.
    pub rebuild: Rebuild,
    /// The files the recipe reads (watched).
    pub inputs: Inputs,
    /// Accuracy knobs: the command line's, then as the page sets them.
    pub knobs: Knobs,
    /// Paths per second of the newest full-resolution range rendered with [`State::knobs`].
    pub refined_paths_per_second: Option<f64>,
    /// The page's knob changes and what each costs, newest last, one per knob.
    pub knob_costs: Vec<KnobCost>,
    /// When a page last asked for anything: with no page for [`Shared::idle`] (the tab was
    /// closed) the worker pauses until one comes back.
    pub last_client: Instant,
    /// How many times the worker has paused for want of a page this session (the status
    /// reports it: a request that asks for the state also ends a pause, so `phase` alone
    /// cannot show one afterwards).
    pub pauses: u64,
    /// Seconds the worker has spent paused this session.
    pub paused_seconds: f64,
}

/// The state and the signals around it.
#[derive(Debug)]
pub struct Shared {
    state: Mutex<State>,
    /// Signalled when an image or the state is published (long polls wait on it).
    published: Condvar,
    /// Signalled when a request arrives (the worker waits on it when idle).
    pub(super) wake: Condvar,
    /// Set to stop the range in flight.
    pub(super) restart: AtomicBool,
    /// Materials built so far, reused across rebuilds.
    pub(super) cache: MaterialCache,
    /// The recipe.
    pub recipe: PathBuf,
    /// Worker threads (`None`: one per core).
    pub threads: Option<usize>,
    /// How long the worker renders with no page asking ([`CLIENT_TIMEOUT`] by default).
    pub idle: Duration,
    /// Whether renders measure the Stokes vector (`preview --stokes`): the page then shows the
    /// S0–S3 views and the export writes the AOVs.
    pub stokes: bool,
    /// The folder watcher (kept alive here; the worker adds folders when the inputs change).
    pub(super) watcher: Mutex<Option<notify::RecommendedWatcher>>,
}

impl Shared {
    /// A session for `recipe` (nothing loaded yet: [`super::session::run_worker`] does it).
    pub fn new(
        recipe: PathBuf,
        request: Request,
        knobs: Knobs,
        threads: Option<usize>,
        idle: Duration,
        stokes: bool,
    ) -> Arc<Shared> {
        let now = Instant::now();
        Arc::new(Shared {
            state: Mutex::new(State {
                request,
                reload: true,
                last_change: now - DEBOUNCE,
                quit: false,
                frame: 0,
                generation: 0,
                generation_start: now,
                first_pixels: None,
                phase: Phase::Loading,
                error: None,
                image: None,
                paths_per_second: 0.0,
                render_seconds: 0.0,
                rebuild: Rebuild::default(),
                inputs: Inputs::of_recipe(&recipe),
                knobs,
                refined_paths_per_second: None,
                knob_costs: vec![],
                last_client: now,
                pauses: 0,
                paused_seconds: 0.0,
            }),
            published: Condvar::new(),
            wake: Condvar::new(),
            restart: AtomicBool::new(false),
            cache: MaterialCache::default(),
            recipe,
            threads,
            idle,
            stokes,
            watcher: Mutex::new(None),
        })
    }

    /// The state (a poisoned lock is taken over: the state is plain data, always consistent
    /// between statements).
    pub fn lock(&self) -> MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// Changes the request; a change stops the range in flight and starts a new generation.
    pub fn set_request(&self, f: impl FnOnce(&mut Request)) {
        let mut s = self.lock();
        let before = s.request;
        f(&mut s.request);
        if s.request != before {
            self.restart.store(true, Ordering::SeqCst);
            self.wake.notify_all();
        }
    }

    /// Replaces the knobs (`changed`: the keys and values the page sent): the recipe is compiled
    /// again with them at once, and each changed knob's cost is measured from the next ranges.
    pub fn set_knobs(&self, knobs: Knobs, changed: &[(String, String)]) {
        let mut s = self.lock();
        if s.knobs != knobs {
            let before = s.refined_paths_per_second.take();
            for (key, value) in changed {
                s.knob_costs.retain(|c| &c.key != key);
                if s.knob_costs.len() >= MAX_KNOB_COSTS {
                    s.knob_costs.remove(0);
                }
                s.knob_costs.push(KnobCost {
                    key: key.clone(),
                    value: value.clone(),
                    before,
                    after: None,
                    knobs: knobs.clone(),
                });
            }
            s.knobs = knobs;
            s.reload = true;
            s.last_change = Instant::now() - DEBOUNCE;
            self.restart.store(true, Ordering::SeqCst);
            self.wake.notify_all();
        }
    }

    /// Notes that a page asked for something (wakes a paused worker).
    pub fn client_seen(&self) {
        let mut s = self.lock();
        s.last_client = Instant::now();
        if s.phase == Phase::Paused {
            self.wake.notify_all();
        }
    }

    /// Marks the recipe's files changed (the watcher calls it).
    pub fn files_changed(&self) {
        let mut s = self.lock();
        // A late event for a save the worker has read already (its stamps are the file's now).
        if !s.inputs.differ_on_disk() {
            return;
        }
        s.reload = true;
        s.last_change = Instant::now();
        self.restart.store(true, Ordering::SeqCst);
        self.wake.notify_all();
    }

    /// Publishes an error (shown over the last good image) and the error phase.
    pub fn publish_error(&self, message: String) {
        let s = self.lock();
        self.publish(s, |s| {
            s.phase = Phase::Error;
            s.error = Some(message);
        });
    }

    /// Asks the worker to stop.
    pub fn quit(&self) {
        self.lock().quit = true;
        self.restart.store(true, Ordering::SeqCst);
        self.wake.notify_all();
        self.published.notify_all();
    }

    /// Waits up to `timeout` for a frame newer than `since` (or any state change) and returns
    /// the guard.
    pub fn wait_newer(&self, since: u64, timeout: Duration) -> MutexGuard<'_, State> {
        let deadline = Instant::now() + timeout;
        let mut s = self.lock();
        while s.frame <= since && !s.quit {
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                break;
            }
            s = match self.published.wait_timeout(s, left) {
                Ok((g, _)) => g,
                Err(p) => p.into_inner().0,
            };
        }
        s
    }

    /// Publishes a state change to the long polls (the frame counter moves so they answer).
    pub(super) fn publish(&self, mut s: MutexGuard<'_, State>, f: impl FnOnce(&mut State)) {
        f(&mut s);
        s.frame += 1;
        drop(s);
        self.published.notify_all();
    }
}

impl State {
    /// Whether the worker has unfinished work for the current generation.
    pub(super) fn phase_needs_work(&self) -> bool {
        matches!(
            self.phase,
            Phase::Loading | Phase::Building | Phase::Rendering
        )
    }
}
