//! The writer every output goes through: a buffered file whose every failure is kept.
//!
//! Encoders are not all careful with I/O errors: a `BufWriter` dropped without `flush` discards
//! the error of its last write, and some encoders write their final chunk that way, so a full disk
//! could leave a truncated file behind a successful return. A [`Sink`] records the first error of
//! any `write`, `flush` or `seek`; once one has failed, every later call fails the same way, and
//! [`Sink::finish`] reports it even when the encoder swallowed it. `finish` then flushes the
//! buffer, `fsync`s the file (on Linux a delayed write-back error — `EIO`, `ENOSPC`, `EDQUOT` on
//! file systems that allocate late — is reported by `fsync`, the last point where the standard
//! library lets a program see it: `close` results are discarded when a `File` is dropped, and
//! after a successful `fsync` `close` has nothing left to report), and checks that the file on disk
//! has exactly the length written.
//!
//! **Fault injection** (debug and test builds only; absent from release builds): the environment
//! variable `LAPIDARY_WRITE_FAULT=ERRNO@WHERE[:EXT]` makes sinks fail with `ERRNO` (`ENOSPC`, `EIO`
//! or `EDQUOT`) at byte `WHERE` of the file (a number: the write that would cross it fails), or at
//! `flush` or `sync`; with `:EXT` only for files whose name ends in `.EXT`. The integration tests
//! use it to prove, for every command that writes, that an I/O error at any point leaves the old
//! outputs byte-identical.

use std::fs::File;
use std::io::{self, BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

/// A buffered output file that keeps the first I/O error (see the module documentation).
pub struct Sink {
    file: BufWriter<File>,
    path: PathBuf,
    /// The first failure: its kind, OS error number and message, to be returned again.
    failed: Option<Failure>,
    /// Current position and the largest position written, bytes.
    pos: u64,
    end: u64,
    fault: Option<Fault>,
}

/// A remembered I/O error (`io::Error` is not `Clone`).
#[derive(Clone, Debug)]
struct Failure {
    kind: io::ErrorKind,
    os: Option<i32>,
    message: String,
}

impl Failure {
    fn of(e: &io::Error) -> Failure {
        Failure {
            kind: e.kind(),
            os: e.raw_os_error(),
            message: e.to_string(),
        }
    }

    fn error(&self) -> io::Error {
        match self.os {
            Some(code) => io::Error::from_raw_os_error(code),
            None => io::Error::new(self.kind, self.message.clone()),
        }
    }
}

impl Sink {
    /// Creates `path` (which must not exist) for writing.
    pub(crate) fn create(path: &Path) -> io::Result<Sink> {
        let file = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(path)?;
        Ok(Sink {
            file: BufWriter::with_capacity(1 << 16, file),
            path: path.to_path_buf(),
            failed: None,
            pos: 0,
            end: 0,
            fault: Fault::for_path(path),
        })
    }

    /// The temporary file being written (for encoders that need a path, and for setting its
    /// permissions before it is renamed).
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Records `e` as the sink's failure (the first one wins) and returns it.
    fn fail(&mut self, e: io::Error) -> io::Error {
        let f = self.failed.get_or_insert_with(|| Failure::of(&e));
        f.error()
    }

    /// The remembered failure, if any.
    fn check(&self) -> io::Result<()> {
        match &self.failed {
            Some(f) => Err(f.error()),
            None => Ok(()),
        }
    }

    /// Ends the file: reports any failure seen so far, flushes, `fsync`s and checks the length on
    /// disk. Only a sink that finished without error may be renamed over a target.
    pub(crate) fn finish(mut self) -> io::Result<()> {
        Write::flush(&mut self)?;
        if let Some(e) = self
            .fault
            .as_ref()
            .and_then(|f| f.at_flush_or_sync(At::Sync))
        {
            return Err(e);
        }
        self.file.get_ref().sync_all()?;
        let len = self.file.get_ref().metadata()?.len();
        if len != self.end {
            return Err(io::Error::other(format!(
                "the file holds {len} bytes after writing {}",
                self.end
            )));
        }
        Ok(())
    }
}

impl Write for Sink {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.check()?;
        if let Some(e) = self
            .fault
            .as_ref()
            .and_then(|f| f.at_write(self.pos, buf.len()))
        {
            return Err(self.fail(e));
        }
        match self.file.write(buf) {
            Ok(n) => {
                self.pos += n as u64;
                self.end = self.end.max(self.pos);
                Ok(n)
            }
            Err(e) if e.kind() == io::ErrorKind::Interrupted => Err(e),
            Err(e) => Err(self.fail(e)),
        }
    }

    fn flush(&mut self) -> io::Result<()> {
        self.check()?;
        if let Some(e) = self
            .fault
            .as_ref()
            .and_then(|f| f.at_flush_or_sync(At::Flush))
        {
            return Err(self.fail(e));
        }
        self.file.flush().map_err(|e| self.fail(e))
    }
}

impl Seek for Sink {
    fn seek(&mut self, to: SeekFrom) -> io::Result<u64> {
        self.check()?;
        match self.file.seek(to) {
            Ok(p) => {
                self.pos = p;
                Ok(p)
            }
            Err(e) => Err(self.fail(e)),
        }
    }
}

