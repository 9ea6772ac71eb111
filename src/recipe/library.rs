//! Material libraries: `materials/*.ron` files and the `materials` of a gem recipe, with their
//! `include`s resolved into one set of named layered stacks.
//!
//! ```ron
//! (
//!     include: ["course.ron"],   // optional: other libraries, relative to this file
//!     materials: { "name": (coats: [...], base: ...), ... },
//! )
//! ```
//!
//! Includes are loaded depth first, each file once (a file included twice by different routes is
//! the same file); a file that includes itself, directly or through others, is an error, as is a
//! missing or unreadable include and a material name defined twice.

use super::source::Source;
use super::{MaterialDesc, RecipeError, did_you_mean};
use crate::bsdf::{LayeredBsdf, Model, StackDesc};
use indexmap::IndexMap;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The built-in course catalogue (`materials/course.ron`), compiled into the binary.
pub const COURSE_CATALOGUE: &str = include_str!("../../materials/course.ron");

/// Most nested includes (a chain `a → b → c …` longer than this is an error).
pub const MAX_INCLUDE_DEPTH: usize = 16;

/// A material library file: `(include: [...], materials: { "name": (...), ... })`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialFile {
    /// Other library files whose materials this one uses, relative to this file.
    #[serde(default, deserialize_with = "super::ranged::includes")]
    pub include: Vec<String>,
    /// Materials in file order.
    #[serde(default, deserialize_with = "super::ranged::materials")]
    pub materials: IndexMap<String, MaterialDesc>,
}

/// A resolved material library: every material of a file and of the files it includes.
#[derive(Clone, Debug)]
pub struct MaterialLibrary {
    /// The root file first, then included files in load order.
    sources: Vec<Source>,
    /// Materials: the root's own first (file order), then included ones in load order, each with
    /// the index of the source that defines it.
    materials: IndexMap<String, (MaterialDesc, usize)>,
}

impl MaterialLibrary {
    /// Reads a library file and its includes; the first error, if any.
    pub fn load(path: &Path) -> Result<Self, RecipeError> {
        let (lib, errors) = Self::check(path);
        match errors.into_iter().next() {
            Some(e) => Err(e),
            None => Ok(lib.expect("no errors means a library")),
        }
    }

    /// Reads a library file and its includes, collecting every error found: values the parser
    /// refused (it goes on past them, [`super::source::recover`]), includes, every material. The
    /// library is `None` only when the root file cannot be read or the parser stopped in it.
    pub fn check(path: &Path) -> (Option<Self>, Vec<RecipeError>) {
        match Source::read(path) {
            Ok(source) => Self::check_source(source, Some(path)),
            Err(e) => (None, vec![e]),
        }
    }

    /// [`MaterialLibrary::check`] over text already in memory; includes are relative to `path`.
    pub fn check_source(source: Source, path: Option<&Path>) -> (Option<Self>, Vec<RecipeError>) {
        let mut errors = vec![];
        let lib = Self::from_source(source, path, &mut errors);
        (lib, errors)
    }

    /// The built-in course catalogue.
    pub fn course() -> Self {
        Self::parse("materials/course.ron", COURSE_CATALOGUE)
            .expect("the built-in catalogue parses (tested)")
    }

    /// Parses library text; `file` is used in messages and as the base of relative includes.
    pub fn parse(file: &str, text: &str) -> Result<Self, RecipeError> {
        let mut errors = vec![];
        let lib = Self::from_source(Source::new(file, text), Some(Path::new(file)), &mut errors);
        match errors.into_iter().next() {
            Some(e) => Err(e),
            None => Ok(lib.expect("no errors means a library")),
        }
    }

    fn from_source(
        source: Source,
        path: Option<&Path>,
        errors: &mut Vec<RecipeError>,
    ) -> Option<Self> {
        let (content, mut found) = super::ranged::parse::<MaterialFile>(&source);
        errors.append(&mut found);
        let content = content?;
        let lib = Self::assemble(source, path, content.include, content.materials, errors);
        lib.check_all(errors);
        Some(lib)
    }

    /// Builds a library from already-parsed root content (a gem recipe's `include` and
    /// `materials`), resolving includes relative to `path`. Errors are collected, not returned:
    /// the library holds whatever could be loaded.
    pub fn assemble(
        root: Source,
        path: Option<&Path>,
        include: Vec<String>,
        own: IndexMap<String, MaterialDesc>,
        errors: &mut Vec<RecipeError>,
    ) -> Self {
        let mut lib = MaterialLibrary {
            sources: vec![root],
            materials: own.into_iter().map(|(k, v)| (k, (v, 0))).collect(),
        };
        let mut chain: Vec<PathBuf> = path
            .and_then(|p| std::fs::canonicalize(p).ok())
            .into_iter()
            .collect();
        let mut loaded: Vec<PathBuf> = chain.clone();
        lib.include(0, path, &include, &mut chain, &mut loaded, errors);
        lib
    }

