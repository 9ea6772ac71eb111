//! The README's example outputs cannot drift: every ```` ```text ```` block of README.md whose
//! first line is `$ lapidary …` is run, and each line it shows must be printed by the command, in
//! the order shown (a block may show an excerpt). Times and rates, which differ from run to run,
//! are compared as "a number"; counts (paths, rays, dropped samples), messages, positions and
//! effects are compared exactly. A ```` ```ron ```` block whose first line is `// NAME.ron` is a
//! file the examples after it may use. The render example's picture is compared with the
//! README's image (docs/images/lepidolite.png) too.

use std::path::Path;
use std::process::{Command, Stdio};

#[path = "common/scratch.rs"]
mod scratch;
use scratch::{Scratch, text};

/// One checked example.
#[derive(Debug)]
struct Example {
    /// README line of the command.
    line: usize,
    /// The arguments after `lapidary`.
    args: Vec<String>,
    /// The lines the README shows.
    shown: Vec<String>,
}

/// The examples and the files the README gives.
fn parse(readme: &str) -> (Vec<Example>, Vec<(String, String)>) {
    let mut examples = vec![];
    let mut files = vec![];
    let mut lines = readme.lines().enumerate();
    while let Some((_, l)) = lines.next() {
        let Some(lang) = l.strip_prefix("```") else {
            continue;
        };
        let mut body = vec![];
        let mut first = None;
        for (n, l) in lines.by_ref() {
            if l.starts_with("```") {
                break;
            }
            first.get_or_insert(n + 1);
            body.push(l.to_string());
        }
        let head = body.first().map(String::as_str).unwrap_or("");
        match lang {
            "text" if head.starts_with("$ lapidary ") => examples.push(Example {
                line: first.unwrap_or(0),
                args: head["$ lapidary ".len()..]
                    .split_whitespace()
                    .map(str::to_string)
                    .collect(),
                shown: body[1..]
                    .iter()
                    .filter(|l| !l.trim().is_empty())
                    .cloned()
                    .collect(),
            }),
            "ron" if head.starts_with("// ") && head.ends_with(".ron") => {
                files.push((head[3..].to_string(), body.join("\n") + "\n"));
            }
            _ => {}
        }
    }
    (examples, files)
}

/// A line with its run-to-run numbers (a time in seconds, a rate per second) replaced by `#`.
fn normalise(line: &str) -> String {
    let words: Vec<&str> = line.split(' ').collect();
    let number = |w: &str| w.trim_start_matches('(').parse::<f64>().is_ok();
    let mut out = Vec::with_capacity(words.len());
    for (i, w) in words.iter().enumerate() {
        let next = words.get(i + 1).copied().unwrap_or("");
        let after = words.get(i + 2).copied().unwrap_or("");
        let seconds = matches!(next, "s" | "s:" | "s," | "s)" | "s;");
        let rate = next.starts_with("paths/s") || (next == "M" && after.starts_with("rays/s"));
        if number(w) && (seconds || rate) {
            out.push(if w.starts_with('(') { "(#" } else { "#" });
        } else {
            out.push(w);
        }
    }
    out.join(" ")
}

/// Whether every shown line is printed, those of one stream in the order shown.
fn missing(shown: &[String], streams: &[&str]) -> Vec<String> {
    let printed: Vec<Vec<String>> = streams
        .iter()
        .map(|s| s.lines().map(normalise).collect())
        .collect();
    let mut at = vec![0usize; streams.len()];
    let mut out = vec![];
    for line in shown {
        let want = normalise(line);
        let found = printed.iter().enumerate().find_map(|(k, p)| {
            p[at[k]..]
                .iter()
                .position(|l| *l == want)
                .map(|i| (k, at[k] + i + 1))
        });
        match found {
            Some((k, next)) => at[k] = next,
            None => out.push(line.clone()),
        }
    }
    out
}

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A scratch folder that sees the repository's recipes, libraries, assets and data where the
/// README's relative paths expect them.
fn workspace(test: &str, files: &[(String, String)]) -> Scratch {
    let s = Scratch::new("readme", test);
    for dir in ["gems", "materials", "assets", "data", "scenes"] {
        let target = repo().join(dir);
        if target.exists() {
            #[cfg(unix)]
            std::os::unix::fs::symlink(&target, s.path(dir)).unwrap();
        }
    }
    for (name, body) in files {
        std::fs::write(s.path(name), body).unwrap();
    }
    s
}

#[test]
fn normalising_keeps_counts_and_hides_times() {
    assert_eq!(
        normalise("depth 8 in 16.2 s: setup 1.2 s, rendering 15.0 s"),
        "depth 8 in # s: setup # s, rendering # s"
    );
    assert_eq!(
        normalise(
            "  19 660 800 paths (1308923 paths/s), 58 910 376 rays (3.92 M rays/s), 0 dropped"
        ),
        "  19 660 800 paths (# paths/s), 58 910 376 rays (# M rays/s), 0 dropped"
    );
    let shown = vec!["b".to_string(), "d".to_string()];
    assert!(missing(&shown, &["a\nb\nc\nd"]).is_empty());
    assert_eq!(missing(&shown, &["d\nb"]), ["d"]);
    assert!(
        missing(&shown, &["d", "b"]).is_empty(),
        "lines of two streams"
    );
}

#[test]
fn the_readme_examples_print_what_the_readme_shows() {
    let readme = std::fs::read_to_string(repo().join("README.md")).unwrap();
    let (examples, files) = parse(&readme);
    assert!(
        examples.len() >= 5,
        "the README's examples were not found: {examples:?}"
    );
    let s = workspace("examples", &files);
    let mut failures = vec![];
    for ex in &examples {
        let out = Command::new(env!("CARGO_BIN_EXE_lapidary"))
            .args(&ex.args)
            .current_dir(&s.0)
            .stdin(Stdio::null())
            .output()
            .expect("binary runs");
        let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
        let lost = missing(&ex.shown, &[&stdout, &stderr]);
        if !lost.is_empty() {
            failures.push(format!(
                "README.md:{}: `lapidary {}` did not print, in order:\n  {}\nIt printed:\n{stdout}{stderr}",
                ex.line,
                ex.args.join(" "),
                lost.join("\n  ")
            ));
        }
    }
    // The picture: the default render's PNG is the README's image (a tolerance for other CPUs'
    // last bits; on this project's machines it is identical).
    let png = s.path("lepidolite.png");
    if examples
        .iter()
        .any(|e| e.args == ["render", "gems/lepidolite.ron"])
    {
        let shown = image::open(repo().join("docs/images/lepidolite.png"))
            .unwrap()
            .to_rgb8();
        let made = image::open(&png).unwrap().to_rgb8();
        assert_eq!(shown.dimensions(), made.dimensions());
        let diffs: Vec<u8> = shown
            .as_raw()
            .iter()
            .zip(made.as_raw())
            .map(|(a, b)| a.abs_diff(*b))
            .collect();
        let mean = diffs.iter().map(|&d| f64::from(d)).sum::<f64>() / diffs.len() as f64;
        let far = diffs.iter().filter(|&&d| d > 8).count() as f64 / diffs.len() as f64;
        if mean > 0.5 || far > 1e-3 {
            failures.push(format!(
                "docs/images/lepidolite.png is not what `lapidary render gems/lepidolite.ron` \
                 draws: mean |Δ| {mean:.3} of 255, {:.3} % of values off by more than 8 \
                 (regenerate it with that command)",
                100.0 * far
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}
