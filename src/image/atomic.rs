//! Atomic file replacement: write a temporary file beside the target, flush it to disk, then
//! rename it over the target. Readers see either the old file or the complete new one, and a
//! failed (or panicking) write leaves the old file untouched and no temporary file behind.
//!
//! Every byte goes through a [`Sink`], which keeps the first I/O error of any write, flush or
//! seek — even one an encoder ignored — and `fsync`s the file before it may be renamed: on a full
//! disk, a quota or an I/O error (`ENOSPC`, `EDQUOT`, `EIO`) nothing is renamed, and the command
//! fails naming the file and the error.
//!
//! Several files can be replaced all or nothing ([`all_or_nothing`]): every temporary file is
//! written first, and only when all of them are complete are they renamed, one after the other,
//! under a lock that [`abort_process`] (the second Ctrl-C) also takes — so an abort sees either no
//! rename or all of them. The renames also hold an advisory lock on each target directory
//! ([`lock`]), so two lapidary processes replacing the same files never interleave: the set on
//! disk is always one run's.
//!
//! Temporary files are named `.NAME.lapidary-PID-N.tmp.EXT`. One left behind by a process that
//! was killed outright (SIGKILL, power loss) is recognised by that name: the first write of a
//! later run into the same directory removes every such file whose process no longer exists
//! (checked as `/proc/PID`; where there is no `/proc`, leftovers are kept).

mod lock;
mod sink;

use self::lock::DirLocks;
pub use self::sink::Sink;
use std::cell::RefCell;
use std::collections::HashSet;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard};

/// The marker between a target's name and the process id in a temporary file's name.
const MARKER: &str = ".lapidary-";

/// Writes a file atomically: `write` fills a [`Sink`] on a temporary file beside `path` (same
/// extension), which then replaces `path` by a rename. A failure — of `write`, of any I/O call
/// it made, of the final flush and `fsync` — leaves an existing `path` untouched. Inside
/// [`all_or_nothing`] the rename waits for the others.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut Sink) -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    replace_with(path, write, |p, what, e| {
        anyhow::Error::new(crate::image::ImageError::io(p, what, e))
    })
}

/// Runs `write`, in which every atomic write of this thread ([`write_atomically`], the image
/// writers) only writes and flushes its temporary file; when `write` succeeds, all of them are
/// renamed over their targets. When `write` fails (or panics), none is: the temporary files are
/// removed and every target keeps its old content. A rename that fails after others succeeded
/// (a file system that changed during the run) is reported with the files already replaced.
/// Nested calls join the outer one.
pub fn all_or_nothing<T>(write: impl FnOnce() -> anyhow::Result<T>) -> anyhow::Result<T> {
    if BATCH.with(|b| b.borrow().is_some()) {
        return write();
    }
    BATCH.with(|b| *b.borrow_mut() = Some(vec![]));
    // Removes the temporary files if `write` fails or panics.
    let guard = BatchGuard;
    let value = write()?;
    let pending = BATCH.with(|b| b.borrow_mut().take()).unwrap_or_default();
    std::mem::forget(guard);
    let dirs = DirLocks::of(pending.iter().map(|(_, t)| t.as_path()));
    let live = live();
    let mut done: Vec<&Path> = vec![];
    let mut failure = None;
    for (tmp, target) in &pending {
        if failure.is_none() {
            match std::fs::rename(tmp, target) {
                Ok(()) => done.push(target),
                Err(e) => failure = Some((target, e)),
            }
        }
        if failure.is_some() {
            let _ = std::fs::remove_file(tmp);
        }
    }
    forget_live(live, pending.iter().map(|(t, _)| t.as_path()));
    drop(dirs);
    match failure {
        None => Ok(value),
        Some((target, e)) => {
            let replaced: Vec<String> = done.iter().map(|p| p.display().to_string()).collect();
            anyhow::bail!(
                "{}: cannot replace: {e} (already replaced: {})",
                target.display(),
                if replaced.is_empty() {
                    "none".into()
                } else {
                    replaced.join(", ")
                }
            )
        }
    }
}

/// Removes every temporary file this process is writing or holds for an [`all_or_nothing`]
/// commit, then exits with `code`. Renames in progress finish first; none starts afterwards.
pub fn abort_process(code: i32) -> ! {
    let live = live();
    for tmp in live.iter() {
        let _ = std::fs::remove_file(tmp);
    }
    // Keep the lock: no rename may start while the process exits.
    std::mem::forget(live);
    std::process::exit(code)
}

