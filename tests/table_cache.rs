//! The material-table store between runs (`LAPIDARY_CACHE_DIR`, `lapidary::bsdf::store`): a
//! render whose tables are read back is the render that measured them, bit for bit, and the
//! render with the store off; damaged files are measured again; a folder that cannot hold the
//! store only costs the time.

#[path = "common/scratch.rs"]
mod scratch;

use scratch::{Scratch, text};
use std::path::Path;
use std::process::{Command, Output};

const LEPIDOLITE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/gems/lepidolite.ron");

fn run(cache: &str, args: &[&str]) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_lapidary"))
        .args(args)
        .env("LAPIDARY_CACHE_DIR", cache)
        .output()
        .expect("binary runs");
    assert!(out.status.success(), "{}", text(&out.stderr));
    out
}

/// Renders `recipe` small into `exr` with the store at `cache`; returns the summary.
fn render(cache: &str, recipe: &str, exr: &Path, more: &[&str]) -> String {
    let exr = exr.to_str().unwrap();
    let mut args = vec![
        "render", recipe, "-o", exr, "--no-png", "--size", "24x16", "--spp", "2",
    ];
    args.extend(more);
    text(&run(cache, &args).stdout)
}

/// Every channel's values as bits, by name.
fn pixels(exr: &Path) -> Vec<(String, Vec<u32>)> {
    let img = lapidary::image::read_exr(exr).unwrap();
    let mut v: Vec<(String, Vec<u32>)> = img
        .channels
        .iter()
        .map(|c| (c.name.clone(), c.data.iter().map(|x| x.to_bits()).collect()))
        .collect();
    v.sort();
    v
}

/// `(measured, read back)` from the summary's tables line.
fn counts(summary: &str) -> (usize, usize) {
    let line = summary
        .lines()
        .find(|l| l.trim_start().starts_with("material tables:"))
        .unwrap_or_else(|| panic!("no tables line in {summary}"));
    let words: Vec<&str> = line.split_whitespace().collect();
    (words[2].parse().unwrap(), words[4].parse().unwrap())
}

fn tab_files(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .map(|d| d.map(|e| e.unwrap().path()).collect())
        .unwrap_or_default();
    v.sort();
    v
}

#[test]
fn tables_read_back_render_the_same_pixels() {
    let dir = Scratch::new("table-cache", "same-pixels");
    let root = dir.path("cache");
    let c = root.to_str().unwrap();
    let cache = root.join("tables");

    let off = render("off", LEPIDOLITE, &dir.path("off.exr"), &[]);
    assert!(!off.contains("material tables:"), "{off}");
    let cold = render(c, LEPIDOLITE, &dir.path("cold.exr"), &[]);
    let (measured, read) = counts(&cold);
    assert!(measured >= 20 && read == 0, "{cold}");
    // (Two threads may measure the same table at once; both write the same file.)
    let files = tab_files(&cache);
    assert!(files.len() >= 20 && files.len() <= measured, "{files:?}");
    let warm = render(c, LEPIDOLITE, &dir.path("warm.exr"), &["--threads", "1"]);
    let (m, r) = counts(&warm);
    assert!(m == 0 && r >= files.len(), "{warm}");
    let want = pixels(&dir.path("off.exr"));
    assert!(want.len() >= 3);
    assert_eq!(pixels(&dir.path("cold.exr")), want);
    assert_eq!(pixels(&dir.path("warm.exr")), want);
    assert_eq!(tab_files(&cache), files, "reading writes nothing");

    // Damaged files (truncated, a flipped bit, emptied) are measured again and rewritten whole.
    let whole: Vec<Vec<u8>> = files.iter().map(|f| std::fs::read(f).unwrap()).collect();
    for (i, f) in files.iter().enumerate() {
        let mut b = whole[i].clone();
        match i % 3 {
            0 => b.truncate(b.len() / 2),
            1 => {
                let k = b.len() - 20;
                b[k] ^= 0x10;
            }
            _ => b.clear(),
        }
        std::fs::write(f, b).unwrap();
    }
    let again = render(c, LEPIDOLITE, &dir.path("again.exr"), &[]);
    assert!(counts(&again).0 >= files.len(), "{again}");
    assert_eq!(pixels(&dir.path("again.exr")), want);
    for (f, w) in files.iter().zip(&whole) {
        assert_eq!(&std::fs::read(f).unwrap(), w, "{}", f.display());
    }
    assert_eq!(tab_files(&cache), files, "no temporary file is left");

    // The spectral variant's tables (a measured base spectrum's ladder of stacks) too.
    let sunstone = concat!(env!("CARGO_MANIFEST_DIR"), "/gems/sunstone.ron");
    render("off", sunstone, &dir.path("s-off.exr"), &["--spectral"]);
    let s_cold = render(c, sunstone, &dir.path("s-cold.exr"), &["--spectral"]);
    let s_warm = render(c, sunstone, &dir.path("s-warm.exr"), &["--spectral"]);
    assert!(counts(&s_cold).0 > 0, "{s_cold}");
    assert_eq!(counts(&s_warm).0, 0, "{s_warm}");
    let want = pixels(&dir.path("s-off.exr"));
    assert_eq!(pixels(&dir.path("s-warm.exr")), want);
}

#[test]
fn a_folder_that_cannot_hold_the_store_only_costs_time() {
    let dir = Scratch::new("table-cache", "unwritable");
    // The store's folder would be inside a file.
    std::fs::write(dir.path("plain-file"), b"mine").unwrap();
    let inside = dir.path("plain-file").join("cache");
    let s = render(
        inside.to_str().unwrap(),
        LEPIDOLITE,
        &dir.path("a.exr"),
        &[],
    );
    let (measured, read) = counts(&s);
    assert!(measured >= 20 && read == 0, "{s}");
    assert_eq!(std::fs::read(dir.path("plain-file")).unwrap(), b"mine");
    assert_eq!(pixels(&dir.path("a.exr")), {
        render("off", LEPIDOLITE, &dir.path("b.exr"), &[]);
        pixels(&dir.path("b.exr"))
    });
}

#[test]
fn info_names_the_store() {
    let dir = Scratch::new("table-cache", "info");
    let cache = dir.path("cache");
    let out = run(cache.to_str().unwrap(), &["info", LEPIDOLITE]);
    let o = text(&out.stdout);
    assert!(
        o.contains(&format!(
            "kept between runs in {}",
            cache.join("tables").display()
        )),
        "{o}"
    );
    let out = run("off", &["info", LEPIDOLITE]);
    assert!(text(&out.stdout).contains("measured every run"));
}
