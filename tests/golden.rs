//! Golden renders (issue 6, docs/design.md §10): every recipe in `gems/` and every analytic scene in
//! `tests/scenes/` is rendered small and fast (96×96, 256 spp, independent sampler, seed 7) and
//! z-tested against its high-spp reference in `tests/refs/` (96×96, 2048 spp, Sobol', seed 1000;
//! regenerate with `scripts/update-refs`) by `lapidary::image::compare`: per pixel and channel
//! `z = (t − r)/√(var_t + var_r)`, α = 0.01 with Šidák correction over all pixel-channels, the
//! image passing when ≥ 99.75 % of its pixels pass (Mitsuba's practice), and by the aggregate
//! test of the mean difference over the whole image, 32², 16², 8² tiles and each material's
//! pixels (α = 0.01 shared by the scales). The independent sampler keeps the test's sample variance an honest estimate of
//! its error.
//!
//! A failure writes the test render, the reference and a heatmap under `target/golden/` and names
//! them in the message.
//!
//! The bias tests of `compare` (module `bias`, issue 14) share these renders: one golden render of
//! every scene serves both.

#[path = "golden/bias.rs"]
mod bias;

use lapidary::image::compare::{Comparison, ZTest, compare};
use lapidary::image::write_heatmap;
use lapidary::image::{ExrImage, read_exr, write_exr};
use lapidary::recipe::GemRecipe;
use lapidary::render::{Control, Metadata, World, exr_image, render_scene};
use lapidary::sampler::SamplerKind;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The recipe a reference belongs to.
fn recipe_of(name: &str) -> PathBuf {
    let gem = Path::new("gems").join(format!("{name}.ron"));
    if gem.exists() {
        gem
    } else {
        Path::new("tests/scenes").join(format!("{name}.ron"))
    }
}

/// The golden scenes: every reference in `tests/refs/`, sorted by name.
fn scenes() -> Vec<String> {
    references().into_iter().map(|(n, _)| n).collect()
}

/// The reference `tests/refs/NAME.exr`.
fn reference(name: &str) -> ExrImage {
    read_exr(&Path::new("tests/refs").join(format!("{name}.exr"))).unwrap_or_else(|e| panic!("{e}"))
}

/// Renders `text` (recipe source, read as if it were the file `recipe`) at `size`² and `spp`
/// with the independent sampler and `seed`, as the golden tests do.
fn render_text(recipe: &Path, text: &str, size: u32, spp: u32, seed: u64) -> ExrImage {
    let file = recipe.to_str().unwrap();
    let gem = GemRecipe::parse(file, text).unwrap_or_else(|e| panic!("{e}"));
    let mut scene = gem.compile().unwrap_or_else(|e| panic!("{e}"));
    let r = &mut scene.stage.render;
    (r.width, r.height, r.spp, r.seed) = (size, size, spp, seed);
    r.sampler = SamplerKind::Independent;
    let world = World::new(&scene).expect("world");
    let rendered = render_scene(&world, &scene, &Control::default());
    exr_image(&rendered, &Metadata::of(file, &scene))
}

/// Every golden scene at the golden settings (96×96, 256 spp, independent, seed 7), rendered once
/// for all tests of this binary.
fn golden_renders() -> &'static [(String, ExrImage)] {
    static RENDERS: OnceLock<Vec<(String, ExrImage)>> = OnceLock::new();
    RENDERS.get_or_init(|| {
        scenes()
            .into_iter()
            .map(|n| {
                let recipe = recipe_of(&n);
                let text = std::fs::read_to_string(&recipe).unwrap();
                let img = render_text(&recipe, &text, 96, 256, 7);
                (n, img)
            })
            .collect()
    })
}

/// The golden render of `name`.
fn golden(name: &str) -> &'static ExrImage {
    golden_renders()
        .iter()
        .find(|(n, _)| n == name)
        .map(|(_, img)| img)
        .unwrap_or_else(|| panic!("no golden scene {name}"))
}

