//! The description layer: what users write (RON, serde, `deny_unknown_fields`), kept apart from
//! the runtime tables it compiles into.
//!
//! Material libraries (`materials/*.ron`: names → layered stacks, with includes), gem recipes
//! (`gems/*.ron`: materials, the surface map tree, an optional stage) and the checks that turn them
//! into runtime [`crate::scene`] tables. Every error names `file:line:col`, what is wrong and, for
//! numbers, the allowed range; no input makes it panic (a fuzz target feeds it random bytes). A
//! number out of range does not stop the parser ([`source::recover`]), so one check reports every
//! error it can find.

#[macro_use]
mod ranged;
pub mod body;
mod body_compiler;
pub mod color;
mod compile;
pub mod crystal;
pub mod cut;
pub mod dispersion;
mod faceted;
pub mod fluorescence;
pub mod gem;
pub mod library;
mod map_compiler;
pub mod material;
mod platelet_compiler;
pub mod platelets;
pub mod pleochroism;
pub mod render_desc;
mod resolve;
mod shape;
pub mod source;
pub mod spectrum;
pub mod stage;
pub mod surface;

pub use body::{BodyDesc, MediumDesc, PhaseDesc};
pub use compile::Report;
pub use gem::{GemDesc, GemRecipe};
pub use library::{COURSE_CATALOGUE, MaterialFile, MaterialLibrary};
pub use material::{BaseDesc, CoatDesc, MaterialDesc, MetalDesc, ModelDesc};
pub use source::Source;
pub use stage::StageDesc;
use std::fmt;
pub use surface::{BumpDesc, FieldDesc, MapDesc, SwitchDesc};

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

/// RON options shared by every description file: optional fields are written without `Some(..)`,
/// and a variant wrapping a struct is written `Switch(by: …)` rather than `Switch((by: …))`.
pub fn ron_options() -> ron::Options {
    use ron::extensions::Extensions;
    ron::Options::default()
        .with_default_extension(Extensions::IMPLICIT_SOME | Extensions::UNWRAP_VARIANT_NEWTYPES)
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

/// Runs `text` through everything a description file goes through — checked as a gem recipe
/// (parse, includes relative to the working directory, every material, compile, stage) and parsed
/// as a material library — then looks a point up in the compiled scene and compiles it a second
/// time. Returns whether a scene came out. Any panic here is a bug: this is what the fuzz target
/// (`fuzz/`) and the seeded fuzz test (`tests/fuzz_recipes.rs`) run on their inputs.
pub fn exercise(text: &str) -> bool {
    let report = GemRecipe::check_source(Source::new("fuzz.ron", text), None);
    let _ = MaterialLibrary::parse("fuzz.ron", text);
    let Some(scene) = report.scene else {
        return false;
    };
    let hit = scene
        .surface
        .map
        .lookup(glam::Vec3::new(0.3, 0.1, -0.2), 0.5);
    // The leaves: the materials, then `Body` when the recipe has a body.
    let leaves = scene.surface.leaf_names().len();
    assert!(
        (hit.material as usize) < leaves,
        "material index {} out of {leaves} map leaves",
        hit.material
    );
    let again = GemRecipe::check_source(Source::new("fuzz.ron", text), None);
    assert_eq!(
        again.scene.as_ref(),
        Some(&scene),
        "compiling twice differs"
    );
    true
}
