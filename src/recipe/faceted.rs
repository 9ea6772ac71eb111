//! Resolves a faceted shape: a parametric cut into its half-spaces, a GemCad `.asc` design read
//! from its file (errors positioned at the `.asc` line and column).

use super::RecipeError;
use super::cut::CutDesc;
use super::gem::GemRecipe;
use crate::cut::asc::{Design, decode};
use crate::scene::stage::Shape;
use std::path::Path;
use std::sync::Arc;

/// Largest `.asc` file read (designs are a few kilobytes).
const MAX_ASC_BYTES: u64 = 1 << 20;

/// The shape of `shape: Cut(…)`, or `None` after pushing an error at the `Cut`.
pub(super) fn cut(r: &GemRecipe, desc: &CutDesc, errors: &mut Vec<RecipeError>) -> Option<Shape> {
    let (cut, width) = desc.to_cut();
    match cut.facets(width) {
        Ok(f) => Some(Shape::Faceted(Arc::new(f))),
        Err(e) => {
            let at = r.source.find(&["Cut", "("]);
            errors.push(r.source.error(at, format!("shape: Cut: {e}")));
            None
        }
    }
}

/// The shape of `shape: Design(file: …)` read from `path` (`name` as the recipe writes it), or
/// `None` after pushing an error (at the `.asc` position for a broken design).
pub(super) fn design(
    r: &GemRecipe,
    path: &Path,
    name: &str,
    width: f32,
    errors: &mut Vec<RecipeError>,
) -> Option<Shape> {
    let at = r.source.find(&[&format!("{name:?}")]);
    let bytes = match std::fs::metadata(path) {
        Ok(m) if m.len() > MAX_ASC_BYTES => {
            errors.push(r.source.error(
                at,
                format!(
                    "design \"{name}\": {} bytes, at most {MAX_ASC_BYTES}",
                    m.len()
                ),
            ));
            return None;
        }
        _ => match std::fs::read(path) {
            Ok(b) => b,
            Err(e) => {
                errors.push(r.source.error(at, format!("design \"{name}\": {e}")));
                return None;
            }
        },
    };
    let design = match Design::parse(&decode(&bytes)) {
        Ok(d) => d,
        Err(e) => {
            errors.push(RecipeError {
                file: path.display().to_string(),
                line: e.line,
                col: e.col,
                message: e.message,
            });
            return None;
        }
    };
    let label = format!("GemCad design {name}");
    match crate::cut::design_facets(&design, f64::from(width), label) {
        Ok(f) => Some(Shape::Faceted(Arc::new(f))),
        Err(e) => {
            errors.push(r.source.error(at, format!("design \"{name}\": {e}")));
            None
        }
    }
}
