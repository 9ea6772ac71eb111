//! Fuzz target: the recipe parser and compiler must never panic, whatever the input.
//!
//! Run from the repository root (stable Rust needs `RUSTC_BOOTSTRAP=1` for cargo-fuzz's `-Z` flags):
//! `RUSTC_BOOTSTRAP=1 cargo fuzz run recipe /tmp/recipe-corpus fuzz/corpus/recipe -- -seed=1 -max_total_time=120`
//! (new inputs go to the first directory, so the committed seed corpus stays as it is).
//! The same checks run deterministically under `cargo test` in `tests/fuzz_recipes.rs`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        lapidary::recipe::exercise(text);
    }
});
