//! A gem recipe (`gems/*.ron`): materials (own and included), optional named `maps`, the
//! `surface` map tree, an optional `stage`; and its compilation into a runtime [`Scene`].
//!
//! ```ron
//! (
//!     seed: 0,                                  // optional: re-rolls every default seed
//!     include: ["../materials/course.ron"],     // optional: material libraries
//!     materials: { "name": (coats: [...], base: ...), ... },
//!     maps: { "tiles": Voronoi(...), ... },     // optional: sub-maps used as Map("tiles")
//!     body: (ior: 1.52, medium: (...)),         // optional: a translucent body (`body.rs`)
//!     surface: Overlay(under: ..., over: ...),  // the tree (see `surface.rs`)
//!     stage: (camera: ..., render: (...)),      // optional: replaces parts of the studio stage
//! )
//! ```
//!
//! Compiling a recipe and looking up its surface:
//!
//! ```
//! use lapidary::recipe::GemRecipe;
//! use lapidary::scene::Effect;
//! let recipe = GemRecipe::parse("inline.ron", r#"(
//!     materials: {
//!         "body": (coats: [(ior: 1.58, roughness: 0.5)], base: Lambert(albedo: Gray(0.6))),
//!         "flake": (base: Conductor(metal: Copper, roughness: 3.0)),
//!     },
//!     surface: Overlay(
//!         under: Material("body"),
//!         over: Voronoi(scale: 0.05, fill: 0.1, entries: [(1.0, Material("flake"))],
//!                       bump: Beckmann(rms: 10.0)),
//!     ),
//! )"#)?;
//! let scene = recipe.compile()?;
//! let hit = scene.surface.map.lookup(glam::Vec3::new(0.1, 0.2, 0.3), 0.5);
//! let name = &scene.surface.names[hit.material as usize];
//! // Flakes carry a tilted facet normal; the body does not.
//! assert_eq!(hit.facet.is_some(), name == "flake");
//! // The scene turns on what it uses, and nothing else.
//! assert!(scene.effects.on(Effect::FacetBump) && !scene.effects.on(Effect::Absorption));
//! # Ok::<(), lapidary::recipe::RecipeError>(())
//! ```

use super::body::BodyDesc;
use super::source::Source;
use super::stage::StageDesc;
use super::surface::MapDesc;
use super::{MaterialDesc, MaterialLibrary, RecipeError};
use indexmap::IndexMap;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// What a gem recipe file holds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GemDesc {
    /// Recipe seed (default 0): every default Voronoi and noise seed derives from it.
    #[serde(default, deserialize_with = "super::ranged::any_seed")]
    pub seed: u64,
    /// Material libraries whose materials the tree may use, relative to this file.
    #[serde(default, deserialize_with = "super::ranged::includes")]
    pub include: Vec<String>,
    /// The recipe's own layered materials by name, in file order (at most 100 000).
    #[serde(default, deserialize_with = "super::ranged::materials")]
    pub materials: IndexMap<String, MaterialDesc>,
    /// Named sub-maps, usable as `Map("name")` anywhere in the tree.
    #[serde(default, deserialize_with = "super::ranged::named_maps")]
    pub maps: IndexMap<String, MapDesc>,
    /// A translucent body (issue 17): the boundary and the interior that `Body` leaves of the
    /// surface show ([`BodyDesc`]). Without it the stone is opaque.
    #[serde(default)]
    pub body: Option<BodyDesc>,
    /// The surface map tree.
    pub surface: MapDesc,
    /// Parts of the studio stage to replace.
    #[serde(default)]
    pub stage: Option<StageDesc>,
}

/// A parsed gem recipe with its source text (for error positions) and its resolved materials.
#[derive(Clone, Debug)]
pub struct GemRecipe {
    pub(crate) source: Source,
    pub(crate) path: Option<PathBuf>,
    /// The parsed content.
    pub content: GemDesc,
    /// Own and included materials.
    pub library: MaterialLibrary,
}

