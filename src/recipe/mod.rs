//! The description layer: what users write (RON, serde, `deny_unknown_fields`), kept apart from
//! the runtime tables it compiles into.
//!
//! Today this holds material libraries (`materials/*.ron`: a map from names to layered stacks);
//! gem recipes (surface maps, stages) extend it. Every error names `file:line:col`, what is wrong
//! and, for numbers, the allowed range; no input makes it panic.

pub mod color;
pub mod gem;
pub mod material;
pub mod surface;

use crate::bsdf::{LayeredBsdf, Model};
pub use gem::{GemDesc, GemRecipe};
use indexmap::IndexMap;
pub use material::{BaseDesc, CoatDesc, MaterialDesc, MetalDesc, ModelDesc};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::Path;
pub use surface::{BumpDesc, FieldDesc, MapDesc, SwitchDesc};

/// The built-in course catalogue (`materials/course.ron`), compiled into the binary.
pub const COURSE_CATALOGUE: &str = include_str!("../../materials/course.ron");

/// An error in a description file, with its position.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub struct RecipeError {
    /// File name as given.
    pub file: String,
    /// 1-based line (0 when unknown).
    pub line: usize,
    /// 1-based column (0 when unknown).
    pub col: usize,
    /// What is wrong, and the allowed range where there is one.
    pub message: String,
}

impl fmt::Display for RecipeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line > 0 {
            write!(
                f,
                "{}:{}:{}: {}",
                self.file, self.line, self.col, self.message
            )
        } else {
            write!(f, "{}: {}", self.file, self.message)
        }
    }
}

/// A material library file: `(materials: { "name": (...), ... })`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialFile {
    /// Materials in file order.
    pub materials: IndexMap<String, MaterialDesc>,
}

/// A parsed material library together with its source (for error positions).
#[derive(Clone, Debug)]
pub struct MaterialLibrary {
    file: String,
    source: String,
    /// The parsed content.
    pub content: MaterialFile,
}

impl MaterialLibrary {
    /// Reads and parses a library file.
    pub fn load(path: &Path) -> Result<Self, RecipeError> {
        let (file, source) = read_source(path)?;
        Self::parse(&file, &source)
    }

    /// The built-in course catalogue.
    pub fn course() -> Self {
        Self::parse("materials/course.ron", COURSE_CATALOGUE)
            .expect("the built-in catalogue parses (tested)")
    }

    /// A library over already-parsed content whose positions refer to `source` (a gem recipe's
    /// `materials` section). Not validated: call [`MaterialLibrary::stack`] per name.
    pub fn from_parts(file: &str, source: &str, content: MaterialFile) -> Self {
        MaterialLibrary {
            file: file.to_string(),
            source: source.to_string(),
            content,
        }
    }

    /// Parses library text; `file` is used in messages.
    pub fn parse(file: &str, source: &str) -> Result<Self, RecipeError> {
        let content: MaterialFile = ron_options().from_str(source).map_err(|e| RecipeError {
            file: file.to_string(),
            line: e.span.start.line,
            col: e.span.start.col,
            message: e.code.to_string(),
        })?;
        let lib = MaterialLibrary {
            file: file.to_string(),
            source: source.to_string(),
            content,
        };
        for name in lib.content.materials.keys() {
            lib.stack(name)?;
        }
        Ok(lib)
    }

    /// Material names in file order.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.content.materials.keys().map(String::as_str)
    }

    /// The file name used in messages.
    pub fn file(&self) -> &str {
        &self.file
    }

    /// The description of `name`, or an error with the closest known name.
    pub fn get(&self, name: &str) -> Result<&MaterialDesc, RecipeError> {
        self.content.materials.get(name).ok_or_else(|| {
            let hint = did_you_mean(name, self.names())
                .map(|s| format!(" (did you mean \"{s}\"?)"))
                .unwrap_or_default();
            RecipeError {
                file: self.file.clone(),
                line: 0,
                col: 0,
                message: format!(
                    "unknown material \"{name}\"{hint}; known: {}",
                    self.names().collect::<Vec<_>>().join(", ")
                ),
            }
        })
    }

    /// Validates `name` and returns its runtime description.
    pub fn stack(&self, name: &str) -> Result<crate::bsdf::StackDesc, RecipeError> {
        let desc = self.get(name)?;
        let stack = desc.to_stack().map_err(|m| self.error_at(name, &m))?;
        // Range checks without building tables.
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

    /// An error located at the field a message names (`coats[1].ior …`), inside material `name`.
    fn error_at(&self, name: &str, message: &str) -> RecipeError {
        let (line, col) = locate(&self.source, name, message);
        RecipeError {
            file: self.file.clone(),
            line,
            col,
            message: format!("material \"{name}\": {message}"),
        }
    }
}