#[cfg(test)]
thread_local! {
    /// A fault for the sinks this test thread creates (unit tests share one environment).
    pub(crate) static TEST_FAULT: std::cell::RefCell<Option<String>> =
        const { std::cell::RefCell::new(None) };
}

/// Where an injected fault strikes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum At {
    /// The write that would cross this byte offset.
    Byte(u64),
    /// An explicit `flush`.
    Flush,
    /// The final `fsync`.
    Sync,
}

/// An injected I/O fault (debug and test builds only).
#[derive(Clone, Debug)]
struct Fault {
    errno: i32,
    at: At,
}

impl Fault {
    /// The fault `LAPIDARY_WRITE_FAULT` asks for on a file at `path`, if any. Release builds
    /// never inject.
    fn for_path(path: &Path) -> Option<Fault> {
        if !cfg!(debug_assertions) {
            return None;
        }
        #[cfg(test)]
        if let Some(spec) = TEST_FAULT.with(|f| f.borrow().clone()) {
            return Fault::parse(&spec, path);
        }
        let spec = std::env::var("LAPIDARY_WRITE_FAULT").ok()?;
        Fault::parse(&spec, path)
    }

    /// Parses `ERRNO@WHERE[:EXT]`; `None` when it does not apply to `path` (or is malformed:
    /// a test hook, not user input).
    fn parse(spec: &str, path: &Path) -> Option<Fault> {
        let (spec, ext) = match spec.split_once(':') {
            Some((s, e)) => (s, Some(e)),
            None => (spec, None),
        };
        if let Some(ext) = ext {
            let name = path.to_string_lossy().to_ascii_lowercase();
            if !name.ends_with(&format!(".{}", ext.to_ascii_lowercase())) {
                return None;
            }
        }
        let (name, at) = spec.split_once('@')?;
        let errno = match name {
            "ENOSPC" => 28,
            "EIO" => 5,
            "EDQUOT" => 122,
            _ => return None,
        };
        let at = match at {
            "flush" => At::Flush,
            "sync" => At::Sync,
            n => At::Byte(n.parse().ok()?),
        };
        Some(Fault { errno, at })
    }

    fn at_write(&self, pos: u64, len: usize) -> Option<io::Error> {
        match self.at {
            At::Byte(b) if pos + len as u64 > b => Some(io::Error::from_raw_os_error(self.errno)),
            _ => None,
        }
    }

    fn at_flush_or_sync(&self, when: At) -> Option<io::Error> {
        (self.at == when).then(|| io::Error::from_raw_os_error(self.errno))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("lapidary-sink-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join(name);
        let _ = std::fs::remove_file(&p);
        p
    }

    /// A sink whose fault is set directly (the environment is shared by every test thread).
    fn faulty(path: &Path, spec: &str) -> Sink {
        let mut s = Sink::create(path).unwrap();
        s.fault = Some(Fault::parse(spec, path).expect("a fault"));
        s
    }

    #[test]
    fn a_clean_write_finishes_with_its_length() {
        let p = scratch("clean.bin");
        let mut s = Sink::create(&p).unwrap();
        s.write_all(&[7u8; 100_000]).unwrap();
        s.seek(SeekFrom::Start(10)).unwrap();
        s.write_all(b"xy").unwrap();
        s.finish().unwrap();
        let back = std::fs::read(&p).unwrap();
        assert_eq!(back.len(), 100_000);
        assert_eq!(&back[10..12], b"xy");
    }

    #[test]
    fn every_injected_errno_is_kept_even_when_the_encoder_ignores_it() {
        for (name, errno) in [("ENOSPC", 28), ("EIO", 5), ("EDQUOT", 122)] {
            for at in ["0", "4096", "70000", "flush", "sync"] {
                let p = scratch(&format!("fault-{name}-{at}.png"));
                let mut s = faulty(&p, &format!("{name}@{at}"));
                // An encoder that drops write errors on the floor, as a BufWriter dropped
                // without flush does.
                for _ in 0..20 {
                    let _ = s.write(&[1u8; 5000]);
                }
                let e = s.finish().expect_err("the fault must surface");
                assert_eq!(e.raw_os_error(), Some(errno), "{name}@{at}: {e}");
            }
        }
    }

    #[test]
    fn after_a_failure_every_call_fails() {
        let p = scratch("sticky.exr");
        let mut s = faulty(&p, "EIO@10");
        assert!(s.write_all(&[0u8; 8]).is_ok());
        assert!(s.write_all(&[0u8; 8]).is_err());
        // A write that would have fitted still fails: the file has a hole now.
        assert_eq!(s.write(&[0u8; 1]).unwrap_err().raw_os_error(), Some(5));
        assert!(s.flush().is_err());
        assert!(s.seek(SeekFrom::Start(0)).is_err());
    }

    #[test]
    fn faults_apply_to_their_extension_only() {
        let exr = Path::new("a/b.exr");
        assert!(Fault::parse("ENOSPC@0:png", exr).is_none());
        assert!(Fault::parse("ENOSPC@0:EXR", exr).is_some());
        assert!(Fault::parse("ENOSPC@0", exr).is_some());
        assert!(Fault::parse("EPERM@0", exr).is_none());
        assert!(Fault::parse("ENOSPC@x", exr).is_none());
    }
}
