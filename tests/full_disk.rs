//! A full disk, for real: every command that writes runs on a small tmpfs that is full (or has one
//! page, or a few pages, left). It must fail naming the file and "No space left on device", keep
//! every existing output byte-identical and leave no temporary file; with the space freed, the
//! same command succeeds and replaces the outputs.
//!
//! Mounting needs root (CI runs as root). Elsewhere the test says it skipped, unless
//! `LAPIDARY_REQUIRE_TMPFS=1` (set by `.ci/run`) makes an unavailable mount a failure.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;
use std::process::{Command, Output, Stdio};

#[path = "common/scratch.rs"]
mod scratch;
use scratch::{Scratch, text};
#[path = "common/writes.rs"]
mod writes;
use writes::{Case, cases};

/// A tmpfs mounted over a scratch directory, unmounted when dropped.
struct Tmpfs(std::path::PathBuf);

impl Tmpfs {
    /// Mounts a tmpfs of `bytes` over `dir`; `None` where mounting is not allowed.
    fn mount(dir: &Path, bytes: u64) -> Option<Tmpfs> {
        let ok = Command::new("mount")
            .args(["-t", "tmpfs", "-o", &format!("size={bytes}"), "tmpfs"])
            .arg(dir)
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success());
        if ok {
            Some(Tmpfs(dir.to_path_buf()))
        } else if std::env::var_os("LAPIDARY_REQUIRE_TMPFS").is_some() {
            panic!(
                "cannot mount a tmpfs on {} (LAPIDARY_REQUIRE_TMPFS is set)",
                dir.display()
            );
        } else {
            eprintln!("skipped: mounting a tmpfs needs root");
            None
        }
    }

    /// Fills the file system, then frees `keep` bytes of the filler.
    fn fill(&self, keep: u64) {
        let path = self.0.join("filler");
        let mut f = std::fs::File::create(&path).unwrap();
        let block = vec![0xa5u8; 1 << 16];
        let mut written = 0u64;
        loop {
            match f.write(&block) {
                Ok(0) => break,
                Ok(n) => written += n as u64,
                Err(e) if e.raw_os_error() == Some(28) => break,
                Err(e) => panic!("filling: {e}"),
            }
        }
        f.set_len(written.saturating_sub(keep)).unwrap();
        f.sync_all().unwrap();
    }

    fn empty(&self) {
        std::fs::remove_file(self.0.join("filler")).unwrap();
    }
}

impl Drop for Tmpfs {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg("-l").arg(&self.0).status();
    }
}

fn run(dir: &Path, args: &[String]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lapidary"))
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .env_remove("LAPIDARY_WRITE_FAULT")
        .output()
        .expect("binary runs")
}

fn snapshot(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().map(Result::unwrap) {
            let p = e.path();
            let rel = p.strip_prefix(dir).unwrap().display().to_string();
            if e.file_type().unwrap().is_dir() {
                stack.push(p);
            } else if rel != "filler" {
                out.insert(rel, std::fs::read(&p).unwrap());
            }
        }
    }
    out
}

fn check(case: &Case) {
    let s = Scratch::new("full-disk", case.name);
    let Some(fs) = Tmpfs::mount(&s.0, 16 << 20) else {
        return;
    };
    (case.setup)(&s);
    let ok = |o: &Output| case.ok_status.contains(&o.status.code().unwrap_or(-1));
    let first = run(&s.0, &case.first);
    assert!(
        ok(&first),
        "{}: first run:\n{}",
        case.name,
        text(&first.stderr)
    );
    let before = snapshot(&s.0);
    // Full, then room for the first output, the first two, …: every split of the outputs
    // into those that fit and those that do not (files are written in the listed order; a
    // cache the command writes first counts before them).
    let page = |n: usize| (n as u64).div_ceil(4096);
    let mut sizes: Vec<u64> = before
        .iter()
        .filter(|(k, _)| case.may_add.iter().any(|p| k.starts_with(p)))
        .map(|(_, v)| page(v.len()))
        .collect();
    sizes.extend(case.outputs.iter().map(|o| page(before[*o].len())));
    let mut free = vec![0u64];
    for s in sizes {
        free.push(free.last().unwrap() + s);
    }
    free.dedup();
    let mut failed = 0;
    for &pages in &free {
        let keep = pages * 4096;
        fs.fill(keep);
        let o = run(&s.0, &case.second);
        fs.empty();
        if ok(&o) {
            break;
        }
        failed += 1;
        let err = text(&o.stderr);
        let code = o.status.code().unwrap_or(0);
        assert!(
            code != 0 && !case.ok_status.contains(&code),
            "{} with {keep} bytes free: exit {code}\n{err}",
            case.name
        );
        assert!(
            err.contains("No space left on device"),
            "{} with {keep} bytes free:\n{err}",
            case.name
        );
        let after = snapshot(&s.0);
        for (name, bytes) in &before {
            assert!(
                after.get(name) == Some(bytes),
                "{} with {keep} bytes free: {name} changed or vanished",
                case.name
            );
        }
        for name in after.keys() {
            assert!(
                !name.contains(".lapidary-"),
                "{} with {keep} bytes free: temporary file {name} left",
                case.name
            );
        }
    }
    assert!(failed > 0, "{}: did not fail on a full disk", case.name);
    eprintln!(
        "{}: failed cleanly with {:?} pages free",
        case.name,
        &free[..failed]
    );
    let o = run(&s.0, &case.second);
    assert!(ok(&o), "{}: with space:\n{}", case.name, text(&o.stderr));
    let after = snapshot(&s.0);
    for out in &case.outputs {
        assert_ne!(
            before.get(*out),
            after.get(*out),
            "{}: {out} unchanged",
            case.name
        );
    }
    drop(fs);
}

#[test]
fn a_full_disk_fails_every_command_and_keeps_every_file() {
    for case in cases() {
        if std::env::var("ONLY").is_ok_and(|o| o != case.name) {
            continue;
        }
        check(&case);
    }
}
