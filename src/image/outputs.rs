//! Output paths, checked before any work starts, so that no run destroys a file.
//!
//! Every command collects its inputs and outputs in an [`OutputPlan`] before it renders. An output
//! must be a regular file or not exist yet, with a name ending in its format's extension, in an
//! existing directory it may write in; it may not be one of the inputs, nor another output.
//!
//! - A directory, character or block device (`/dev/null`, `/dev/stdout`), FIFO or socket is
//!   refused, naming what it is. Nothing is ever renamed over such a path, even by root.
//! - A symbolic link is written through: the file written is the link's final target (checked by
//!   the same rules; the temporary file goes beside the target), and the link stays a link. A
//!   link whose target does not exist, or a loop of links, is refused.
//! - An existing output without write permission is refused, not replaced. The mode bits are
//!   checked as well as the right to open it for writing, because root may open anything: a file
//!   with no write bit (`chmod a-w`) is refused for every user. A directory without a write bit is
//!   refused the same way.
//! - Identity is the file itself (device and inode) for files that exist, so a hard link or a
//!   symlink to an input is caught; for a new file, its canonical directory and name.

mod error;

pub use self::error::{Format, Kind, OutputError};
use std::fs::{Metadata, OpenOptions};
use std::io;
use std::path::{Path, PathBuf};

/// Which file a path is: device and inode if it exists, else its canonical directory and name.
#[derive(Clone, Debug, PartialEq, Eq)]
enum Identity {
    File(u64, u64),
    New(PathBuf),
}

fn identity_of(meta: &Metadata, path: &Path) -> Identity {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        let _ = path;
        Identity::File(meta.dev(), meta.ino())
    }
    #[cfg(not(unix))]
    {
        let _ = meta;
        Identity::New(std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf()))
    }
}

/// The inputs and outputs of one run, checked against each other as they are added.
#[derive(Debug, Default)]
pub struct OutputPlan {
    inputs: Vec<(Identity, String)>,
    outputs: Vec<(Identity, PathBuf)>,
}

impl OutputPlan {
    /// An empty plan.
    pub fn new() -> Self {
        OutputPlan::default()
    }

    /// Records an input file described as `role` (e.g. "the recipe"); refused if it is an output
    /// already added. An input that does not exist is ignored (its reader reports it).
    pub fn input(&mut self, path: &Path, role: &str) -> Result<(), OutputError> {
        let Ok(meta) = std::fs::metadata(path) else {
            return Ok(());
        };
        let id = identity_of(&meta, path);
        let role = format!("{role} {}", path.display());
        if let Some((_, out)) = self.outputs.iter().find(|(o, _)| *o == id) {
            return Err(OutputError::IsInput {
                path: out.clone(),
                role,
            });
        }
        self.inputs.push((id, role));
        Ok(())
    }

    /// Checks an output file of `format` (see the module documentation) and returns the path to
    /// write: `path` itself, or the final target when `path` is a symlink.
    pub fn output(&mut self, path: &Path, format: Format) -> Result<PathBuf, OutputError> {
        // What the path is first, then whether it is an input: the most telling message wins.
        let target = resolve(path)?;
        let existing = match std::fs::metadata(&target) {
            Ok(meta) => Some(meta),
            Err(e) if e.kind() == io::ErrorKind::NotFound => None,
            Err(e) => return Err(inaccessible(path, &e)),
        };
        let dir = match target.parent().filter(|d| !d.as_os_str().is_empty()) {
            Some(d) => d.to_path_buf(),
            None => PathBuf::from("."),
        };
        check_directory(path, &dir)?;
        let id = match &existing {
            Some(meta) => identity_of(meta, &target),
            None => {
                let dir = std::fs::canonicalize(&dir).map_err(|e| inaccessible(path, &e))?;
                Identity::New(dir.join(target.file_name().unwrap_or_default()))
            }
        };
        if let Some((_, role)) = self.inputs.iter().find(|(i, _)| *i == id) {
            return Err(OutputError::IsInput {
                path: path.into(),
                role: role.clone(),
            });
        }
        if let Some((_, other)) = self.outputs.iter().find(|(o, _)| *o == id) {
            return Err(OutputError::Duplicate {
                path: path.into(),
                other: other.clone(),
            });
        }
        check_extension(path, format)?;
        if let Some(meta) = &existing
            && (meta.permissions().readonly()
                || OpenOptions::new().write(true).open(&target).is_err())
        {
            return Err(OutputError::ReadOnly { path: path.into() });
        }
        self.outputs.push((id, path.into()));
        Ok(target)
    }

