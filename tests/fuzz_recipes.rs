//! A short, seeded, deterministic fuzz run of the recipe parser and compiler: no input may panic.
//!
//! Starting from the shipped texts (`gems/*.ron`, `materials/course.ron`), each case stacks a few
//! random mutations — byte changes, deleted/duplicated/spliced spans, tokens from a RON/recipe
//! dictionary, numbers swapped for extreme values, deep nesting — or is random bytes or random
//! tokens. Each case runs the same checks as the cargo-fuzz target (`fuzz/fuzz_targets/recipe.rs`)
//! under `catch_unwind`; the test fails listing the first failing inputs with seed and index.
//!
//! The longer run (10× the cases):
//! `cargo test --release --test fuzz_recipes -- --ignored --nocapture`

use std::cell::RefCell;
use std::panic::{self, AssertUnwindSafe};
use std::path::Path;
use std::time::Instant;

const SEED: u64 = 0x1a91_da7e_5eed;
/// Cases of the short run, split in two halves with their own seeds that the test harness runs
/// on its two threads (about 40 s each in the test profile on 2 cores).
const CASES: usize = 40_000;

/// The fuzz target's checks (`lapidary::recipe::exercise`); whether a scene came back.
fn check(text: &str) -> bool {
    lapidary::recipe::exercise(text)
}

/// The crate's own counter-based generator, with the picks the mutator needs.
struct Rng(lapidary::sampler::Rng);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0.next_u64()
    }
    /// Uniform in `0..n` (`n > 0`).
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

const TOKENS: &[&str] = &[
    "(",
    ")",
    "[",
    "]",
    "{",
    "}",
    ",",
    ":",
    "\"",
    " ",
    "\n",
    "//",
    "/*",
    "*/",
    "r#\"",
    "Some(",
    "Voronoi",
    "Overlay",
    "Switch",
    "Cone",
    "Beckmann",
    "Perlin",
    "Turbulence",
    "Marble",
    "Sum",
    "Product",
    "Remap",
    "Constant",
    "Material(\"x\")",
    "Material(\"body\")",
    "Map(\"x\")",
    "Map(\"tiles\")",
    "maps: { \"x\": Map(\"x\") },",
    "maps: { \"x\": Map(\"y\"), \"y\": Map(\"x\") },",
    "1e39",
    "-1e39",
    "-1",
    "NaN",
    "inf",
    "-inf",
    "0",
    "0.0",
    "-0.0",
    "1e-45",
    "3.4e38",
    "18446744073709551615",
    "18446744073709551616",
    "-9223372036854775808",
    "4294967296",
    "include: [\"x.ron\"],",
    "include: [\"/dev/zero\"],",
    "include: [\"../gems/lepidolite.ron\"],",
    "include: [\"fuzz.ron\"],",
    "include: [\"materials/course.ron\"],",
    "include: [\"/\"],",
    "include: [\"\"],",
    "surface:",
    "materials: {},",
    "maps: {},",
    "(materials: {}, surface: Material(\"x\"))",
    "surface: Material(\"x\"),",
    "seed:",
    "materials:",
    "maps:",
    "stage: (camera: Perspective(from: (0,0,0), to: (0,0,0))),",
    "stage: (camera: Orthographic(from: (0,0,0), to: (0,1,0), up: (0,1,0))),",
    "stage:",
    "coats: [(ior: 1.0, roughness: 0.0)],",
    "base: Lambert(albedo: Gray(0.5))",
    "thickness:",
    "entries: [(1.0, Material(\"x\"))]",
    "entries: []",
    "entries: [(0.0, Material(\"x\"))]",
    "fill:",
    "scale:",
    "bump:",
    "rms:",
    "by:",
    "bands:",
    "under:",
    "over:",
    "ior:",
    "roughness:",
    "Gray(",
    "Srgb(",
    "Copper",
    "Gold",
    "Conductor(metal: Copper, roughness: 90.0)",
    "Mesh(path: \"/dev/zero\")",
    "Mesh(path: \"x.obj\")",
    "Map(path: \"/dev/null\")",
    "\u{feff}",
    "é",
    "\u{10ffff}",
    "\\u{0}",
    "\0",
];

const EXTREMES: &[&str] = &[
    "0",
    "-0",
    "-1",
    "1e39",
    "-1e39",
    "1e-45",
    "1e308",
    "NaN",
    "inf",
    "-inf",
    "0x7fffffff",
    "4294967295",
    "4294967296",
    "18446744073709551615",
    "99999999999999999999999",
    "-2147483649",
    "0.000000001",
    "1e-300",
    "340282350000000000000000000000000000000",
];

