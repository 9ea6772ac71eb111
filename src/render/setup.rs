//! What building a [`super::World`] can fail with, and how it is built: when to give up, and
//! whether to show progress.

use crate::bsdf::StackError;
use crate::geometry::GeometryError;
use crate::image::ImageError;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};
use thiserror::Error;

/// Why a scene cannot be turned into a world.
#[derive(Debug, Error)]
pub enum WorldError {
    /// The stone's shape could not be built (a mesh that does not load, …).
    #[error("stone shape: {0}")]
    Shape(#[from] GeometryError),
    /// A material's stack is invalid.
    #[error("material `{name}`: {source}")]
    Material {
        /// Its name.
        name: String,
        /// What is wrong.
        source: StackError,
    },
    /// The environment map could not be read.
    #[error("environment map: {0}")]
    Environment(#[from] ImageError),
    /// A translucent body on a mesh that is not closed and consistently wound: its inside is
    /// undefined.
    #[error(
        "the stone's mesh has {0} open or inconsistently wound edges: a translucent body needs a \
         closed mesh whose triangles are all wound counter-clockwise seen from outside"
    )]
    OpenBody(usize),
    /// A translucent body on a closed mesh wound inside-out (or enclosing no volume): its normals
    /// would point into the stone.
    #[error(
        "the stone's mesh is closed but wound inside-out (signed volume {0:.4e} object units³): a          translucent body needs its triangles wound counter-clockwise seen from outside (flip          every face, e.g. reverse each `f` line's vertex order in the OBJ)"
    )]
    InsideOutBody(f64),
    /// A walk of the body's explicit platelets could not cover the stone (its diagonal spans more
    /// cells of a population than a walk visits).
    #[error(transparent)]
    PlateletSpan(#[from] crate::platelet::grid::SpanError),
    /// The deadline passed or the cancel flag was set before the world was built.
    #[error("stopped during setup: nothing rendered, nothing written")]
    Stopped,
}

/// How a world is built: when to give up, and whether to show its progress.
#[derive(Clone, Copy, Debug, Default)]
pub struct Setup<'a> {
    /// Give up (with [`WorldError::Stopped`]) once this instant has passed.
    pub deadline: Option<Instant>,
    /// Give up once this is set (Ctrl-C).
    pub cancel: Option<&'a AtomicBool>,
    /// Show a progress bar on standard error (only on a terminal) once building the material
    /// tables has taken more than [`PROGRESS_AFTER`].
    pub progress: bool,
    /// Materials built by earlier worlds, reused when a stack is the same (`lapidary preview`
    /// rebuilds the world on every save and keeps this cache: an edit rebuilds only the materials
    /// it changed). `None`: every material is built.
    pub cache: Option<&'a MaterialCache>,
}

/// Built materials by their description (a [`crate::bsdf::StackDesc`] with the effects that
/// shape its build): a material's tables are a deterministic function of that key, so reusing
/// one changes no result. Bounded: past [`MaterialCache::CAPACITY`] entries it starts afresh.
#[derive(Debug, Default)]
pub struct MaterialCache {
    built:
        std::sync::Mutex<std::collections::HashMap<String, (crate::bsdf::Bsdf, crate::color::Rgb)>>,
    hits: std::sync::atomic::AtomicU64,
    misses: std::sync::atomic::AtomicU64,
}

impl MaterialCache {
    /// Most materials kept.
    pub const CAPACITY: usize = 256;

    /// The material stored under `key`, or `build`'s (stored unless it failed).
    pub(crate) fn get_or_build<E>(
        &self,
        key: String,
        build: impl FnOnce() -> Result<(crate::bsdf::Bsdf, crate::color::Rgb), E>,
    ) -> Result<(crate::bsdf::Bsdf, crate::color::Rgb), E> {
        if let Some(v) = self.built.lock().ok().and_then(|m| m.get(&key).cloned()) {
            self.hits.fetch_add(1, Ordering::Relaxed);
            return Ok(v);
        }
        self.misses.fetch_add(1, Ordering::Relaxed);
        let v = build()?;
        if let Ok(mut m) = self.built.lock() {
            if m.len() >= Self::CAPACITY {
                m.clear();
            }
            m.insert(key, v.clone());
        }
        Ok(v)
    }

    /// Materials taken from the cache and materials built through it, so far.
    pub fn counts(&self) -> (u64, u64) {
        (
            self.hits.load(Ordering::Relaxed),
            self.misses.load(Ordering::Relaxed),
        )
    }
}

/// How long table building runs before its progress bar appears.
pub const PROGRESS_AFTER: Duration = Duration::from_secs(1);

impl Setup<'_> {
    /// Whether to give up now.
    pub(crate) fn stopped(&self) -> bool {
        self.cancel.is_some_and(|c| c.load(Ordering::Relaxed))
            || self.deadline.is_some_and(|d| Instant::now() >= d)
    }

    /// `Err(Stopped)` when it is time to give up.
    pub(crate) fn check(&self) -> Result<(), WorldError> {
        if self.stopped() {
            Err(WorldError::Stopped)
        } else {
            Ok(())
        }
    }
}
