//! One check reports every error it can find: a number out of range does not stop the parser, so
//! the errors after it — more numbers, unknown names, bad coats, the stage — come out in the same
//! run, each at the position (and with the message) it has when it is the only error in the file,
//! and none twice. (A module of `tests/recipe_errors.rs`.)

use super::{fixtures, gem, lapidary_check};
use lapidary::recipe::source::recover::MAX_VALUE_ERRORS;
use lapidary::recipe::{GemRecipe, MaterialLibrary, RecipeError, Source};
use std::collections::HashSet;

/// One expected error: `line:col` and words of its message.
type Expected = (usize, usize, &'static [&'static str]);

/// A fixture with several mistakes: each error expected, and for each the edit (same length, so
/// no position moves) that removes that mistake alone.
struct Fixture {
    file: &'static str,
    expected: [Expected; 4],
    fixes: [(&'static str, &'static str); 4],
}

/// `four_mistakes.ron`: two numbers out of range (read while parsing) around an unknown material
/// and a bad coat in a later material (found after parsing).
const RECIPE: Fixture = Fixture {
    file: "four_mistakes.ron",
    expected: [
        (6, 47, &["fill = 1.5 is out of range: allowed 0 ..= 1"]),
        (14, 78, &["fov = 200 is out of range: allowed 1 ..= 170"]),
        (
            10,
            28,
            &["material \"glaze\": coats[0].ior = 0.9 is out of range"],
        ),
        (
            12,
            29,
            &["unknown material \"bodyy\"", "did you mean \"body\""],
        ),
    ],
    fixes: [
        ("fill: 1.5", "fill: 1.0"),
        ("fov: 200.0", "fov: 100.0"),
        ("ior: 0.9", "ior: 1.9"),
        ("\"bodyy\"", "\"body\" "),
    ],
};

/// `four_mistakes_lib.ron`: two whole numbers out of range, a bad coat between them and a name
/// defined twice.
const LIBRARY: Fixture = Fixture {
    file: "four_mistakes_lib.ron",
    expected: [
        (6, 78, &["samples = 0 is out of range: allowed 1 ..= 256"]),
        (
            8,
            80,
            &["max_depth = 5000 is out of range: allowed 1 ..= 4096"],
        ),
        (9, 10, &["\"slow\" is defined twice; names must be unique"]),
        (
            7,
            28,
            &["material \"glaze\": coats[0].ior = 0.9 is out of range"],
        ),
    ],
    fixes: [
        ("samples: 0", "samples: 4"),
        ("max_depth: 5000", "max_depth: 4000"),
        (
            "\"slow\": (base: Lambert(albedo: Gray(0.2)))",
            "\"fast\": (base: Lambert(albedo: Gray(0.2)))",
        ),
        ("ior: 0.9", "ior: 1.9"),
    ],
};

/// Every error of `text` (named `fixture.file`, in the fixtures folder), as a recipe or library.
fn errors_of(fixture: &Fixture, text: &str) -> Vec<RecipeError> {
    let path = fixtures().join(fixture.file);
    let source = Source::new(&path.display().to_string(), text);
    if fixture.file == LIBRARY.file {
        MaterialLibrary::check_source(source, Some(&path)).1
    } else {
        let report = GemRecipe::check_source(source, Some(&path));
        assert!(report.errors.is_empty() || report.scene.is_none());
        report.errors
    }
}

fn text_of(fixture: &Fixture) -> String {
    std::fs::read_to_string(fixtures().join(fixture.file)).expect("the fixture is readable")
}

/// Every expected error, each once, and nothing else; none twice.
fn assert_exactly(fixture: &Fixture, errors: &[RecipeError]) {
    let all: Vec<String> = errors.iter().map(|e| e.to_string()).collect();
    assert_eq!(errors.len(), fixture.expected.len(), "{all:#?}");
    for (line, col, words) in fixture.expected {
        let hits = errors
            .iter()
            .filter(|e| {
                (e.line, e.col) == (line, col)
                    && e.file.ends_with(fixture.file)
                    && words.iter().all(|w| e.message.contains(w))
            })
            .count();
        assert_eq!(hits, 1, "{line}:{col} {words:?}; got {all:#?}");
    }
    let distinct: HashSet<&String> = all.iter().collect();
    assert_eq!(distinct.len(), all.len(), "reported twice: {all:#?}");
}

#[test]
fn one_check_reports_all_four_mistakes_of_a_recipe() {
    let path = fixtures().join(RECIPE.file);
    let report = GemRecipe::check(&path);
    assert!(report.scene.is_none());
    assert_exactly(&RECIPE, &report.errors);
    // `render` and `info` load through `load`: they stop at the first of them.
    let e = GemRecipe::load(&path).expect_err("the recipe has errors");
    assert_eq!(e, report.errors[0]);
}

#[test]
fn one_check_reports_all_four_mistakes_of_a_library() {
    let (lib, errors) = MaterialLibrary::check(&fixtures().join(LIBRARY.file));
    assert!(lib.is_some(), "the parser went to the end");
    assert_exactly(&LIBRARY, &errors);
}

