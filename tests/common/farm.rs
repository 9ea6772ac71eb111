//! Helpers shared by the farm tests (`#[path]`-included by `distributed`, `slurm` and
//! `farm_hostile`): stand-ins for `lapidary` and `sbatch` that record their arguments, a model of
//! sbatch's `#SBATCH` parser, FIFOs, a runner that cannot block forever, and forged part files.

#![allow(dead_code)] // each test file uses a different part

use std::collections::BTreeSet;
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Output;

/// The standard output of a process that must have succeeded (else both streams in the panic).
pub fn ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// A `regress` table without its time column (the one column that differs between runs).
pub fn table(stdout: &str) -> Vec<String> {
    stdout
        .lines()
        .map(|l| match l.rfind(" s  ") {
            Some(i) => l[..l[..i].rfind(' ').unwrap_or(i)].to_string() + &l[i + 3..],
            None => l.to_string(),
        })
        .collect()
}

/// A small coated recipe for regression suites; replace `0.5` for other greys.
pub const RECIPE: &str = r#"(
    materials: { "a": (coats: [(ior: 1.5, roughness: 8.0)], base: Lambert(albedo: Gray(0.5))) },
    surface: Material("a"),
    stage: (ground: Off),
)"#;

/// Writes an executable `lapidary` stand-in at `path` that records its arguments, each ended by a
/// NUL, in the file `$ARGV_LOG` (so that every byte of every argument can be compared).
#[cfg(unix)]
pub fn fake_lapidary(path: &Path) {
    executable(path, "#!/bin/bash\nprintf '%s\\0' \"$@\" > \"$ARGV_LOG\"\n");
}

/// Writes an executable `sbatch` stand-in into the folder `bin`: each call records its arguments
/// (NUL-ended) in a new file `$SBATCH_LOG/N` and prints the job id `424N`.
#[cfg(unix)]
pub fn fake_sbatch(bin: &Path) {
    std::fs::create_dir_all(bin).unwrap();
    executable(
        &bin.join("sbatch"),
        "#!/bin/bash\nn=$(ls \"$SBATCH_LOG\" | wc -l)\nprintf '%s\\0' \"$@\" > \"$SBATCH_LOG/$n\"\n\
         echo \"424$n\"\n",
    );
}

#[cfg(unix)]
fn executable(path: &Path, text: &str) {
    use std::os::unix::fs::PermissionsExt;
    std::fs::write(path, text).unwrap();
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755)).unwrap();
}

/// The arguments a stand-in recorded (NUL-ended) in `file`.
pub fn recorded(file: &Path) -> Vec<String> {
    let bytes = std::fs::read(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let text = String::from_utf8(bytes).unwrap();
    let mut v: Vec<String> = text.split('\0').map(str::to_string).collect();
    assert_eq!(v.pop().as_deref(), Some(""), "every argument ends in a NUL");
    v
}

/// The options a batch script's `#SBATCH` lines give sbatch, read as sbatch reads them (Slurm's
/// `src/sbatch/opt.c`, `_opt_batch_script` and `_get_argument`): only the comment lines before the
/// first command count; in each, arguments are split at blanks, `'…'` and `"…"` group, `\`
/// escapes the next character (also inside quotes), and an unquoted `#` ends the line.
pub fn sbatch_directives(script: &str) -> Vec<String> {
    let mut argv = Vec::new();
    for line in script.split('\n') {
        let Some(rest) = line.strip_prefix("#SBATCH") else {
            let t = line.trim_start_matches(is_c_space);
            if t.is_empty() || t.starts_with('#') {
                continue;
            }
            break;
        };
        let c: Vec<char> = rest.chars().collect();
        let mut i = 0;
        loop {
            while i < c.len() && is_c_space(c[i]) {
                i += 1;
            }
            let (mut arg, mut quote, mut escaped) = (String::new(), None, false);
            while i < c.len() && (quote.is_some() || !is_c_space(c[i])) {
                let ch = c[i];
                if escaped {
                    escaped = false;
                } else if ch == '\\' {
                    escaped = true;
                    i += 1;
                    continue;
                } else if let Some(q) = quote {
                    if ch == q {
                        quote = None;
                        i += 1;
                        continue;
                    }
                } else if ch == '"' || ch == '\'' {
                    quote = Some(ch);
                    i += 1;
                    continue;
                } else if ch == '#' {
                    break;
                }
                arg.push(ch);
                i += 1;
            }
            assert!(quote.is_none(), "sbatch: unmatched quote in {line:?}");
            // sbatch stops reading a line at the first place where no argument starts.
            if arg.is_empty() {
                break;
            }
            argv.push(arg);
        }
    }
    argv
}

/// C's `isspace` in the C locale.
fn is_c_space(c: char) -> bool {
    matches!(c, ' ' | '\t' | '\n' | '\x0b' | '\x0c' | '\r')
}

/// Runs `cmd` to its end, or kills it (by its process id) and fails the test when it is still
/// running after a minute: a command that opens a FIFO for reading blocks until a writer comes.
pub fn bounded(cmd: &mut std::process::Command) -> Output {
    use std::process::Stdio;
    let child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn");
    let pid = child.id();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(child.wait_with_output());
    });
    match rx.recv_timeout(std::time::Duration::from_secs(60)) {
        Ok(out) => out.expect("wait"),
        Err(_) => {
            let _ = std::process::Command::new("kill")
                .args(["-9", &pid.to_string()])
                .status();
            panic!("{cmd:?} blocked: still running after a minute (killed)");
        }
    }
}

