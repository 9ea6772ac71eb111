//! Atomic file replacement: write a temporary file beside the target, flush it to disk, then
//! rename it over the target. Readers see either the old file or the complete new one, and a
//! failed (or panicking) write leaves the old file untouched and no temporary file behind.

use std::fs::OpenOptions;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Writes a file atomically: `write` fills a temporary file beside `path` (same extension, so
/// encoders that look at it still work), which then replaces `path` by a rename. A failure leaves
/// an existing `path` untouched.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&Path) -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    replace_with(path, write, |p, e| {
        anyhow::anyhow!("{}: cannot replace: {e}", p.display())
    })
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
    let guard = RemoveOnDrop(&tmp);
    write(&tmp)?;
    // Flush the data before the rename so a crash cannot leave a renamed but empty file.
    let committed = OpenOptions::new()
        .write(true)
        .open(&tmp)
        .and_then(|f| f.sync_all())
        .and_then(|()| std::fs::rename(&tmp, path));
    match committed {
        Ok(()) => {
            std::mem::forget(guard);
            Ok(())
        }
        Err(e) => Err(io_error(path, e)),
    }
}

/// `dir/.name.<pid>.<n>.tmp.ext`: hidden, unique per process and call, same directory (so the
/// rename stays on one file system) and same extension as `path`.
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
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    Ok(dir.join(format!(
        ".{}.{}.{n}.tmp{ext}",
        name.to_string_lossy(),
        std::process::id()
    )))
}

/// Deletes the temporary file unless forgotten after a successful rename.
struct RemoveOnDrop<'a>(&'a Path);

impl Drop for RemoveOnDrop<'_> {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(self.0);
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
            Ok(std::fs::write(tmp, "new")?)
        })
        .unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new");
        assert!(leftovers(&path).is_empty());
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
}
