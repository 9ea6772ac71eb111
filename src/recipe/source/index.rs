//! One-pass indexes over a description file's text, so that locating things stays linear in the
//! file however many names it defines: where each line starts (for `line:col`), and where each
//! quoted map key (`"name":`) and each call with a quoted argument (`Material("name")`) is first
//! written outside comments; and how deeply brackets, map nodes and fields nest.

use std::collections::HashMap;
use std::ops::Range;

/// Identifiers of the map-tree nodes of a gem recipe (`Material("x")` and `Map("x")` are leaves).
const MAP_NODES: [&str; 5] = ["Voronoi", "Overlay", "Switch", "Material", "Map"];
/// Identifiers of the scalar fields of a `Switch`.
const FIELDS: [&str; 7] = [
    "Constant",
    "Perlin",
    "Turbulence",
    "Marble",
    "Sum",
    "Product",
    "Remap",
];
/// Depths beyond this are not given a position (the deepest depth is still counted).
const POSITIONS_KEPT: usize = 1024;

/// How deep one kind of thing nests in a text, and where each depth is first reached.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Depth {
    /// The deepest nesting (0: none at all).
    pub deepest: usize,
    /// `first[d - 1]`: byte offset where depth `d` is first reached (up to 1024 kept).
    first: Vec<usize>,
}

impl Depth {
    fn reach(&mut self, depth: usize, at: usize) {
        if depth > self.first.len() && self.first.len() < POSITIONS_KEPT {
            self.first.push(at);
        }
        self.deepest = self.deepest.max(depth);
    }

    /// Byte offset where depth `depth` (≥ 1) is first reached, if it is and was kept.
    pub fn first_at(&self, depth: usize) -> Option<usize> {
        self.first.get(depth.checked_sub(1)?).copied()
    }
}

/// How deeply a text nests, outside comments and strings: any brackets (`(`, `[`, `{`), map-tree
/// nodes (a node counts one level, its parenthesis holding the levels below), and fields.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Nesting {
    /// All brackets; positions at the bracket.
    pub brackets: Depth,
    /// Map-tree nodes written inline; positions at the node's identifier.
    pub maps: Depth,
    /// Fields written inline; positions at the field's identifier.
    pub fields: Depth,
}

/// What an open bracket belongs to.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Opened {
    Map,
    Field,
    Other,
}

/// Line starts and key positions of one text.
#[derive(Clone, Debug, Default)]
pub(super) struct TextIndex {
    /// Byte offset of the start of every line (the first is 0).
    line_starts: Vec<usize>,
    /// Whether each line is all ASCII (its columns are then byte differences, not a count).
    ascii: Vec<bool>,
    /// Raw text between the quotes of a string followed by `:` → byte offset of its first
    /// opening quote.
    keys: HashMap<String, usize>,
    /// (identifier, raw text between the quotes) of `Ident("…")` → byte offset of the identifier.
    calls: HashMap<(String, String), usize>,
    /// Nesting depths.
    nesting: Nesting,
}

impl TextIndex {
    /// Indexes `text`, whose comments (sorted, disjoint byte ranges) are `comments`.
    pub(super) fn new(text: &str, comments: &[Range<usize>]) -> Self {
        let line_starts = std::iter::once(0)
            .chain(text.match_indices('\n').map(|(i, _)| i + 1))
            .collect::<Vec<usize>>();
        let ascii = text.split('\n').map(|l| l.is_ascii()).collect();
        let b = text.as_bytes();
        let mut keys = HashMap::new();
        let mut calls = HashMap::new();
        let mut nesting = Nesting::default();
        let mut open: Vec<Opened> = vec![];
        let (mut maps, mut fields) = (0usize, 0usize);
        let mut next_comment = comments.iter().peekable();
        let mut i = 0;
        while i < b.len() {
            while next_comment.peek().is_some_and(|c| c.end <= i) {
                next_comment.next();
            }
            if let Some(c) = next_comment.peek()
                && c.contains(&i)
            {
                i = c.end;
                continue;
            }
            match b[i] {
                b'(' | b'[' | b'{' => {
                    let (ident, at) = ident_before(text, i);
                    let kind = if b[i] != b'(' {
                        Opened::Other
                    } else if MAP_NODES.contains(&ident) {
                        maps += 1;
                        nesting.maps.reach(maps, at);
                        Opened::Map
                    } else if FIELDS.contains(&ident) {
                        fields += 1;
                        nesting.fields.reach(fields, at);
                        Opened::Field
                    } else {
                        Opened::Other
                    };
                    open.push(kind);
                    nesting.brackets.reach(open.len(), i);
                }
                b')' | b']' | b'}' => match open.pop() {
                    Some(Opened::Map) => maps -= 1,
                    Some(Opened::Field) => fields -= 1,
                    _ => {}
                },
                _ => {}
            }
            if b[i] != b'"' {
                i += 1;
                continue;
            }
            let start = i;
            i += 1;
            while i < b.len() && b[i] != b'"' {
                i += if b[i] == b'\\' { 2 } else { 1 };
            }
            let close = i.min(b.len());
            i = close + 1;
            let after = text.get(i..).unwrap_or("").trim_start();
            let Some(raw) = text.get(start + 1..close) else {
                continue;
            };
            if after.starts_with(':') {
                keys.entry(raw.to_string()).or_insert(start);
            }
            if let Some(paren) = text[..start].trim_end().strip_suffix('(') {
                let (ident, at) = ident_before(text, paren.len());
                if !ident.is_empty() {
                    calls
                        .entry((ident.to_string(), raw.to_string()))
                        .or_insert(at);
                }
            }
        }
        TextIndex {
            line_starts,
            ascii,
            keys,
            calls,
            nesting,
        }
    }