/// Writes the evidence of a failed comparison and returns a message naming it.
fn evidence(name: &str, test: &ExrImage, reference: &ExrImage, c: &Comparison) -> String {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("golden");
    std::fs::create_dir_all(&dir).expect("target dir");
    let (t, r, h) = (
        dir.join(format!("{name}-test.exr")),
        dir.join(format!("{name}-ref.exr")),
        dir.join(format!("{name}-heatmap.png")),
    );
    write_exr(&t, test).expect("write test");
    write_exr(&r, reference).expect("write ref");
    write_heatmap(&h, c).expect("write heatmap");
    format!(
        "{name}: test {} vs reference {} failed ({:?}); wrote {}, {}, {}",
        t.display(),
        r.display(),
        c.ztest,
        t.display(),
        r.display(),
        h.display()
    )
}

/// The aggregate test's scales as `label |z|/limit`, failing ones marked.
fn scales(z: &ZTest) -> String {
    z.scales
        .iter()
        .map(|s| {
            let mark = if s.passed { "" } else { " FAIL" };
            format!("{} {:.2}/{:.2}{mark}", s.label(), s.max_abs_z, s.z_crit)
        })
        .collect::<Vec<_>>()
        .join(", ")
}

fn references() -> Vec<(String, PathBuf)> {
    let mut refs: Vec<(String, PathBuf)> = std::fs::read_dir("tests/refs")
        .expect("tests/refs")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "exr"))
        .map(|p| (p.file_stem().unwrap().to_string_lossy().into_owned(), p))
        .collect();
    refs.sort();
    refs
}

#[test]
fn every_recipe_and_scene_has_a_reference() {
    let names: Vec<String> = references().into_iter().map(|(n, _)| n).collect();
    for dir in ["gems", "tests/scenes"] {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "ron") {
                let stem = p.file_stem().unwrap().to_string_lossy().into_owned();
                assert!(
                    names.iter().any(|n| n.starts_with(&stem)),
                    "{} has no reference in tests/refs/ (run scripts/update-refs {stem})",
                    p.display()
                );
            }
        }
    }
}

#[test]
fn golden_renders_match_their_references() {
    let refs = references();
    assert!(refs.len() >= 10, "{} references", refs.len());
    let mut failures = Vec::new();
    for (name, path) in &refs {
        let reference = read_exr(path).unwrap_or_else(|e| panic!("{e}"));
        let test = golden(name);
        let c = compare(test, &reference).unwrap_or_else(|e| panic!("{name}: {e}"));
        let z = c.ztest.as_ref().expect("references carry variance");
        eprintln!(
            "{name}: {:.2} % of pixels pass (max |z| {:.2}, limit {:.2}), relMSE {:.2e}, FLIP {:.4}; \
             tiles |z|/limit: {}",
            100.0 * z.pass_fraction,
            z.max_abs_z,
            z.z_crit,
            c.rel_mse,
            c.flip,
            scales(z)
        );
        if !c.passed {
            failures.push(evidence(name, test, &reference, &c));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn golden_comparison_has_power() {
    // Negative controls: the mirror sphere 2 % brighter, and Lepidolite 30 % brighter, must fail
    // against their references. (Per-pixel tests of a 256-spp gem are blind to a few per cent:
    // its pixels' relative noise is 10–30 %; the analytic scenes carry the fine checks.)
    for (name, scale) in [("mirror", 1.02f32), ("lepidolite", 1.3)] {
        let reference = reference(name);
        let mut test = golden(name).clone();
        for ch in &mut test.channels {
            if ["R", "G", "B"].contains(&ch.name.as_str()) {
                ch.data.iter_mut().for_each(|v| *v *= scale);
            }
        }
        let c = compare(&test, &reference).unwrap();
        eprintln!(
            "{name} × {scale}: {:?}",
            c.ztest.as_ref().map(|z| z.pass_fraction)
        );
        assert!(!c.passed, "{name} × {scale} passed: {:?}", c.ztest);
    }
}
