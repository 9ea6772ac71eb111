//! Advisory locks on the directories a set of renames writes into, so that two lapidary
//! processes replacing the same outputs cannot interleave their renames: the pair (EXR, PNG) on
//! disk is always from one run.
//!
//! The lock is `flock(LOCK_EX)` on the directory itself, opened read-only (through
//! [`std::fs::File::lock`]): nothing is created in the user's folder, and the kernel drops the
//! lock when the process exits, however it ends. Directories are locked in the order of their
//! canonical paths, so two processes locking overlapping sets cannot deadlock. A directory that
//! cannot be opened or locked (a file system without `flock`) is renamed into unlocked: the
//! renames themselves still replace each file atomically.

use std::fs::File;
use std::path::{Path, PathBuf};

/// Holds exclusive locks on some directories until dropped.
pub(crate) struct DirLocks {
    _held: Vec<File>,
}

impl DirLocks {
    /// Locks the directories of `targets` (each target's parent; `.` for a bare name), waiting
    /// for other lapidary processes that hold any of them.
    pub(crate) fn of<'a>(targets: impl IntoIterator<Item = &'a Path>) -> DirLocks {
        let mut dirs: Vec<PathBuf> = targets
            .into_iter()
            .map(|t| {
                let dir = t
                    .parent()
                    .filter(|p| !p.as_os_str().is_empty())
                    .unwrap_or(Path::new("."));
                std::fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf())
            })
            .collect();
        dirs.sort();
        dirs.dedup();
        let held = dirs
            .iter()
            .filter_map(|d| {
                let f = File::open(d).ok()?;
                f.lock().ok()?;
                Some(f)
            })
            .collect();
        DirLocks { _held: held }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;
    use std::sync::atomic::{AtomicBool, Ordering};

    #[test]
    fn a_second_holder_waits_for_the_first() {
        let dir = std::env::temp_dir().join(format!("lapidary-lock-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        let a = dir.join("a.exr");
        let b = dir.join("sub/../b.png");
        let first = DirLocks::of([a.as_path(), b.as_path()]);
        assert_eq!(first._held.len(), 1, "one directory, locked once");
        let released = Arc::new(AtomicBool::new(false));
        let seen = released.clone();
        let target = dir.join("c.exr");
        let waiter = std::thread::spawn(move || {
            // A lock taken through another open file description conflicts like another
            // process's would.
            let _second = DirLocks::of([target.as_path()]);
            seen.load(Ordering::SeqCst)
        });
        std::thread::sleep(std::time::Duration::from_millis(200));
        released.store(true, Ordering::SeqCst);
        drop(first);
        assert!(
            waiter.join().unwrap(),
            "the second lock was taken before the first was released"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