fn is_num(b: u8) -> bool {
    b.is_ascii_digit() || matches!(b, b'.' | b'-' | b'+' | b'e' | b'E')
}

/// One random mutation of `bytes` in place; `seeds` supplies spans for splicing.
fn mutate(rng: &mut Rng, bytes: &mut Vec<u8>, seeds: &[String]) {
    let len = bytes.len();
    let at = |rng: &mut Rng| rng.below(len + 1);
    let span = |rng: &mut Rng| {
        let a = rng.below(len + 1);
        let n = [1, 4, 16, 64, 512][rng.below(5)];
        (a, (a + rng.below(n + 1)).min(len))
    };
    match rng.below(10) {
        0 if len > 0 => {
            let i = rng.below(len);
            bytes[i] = match rng.below(3) {
                0 => bytes[i] ^ (1 << rng.below(8)),
                1 => *rng.pick(b"()[]{},:\"0123456789.-e \n/"),
                _ => rng.next() as u8,
            };
        }
        1 => {
            let (a, b) = span(rng);
            bytes.drain(a..b);
        }
        2 => {
            let (a, b) = span(rng);
            let copy = bytes[a..b].to_vec();
            let i = at(rng);
            bytes.splice(i..i, copy);
        }
        3 | 4 => {
            let i = at(rng);
            let token = rng.pick(TOKENS).as_bytes().to_vec();
            bytes.splice(i..i, token);
        }
        5 => {
            // Swap a number for an extreme value.
            let starts: Vec<usize> = (0..len)
                .filter(|&i| bytes[i].is_ascii_digit() && (i == 0 || !is_num(bytes[i - 1])))
                .collect();
            if !starts.is_empty() {
                let a = *rng.pick(&starts);
                let a = if a > 0 && bytes[a - 1] == b'-' {
                    a - 1
                } else {
                    a
                };
                let mut b = a + 1;
                while b < len && is_num(bytes[b]) {
                    b += 1;
                }
                let value = rng.pick(EXTREMES).as_bytes().to_vec();
                bytes.splice(a..b, value);
            }
        }
        6 => {
            // Deep nesting, closed or not.
            let i = at(rng);
            let depth = [8, 64, 127, 128, 200, 1000][rng.below(6)];
            let open = *rng.pick(&["Overlay(under: ", "Sum([", "[", "(", "Switch(by: "]);
            let mut nest = open.repeat(depth);
            if rng.below(2) == 0 {
                nest.push_str("Material(\"x\")");
                let close = if open.ends_with('[') { "])" } else { ")" };
                nest.push_str(&close.repeat(depth));
            }
            bytes.splice(i..i, nest.into_bytes());
        }
        7 => {
            // Splice a span of another shipped file.
            let other = rng.pick(seeds).as_bytes();
            let a = rng.below(other.len());
            let b = (a + rng.below(256)).min(other.len());
            let i = at(rng);
            bytes.splice(i..i, other[a..b].iter().copied());
        }
        8 => {
            // Replace a quoted name with another quoted token.
            let quotes: Vec<usize> = (0..len).filter(|&i| bytes[i] == b'"').collect();
            if quotes.len() >= 2 {
                let q = rng.below(quotes.len() - 1);
                let (a, b) = (quotes[q], quotes[q + 1] + 1);
                let name = *rng.pick(&[
                    "\"x\"",
                    "\"\"",
                    "\"body\"",
                    "\"x.ron\"",
                    "\"/dev/zero\"",
                    "\"../gems/lepidolite.ron\"",
                    "\"fuzz.ron\"",
                ]);
                bytes.splice(a..b, name.bytes());
            }
        }
        _ => {
            // Truncate.
            let i = at(rng);
            bytes.truncate(i);
        }
    }
}