/// The generic form of [`write_atomically`]: `io_error(path, what, e)` turns a file-system
/// failure (of the temporary file's creation or writing, `what` = "write", or of the rename,
/// `what` = "replace") into the caller's error type.
pub(crate) fn replace_with<E>(
    path: &Path,
    write: impl FnOnce(&mut Sink) -> Result<(), E>,
    io_error: impl Fn(&Path, &str, io::Error) -> E,
) -> Result<(), E> {
    let tmp = match temp_path(path) {
        Ok(t) => t,
        Err(e) => return Err(io_error(path, "write", e)),
    };
    live().push(tmp.clone());
    let guard = RemoveOnDrop(&tmp);
    let mut sink = match Sink::create(&tmp) {
        Ok(s) => s,
        Err(e) => return Err(io_error(path, "write", e)),
    };
    let written = write(&mut sink);
    // An I/O error the encoder saw is the cause even when it reported something vaguer.
    let finished = sink.finish();
    if let Err(e) = finished {
        return Err(io_error(path, "write", e));
    }
    written?;
    let deferred = BATCH.with(|b| match b.borrow_mut().as_mut() {
        Some(pending) => {
            pending.push((tmp.clone(), path.to_path_buf()));
            true
        }
        None => false,
    });
    if deferred {
        std::mem::forget(guard);
        return Ok(());
    }
    let dirs = DirLocks::of([path]);
    let mut live = live();
    let renamed = std::fs::rename(&tmp, path);
    if renamed.is_ok() {
        live.retain(|p| p != &tmp);
    }
    drop(live);
    drop(dirs);
    match renamed {
        Ok(()) => {
            std::mem::forget(guard);
            Ok(())
        }
        Err(e) => Err(io_error(path, "replace", e)),
    }
}

thread_local! {
    /// The (temporary, target) pairs of this thread's open [`all_or_nothing`], if any.
    static BATCH: RefCell<Option<Vec<(PathBuf, PathBuf)>>> = const { RefCell::new(None) };
}

/// Temporary files of this process that exist (or are about to): removed by [`abort_process`].
fn live() -> MutexGuard<'static, Vec<PathBuf>> {
    static LIVE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
    LIVE.lock().unwrap_or_else(|p| p.into_inner())
}

/// Drops `done` from the live list.
fn forget_live<'a>(
    mut live: MutexGuard<'static, Vec<PathBuf>>,
    done: impl IntoIterator<Item = &'a Path>,
) {
    for d in done {
        live.retain(|p| p != d);
    }
}

/// `dir/.name.lapidary-<pid>-<n>.tmp.ext`: hidden, unique per process and call, same directory
/// (so the rename stays on one file system) and same extension as `path`. The first call for a
/// directory removes the leftovers of dead processes there.
fn temp_path(path: &Path) -> io::Result<PathBuf> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path
        .file_name()
        .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "not a file path"))?;
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let ext = path
        .extension()
        .map(|e| format!(".{}", e.to_string_lossy()))
        .unwrap_or_default();
    clean_once(dir);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    Ok(dir.join(format!(
        ".{}{MARKER}{}-{n}.tmp{ext}",
        name.to_string_lossy(),
        std::process::id()
    )))
}

/// Runs [`remove_stale_temps`] on `dir` the first time this process writes there.
fn clean_once(dir: &Path) {
    static CLEANED: Mutex<Option<HashSet<PathBuf>>> = Mutex::new(None);
    let key = std::fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf());
    let mut cleaned = CLEANED.lock().unwrap_or_else(|p| p.into_inner());
    if cleaned.get_or_insert_with(HashSet::new).insert(key) {
        drop(cleaned);
        remove_stale_temps(dir);
    }
}

/// Removes the temporary files in `dir` left by processes that no longer exist (see the module
/// documentation); returns how many were removed. Without `/proc` nothing is removed.
pub fn remove_stale_temps(dir: &Path) -> usize {
    if !Path::new("/proc/self").exists() {
        return 0;
    }
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    let mut removed = 0;
    for entry in entries.filter_map(Result::ok) {
        let name = entry.file_name();
        let Some(pid) = name.to_str().and_then(temp_owner) else {
            continue;
        };
        let dead = pid != std::process::id() && !Path::new(&format!("/proc/{pid}")).exists();
        let regular = entry.file_type().is_ok_and(|t| t.is_file());
        if dead && regular && std::fs::remove_file(entry.path()).is_ok() {
            removed += 1;
        }
    }
    removed
}

