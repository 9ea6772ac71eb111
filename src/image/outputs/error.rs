//! The vocabulary of output checks: the formats, the kinds of non-regular file, and the errors
//! (each naming the path).

use std::fmt;
use std::fs::Metadata;
use std::path::PathBuf;

/// The format an output is written in; its name must end in [`Format::extension`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// OpenEXR (`.exr`).
    Exr,
    /// PNG (`.png`).
    Png,
    /// Comma-separated values (`.csv`).
    Csv,
}

impl Format {
    /// The extension a file of this format must have, lower case, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            Format::Exr => "exr",
            Format::Png => "png",
            Format::Csv => "csv",
        }
    }
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Format::Exr => "EXR",
            Format::Png => "PNG",
            Format::Csv => "CSV",
        })
    }
}

/// What a path names when it is not a regular file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A directory.
    Directory,
    /// A character device (`/dev/null`, a terminal).
    CharDevice,
    /// A block device (a disk).
    BlockDevice,
    /// A named pipe.
    Fifo,
    /// A Unix socket.
    Socket,
    /// Anything else the platform has.
    Other,
}

impl Kind {
    /// The kind of a non-regular file's metadata.
    pub(crate) fn of(meta: &Metadata) -> Kind {
        let t = meta.file_type();
        if t.is_dir() {
            return Kind::Directory;
        }
        #[cfg(unix)]
        {
            use std::os::unix::fs::FileTypeExt;
            if t.is_char_device() {
                return Kind::CharDevice;
            }
            if t.is_block_device() {
                return Kind::BlockDevice;
            }
            if t.is_fifo() {
                return Kind::Fifo;
            }
            if t.is_socket() {
                return Kind::Socket;
            }
        }
        Kind::Other
    }
}

impl fmt::Display for Kind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Kind::Directory => "a directory",
            Kind::CharDevice => "a character device",
            Kind::BlockDevice => "a block device",
            Kind::Fifo => "a FIFO (named pipe)",
            Kind::Socket => "a socket",
            Kind::Other => "not a regular file",
        })
    }
}

/// Why an output path is refused; every message names the path.
#[derive(thiserror::Error, Debug)]
pub enum OutputError {
    /// The path exists and is not a regular file (or is a symlink to one that is not).
    #[error("{}: is {what}; an output must be a regular file or a new name", .path.display())]
    NotAFile {
        /// The output as given.
        path: PathBuf,
        /// What it is, e.g. "a character device" or "a symlink to a directory (/tmp)".
        what: String,
    },
    /// An output folder that exists and is not a directory.
    #[error("{}: is {what}; an output folder must be a directory or a new name", .path.display())]
    NotAFolder {
        /// The folder as given.
        path: PathBuf,
        /// What it is, e.g. "a regular file".
        what: String,
    },
    /// A symlink whose target does not exist, or a loop of links.
    #[error("{}: is a symlink that leads to no file ({reason}); outputs are written through links to existing files only", .path.display())]
    BrokenLink {
        /// The output as given.
        path: PathBuf,
        /// What resolving it reported.
        reason: String,
    },
    /// An existing output that may not be written.
    #[error("{}: is read-only; refusing to replace it (make it writable or choose another name)", .path.display())]
    ReadOnly {
        /// The output as given.
        path: PathBuf,
    },
    /// The output's directory is missing or not a directory.
    #[error("{}: directory {} {why}", .path.display(), .dir.display())]
    NoDirectory {
        /// The output as given.
        path: PathBuf,
        /// Its directory.
        dir: PathBuf,
        /// "does not exist" or "is not a directory".
        why: &'static str,
    },
    /// The output's directory (or an output folder) may not be written in.
    #[error("{}: directory {} is not writable ({reason})", .path.display(), .dir.display())]
    DirectoryReadOnly {
        /// The output as given.
        path: PathBuf,
        /// The directory.
        dir: PathBuf,
        /// Why, e.g. "no write permission".
        reason: String,
    },
    /// The name's extension is not its format's.
    #[error("{}: {format} output, but the name {found}; it must end in .{}", .path.display(), .format.extension())]
    WrongExtension {
        /// The output as given.
        path: PathBuf,
        /// The format that would be written.
        format: Format,
        /// "ends in .png" or "has no extension".
        found: String,
    },
    /// The output is one of the inputs.
    #[error("{}: is also an input ({role}); refusing to overwrite it", .path.display())]
    IsInput {
        /// The output as given.
        path: PathBuf,
        /// Which input, e.g. "the recipe x.ron".
        role: String,
    },
    /// Two outputs are the same file.
    #[error("{}: is given for two outputs (also as {}); each output needs its own file", .path.display(), .other.display())]
    Duplicate {
        /// The second output as given.
        path: PathBuf,
        /// The first.
        other: PathBuf,
    },
    /// The path could not be examined.
    #[error("{}: cannot examine: {reason}", .path.display())]
    Inaccessible {
        /// The output as given.
        path: PathBuf,
        /// The system's message.
        reason: String,
    },
}