    /// Checks an output folder: a directory this run may write in, or a path that does not exist
    /// yet (the command creates it).
    pub fn folder(&mut self, dir: &Path) -> Result<(), OutputError> {
        match std::fs::metadata(dir) {
            Ok(meta) if meta.is_dir() => check_directory(dir, dir),
            Ok(meta) => Err(OutputError::NotAFolder {
                path: dir.into(),
                what: kind_name(&meta),
            }),
            Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(()),
            Err(e) => Err(inaccessible(dir, &e)),
        }
    }

    /// Checks the output `dir/name` when `dir` exists (as [`OutputPlan::output`]); when it does
    /// not exist yet only the extension can be wrong. Returns the path to write.
    pub fn output_in(
        &mut self,
        dir: &Path,
        name: &str,
        format: Format,
    ) -> Result<PathBuf, OutputError> {
        let path = dir.join(name);
        if dir.is_dir() {
            self.output(&path, format)
        } else {
            check_extension(&path, format)?;
            Ok(path)
        }
    }
}

fn inaccessible(path: &Path, e: &io::Error) -> OutputError {
    // "Not a directory" alone does not say which part of the path is the file in the way.
    if e.kind() == io::ErrorKind::NotADirectory
        && let Some((dir, meta)) = path
            .ancestors()
            .skip(1)
            .filter(|a| !a.as_os_str().is_empty())
            .find_map(|a| std::fs::metadata(a).ok().map(|m| (a, m)))
        && !meta.is_dir()
    {
        return OutputError::NoDirectory {
            path: path.into(),
            dir: dir.into(),
            why: "is not a directory (a file is in the way)",
        };
    }
    OutputError::Inaccessible {
        path: path.into(),
        reason: e.to_string(),
    }
}

fn kind_name(meta: &Metadata) -> String {
    if meta.is_file() {
        "a regular file".into()
    } else {
        Kind::of(meta).to_string()
    }
}

fn check_extension(path: &Path, format: Format) -> Result<(), OutputError> {
    let ext = path.extension().map(|e| e.to_string_lossy().to_string());
    match ext {
        Some(e) if e.eq_ignore_ascii_case(format.extension()) => Ok(()),
        _ => Err(OutputError::WrongExtension {
            path: path.into(),
            format,
            found: ext.map_or("has no extension".into(), |e| format!("ends in .{e}")),
        }),
    }
}

/// The file an output path writes: the path, or the final target of a symlink; refuses paths
/// that are not regular files.
fn resolve(path: &Path) -> Result<PathBuf, OutputError> {
    // `/dev/stdout` and its kind lead through `/proc/self/fd` to whatever the stream is, perhaps
    // a file another program has open: never an output.
    let mut hop = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        if special(&hop) {
            let kind = match std::fs::metadata(&hop) {
                Ok(m) if !m.is_file() => Kind::of(&m).to_string(),
                _ => "a device or process file".into(),
            };
            let what = if hop == path {
                kind
            } else {
                format!("a symlink to {kind} ({})", hop.display())
            };
            return Err(OutputError::NotAFile {
                path: path.into(),
                what,
            });
        }
        match std::fs::read_link(&hop) {
            Ok(next) => hop = hop.parent().unwrap_or(Path::new("")).join(next),
            Err(_) => break,
        }
    }
    let meta = match std::fs::symlink_metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(path.into()),
        Err(e) => return Err(inaccessible(path, &e)),
    };
    if meta.is_file() {
        return Ok(path.into());
    }
    if !meta.file_type().is_symlink() {
        return Err(OutputError::NotAFile {
            path: path.into(),
            what: Kind::of(&meta).to_string(),
        });
    }
    let target = std::fs::canonicalize(path).map_err(|e| OutputError::BrokenLink {
        path: path.into(),
        reason: e.to_string(),
    })?;
    let meta = std::fs::metadata(&target).map_err(|e| inaccessible(path, &e))?;
    if !meta.is_file() {
        return Err(OutputError::NotAFile {
            path: path.into(),
            what: format!("a symlink to {} ({})", Kind::of(&meta), target.display()),
        });
    }
    Ok(target)
}

