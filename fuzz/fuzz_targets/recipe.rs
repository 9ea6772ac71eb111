//! Fuzz target: the recipe parser and compiler must never panic, whatever the input.
//!
//! Run from the repository root (stable Rust needs `RUSTC_BOOTSTRAP=1` for cargo-fuzz's `-Z` flags):
//! `RUSTC_BOOTSTRAP=1 cargo fuzz run recipe /tmp/recipe-corpus fuzz/corpus/recipe -- -seed=1 -max_total_time=120`
//! (new inputs go to the first directory, so the committed seed corpus stays as it is).
//! The same checks run deterministically under `cargo test` in `tests/fuzz_recipes.rs`.
#![no_main]

use lapidary::recipe::{GemRecipe, MaterialLibrary, Source};
use libfuzzer_sys::fuzz_target;

/// Parses and compiles `text` as a gem recipe and as a material library; checks the scene.
fn check(text: &str) {
    let report = GemRecipe::check_source(Source::new("fuzz.ron", text), None);
    let _ = MaterialLibrary::parse("fuzz.ron", text);
    if let Some(scene) = report.scene {
        let hit = scene
            .surface
            .map
            .lookup(glam::Vec3::new(0.3, 0.1, -0.2), 0.5);
        assert!(
            (hit.material as usize) < scene.surface.names.len(),
            "material index {} out of {} materials",
            hit.material,
            scene.surface.names.len()
        );
        let again = GemRecipe::check_source(Source::new("fuzz.ron", text), None);
        assert_eq!(
            again.scene.as_ref(),
            Some(&scene),
            "compiling twice differs"
        );
    }
}

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        check(text);
    }
});