    /// How deeply the text nests.
    pub(super) fn nesting(&self) -> &Nesting {
        &self.nesting
    }

    /// Where the key `"raw":` is first written (the opening quote), if anywhere.
    pub(super) fn key(&self, raw: &str) -> Option<usize> {
        self.keys.get(raw).copied()
    }

    /// Where `ident("raw")` is first written (the identifier), if anywhere.
    pub(super) fn call(&self, ident: &str, raw: &str) -> Option<usize> {
        self.calls
            .get(&(ident.to_string(), raw.to_string()))
            .copied()
    }

    /// 1-based line and column (in characters) of byte offset `pos` of `text`.
    pub(super) fn line_col(&self, text: &str, pos: usize) -> (usize, usize) {
        let mut pos = pos.min(text.len());
        while !text.is_char_boundary(pos) {
            pos -= 1;
        }
        let line = self.line_starts.partition_point(|&s| s <= pos).max(1);
        let start = self.line_starts.get(line - 1).copied().unwrap_or(0);
        let col = if self.ascii.get(line - 1).copied().unwrap_or(false) {
            pos - start
        } else {
            text[start..pos].chars().count()
        };
        (line, col + 1)
    }
}

/// The identifier written just before byte `at` (blanks allowed between), and where it starts.
fn ident_before(text: &str, at: usize) -> (&str, usize) {
    let before = text[..at].trim_end();
    let len = before
        .bytes()
        .rev()
        .take_while(|c| c.is_ascii_alphanumeric() || *c == b'_')
        .count();
    let start = before.len() - len;
    (&before[start..], start)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_skip_comments_and_values() {
        let text = "// \"a\": no\n{ \"b\": \"a\", /* \"a\": */ \"a\" :\n 1 }";
        let c1 = text.find("/*").unwrap();
        let comments = [0..10, c1..c1 + 10];
        assert_eq!(&text[comments[1].clone()], "/* \"a\": */");
        let ix = TextIndex::new(text, &comments);
        assert_eq!(ix.key("b"), text.find("\"b\""));
        let a = text.rfind("\"a\"").unwrap();
        assert_eq!(ix.key("a"), Some(a));
        assert_eq!(ix.line_col(text, a), (2, a - 10));
        assert_eq!(ix.line_col(text, text.len()), (3, 5));
        assert_eq!(ix.key("c"), None);
        let ix = TextIndex::new(
            "x: Material (\"a\"), /* Map(\"b\") */ Map( \"b\")",
            &[std::ops::Range { start: 19, end: 33 }],
        );
        assert_eq!(ix.call("Material", "a"), Some(3));
        assert_eq!(ix.call("Map", "b"), Some(34));
        assert_eq!(ix.call("Map", "a"), None);
        let text = "(s: Switch(by: Sum([Constant(1), Perlin(scale: 1)]), stops: [(0, Material(\"a\")), /* Map( */ (1, Overlay(under: Map(\"b\"), over: Material(\"c\")))]))";
        let n = TextIndex::new(
            text,
            &[std::ops::Range {
                start: text.find("/*").unwrap(),
                end: text.find("*/").unwrap() + 2,
            }],
        )
        .nesting;
        assert_eq!(n.maps.deepest, 3);
        assert_eq!(n.maps.first_at(2), text.find("Material"));
        assert_eq!(n.maps.first_at(3), text.find("Map(\""));
        assert_eq!(n.fields.deepest, 2);
        assert_eq!(n.fields.first_at(2), text.find("Constant"));
        assert_eq!(n.brackets.deepest, 6);
    }
}
