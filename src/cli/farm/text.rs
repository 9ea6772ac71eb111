//! Text in farm scripts. The scripts are bash, and their `#SBATCH` lines are read by sbatch's own
//! parser; both end a line at a newline, so a newline in a recipe's name would start a command of
//! its own in every task (or a `#SBATCH` line). Every piece of text a user controls — a path, a
//! `--render-arg`, an sbatch option, a suite's recipe names — enters a script as a [`Text`]:
//!
//! - refused when it holds a control character ([`char::is_control`]: newline, carriage return,
//!   tab, escape, DEL, C1 controls) or, for a path, is not UTF-8 (the scripts are text);
//! - written quoted for whoever reads it: [`Text::sh`] for bash (single quotes, in which nothing
//!   is special but the quote itself), [`Text::sbatch`] for a `#SBATCH` line (double quotes, in
//!   which sbatch takes `\` as an escape and `#` as text).
//!
//! Everything else in a script is the farm's own text: fixed words, numbers and sample ranges.

use super::shell_quote;
use anyhow::{Result, anyhow, bail};
use std::path::Path;

/// A string that may go into a farm script: UTF-8 without control characters.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Text(String);

impl Text {
    /// `s`, given as `what` (e.g. `--render-arg`); refused if it holds a control character.
    pub fn new(s: &str, what: &str) -> Result<Text> {
        if let Some(c) = s.chars().find(|c| c.is_control()) {
            bail!(
                "{what} {}: contains {}: control characters are not allowed in names a farm \
                 script holds",
                s.escape_debug(),
                describe(c)
            );
        }
        Ok(Text(s.to_string()))
    }

    /// A path given as `what` (e.g. `the recipe`); refused if it is not UTF-8 or holds a control
    /// character.
    pub fn path(p: &Path, what: &str) -> Result<Text> {
        let s = p.to_str().ok_or_else(|| {
            anyhow!(
                "{what} {}: is not valid UTF-8: a farm script is text and cannot name it",
                p.display()
            )
        })?;
        Text::new(s, what)
    }

    /// The text itself.
    pub fn as_str(&self) -> &str {
        &self.0
    }

    /// Quoted for bash: one word, whatever it holds.
    pub fn sh(&self) -> String {
        shell_quote(&self.0)
    }

    /// Quoted for a `#SBATCH` line: one argument of sbatch's line parser (double quotes; `\` and
    /// `"` escaped with `\`, which that parser honours inside quotes too).
    pub fn sbatch(&self) -> String {
        format!("\"{}\"", self.0.replace('\\', "\\\\").replace('"', "\\\""))
    }

    /// This path as a Slurm file name pattern that names itself: `%` doubled (Slurm replaces
    /// `%j`, `%a`, … in `--output`). A backslash turns Slurm's patterns off altogether (so `%a`
    /// would not name the task either), and is refused.
    pub fn slurm_file(&self, what: &str) -> Result<Text> {
        if self.0.contains('\\') {
            bail!(
                "{what} {}: holds a backslash, which turns off Slurm's file name patterns (the \
                 `%a` of the log names): choose another folder",
                self.0
            );
        }
        Ok(Text(self.0.replace('%', "%%")))
    }

    /// A Slurm job name from this text: characters other than ASCII letters, digits, `.`, `_`
    /// and `-` become `_` (a job name shows in `squeue`, and needs no quoting anywhere).
    pub fn job_name(&self) -> Text {
        Text(
            self.0
                .chars()
                .map(|c| {
                    if c.is_ascii_alphanumeric() || "._-".contains(c) {
                        c
                    } else {
                        '_'
                    }
                })
                .collect(),
        )
    }
}

/// A control character by name and code point: `a newline (U+000A)`.
fn describe(c: char) -> String {
    let name = match c {
        '\n' => "a newline",
        '\r' => "a carriage return",
        '\t' => "a tab",
        '\u{1b}' => "an escape",
        '\0' => "a NUL",
        _ => "a control character",
    };
    format!("{name} (U+{:04X})", c as u32)
}

/// Whether a whole script is free of control characters but its line ends: the last guard
/// before a script is written (every piece of it came through [`Text`] or is the farm's own).
pub fn script_is_clean(script: &str) -> bool {
    !script.chars().any(|c| c.is_control() && c != '\n')
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_characters_are_refused_by_name() {
        let e = Text::new("a\nb.ron", "the recipe").unwrap_err().to_string();
        assert_eq!(
            e,
            "the recipe a\\nb.ron: contains a newline (U+000A): control characters are not \
             allowed in names a farm script holds"
        );
        for bad in ["\r", "\t", "\u{1b}[2J", "\u{7f}", "\u{85}", "\0"] {
            assert!(Text::new(bad, "x").is_err(), "{bad:?}");
        }
        assert!(Text::new("a b $c `d` 'e' \"f\" ;g", "x").is_ok());
        #[cfg(unix)]
        {
            use std::os::unix::ffi::OsStrExt;
            let p = Path::new(std::ffi::OsStr::from_bytes(b"a\xffb"));
            let e = Text::path(p, "--dir").unwrap_err().to_string();
            assert!(e.contains("is not valid UTF-8"), "{e}");
        }
    }

    #[test]
    fn sbatch_quoting_escapes_what_sbatch_reads() {
        let t = Text::new(r#"/a b/"c"\d#e'f"#, "x").unwrap();
        assert_eq!(t.sbatch(), r#""/a b/\"c\"\\d#e'f""#);
        assert_eq!(t.job_name().as_str(), "_a_b__c__d_e_f");
        let p = Text::new("/x/100%/logs", "x").unwrap();
        assert_eq!(p.slurm_file("--dir").unwrap().as_str(), "/x/100%%/logs");
        assert!(t.slurm_file("--dir").is_err());
        assert!(script_is_clean("#!/bin/bash\necho 'a'\n"));
        assert!(!script_is_clean("echo a\rb\n"));
    }
}