/// Makes a FIFO (named pipe) at `path`.
pub fn mkfifo(path: &Path) {
    let st = std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .expect("mkfifo");
    assert!(st.success(), "mkfifo {}", path.display());
}

/// Rewrites the part file `path` after `edit` changed its image (display channels and
/// attributes) or its raw sums: how a forged or damaged part is made from a real one.
pub fn forge(
    path: &Path,
    edit: impl FnOnce(&mut lapidary::image::ExrImage, &mut Vec<lapidary::image::RawChannel>),
) {
    let (mut img, mut raw) = lapidary::image::read_exr_raw(path).unwrap();
    // The raw channels also read back as float channels of the image: keep them once.
    img.channels.retain(|c| !c.name.starts_with("raw."));
    edit(&mut img, &mut raw);
    lapidary::image::write_exr_raw(path, &img, &raw).unwrap();
}

/// Sets attribute `key` of `img` to `value`.
pub fn set_attr(img: &mut lapidary::image::ExrImage, key: &str, value: &str) {
    match img.attributes.iter_mut().find(|(k, _)| k == key) {
        Some((_, v)) => *v = value.to_string(),
        None => img.attributes.push((key.to_string(), value.to_string())),
    }
}

/// The raw channel `name` of a part.
pub fn raw_mut<'a>(raw: &'a mut [lapidary::image::RawChannel], name: &str) -> &'a mut Vec<u32> {
    &mut raw.iter_mut().find(|c| c.name == name).unwrap().data
}

/// Asserts a refusal (exit 1) whose message holds every needle.
pub fn refused(out: &Output, needles: &[&str]) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        out.status.code(),
        Some(1),
        "{err}{}",
        String::from_utf8_lossy(&out.stdout)
    );
    for n in needles {
        assert!(err.contains(n), "wanted `{n}` in:\n{err}");
    }
}

/// Every file and folder under `dir`, as paths relative to it.
pub fn tree(dir: &Path) -> BTreeSet<PathBuf> {
    let mut out = BTreeSet::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() && !p.is_symlink() {
                stack.push(p.clone());
            }
            out.insert(p.strip_prefix(dir).unwrap().to_path_buf());
        }
    }
    out
}

/// No file whose name starts with `pwned` exists under `dir`: no injected command ran.
pub fn nothing_ran(dir: &Path) {
    let hits: Vec<_> = tree(dir)
        .into_iter()
        .filter(|p| {
            p.file_name()
                .is_some_and(|n| n.as_encoded_bytes().starts_with(b"pwned"))
        })
        .collect();
    assert!(hits.is_empty(), "injected commands ran: {hits:?}");
}

/// Runs a script with `bash` in `cwd`, with `env` set.
pub fn bash(script: &Path, cwd: &Path, env: &[(&str, &OsStr)]) -> Output {
    let mut c = std::process::Command::new("bash");
    c.arg(script).current_dir(cwd);
    for (k, v) in env {
        c.env(k, v);
    }
    bounded(&mut c)
}