/// The process id in a temporary file name `.NAME.lapidary-PID-N.tmp[.EXT]`, if it is one.
fn temp_owner(name: &str) -> Option<u32> {
    if !name.starts_with('.') {
        return None;
    }
    let at = name.rfind(MARKER)?;
    let rest = &name[at + MARKER.len()..];
    let (pid, rest) = rest.split_once('-')?;
    let (n, rest) = rest.split_once(".tmp")?;
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    if !digits(pid) || !digits(n) || !(rest.is_empty() || rest.starts_with('.')) {
        return None;
    }
    pid.parse().ok()
}

/// Deletes the temporary file unless forgotten after a successful rename.
struct RemoveOnDrop<'a>(&'a Path);

impl Drop for RemoveOnDrop<'_> {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(self.0);
        forget_live(live(), [self.0]);
    }
}

/// Ends a failed [`all_or_nothing`]: removes its temporary files.
struct BatchGuard;

impl Drop for BatchGuard {
    fn drop(&mut self) {
        let pending = BATCH.with(|b| b.borrow_mut().take()).unwrap_or_default();
        for (tmp, _) in &pending {
            let _ = std::fs::remove_file(tmp);
        }
        forget_live(live(), pending.iter().map(|(t, _)| t.as_path()));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("lapidary-atomic-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join(name)
    }

    fn leftovers(path: &Path) -> Vec<String> {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        std::fs::read_dir(path.parent().unwrap())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.starts_with(&format!(".{name}.")))
            .collect()
    }

