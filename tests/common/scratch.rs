//! A fresh directory per test for the command-line tests (`#[path]`-included by `cli_render`,
//! `cli_compare`, `cli_regress`): removed when the test passes, kept (and named) when it fails.

#![allow(dead_code)] // each test file uses a different part

use std::path::PathBuf;

/// A scratch directory `$TMP/lapidary-<suite>-<test>-<pid>`.
pub struct Scratch(pub PathBuf);

impl Scratch {
    /// A new, empty directory for test `test` of suite `suite`.
    pub fn new(suite: &str, test: &str) -> Self {
        let dir =
            std::env::temp_dir().join(format!("lapidary-{suite}-{test}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Scratch(dir)
    }

    /// A path inside the directory.
    pub fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }

    /// `name` as an absolute path string, for arguments.
    pub fn arg(&self, name: &str) -> String {
        self.path(name).to_str().unwrap().to_owned()
    }

    /// The directory's entries, sorted.
    pub fn files(&self) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(&self.0)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if std::thread::panicking() {
            eprintln!("kept {} for inspection", self.0.display());
        } else {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

/// Bytes of a process's output as text.
pub fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// Whether the process has installed its signal handler (the `ctrlc` crate runs it on a thread
/// named `ctrl-c`). Without `/proc`, assume so after a while.
#[cfg(unix)]
pub fn handler_installed(pid: u32, since: std::time::Instant) -> bool {
    let Ok(tasks) = std::fs::read_dir(format!("/proc/{pid}/task")) else {
        return since.elapsed() > std::time::Duration::from_secs(3);
    };
    tasks
        .filter_map(Result::ok)
        .any(|t| std::fs::read_to_string(t.path().join("comm")).is_ok_and(|c| c.trim() == "ctrl-c"))
}
