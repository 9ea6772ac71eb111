//! The files a recipe reads, watched for saves: `notify` reports changes in their folders at
//! once, and the worker also compares their modification times and sizes when idle (a fallback
//! for file systems where notifications do not arrive, such as network mounts).

use crate::recipe::GemRecipe;
use std::path::{Path, PathBuf};
use std::time::SystemTime;

/// Most files watched (a recipe with more inputs is watched on its first ones).
pub const MAX_INPUTS: usize = 256;

/// One watched file and what it looked like when read.
#[derive(Clone, Debug, PartialEq)]
struct Stamp {
    path: PathBuf,
    seen: Option<(SystemTime, u64)>,
}

/// The watched files.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Inputs {
    files: Vec<Stamp>,
}

fn stamp(path: &Path) -> Option<(SystemTime, u64)> {
    let m = std::fs::metadata(path).ok()?;
    Some((m.modified().ok()?, m.len()))
}

impl Inputs {
    /// The recipe alone (before it could be read).
    pub fn of_recipe(recipe: &Path) -> Inputs {
        Inputs::of_paths(vec![recipe.to_path_buf()])
    }

    /// The recipe and every file it reads: included libraries, the mesh, the environment map,
    /// and the spectrum files its texts name (quoted `.csv` names, relative to the recipe).
    pub fn of_loaded(recipe: &Path, loaded: &GemRecipe) -> Inputs {
        let mut paths = vec![recipe.to_path_buf()];
        paths.extend(
            crate::cli::load::recipe_inputs(loaded)
                .into_iter()
                .map(|(p, _)| p),
        );
        let base = loaded.base_dir();
        for source in loaded.library.sources() {
            for name in quoted_csv(&source.text) {
                paths.push(base.join(name));
            }
        }
        Inputs::of_paths(paths)
    }

    fn of_paths(mut paths: Vec<PathBuf>) -> Inputs {
        paths.dedup();
        paths.truncate(MAX_INPUTS);
        Inputs {
            files: paths
                .into_iter()
                .map(|path| Stamp {
                    seen: stamp(&path),
                    path,
                })
                .collect(),
        }
    }

    /// Whether any file changed since it was read or last compared (and remembers the new
    /// stamps).
    pub fn changed_on_disk(&mut self) -> bool {
        let mut changed = false;
        for f in &mut self.files {
            let now = stamp(&f.path);
            if now != f.seen {
                f.seen = now;
                changed = true;
            }
        }
        changed
    }

    /// Whether any file differs from its stamp now (the stamps are left as they are).
    pub fn differ_on_disk(&self) -> bool {
        self.files.iter().any(|f| stamp(&f.path) != f.seen)
    }

    /// Whether `path` (as an event reports it) is one of the files.
    pub fn contains(&self, path: &Path) -> bool {
        let name = path.file_name();
        self.files.iter().any(|f| {
            f.path.file_name() == name
                && match (f.path.canonicalize(), path.canonicalize()) {
                    (Ok(a), Ok(b)) => a == b,
                    // A file removed or renamed away: compare the folders.
                    _ => same_dir(&f.path, path),
                }
        })
    }

    /// The files.
    pub fn paths(&self) -> Vec<PathBuf> {
        self.files.iter().map(|f| f.path.clone()).collect()
    }

    /// The folders to watch.
    pub fn dirs(&self) -> Vec<PathBuf> {
        let mut dirs: Vec<PathBuf> = self
            .files
            .iter()
            .map(|f| match f.path.parent() {
                Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
                _ => PathBuf::from("."),
            })
            .collect();
        dirs.sort();
        dirs.dedup();
        dirs
    }
}

fn same_dir(a: &Path, b: &Path) -> bool {
    let dir = |p: &Path| {
        let d = p.parent().filter(|d| !d.as_os_str().is_empty());
        d.unwrap_or(Path::new(".")).canonicalize().ok()
    };
    dir(a).is_some() && dir(a) == dir(b)
}

/// The quoted strings ending in `.csv` in a recipe's text.
fn quoted_csv(text: &str) -> Vec<&str> {
    text.split('"')
        .skip(1)
        .step_by(2)
        .filter(|s| s.len() > 4 && s.to_ascii_lowercase().ends_with(".csv") && !s.contains('\n'))
        .collect()
}

/// Watches the folders of `now` that `before` did not have.
pub fn rewatch(watcher: &mut notify::RecommendedWatcher, before: &Inputs, now: &Inputs) {
    use notify::Watcher;
    let old = before.dirs();
    for dir in now.dirs().into_iter().filter(|d| !old.contains(d)) {
        let _ = watcher.watch(&dir, notify::RecursiveMode::NonRecursive);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_quoted_spectrum_files() {
        let text = r#"(absorption_spectrum: (file: "spectra/a.csv", scale: 2), name: "x.CSV", b: "no.csv
        ")"#;
        assert_eq!(quoted_csv(text), vec!["spectra/a.csv", "x.CSV"]);
    }

    #[test]
    fn notices_a_changed_file() {
        let dir = std::env::temp_dir().join(format!("lapidary-watch-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("r.ron");
        std::fs::write(&f, "a").unwrap();
        let mut inputs = Inputs::of_recipe(&f);
        assert!(!inputs.changed_on_disk());
        std::fs::write(&f, "ab").unwrap();
        assert!(inputs.changed_on_disk());
        assert!(!inputs.changed_on_disk());
        assert!(inputs.contains(&dir.join("r.ron")));
        assert!(!inputs.contains(&dir.join("s.ron")));
        assert_eq!(inputs.dirs(), vec![dir.clone()]);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