    #[test]
    fn failed_write_keeps_old_file() {
        let path = scratch("keep.txt");
        std::fs::write(&path, "old").unwrap();
        let err = write_atomically(&path, |sink| {
            sink.write_all(b"partial")?;
            anyhow::bail!("encoder failed")
        })
        .unwrap_err();
        assert!(err.to_string().contains("encoder failed"));
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "old");
        assert!(leftovers(&path).is_empty(), "{:?}", leftovers(&path));
    }

    #[test]
    fn panicking_write_keeps_old_file() {
        let path = scratch("panic.txt");
        std::fs::write(&path, "old").unwrap();
        let r = std::panic::catch_unwind(|| {
            write_atomically(&path, |sink| {
                sink.write_all(b"partial").unwrap();
                panic!("boom")
            })
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "old");
        assert!(leftovers(&path).is_empty());
    }

    #[test]
    fn success_replaces_and_keeps_extension() {
        let path = scratch("new.png");
        std::fs::write(&path, "old").unwrap();
        write_atomically(&path, |sink| {
            let tmp = sink.path().to_path_buf();
            assert_eq!(tmp.extension().unwrap(), "png");
            assert_eq!(tmp.parent(), path.parent());
            assert_eq!(
                temp_owner(&tmp.file_name().unwrap().to_string_lossy()),
                Some(std::process::id())
            );
            Ok(sink.write_all(b"new")?)
        })
        .unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new");
        assert!(leftovers(&path).is_empty());
        assert!(
            !live()
                .iter()
                .any(|p| p.to_string_lossy().contains("new.png"))
        );
    }

    #[test]
    fn a_path_that_is_no_file_is_an_error() {
        let err = write_atomically(Path::new("/"), |_| Ok(())).unwrap_err();
        assert!(err.to_string().starts_with("/: cannot write"), "{err}");
        let missing = scratch("no/such/dir/x.txt");
        let err = write_atomically(&missing, |_| Ok(())).unwrap_err();
        assert!(err.to_string().contains("x.txt: cannot write"), "{err}");
    }

    #[test]
    fn a_batch_renames_all_or_none() {
        let (a, b) = (scratch("batch-a.txt"), scratch("batch-b.txt"));
        std::fs::write(&a, "old a").unwrap();
        std::fs::write(&b, "old b").unwrap();
        // The second write fails: the first, already complete, must not be renamed.
        let err = all_or_nothing(|| {
            write_atomically(&a, |s| Ok(s.write_all(b"new a")?))?;
            assert_eq!(
                std::fs::read_to_string(&a).unwrap(),
                "old a",
                "renamed early"
            );
            write_atomically(&b, |_| anyhow::bail!("disk full"))
        })
        .unwrap_err();
        assert!(err.to_string().contains("disk full"), "{err}");
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old a");
        assert_eq!(std::fs::read_to_string(&b).unwrap(), "old b");
        assert!(leftovers(&a).is_empty() && leftovers(&b).is_empty());
        // A panic inside the batch: the same.
        let r = std::panic::catch_unwind(|| {
            all_or_nothing::<()>(|| {
                write_atomically(&a, |s| Ok(s.write_all(b"new a")?))?;
                panic!("boom")
            })
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old a");
        assert!(leftovers(&a).is_empty());
        // Both succeed: both replaced.
        all_or_nothing(|| {
            write_atomically(&a, |s| Ok(s.write_all(b"new a")?))?;
            write_atomically(&b, |s| Ok(s.write_all(b"new b")?))
        })
        .unwrap();
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "new a");
        assert_eq!(std::fs::read_to_string(&b).unwrap(), "new b");
        assert!(leftovers(&a).is_empty() && leftovers(&b).is_empty());
    }

    #[test]
    fn an_io_error_an_encoder_ignores_still_keeps_every_old_file() {
        // Faults are injected only with debug assertions (the test profile has them; a
        // `--release` test run has nothing to inject, and the write simply succeeds).
        if !cfg!(debug_assertions) {
            eprintln!("skipped: fault injection needs debug assertions");
            return;
        }
        let (exr, png) = (scratch("io-a.exr"), scratch("io-b.png"));
        std::fs::write(&exr, "old exr").unwrap();
        std::fs::write(&png, "old png").unwrap();
        let pixels = vec![0x5au8; 3 * 64 * 64];
        for (errno, code) in [("ENOSPC", 28), ("EIO", 5), ("EDQUOT", 122)] {
            for at in ["0", "100", "sync"] {
                sink::TEST_FAULT.with(|f| *f.borrow_mut() = Some(format!("{errno}@{at}:png")));
                let err = all_or_nothing(|| {
                    write_atomically(&exr, |s| Ok(s.write_all(b"new exr")?))?;
                    // The PNG encoder's own errors are dropped here on purpose.
                    Ok(crate::image::png::write_rgb8(&png, 64, 64, pixels.clone())?)
                })
                .unwrap_err();
                sink::TEST_FAULT.with(|f| *f.borrow_mut() = None);
                let io = err
                    .chain()
                    .find_map(|c| c.downcast_ref::<crate::image::ImageError>())
                    .map(|e| e.to_string())
                    .unwrap_or_default();
                assert!(
                    io.contains("io-b.png") && io.contains(&format!("os error {code}")),
                    "{errno}@{at}: {err:#}"
                );
                assert_eq!(std::fs::read_to_string(&exr).unwrap(), "old exr");
                assert_eq!(std::fs::read_to_string(&png).unwrap(), "old png");
                assert!(leftovers(&exr).is_empty() && leftovers(&png).is_empty());
            }
        }
    }

    #[test]
    fn temp_names_are_recognised() {
        assert_eq!(temp_owner(".x.exr.lapidary-123-4.tmp.exr"), Some(123));
        assert_eq!(temp_owner(".x.lapidary-7-0.tmp"), Some(7));
        assert_eq!(temp_owner(".a.lapidary-b.lapidary-9-1.tmp.png"), Some(9));
        for not in [
            "x.exr.lapidary-1-2.tmp.exr",
            ".x.lapidary--2.tmp",
            ".x.lapidary-1-2.tmpfoo",
            ".x.lapidary-1x-2.tmp",
            ".x.exr",
        ] {
            assert_eq!(temp_owner(not), None, "{not}");
        }
    }

    #[test]
    fn stale_temps_of_dead_processes_are_removed() {
        if !Path::new("/proc/self").exists() {
            return;
        }
        let dir = scratch("stale").with_extension("d");
        std::fs::create_dir_all(&dir).unwrap();
        // Process ids above the kernel's maximum (4194304) never exist.
        let dead = dir.join(".out.exr.lapidary-4999999-0.tmp.exr");
        let mine = dir.join(format!(
            ".out.exr.lapidary-{}-99.tmp.exr",
            std::process::id()
        ));
        let other = dir.join(".out.exr.tmp.exr");
        for f in [&dead, &mine, &other] {
            std::fs::write(f, "x").unwrap();
        }
        assert_eq!(remove_stale_temps(&dir), 1);
        assert!(!dead.exists() && mine.exists() && other.exists());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