/// Reads a description file: its name for messages and its text, or an error naming the file.
pub fn read_source(path: &Path) -> Result<(String, String), RecipeError> {
    let file = path.display().to_string();
    let source = std::fs::read_to_string(path).map_err(|e| RecipeError {
        file: file.clone(),
        line: 0,
        col: 0,
        message: format!("cannot read the file: {e}"),
    })?;
    Ok((file, source))
}

/// RON options shared by every description file: optional fields are written without `Some(..)`,
/// and a variant wrapping a struct is written `Switch(by: …)` rather than `Switch((by: …))`.
pub fn ron_options() -> ron::Options {
    use ron::extensions::Extensions;
    ron::Options::default()
        .with_default_extension(Extensions::IMPLICIT_SOME | Extensions::UNWRAP_VARIANT_NEWTYPES)
}

/// Finds the position of the field a message starts with (e.g. `coats[1].ior`) within material
/// `name`; falls back to the material's key, then to unknown (0, 0).
fn locate(source: &str, name: &str, message: &str) -> (usize, usize) {
    let Some(key) = source.find(&format!("\"{name}\"")) else {
        return (0, 0);
    };
    let mut pos = key;
    let path = message.split([' ', ':']).next().unwrap_or("");
    for seg in path.split('.') {
        let (field, index) = match seg.split_once('[') {
            Some((f, rest)) => (f, rest.trim_end_matches(']').parse::<usize>().ok()),
            None => (seg, None),
        };
        if field.is_empty() || !field.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            break;
        }
        let Some(p) = find_token(source, pos, field) else {
            break;
        };
        pos = p;
        if let Some(i) = index {
            // Skip to the i-th element: elements of coats are parenthesised tuples.
            let mut depth = 0i32;
            let mut count = 0usize;
            for (off, ch) in source[pos..].char_indices() {
                match ch {
                    '(' | '[' | '{' => {
                        depth += 1;
                        if depth == 2 && ch == '(' {
                            if count == i {
                                pos += off;
                                break;
                            }
                            count += 1;
                        }
                    }
                    ')' | ']' | '}' => {
                        depth -= 1;
                        if depth <= 0 {
                            break;
                        }
                    }
                    _ => {}
                }
            }
        }
    }
    line_col(source, pos)
}

fn find_token(source: &str, from: usize, token: &str) -> Option<usize> {
    let mut start = from;
    while let Some(off) = source[start..].find(token) {
        let p = start + off;
        let before = source[..p].chars().next_back();
        let after = source[p + token.len()..].chars().next();
        let boundary = |c: Option<char>| c.is_none_or(|c| !(c.is_ascii_alphanumeric() || c == '_'));
        if boundary(before) && boundary(after) {
            return Some(p);
        }
        start = p + token.len();
    }
    None
}

pub(crate) fn line_col(source: &str, pos: usize) -> (usize, usize) {
    let before = &source[..pos.min(source.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

/// The known name closest to `name` by edit distance, if any is reasonably close.
pub fn did_you_mean<'a>(name: &str, known: impl Iterator<Item = &'a str>) -> Option<&'a str> {
    let dist = |a: &str, b: &str| {
        let b: Vec<char> = b.chars().collect();
        let mut prev: Vec<usize> = (0..=b.len()).collect();
        for (i, ca) in a.chars().enumerate() {
            let mut cur = vec![i + 1; b.len() + 1];
            for (j, &cb) in b.iter().enumerate() {
                cur[j + 1] = (prev[j] + usize::from(ca != cb))
                    .min(prev[j + 1] + 1)
                    .min(cur[j] + 1);
            }
            prev = cur;
        }
        prev[b.len()]
    };
    known
        .map(|k| (dist(name, k), k))
        .filter(|(d, k)| *d <= (k.len() / 3).max(2))
        .min_by_key(|(d, _)| *d)
        .map(|(_, k)| k)
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
}