    /// Loads the `include` list of source `from` (whose file is `path`).
    fn include(
        &mut self,
        from: usize,
        path: Option<&Path>,
        include: &[String],
        chain: &mut Vec<PathBuf>,
        loaded: &mut Vec<PathBuf>,
        errors: &mut Vec<RecipeError>,
    ) {
        let base = path
            .and_then(Path::parent)
            .map(Path::to_path_buf)
            .unwrap_or_default();
        for name in include {
            let at = self.sources[from].find(&[&format!("{name:?}")]);
            let err = |m: String| self.sources[from].error(at, m);
            let target = base.join(name);
            let Ok(canonical) = std::fs::canonicalize(&target) else {
                errors.push(err(format!(
                    "include \"{name}\": no such file ({} relative to this file)",
                    target.display()
                )));
                continue;
            };
            if chain.contains(&canonical) {
                let cycle: Vec<String> = chain
                    .iter()
                    .chain(std::iter::once(&canonical))
                    .map(|p| p.display().to_string())
                    .collect();
                errors.push(err(format!(
                    "include \"{name}\" makes a cycle: {}",
                    cycle.join(" → ")
                )));
                continue;
            }
            if loaded.contains(&canonical) {
                continue; // Already loaded through another route: the same materials.
            }
            if chain.len() >= MAX_INCLUDE_DEPTH {
                errors.push(err(format!(
                    "include \"{name}\": includes nest deeper than {MAX_INCLUDE_DEPTH} files"
                )));
                continue;
            }
            loaded.push(canonical.clone());
            let source = match Source::read(&target) {
                Ok(s) => s,
                Err(e) => {
                    errors.push(err(format!("include \"{name}\": {e}")));
                    continue;
                }
            };
            let (content, mut found) = super::ranged::parse::<MaterialFile>(&source);
            errors.append(&mut found);
            let Some(content) = content else {
                continue;
            };
            self.sources.push(source);
            let index = self.sources.len() - 1;
            chain.push(canonical);
            self.include(
                index,
                Some(&target),
                &content.include,
                chain,
                loaded,
                errors,
            );
            chain.pop();
            for (key, desc) in content.materials {
                if self.materials.len() >= super::ranged::MAX_MATERIALS
                    && !self.materials.contains_key(&key)
                {
                    errors.push(self.sources[from].error(at, format!(
                        "include \"{name}\": more than {max} materials with the files before it; \
                         at most {max} in all",
                        max = super::ranged::MAX_MATERIALS
                    )));
                    break;
                }
                if let Some((_, earlier)) = self.materials.get(&key) {
                    let first = &self.sources[*earlier];
                    let (line, col) = first.key(&key).map_or((0, 0), |p| first.line_col(p));
                    let here = &self.sources[index];
                    errors.push(here.error(
                        here.key(&key),
                        format!(
                            "material \"{key}\" is already defined at {}:{line}:{col}; names must be unique across includes",
                            first.file
                        ),
                    ));
                } else {
                    self.materials.insert(key, (desc, index));
                }
            }
        }
    }

    /// Checks every material, pushing one error per bad material.
    pub(crate) fn check_all(&self, errors: &mut Vec<RecipeError>) {
        for name in self.materials.keys() {
            if let Err(e) = self.stack(name) {
                errors.push(e);
            }
        }
    }