/// Case `index` of the run seeded `seed`: a mutated shipped file, random bytes or random tokens.
fn case(seed: u64, index: usize, seeds: &[String]) -> String {
    let mut rng = Rng(lapidary::sampler::Rng::new(
        seed ^ (index as u64).wrapping_mul(0xd134_2543_de82_ef95),
    ));
    let bytes = match rng.below(20) {
        0 => (0..rng.below(256)).map(|_| rng.next() as u8).collect(),
        1 | 2 => {
            let mut t = String::new();
            for _ in 0..rng.below(64) {
                t.push_str(rng.pick::<&str>(TOKENS));
            }
            t.into_bytes()
        }
        _ => {
            let mut bytes = rng.pick(seeds).clone().into_bytes();
            for _ in 0..*rng.pick(&[1, 1, 1, 1, 2, 2, 3, 5, 8]) {
                mutate(&mut rng, &mut bytes, seeds);
            }
            bytes
        }
    };
    match String::from_utf8(bytes) {
        Ok(t) => t,
        Err(e) => String::from_utf8_lossy(e.as_bytes()).into_owned(),
    }
}

fn seed_texts() -> Vec<String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut paths: Vec<_> = std::fs::read_dir(root.join("gems"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    paths.sort();
    paths.push(root.join("materials/course.ron"));
    paths
        .iter()
        .map(|p| std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display())))
        .collect()
}

thread_local! {
    /// While a case runs: the panic message and location, instead of printing it.
    static CAUGHT: RefCell<Option<Option<String>>> = const { RefCell::new(None) };
}

/// A panic hook (installed once) that records panics of running cases and prints all others.
fn install_hook() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let default_hook = panic::take_hook();
        panic::set_hook(Box::new(move |info| {
            let caught = CAUGHT.with(|c| {
                c.borrow_mut().as_mut().map(|slot| {
                    let payload = info.payload();
                    let message = payload
                        .downcast_ref::<String>()
                        .cloned()
                        .or_else(|| payload.downcast_ref::<&str>().map(|s| s.to_string()))
                        .unwrap_or_default();
                    let at = info.location().map(|l| l.to_string()).unwrap_or_default();
                    *slot = Some(format!("{message} at {at}"));
                })
            });
            if caught.is_none() {
                default_hook(info);
            }
        }));
    });
}

fn run(seed: u64, cases: usize) {
    let seeds = seed_texts();
    install_hook();
    let start = Instant::now();
    let (mut accepted, mut failures, mut slowest) = (0usize, vec![], (0, 0.0));
    for index in 0..cases {
        let text = case(seed, index, &seeds);
        let t0 = Instant::now();
        CAUGHT.with(|c| *c.borrow_mut() = Some(None));
        let result = panic::catch_unwind(AssertUnwindSafe(|| check(&text)));
        let message = CAUGHT.with(|c| c.borrow_mut().take()).flatten();
        let took = t0.elapsed().as_secs_f64();
        if took > slowest.1 {
            slowest = (index, took);
        }
        match result {
            Ok(true) => accepted += 1,
            Ok(false) => {}
            Err(_) => failures.push((index, message.unwrap_or_default(), text)),
        }
    }
    println!(
        "fuzz_recipes: seed {seed:#x}, {cases} cases in {:.1} s: {accepted} compiled, {} rejected, {} panicked; slowest: case {} ({:.1} ms)",
        start.elapsed().as_secs_f64(),
        cases - accepted - failures.len(),
        failures.len(),
        slowest.0,
        slowest.1 * 1e3
    );
    if !failures.is_empty() {
        let shown: Vec<String> = failures
            .iter()
            .take(3)
            .map(|(i, m, t)| {
                let mut end = t.len().min(2000);
                while !t.is_char_boundary(end) {
                    end -= 1;
                }
                let (len, t) = (t.len(), &t[..end]);
                format!("seed {seed:#x} case {i}: {m}\ninput ({len} bytes):\n{t}\n")
            })
            .collect();
        panic!(
            "{} of {cases} inputs panicked; the first:\n{}",
            failures.len(),
            shown.join("\n")
        );
    }
}

/// Runs on a thread with the main thread's usual stack (8 MiB), as the CLI does.
fn on_big_stack(f: impl FnOnce() + Send + 'static) {
    std::thread::Builder::new()
        .stack_size(8 << 20)
        .spawn(f)
        .unwrap()
        .join()
        .unwrap_or_else(|e| panic::resume_unwind(e));
}

#[test]
fn recipes_never_panic() {
    on_big_stack(|| run(SEED, CASES / 2));
}

#[test]
fn recipes_never_panic_second_half() {
    on_big_stack(|| run(SEED ^ 0x20, CASES / 2));
}

#[test]
#[ignore = "long: cargo test --release --test fuzz_recipes -- --ignored"]
fn recipes_never_panic_long() {
    on_big_stack(|| run(SEED ^ 0x10, CASES * 10));
}
