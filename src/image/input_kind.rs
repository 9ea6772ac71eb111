//! What an input path names, checked before it is opened: meshes and environment maps must be
//! regular files. Opening a FIFO blocks until a writer appears and reading a device can run
//! forever, so the file type is taken from the metadata (following symbolic links) before any
//! `open`, and anything but a regular file is refused with a message that says what it is.

use std::fmt;
use std::path::Path;

/// Why an input path cannot be read as a file.
#[derive(Debug)]
pub enum NotAFile {
    /// Nothing exists at the path (or a symbolic link points nowhere).
    Missing,
    /// A directory.
    Directory,
    /// A named pipe: opening it would wait for a writer.
    Fifo,
    /// A character or block device (`/dev/null`, `/dev/zero`, a disk).
    Device,
    /// A Unix domain socket.
    Socket,
    /// The metadata could not be read (permission denied, a name too long, …).
    Io(std::io::Error),
}

impl fmt::Display for NotAFile {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            NotAFile::Missing => f.write_str("no such file"),
            NotAFile::Directory => f.write_str("is a directory, not a file"),
            NotAFile::Fifo => f.write_str("is a FIFO (named pipe), not a file"),
            NotAFile::Device => f.write_str("is a device, not a file"),
            NotAFile::Socket => f.write_str("is a socket, not a file"),
            NotAFile::Io(e) => write!(f, "cannot read: {e}"),
        }
    }
}

impl std::error::Error for NotAFile {}

impl From<NotAFile> for std::io::Error {
    fn from(e: NotAFile) -> Self {
        let kind = match &e {
            NotAFile::Missing => std::io::ErrorKind::NotFound,
            NotAFile::Directory => std::io::ErrorKind::IsADirectory,
            NotAFile::Io(io) => io.kind(),
            _ => std::io::ErrorKind::InvalidInput,
        };
        std::io::Error::new(kind, e.to_string())
    }
}

/// Checks, without opening it, that `path` names a regular file (after following symbolic
/// links); returns its metadata.
pub fn regular_file(path: &Path) -> Result<std::fs::Metadata, NotAFile> {
    let meta = match std::fs::metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Err(NotAFile::Missing),
        Err(e) => return Err(NotAFile::Io(e)),
    };
    let t = meta.file_type();
    if t.is_file() {
        return Ok(meta);
    }
    if t.is_dir() {
        return Err(NotAFile::Directory);
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return Err(NotAFile::Fifo);
        }
        if t.is_socket() {
            return Err(NotAFile::Socket);
        }
    }
    Err(NotAFile::Device)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_what_is_not_a_file() {
        let here = Path::new(env!("CARGO_MANIFEST_DIR"));
        assert!(regular_file(&here.join("Cargo.toml")).is_ok());
        assert!(matches!(
            regular_file(&here.join("src")),
            Err(NotAFile::Directory)
        ));
        assert!(matches!(
            regular_file(&here.join("no-such-file")),
            Err(NotAFile::Missing)
        ));
        #[cfg(unix)]
        assert!(matches!(
            regular_file(Path::new("/dev/null")),
            Err(NotAFile::Device)
        ));
    }
}
