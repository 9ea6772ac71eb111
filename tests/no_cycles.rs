//! The house has no import cycles (issue 15): neither between the concept folders under `src/`
//! nor between files.
//!
//! The check reads the crate's own sources (no external tool), resolves every `use` declaration
//! and every inline `crate::…`, `super::…` and `self::…` path to the file that defines its
//! target, and looks for strongly connected components (Tarjan 1972) in two graphs:
//!
//! - **folders**: the top-level modules under `src/` (`bsdf`, `geometry`, `scene`, …), an edge
//!   when any file of one names anything in another;
//! - **files**: every `.rs` file, an edge when one names an item defined in the other.
//!
//! A folder's `mod.rs` is its face: its `mod` declarations and re-exports (`pub use child::X`)
//! are not edges to its children, and a path through a re-export (`super::X` where `mod.rs`
//! says `pub use child::X`) is attributed to the child that defines `X`. Unit-test modules
//! (`#[cfg(test)] mod tests` at the end of a file) and comments are ignored: they do not shape
//! the architecture.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// A source file as a module: its path segments (`["geometry", "solid"]`; `[]` for `lib.rs`).
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct Module(Vec<String>);

impl Module {
    fn name(&self) -> String {
        if self.0.is_empty() {
            "crate".into()
        } else {
            self.0.join("::")
        }
    }
}

struct Crate {
    /// Module → (file, production code without comments and tests, is a `mod.rs`/`lib.rs`).
    files: BTreeMap<Module, (PathBuf, String, bool)>,
}