/// Most symbolic links followed when looking for `/dev` and `/proc` (Linux's own limit).
const MAX_LINKS: usize = 40;

/// Whether `path`, made absolute, lies under `/dev` or `/proc`.
fn special(path: &Path) -> bool {
    let abs = if path.is_absolute() {
        path.to_path_buf()
    } else {
        std::env::current_dir().unwrap_or_default().join(path)
    };
    ["/dev", "/proc"].iter().any(|d| abs.starts_with(d))
}

/// `dir` (the directory of output `path`) must exist, be a directory with a write bit, and let
/// this process create a file in it (tried with a probe that is removed at once).
fn check_directory(path: &Path, dir: &Path) -> Result<(), OutputError> {
    let no_dir = |why| OutputError::NoDirectory {
        path: path.into(),
        dir: dir.into(),
        why,
    };
    let meta = match std::fs::metadata(dir) {
        Ok(m) if m.is_dir() => m,
        Ok(_) => return Err(no_dir("is not a directory")),
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Err(no_dir("does not exist")),
        Err(e) => return Err(inaccessible(path, &e)),
    };
    let read_only = |reason: String| OutputError::DirectoryReadOnly {
        path: path.into(),
        dir: dir.into(),
        reason,
    };
    if meta.permissions().readonly() {
        return Err(read_only("no write permission".into()));
    }
    // Named like a temporary file, so a probe left by a killed run is cleaned up like one.
    let probe = dir.join(format!(".probe.lapidary-{}-0.tmp", std::process::id()));
    match OpenOptions::new().write(true).create_new(true).open(&probe) {
        Ok(_) => {
            let _ = std::fs::remove_file(&probe);
            Ok(())
        }
        Err(e) if e.kind() == io::ErrorKind::AlreadyExists => Ok(()),
        Err(e) => Err(read_only(e.to_string())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extensions_follow_the_format() {
        assert!(check_extension(Path::new("a/b.EXR"), Format::Exr).is_ok());
        let e = check_extension(Path::new("b.png"), Format::Exr).unwrap_err();
        assert_eq!(
            e.to_string(),
            "b.png: EXR output, but the name ends in .png; it must end in .exr"
        );
        let e = check_extension(Path::new("b"), Format::Csv).unwrap_err();
        assert!(e.to_string().contains("has no extension"), "{e}");
    }

    #[cfg(unix)]
    #[test]
    fn devices_and_directories_are_named() {
        let mut plan = OutputPlan::new();
        let e = plan.output(Path::new("/dev/null"), Format::Png);
        assert!(e.is_err(), "no extension");
        let dir = std::env::temp_dir().join(format!("lapidary-outputs-{}.png", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let e = plan.output(&dir, Format::Png).unwrap_err();
        assert!(e.to_string().contains("is a directory"), "{e}");
        std::fs::remove_dir(&dir).unwrap();
        assert_eq!(
            Kind::of(&std::fs::metadata("/dev/null").unwrap()),
            Kind::CharDevice
        );
    }

    #[test]
    fn an_input_cannot_be_an_output_in_either_order() {
        let dir = std::env::temp_dir().join(format!("lapidary-outputs-io-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("x.exr");
        std::fs::write(&f, "x").unwrap();
        let mut plan = OutputPlan::new();
        plan.input(&f, "the test image").unwrap();
        let e = plan.output(&dir.join("./x.exr"), Format::Exr).unwrap_err();
        assert!(
            e.to_string().contains("also an input (the test image"),
            "{e}"
        );
        let mut plan = OutputPlan::new();
        plan.output(&f, Format::Exr).unwrap();
        assert!(plan.input(&f, "the reference").is_err());
        let new = dir.join("new.png");
        plan.output(&new, Format::Png).unwrap();
        let e = plan.output(
            &dir.join("../")
                .join(dir.file_name().unwrap())
                .join("new.png"),
            Format::Png,
        );
        assert!(matches!(e, Err(OutputError::Duplicate { .. })), "{e:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