impl GemRecipe {
    /// Reads and parses a recipe file and its includes (materials validated, tree not yet
    /// compiled); the first error, if any.
    pub fn load(path: &Path) -> Result<Self, RecipeError> {
        let source = Source::read(path)?;
        first_error(Self::read(source, Some(path)))
    }

    /// Parses recipe text; `file` is used in messages and as the base of relative paths.
    pub fn parse(file: &str, text: &str) -> Result<Self, RecipeError> {
        first_error(Self::read(Source::new(file, text), Some(Path::new(file))))
    }

    /// Parses and resolves includes, collecting every error: the parser's (which go on past a
    /// value out of range, with a stand-in), then the includes' and the materials'. The recipe is
    /// `None` only when the parser stopped.
    pub(super) fn read(source: Source, path: Option<&Path>) -> (Option<Self>, Vec<RecipeError>) {
        let (content, mut errors) = super::ranged::parse::<GemDesc>(&source);
        let Some(content) = content else {
            return (None, errors);
        };
        let library = MaterialLibrary::assemble(
            source.clone(),
            path,
            content.include.clone(),
            content.materials.clone(),
            &mut errors,
        );
        library.check_all(&mut errors);
        let recipe = GemRecipe {
            source,
            path: path.map(Path::to_path_buf),
            content,
            library,
        };
        (Some(recipe), errors)
    }

    /// The file name used in messages.
    pub fn file(&self) -> &str {
        &self.source.file
    }

    /// The directory relative paths (includes, meshes, environment maps) start from.
    pub fn base_dir(&self) -> PathBuf {
        self.path
            .as_deref()
            .and_then(Path::parent)
            .map(Path::to_path_buf)
            .unwrap_or_default()
    }
}