fn collect(dir: &Path, prefix: &[String], out: &mut BTreeMap<Module, (PathBuf, String, bool)>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for path in entries {
        let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
        if path.is_dir() {
            let mut p = prefix.to_vec();
            p.push(stem);
            collect(&path, &p, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            let text = std::fs::read_to_string(&path).unwrap();
            let (segments, face) = match stem.as_str() {
                "mod" => (prefix.to_vec(), true),
                "lib" if prefix.is_empty() => (vec![], true),
                "main" if prefix.is_empty() => continue,
                _ => {
                    let mut p = prefix.to_vec();
                    p.push(stem);
                    (p, false)
                }
            };
            out.insert(
                Module(segments),
                (path.clone(), production_code(&text), face),
            );
        }
    }
}

/// The text without comments, string contents and the trailing `#[cfg(test)]` module.
fn production_code(text: &str) -> String {
    let cut = text
        .find("#[cfg(test)]\nmod tests")
        .or_else(|| text.find("#[cfg(test)]\npub mod tests"))
        .unwrap_or(text.len());
    let src = &text[..cut];
    let b = src.as_bytes();
    let mut out = String::with_capacity(src.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'/' && b.get(i + 1) == Some(&b'/') {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if b[i] == b'/' && b.get(i + 1) == Some(&b'*') {
            i += 2;
            while i + 1 < b.len() && !(b[i] == b'*' && b[i + 1] == b'/') {
                i += 1;
            }
            i += 2;
        } else if b[i] == b'"' {
            // Skip the string (raw strings in this crate hold no quotes that matter here).
            i += 1;
            while i < b.len() && b[i] != b'"' {
                if b[i] == b'\\' {
                    i += 1;
                }
                i += 1;
            }
            i += 1;
            out.push_str("\"\"");
        } else if b[i] == b'\'' && b.get(i + 2) == Some(&b'\'') {
            // A char literal such as '"' or '/'.
            i += 3;
            out.push_str("' '");
        } else {
            let c = src[i..].chars().next().unwrap();
            out.push(c);
            i += c.len_utf8();
        }
    }
    out
}

/// Expands a `use` tree (`a::{b, c::{d, e}}`, `a::b as c`, `a::*`) into full paths.
fn expand_use(tree: &str) -> Vec<Vec<String>> {
    fn split_top(s: &str) -> Vec<&str> {
        let (mut depth, mut start, mut parts) = (0, 0, vec![]);
        for (i, c) in s.char_indices() {
            match c {
                '{' => depth += 1,
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    parts.push(&s[start..i]);
                    start = i + 1;
                }
                _ => {}
            }
        }
        parts.push(&s[start..]);
        parts
    }
    // Drop renames (`X as Y`) while the words are still apart, then the whitespace.
    let words: Vec<&str> = tree.split_whitespace().collect();
    let mut kept = String::new();
    let mut i = 0;
    while i < words.len() {
        if words[i] == "as" && i + 1 < words.len() {
            let renamed = words[i + 1];
            let tail = renamed.trim_start_matches(|c: char| c.is_alphanumeric() || c == '_');
            kept.push_str(tail);
            i += 2;
        } else {
            kept.push_str(words[i]);
            kept.push(' ');
            i += 1;
        }
    }
    let tree: String = kept.chars().filter(|c| !c.is_whitespace()).collect();
    let mut out = vec![];
    fn walk(prefix: &[String], t: &str, out: &mut Vec<Vec<String>>) {
        if t.is_empty() {
            return;
        }
        if let Some(open) = t.find('{') {
            let head: Vec<String> = t[..open]
                .split("::")
                .filter(|s| !s.is_empty())
                .map(String::from)
                .collect();
            let inner = &t[open + 1..t.rfind('}').unwrap_or(t.len())];
            let mut p = prefix.to_vec();
            p.extend(head);
            for part in split_top(inner) {
                walk(&p, part, out);
            }
        } else {
            let mut p = prefix.to_vec();
            p.extend(
                t.split("::")
                    .filter(|s| !s.is_empty() && *s != "self" && *s != "*")
                    .map(String::from),
            );
            out.push(p);
        }
    }
    for part in split_top(&tree) {
        walk(&[], part, &mut out);
    }
    out
}

/// Every path the code names: `use` declarations and inline `crate::`/`super::`/`self::` paths.
fn named_paths(code: &str) -> Vec<Vec<String>> {
    let mut paths = vec![];
    let mut rest = code;
    // `use` declarations.
    while let Some(at) = rest.find("use ") {
        let before = rest[..at].chars().last();
        let after = &rest[at + 4..];
        if before.is_none_or(|c| !(c.is_alphanumeric() || c == '_')) {
            let end = after.find(';').unwrap_or(after.len());
            paths.extend(expand_use(&after[..end]));
            rest = &after[end..];
        } else {
            rest = after;
        }
    }
    // Inline paths.
    let bytes = code.as_bytes();
    for root in ["crate::", "super::", "self::"] {
        let mut from = 0;
        while let Some(rel) = code[from..].find(root) {
            let at = from + rel;
            from = at + root.len();
            if at > 0 && (bytes[at - 1].is_ascii_alphanumeric() || bytes[at - 1] == b'_') {
                continue;
            }
            if at >= 2 && &code[at - 2..at] == "::" {
                continue; // `super::super::` is read from its first segment
            }
            let end = code[at..]
                .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
                .map_or(code.len(), |e| at + e);
            paths.push(
                code[at..end]
                    .split("::")
                    .filter(|s| !s.is_empty())
                    .map(String::from)
                    .collect(),
            );
        }
    }
    paths
}

impl Crate {
    fn load() -> Crate {
        let mut files = BTreeMap::new();
        collect(Path::new("src"), &[], &mut files);
        Crate { files }
    }

    /// The module a path is written in, as the base for `super`/`self`.
    fn absolute(&self, from: &Module, path: &[String]) -> Option<Vec<String>> {
        let face = self.files.get(from).is_some_and(|f| f.2);
        let mut base = from.0.clone();
        let mut segs = path;
        match segs.first().map(String::as_str) {
            Some("crate") => {
                base.clear();
                segs = &segs[1..];
            }
            Some("super") => {
                // In `a/b.rs` (module a::b) `super` is `a`; in `a/b/mod.rs` (module a::b) too.
                while segs.first().map(String::as_str) == Some("super") {
                    base.pop()?;
                    segs = &segs[1..];
                }
            }
            Some("self") => segs = &segs[1..],
            Some(first) => {
                // A relative path from a `use`: a child module of this one (only a face has
                // children), else an external crate.
                let mut child = from.0.clone();
                child.push(first.to_string());
                if !(face && self.files.contains_key(&Module(child))) {
                    return None;
                }
            }
            None => return None,
        }
        let _ = face;
        base.extend(segs.iter().cloned());
        Some(base)
    }

    /// The file that defines what `path` (absolute segments) names, following re-exports of a
    /// face one level at a time.
    fn resolve(&self, path: &[String], depth: usize) -> Option<Module> {
        // The longest prefix that is a module.
        let mut k = path.len();
        while k > 0 && !self.files.contains_key(&Module(path[..k].to_vec())) {
            k -= 1;
        }
        let module = Module(path[..k].to_vec());
        let (_, code, face) = self.files.get(&module)?;
        if *face && k < path.len() && depth < 8 {
            let item = &path[k];
            // `pub use child::…::Item` in the face.
            for p in named_paths_of_uses(code) {
                if p.last() == Some(item)
                    && let Some(abs) = self.absolute(&module, &p)
                    && abs != path
                    && let Some(m) = self.resolve(&abs, depth + 1)
                {
                    return Some(m);
                }
            }
        }
        Some(module)
    }

    /// File-level edges, without a face's edges into its own subtree.
    fn edges(&self) -> BTreeMap<Module, BTreeSet<Module>> {
        let mut edges: BTreeMap<Module, BTreeSet<Module>> = BTreeMap::new();
        for (m, (_, code, face)) in &self.files {
            let set = edges.entry(m.clone()).or_default();
            for p in named_paths(code) {
                let Some(abs) = self.absolute(m, &p) else {
                    continue;
                };
                let Some(target) = self.resolve(&abs, 0) else {
                    continue;
                };
                if &target == m || (*face && target.0.starts_with(&m.0)) {
                    continue;
                }
                set.insert(target);
            }
        }
        edges
    }
}

/// Only the `use` declarations of a file (for re-exports).
fn named_paths_of_uses(code: &str) -> Vec<Vec<String>> {
    let mut paths = vec![];
    for stmt in code.split(';') {
        if let Some(at) = stmt.find("pub use ") {
            paths.extend(expand_use(&stmt[at + 8..]));
        }
    }
    paths
}

/// Strongly connected components with more than one node (Tarjan's algorithm).
fn cycles<N: Ord + Clone>(edges: &BTreeMap<N, BTreeSet<N>>) -> Vec<Vec<N>> {
    struct State<N> {
        index: BTreeMap<N, usize>,
        low: BTreeMap<N, usize>,
        stack: Vec<N>,
        on: BTreeSet<N>,
        out: Vec<Vec<N>>,
    }
    fn visit<N: Ord + Clone>(v: &N, e: &BTreeMap<N, BTreeSet<N>>, s: &mut State<N>) {
        let i = s.index.len();
        s.index.insert(v.clone(), i);
        s.low.insert(v.clone(), i);
        s.stack.push(v.clone());
        s.on.insert(v.clone());
        for w in e.get(v).into_iter().flatten() {
            if !s.index.contains_key(w) {
                visit(w, e, s);
                let l = s.low[w].min(s.low[v]);
                s.low.insert(v.clone(), l);
            } else if s.on.contains(w) {
                let l = s.index[w].min(s.low[v]);
                s.low.insert(v.clone(), l);
            }
        }
        if s.low[v] == s.index[v] {
            let mut comp = vec![];
            loop {
                let w = s.stack.pop().unwrap();
                s.on.remove(&w);
                let done = &w == v;
                comp.push(w);
                if done {
                    break;
                }
            }
            if comp.len() > 1 {
                comp.sort();
                s.out.push(comp);
            }
        }
    }
    let mut s = State {
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: vec![],
        on: BTreeSet::new(),
        out: vec![],
    };
    for v in edges.keys() {
        if !s.index.contains_key(v) {
            visit(v, edges, &mut s);
        }
    }
    s.out
}

/// One edge of a cycle explained: which names in `from` point at `to`.
fn why(c: &Crate, from: &Module, to: &Module) -> String {
    let code = &c.files[from].1;
    let names: BTreeSet<String> = named_paths(code)
        .into_iter()
        .filter(|p| {
            c.absolute(from, p)
                .and_then(|a| c.resolve(&a, 0))
                .is_some_and(|t| &t == to)
        })
        .map(|p| p.join("::"))
        .collect();
    format!(
        "  {} -> {}: {}",
        from.name(),
        to.name(),
        names.into_iter().collect::<Vec<_>>().join(", ")
    )
}

fn report<N: Ord + Clone>(comps: &[Vec<N>], show: impl Fn(&N) -> String) -> String {
    comps
        .iter()
        .map(|c| c.iter().map(&show).collect::<Vec<_>>().join(" <-> "))
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn no_cycles_between_folders() {
    let c = Crate::load();
    let files = c.edges();
    let mut folders: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    let mut evidence: Vec<String> = vec![];
    for (from, tos) in &files {
        let Some(f) = from.0.first() else { continue };
        for to in tos {
            let Some(t) = to.0.first() else { continue };
            if f != t {
                folders.entry(f.clone()).or_default().insert(t.clone());
                evidence.push(why(&c, from, to));
            }
        }
        folders.entry(f.clone()).or_default();
    }
    let comps = cycles(&folders);
    let detail: Vec<&String> = evidence
        .iter()
        .filter(|e| {
            comps.iter().any(|comp| {
                let parts: Vec<&str> = e.trim().split(" -> ").collect();
                let a = parts[0].split("::").next().unwrap();
                let b = parts[1].split("::").next().unwrap();
                comp.iter().any(|x| x == a) && comp.iter().any(|x| x == b)
            })
        })
        .collect();
    assert!(
        comps.is_empty(),
        "import cycles between folders:\n{}\nedges inside them:\n{}",
        report(&comps, |s| s.clone()),
        detail
            .iter()
            .map(|s| s.as_str())
            .collect::<Vec<_>>()
            .join("\n")
    );
}

#[test]
fn no_cycles_between_files() {
    let c = Crate::load();
    let edges = c.edges();
    let comps = cycles(&edges);
    let mut detail = vec![];
    for comp in &comps {
        for a in comp {
            for b in &edges[a] {
                if comp.contains(b) {
                    detail.push(why(&c, a, b));
                }
            }
        }
    }
    assert!(
        comps.is_empty(),
        "import cycles between files:\n{}\nedges inside them:\n{}",
        report(&comps, Module::name),
        detail.join("\n")
    );
}

/// The checker itself finds a planted cycle (so a passing run means something).
#[test]
fn the_checker_sees_a_cycle() {
    let mut edges: BTreeMap<&str, BTreeSet<&str>> = BTreeMap::new();
    edges.entry("a").or_default().insert("b");
    edges.entry("b").or_default().insert("c");
    edges.entry("c").or_default().insert("a");
    edges.entry("d").or_default().insert("a");
    assert_eq!(cycles(&edges), vec![vec!["a", "b", "c"]]);
    let uses = expand_use("super::{a::{B, C as D}, e}, crate::f::*");
    assert_eq!(
        uses,
        vec![
            vec!["super", "a", "B"],
            vec!["super", "a", "C"],
            vec!["super", "e"],
            vec!["crate", "f"],
        ]
    );
    let code = production_code("use x::y; // crate::z\nfn f() { crate::q::R::new(\"crate::s\") }");
    let p = named_paths(&code);
    assert!(p.contains(&vec!["crate".into(), "q".into(), "R".into(), "new".into()]));
    assert!(
        !p.iter()
            .any(|p| p.contains(&"z".to_string()) || p.contains(&"s".to_string()))
    );
}
