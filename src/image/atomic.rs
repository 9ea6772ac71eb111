//! Atomic file replacement: write a temporary file beside the target, flush it to disk, then
//! rename it over the target. Readers see either the old file or the complete new one, and a
//! failed (or panicking) write leaves the old file untouched and no temporary file behind.
//!
//! Several files can be replaced all or nothing ([`all_or_nothing`]): every temporary file is
//! written first, and only when all of them are complete are they renamed, one after the other,
//! under a lock that [`abort_process`] (the second Ctrl-C) also takes — so an abort sees either no
//! rename or all of them.
//!
//! Temporary files are named `.NAME.lapidary-PID-N.tmp.EXT`. One left behind by a process that
//! was killed outright (SIGKILL, power loss) is recognised by that name: the first write of a
//! later run into the same directory removes every such file whose process no longer exists
//! (checked as `/proc/PID`; where there is no `/proc`, leftovers are kept).

use std::cell::RefCell;
use std::collections::HashSet;
use std::fs::OpenOptions;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard};

/// The marker between a target's name and the process id in a temporary file's name.
const MARKER: &str = ".lapidary-";

/// Writes a file atomically: `write` fills a temporary file beside `path` (same extension, so
/// encoders that look at it still work), which then replaces `path` by a rename. A failure leaves
/// an existing `path` untouched. Inside [`all_or_nothing`] the rename waits for the others.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&Path) -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    replace_with(path, write, |p, e| {
        anyhow::anyhow!("{}: cannot replace: {e}", p.display())
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

/// The generic form of [`write_atomically`]: `io_error` turns a file-system failure of the
/// replacement itself (not of `write`) into the caller's error type.
pub(crate) fn replace_with<E>(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), E>,
    io_error: impl FnOnce(&Path, io::Error) -> E,
) -> Result<(), E> {
    let tmp = match temp_path(path) {
        Ok(t) => t,
        Err(e) => return Err(io_error(path, e)),
    };
    live().push(tmp.clone());
    let guard = RemoveOnDrop(&tmp);
    write(&tmp)?;
    // Flush the data before the rename so a crash cannot leave a renamed but empty file.
    let synced = OpenOptions::new()
        .write(true)
        .open(&tmp)
        .and_then(|f| f.sync_all());
    if let Err(e) = synced {
        return Err(io_error(path, e));
    }
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
    let mut live = live();
    let renamed = std::fs::rename(&tmp, path);
    if renamed.is_ok() {
        live.retain(|p| p != &tmp);
    }
    drop(live);
    match renamed {
        Ok(()) => {
            std::mem::forget(guard);
            Ok(())
        }
        Err(e) => Err(io_error(path, e)),
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
        let err = write_atomically(&path, |tmp| {
            std::fs::write(tmp, "partial")?;
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
            write_atomically(&path, |tmp| {
                std::fs::write(tmp, "partial").unwrap();
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
        write_atomically(&path, |tmp| {
            assert_eq!(tmp.extension().unwrap(), "png");
            assert_eq!(tmp.parent(), path.parent());
            assert_eq!(
                temp_owner(&tmp.file_name().unwrap().to_string_lossy()),
                Some(std::process::id())
            );
            Ok(std::fs::write(tmp, "new")?)
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
    fn nothing_written_is_an_error() {
        let path = scratch("never.txt");
        let _ = std::fs::remove_file(&path);
        let err = write_atomically(&path, |_| Ok(())).unwrap_err();
        assert!(err.to_string().contains("never.txt"), "{err}");
        assert!(!path.exists());
        assert!(write_atomically(Path::new("/"), |_| Ok(())).is_err());
    }

    #[test]
    fn a_batch_renames_all_or_none() {
        let (a, b) = (scratch("batch-a.txt"), scratch("batch-b.txt"));
        std::fs::write(&a, "old a").unwrap();
        std::fs::write(&b, "old b").unwrap();
        // The second write fails: the first, already complete, must not be renamed.
        let err = all_or_nothing(|| {
            write_atomically(&a, |t| Ok(std::fs::write(t, "new a")?))?;
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
                write_atomically(&a, |t| Ok(std::fs::write(t, "new a")?))?;
                panic!("boom")
            })
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old a");
        assert!(leftovers(&a).is_empty());
        // Both succeed: both replaced.
        all_or_nothing(|| {
            write_atomically(&a, |t| Ok(std::fs::write(t, "new a")?))?;
            write_atomically(&b, |t| Ok(std::fs::write(t, "new b")?))
        })
        .unwrap();
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "new a");
        assert_eq!(std::fs::read_to_string(&b).unwrap(), "new b");
        assert!(leftovers(&a).is_empty() && leftovers(&b).is_empty());
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