fn first_error<T>((value, errors): (Option<T>, Vec<RecipeError>)) -> Result<T, RecipeError> {
    match errors.into_iter().next() {
        Some(e) => Err(e),
        None => Ok(value.expect("no errors means a value")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn gem(name: &str) -> GemRecipe {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("gems")
            .join(name);
        GemRecipe::load(&path).unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn shipped_gems_compile_and_use_every_material() {
        for (name, materials, depth) in [
            ("lepidolite.ron", 20, 3),
            ("sunstone.ron", 5, 1),
            ("sunstone-pink.ron", 4, 1),
            ("sunstone-patterned.ron", 4, 1),
            ("green-aventurine.ron", 12, 2),
            ("raspberry-aventurine.ron", 12, 2),
            ("aventurine-glass.ron", 6, 1),
            ("oregon-sunstone.ron", 1, 0),
        ] {
            let s = gem(name)
                .compile()
                .unwrap_or_else(|e| panic!("{e}"))
                .surface;
            assert_eq!(s.names.len(), materials, "{name}");
            assert_eq!(
                s.unused().count(),
                0,
                "{name}: {:?}",
                s.unused().collect::<Vec<_>>()
            );
            assert_eq!(s.map.max_trail(s.map.root), depth, "{name}");
            let hit = s.map.lookup(Vec3::new(0.1, 0.2, 0.3), 0.5);
            // A stack, or `Body` (one past the last stack).
            assert!(
                (hit.material as usize) < materials || hit.material == s.body_index(),
                "{name}: {} of {materials}: {:?}",
                hit.material,
                s.names
            );
        }
    }

    fn err(src: &str) -> RecipeError {
        let e = GemRecipe::parse("g.ron", src).and_then(|g| g.compile());
        e.expect_err("must fail")
    }

    const MATS: &str = r#"materials: { "a": (base: Lambert(albedo: Gray(0.5))), "b": (base: Lambert(albedo: Gray(0.2))) },"#;

    #[test]
    fn errors_point_at_the_problem() {
        let e = err(&format!(
            "({MATS}\n surface: Material(\"a\"),\n stage: (render: (manifold_halvings: 9)))"
        ));
        assert_eq!(e.line, 3, "{e}");
        assert!(
            e.message.contains("manifold_halvings = 9") && e.message.contains("0 ..= 8"),
            "{e}"
        );

        let e = err(&format!(
            "({MATS}\n surface: Voronoi(scale: 0.1,\n   fill: 1.5, entries: [(1.0, Material(\"a\"))]))"
        ));
        assert_eq!((e.line, e.col), (3, 10), "{e}");
        assert!(
            e.message.contains("fill = 1.5") && e.message.contains("0 ..= 1"),
            "{e}"
        );

        let e = err(&format!(
            "({MATS}\n surface: Voronoi(scale: 0.1, entries: [(1.0, Material(\"b\")),\n (2.0, Material(\"aa\"))]))"
        ));
        assert_eq!((e.line, e.col), (3, 8), "{e}");
        assert!(
            e.message.contains("unknown material \"aa\"")
                && e.message.contains("did you mean \"a\""),
            "{e}"
        );

        let e = err(&format!(
            "({MATS}\n surface: Voronoi(scale: 0.1, fill: 0.5, entries: [(1.0, Material(\"a\"))]))"
        ));
        assert!(e.message.contains("transparent") && e.line == 2, "{e}");

        let e = err(&format!(
            "({MATS}\n surface: Voronoi(scale: 0.1, entries: [(-1.0, Material(\"a\"))]))"
        ));
        assert!(e.message.contains("weight = -1") && e.line == 2, "{e}");

        let e = err(&format!(
            "({MATS}\n surface: Switch(by: Constant(0.0), stops: [(0.5, Material(\"a\")), (0.2, Material(\"b\"))]))"
        ));
        assert!(e.message.contains("strictly ascending"), "{e}");

        let e = err(&format!(
            "({MATS}\n surface: Switch(by: Constant(0.0), stops: [(0.0, Material(\"a\")), (0.2, Material(\"b\"))], blend: 0.5))"
        ));
        assert!(
            e.message.contains("blend = 0.5") && e.message.contains("0 ..= 0.2"),
            "{e}"
        );

        let e = err(&format!(
            "({MATS}\n maps: {{ \"x\": Voronoi(scale: 1.0, entries: [(1.0, Map(\"x\"))]) }},\n surface: Map(\"x\"))"
        ));
        assert!(e.message.contains("contains itself"), "{e}");

        let e = err(&format!("({MATS}\n surface: Voronoy(scale: 1.0))"));
        assert!(e.line == 2 && e.message.contains("Voronoy"), "{e}");

        let e = err(&format!(
            "({MATS}\n surface: Switch(by: Marble(scale: 1.0, octaves: 40), stops: [(0.0, Material(\"a\"))]))"
        ));
        assert!(
            e.line == 2 && e.message.contains("octaves = 40") && e.message.contains("1 ..= 16"),
            "{e}"
        );
    }

    #[test]
    fn seeds_derive_from_the_recipe_seed() {
        let src = |seed: u64| {
            format!(
                "(seed: {seed}, {MATS}\n surface: Voronoi(scale: 0.1, entries: [(1.0, Material(\"a\")), (1.0, Material(\"b\"))]))"
            )
        };
        let a = GemRecipe::parse("g", &src(0))
            .unwrap()
            .compile()
            .unwrap()
            .surface;
        let b = GemRecipe::parse("g", &src(1))
            .unwrap()
            .compile()
            .unwrap()
            .surface;
        let a2 = GemRecipe::parse("g", &src(0))
            .unwrap()
            .compile()
            .unwrap()
            .surface;
        let mut differ = 0;
        for i in 0..200 {
            let p = Vec3::new(i as f32 * 0.137, 0.3, -0.2);
            let (ha, hb) = (a.map.lookup(p, 0.5), b.map.lookup(p, 0.5));
            assert_eq!(ha, a2.map.lookup(p, 0.5));
            differ += usize::from(ha.material != hb.material);
        }
        assert!(differ > 50, "{differ}");
    }
}