/// Each error has the position and message it has when it is the file's only mistake.
#[test]
fn each_error_is_where_it_is_when_alone() {
    for fixture in [&RECIPE, &LIBRARY] {
        let text = text_of(fixture);
        let together = errors_of(fixture, &text);
        assert_eq!(together.len(), 4, "{together:#?}");
        for (k, (line, col, _)) in fixture.expected.iter().enumerate() {
            let mut alone = text.clone();
            for (j, (from, to)) in fixture.fixes.iter().enumerate() {
                assert_eq!(from.len(), to.len());
                if j != k {
                    assert_eq!(alone.matches(from).count(), 1, "{from}");
                    alone = alone.replace(from, to);
                }
            }
            let single = errors_of(fixture, &alone);
            assert_eq!(single.len(), 1, "{}: {single:#?}", fixture.file);
            let same = together
                .iter()
                .find(|e| (e.line, e.col) == (*line, *col))
                .expect("listed");
            assert_eq!(
                (single[0].line, single[0].col, &single[0].message),
                (same.line, same.col, &same.message),
                "{}",
                fixture.file
            );
        }
    }
}

#[test]
fn check_command_reports_every_mistake_in_one_run() {
    let files: Vec<String> = [RECIPE.file, LIBRARY.file]
        .iter()
        .map(|f| format!("tests/recipe_errors/{f}"))
        .collect();
    let (code, stdout, stderr) = lapidary_check(&files);
    let shown = format!("stdout:\n{stdout}\nstderr:\n{stderr}");
    assert_eq!(code, Some(1), "{shown}");
    for (file, fixture) in files.iter().zip([&RECIPE, &LIBRARY]) {
        for (line, col, words) in fixture.expected {
            let at = format!("error: {file}:{line}:{col}: ");
            let lines: Vec<&str> = stderr.lines().filter(|l| l.starts_with(&at)).collect();
            assert!(
                lines.len() == 1 && words.iter().all(|w| lines[0].contains(w)),
                "{at}{words:?}\n{shown}"
            );
        }
        assert!(stdout.contains(&format!("{file}: 4 errors")), "{shown}");
    }
    assert_eq!(
        stderr.lines().filter(|l| l.starts_with("error: ")).count(),
        8,
        "{shown}"
    );
    assert!(stderr.contains("8 errors in 2 files"), "{shown}");
}

/// A value error in a library included by two routes, in a named map used twice, and an unknown
/// material used three times (once in a named map the surface never uses): each reported once.
#[test]
fn nothing_is_reported_twice() {
    let text = "(include: [\"twice_a.ron\", \"twice_b.ron\"],\n \
        materials: { \"a\": (base: Lambert(albedo: Gray(0.5))) },\n \
        maps: { \"m\": Voronoi(scale: 0.1, jitter: 2.0, entries: [(1.0, Material(\"zz\"))]),\n   \
        \"spare\": Switch(by: Perlin(scale: 1.0, octaves: 40), stops: [(0.0, Material(\"zz\"))]) },\n \
        surface: Switch(by: Constant(0.0),\n   \
        stops: [(0.0, Map(\"m\")), (0.5, Map(\"m\")), (0.7, Material(\"zz\")), (0.9, Material(\"walk\"))]),\n)";
    let path = fixtures().join("twice.ron");
    let report = GemRecipe::check_source(Source::new("twice.ron", text), Some(&path));
    let all: Vec<String> = report.errors.iter().map(|e| e.to_string()).collect();
    let expected = [
        "twice.ron:3:43: jitter = 2 is out of range: allowed 0 ..= 1",
        "twice.ron:4:52: octaves = 40 is out of range: allowed 1 ..= 16",
        "twice_a.ron:4:78: samples = 0 is out of range",
        "twice.ron:3:64: unknown material \"zz\"",
    ];
    assert_eq!(all.len(), expected.len(), "{all:#?}");
    for e in expected {
        assert_eq!(
            all.iter().filter(|a| a.contains(e)).count(),
            1,
            "{e}: {all:#?}"
        );
    }
}

/// Past [`MAX_VALUE_ERRORS`] value errors the parser stops at the next one, which is reported too;
/// every one is at its own number.
#[test]
fn value_errors_stop_the_parser_past_the_limit() {
    let n = MAX_VALUE_ERRORS + 10;
    let maps: String = (0..n)
        .map(|i| {
            format!(
                "  \"m{i}\": Voronoi(scale: 0.1, fill: 2.0, entries: [(1.0, Material(\"a\"))]),\n"
            )
        })
        .collect();
    let text = gem(&format!(
        " maps: {{\n{maps} }},\n surface: Material(\"nowhere\")"
    ));
    let report = GemRecipe::check_source(Source::new("many.ron", &text), None);
    let all: Vec<String> = report.errors.iter().map(|e| e.to_string()).collect();
    assert_eq!(report.errors.len(), MAX_VALUE_ERRORS + 1, "{all:#?}");
    let lines: Vec<&str> = text.lines().collect();
    for (i, e) in report.errors.iter().enumerate() {
        // Line 1: materials; line 2: `maps: {`; map `i` on line 3 + i, its fill at `2.0`.
        let col = lines[2 + i].find("2.0").expect("a fill") + 1;
        assert!(
            (e.line, e.col) == (3 + i, col) && e.message.starts_with("fill = 2 is out of range"),
            "{i}: {e}"
        );
    }
    // The parser stopped, so the unknown material after the maps is not reached.
    assert!(!all.iter().any(|e| e.contains("nowhere")), "{all:#?}");
}