    /// Material names: the root file's own in file order, then included ones.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.materials.keys().map(String::as_str)
    }

    /// The name of material `index` (in the order of [`MaterialLibrary::names`]).
    pub fn name_at(&self, index: usize) -> Option<&str> {
        self.materials.get_index(index).map(|(k, _)| k.as_str())
    }

    /// Number of materials.
    pub fn len(&self) -> usize {
        self.materials.len()
    }

    /// Whether the library is empty.
    pub fn is_empty(&self) -> bool {
        self.materials.is_empty()
    }

    /// The files read: the root first, then included ones in load order.
    pub fn sources(&self) -> &[Source] {
        &self.sources
    }

    /// The root file's name.
    pub fn file(&self) -> &str {
        &self.sources[0].file
    }

    /// The file that defines material `name`.
    pub fn file_of(&self, name: &str) -> Option<&str> {
        self.materials
            .get(name)
            .map(|(_, s)| self.sources[*s].file.as_str())
    }

    /// Where material `name` is defined, as `file:line:col`.
    pub fn position_of(&self, name: &str) -> Option<String> {
        let (_, s) = self.materials.get(name)?;
        let source = &self.sources[*s];
        let (line, col) = source.key(name).map_or((0, 0), |p| source.line_col(p));
        Some(format!("{}:{line}:{col}", source.file))
    }

    /// The index of `name` (root materials first, then included ones), if defined.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.materials.get_index_of(name)
    }

    /// The description of `name`, or an error with the closest known name.
    pub fn get(&self, name: &str) -> Result<&MaterialDesc, RecipeError> {
        match self.materials.get(name) {
            Some((desc, _)) => Ok(desc),
            None => Err(self.sources[0].error(None, self.unknown(name))),
        }
    }

    /// "unknown material …" with a did-you-mean and the known names.
    pub fn unknown(&self, name: &str) -> String {
        self.unknown_hinted(name, true)
    }

    /// "unknown material …" with the known names, and a did-you-mean when `hint` (finding the
    /// closest name costs a comparison with every name: callers reporting many unknown names
    /// hint only the first few, so a file's check stays linear in its size).
    pub fn unknown_hinted(&self, name: &str, hint: bool) -> String {
        let hint = hint
            .then(|| did_you_mean(name, self.names()))
            .flatten()
            .map(|s| format!(" (did you mean \"{s}\"?)"))
            .unwrap_or_default();
        let mut known: Vec<&str> = self.names().take(24).collect();
        if self.len() > known.len() {
            known.push("…");
        }
        format!(
            "unknown material \"{name}\"{hint}; known: {}",
            known.join(", ")
        )
    }

    /// Validates `name` and returns its runtime description.
    pub fn stack(&self, name: &str) -> Result<StackDesc, RecipeError> {
        let desc = self.get(name)?;
        let stack = desc.to_stack().map_err(|m| self.error_at(name, &m))?;
        crate::bsdf::layered::validate(&stack).map_err(|e| self.error_at(name, &e.to_string()))?;
        Ok(stack)
    }

    /// Builds `name` into a runtime stack, optionally under another model than the file says.
    pub fn build(&self, name: &str, model: Option<Model>) -> Result<LayeredBsdf, RecipeError> {
        let mut stack = self.stack(name)?;
        if let Some(m) = model {
            stack.model = m;
        }
        LayeredBsdf::new(&stack).map_err(|e| self.error_at(name, &e.to_string()))
    }

    /// An error located at the field a message names (`coats[1].ior …`), inside material `name`,
    /// in the file that defines it.
    fn error_at(&self, name: &str, message: &str) -> RecipeError {
        let source = self
            .materials
            .get(name)
            .map_or(&self.sources[0], |(_, s)| &self.sources[*s]);
        source.error(
            source.locate_field(name, message),
            format!("material \"{name}\": {message}"),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn catalogue_parses_and_builds() {
        let lib = MaterialLibrary::course();
        let names: Vec<_> = lib.names().collect();
        assert_eq!(names.len(), 11);
        for n in names {
            lib.build(n, None).unwrap_or_else(|e| panic!("{e}"));
        }
    }

    #[test]
    fn errors_have_positions() {
        let src = "(materials: {\n  \"a\": (\n    coats: [(ior: 1.5, roughness: 3.0), (ior: 0.5, roughness: 3.0)],\n    base: Lambert(albedo: Gray(0.5)),\n  ),\n})";
        let e = MaterialLibrary::parse("x.ron", src).unwrap_err();
        assert_eq!((e.line, e.col), (3, 42), "{e}");
        assert!(
            e.message.contains("coats[1].ior") && e.message.contains("1.0001"),
            "{e}"
        );

        let e = MaterialLibrary::parse(
            "x.ron",
            "(materials: { \"a\": (base: Lambert(albedo: Gray(0.5)), colour: 1) })",
        )
        .unwrap_err();
        assert!(e.line == 1 && e.message.contains("colour"), "{e}");

        let lib = MaterialLibrary::course();
        let e = lib.get("sugarr").unwrap_err();
        assert!(e.message.contains("did you mean \"sugar\""), "{e}");
    }

    #[test]
    fn includes_resolve_and_report_cycles_missing_files_and_duplicates() {
        let dir = std::env::temp_dir().join(format!("lapidary-lib-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        let write = |name: &str, text: &str| std::fs::write(dir.join(name), text).unwrap();
        write(
            "a.ron",
            "(include: [\"sub/b.ron\"], materials: { \"a\": (base: Lambert(albedo: Gray(0.5))) })",
        );
        write(
            "sub/b.ron",
            "(include: [\"../a.ron\", \"c.ron\"], materials: { \"b\": (base: Lambert(albedo: Gray(0.2))) })",
        );
        let (lib, errors) = MaterialLibrary::check(&dir.join("a.ron"));
        let lib = lib.unwrap();
        assert_eq!(lib.names().collect::<Vec<_>>(), ["a", "b"]);
        assert!(lib.file_of("b").unwrap().ends_with("b.ron"));
        assert_eq!(errors.len(), 2, "{errors:?}");
        assert!(
            errors[0].message.contains("cycle") && errors[0].line == 1,
            "{}",
            errors[0]
        );
        assert!(
            errors[0].file.ends_with("b.ron") && errors[0].col == 12,
            "{}",
            errors[0]
        );
        assert!(errors[1].message.contains("no such file"), "{}", errors[1]);

        write(
            "d.ron",
            "(include: [\"a.ron\"],\n materials: { \"b\": (base: Lambert(albedo: Gray(0.5))) })",
        );
        let (_, errors) = MaterialLibrary::check(&dir.join("d.ron"));
        let dup = errors
            .iter()
            .find(|e| e.message.contains("already defined"))
            .expect("duplicate reported");
        assert!(
            dup.file.ends_with("b.ron") && dup.message.contains("d.ron:2:"),
            "{dup}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
