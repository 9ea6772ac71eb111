//! Writing and submitting Slurm jobs: an array job, a job that depends on it, and `submit.sh`,
//! which submits both the way `--submit` does.

use super::text::{Text, script_is_clean};
use anyhow::{Context, Result, anyhow, bail};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The first line after the shebang of every script a farm writes; a file without it is never
/// overwritten.
pub const MARKER: &str = "# Written by lapidary farm";

/// Reads a file the farm itself keeps (a script, `parts/command.txt`) if it exists: `None` when
/// nothing is there. Its type is checked before it is opened: a FIFO would block the read and a
/// device never end it, so anything but a regular file is refused.
pub fn read_own(path: &Path) -> Result<Option<String>> {
    use crate::image::input_kind::{NotAFile, regular_file};
    match regular_file(path) {
        Ok(_) => {}
        Err(NotAFile::Missing) if std::fs::symlink_metadata(path).is_err() => return Ok(None),
        Err(e) => bail!(
            "{}: {e}: where the farm keeps a file of its own; not replaced (remove it, or choose \
             another --dir)",
            path.display()
        ),
    }
    match std::fs::read_to_string(path) {
        Ok(text) => Ok(Some(text)),
        Err(e) => bail!(
            "{}: exists and is not a text file ({e}): not replaced",
            path.display()
        ),
    }
}

/// Checks that `path` is free for a script: nothing there, or a file this command wrote before
/// (one whose first or second line is the [`MARKER`]); returns its text.
pub fn check_own(path: &Path) -> Result<Option<String>> {
    let old = read_own(path)?;
    if let Some(old) = &old
        && !old.lines().take(2).any(|l| l.starts_with(MARKER))
    {
        bail!(
            "{}: exists and was not written by `lapidary farm`: not replaced (choose another \
             --dir)",
            path.display()
        );
    }
    Ok(old)
}

/// Writes an executable script (or the farm's record of its part command), replacing only a file
/// this command wrote before ([`check_own`]). The text must be free of control characters but
/// its line ends ([`script_is_clean`]).
pub fn write_script(path: &Path, text: &str) -> Result<()> {
    if !script_is_clean(text) {
        bail!(
            "{}: the script would hold a control character: not written",
            path.display()
        );
    }
    check_own(path)?;
    crate::image::write_atomically(path, |sink| {
        use std::io::Write as _;
        sink.write_all(text.as_bytes())?;
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            std::fs::set_permissions(sink.path(), std::fs::Permissions::from_mode(0o755))?;
        }
        Ok(())
    })
}

/// What a farm submits: an array of tasks, then one job after it.
#[derive(Debug)]
pub struct Jobs {
    /// The farm folder.
    pub dir: PathBuf,
    /// The array's script.
    pub array_script: PathBuf,
    /// Task indices still to run (empty: only the final job is submitted).
    pub indices: Vec<u32>,
    /// At most this many tasks at once (`%K`).
    pub max_running: Option<u32>,
    /// The final job's script.
    pub final_script: PathBuf,
    /// The final job's dependency type on the array: `afterok` (merge) or `afterany` (a table
    /// that reports failed tasks).
    pub dependency: &'static str,
    /// Options for every `sbatch` call (`--partition=…`).
    pub sbatch_args: Vec<Text>,
}

impl Jobs {
    /// The `--array` value.
    fn array(&self) -> String {
        super::array_spec(&self.indices, self.max_running)
    }

    /// Writes `submit.sh`, which submits the array (if any task is left) and the final job,
    /// printing both job ids. Extra `sbatch` options may be given to it.
    pub fn write_submit_sh(&self) -> Result<PathBuf> {
        let opts: Vec<String> = self.sbatch_args.iter().map(Text::sh).collect();
        let opts = opts.join(" ");
        let array_script = Text::path(&self.array_script, "the array script")?;
        let final_script = Text::path(&self.final_script, "the final script")?;
        let mut s = format!(
            "#!/bin/bash\n{MARKER}: submits the array and the job after it; extra sbatch options \
             may be given.\nset -euo pipefail\n"
        );
        if self.indices.is_empty() {
            s += &format!(
                "# Every task's output is present: only the final job.\nsbatch --parsable {opts} \
                 \"$@\" {}\n",
                final_script.sh()
            );
        } else {
            s += &format!(
                "array=$(sbatch --parsable --array={} {opts} \"$@\" {})\narray=${{array%%;*}}\n\
                 echo \"array job $array\"\n\
                 sbatch --parsable --dependency={}:\"$array\" {opts} \"$@\" {}\n",
                self.array(),
                array_script.sh(),
                self.dependency,
                final_script.sh()
            );
        }
        let path = self.dir.join("submit.sh");
        write_script(&path, &s)?;
        Ok(path)
    }

    /// Submits with `sbatch`; returns the array's job id (if one was submitted) and the final
    /// job's.
    pub fn submit(&self) -> Result<(Option<String>, String)> {
        let array = if self.indices.is_empty() {
            None
        } else {
            let mut args = vec![format!("--array={}", self.array())];
            args.extend(self.sbatch_args.iter().map(|a| a.as_str().to_string()));
            args.push(self.array_script.display().to_string());
            Some(sbatch(&args)?)
        };
        let mut args = Vec::new();
        if let Some(id) = &array {
            args.push(format!("--dependency={}:{id}", self.dependency));
        }
        args.extend(self.sbatch_args.iter().map(|a| a.as_str().to_string()));
        args.push(self.final_script.display().to_string());
        Ok((array, sbatch(&args)?))
    }
}

/// Runs `sbatch --parsable ARGS` and returns the job id.
fn sbatch(args: &[String]) -> Result<String> {
    let out = Command::new("sbatch")
        .arg("--parsable")
        .args(args)
        .output()
        .map_err(|e| {
            anyhow!(
                "cannot run sbatch ({e}): run this on a Slurm login node, or submit the written \
                 submit.sh there"
            )
        })?;
    if !out.status.success() {
        bail!(
            "sbatch {} failed: {}",
            args.join(" "),
            String::from_utf8_lossy(&out.stderr).trim()
        );
    }
    let text = String::from_utf8(out.stdout).context("sbatch printed a job id that is not text")?;
    let id = text
        .trim()
        .split(';')
        .next()
        .unwrap_or_default()
        .to_string();
    if id.is_empty() || !id.chars().all(|c| c.is_ascii_digit()) {
        bail!("sbatch printed `{}`, not a job id", text.trim());
    }
    Ok(id)
}
