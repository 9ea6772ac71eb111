//! One-pass indexes over a description file's text, so that locating things stays linear in the
//! file however many names it defines: where each line starts (for `line:col`), and where each
//! quoted map key (`"name":`) and each call with a quoted argument (`Material("name")`) is first
//! written outside comments.

use std::collections::HashMap;
use std::ops::Range;

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
            if b[i] != b'"' {
                i += 1;
                continue;
            }
            let open = i;
            i += 1;
            while i < b.len() && b[i] != b'"' {
                i += if b[i] == b'\\' { 2 } else { 1 };
            }
            let close = i.min(b.len());
            i = close + 1;
            let after = text.get(i..).unwrap_or("").trim_start();
            let Some(raw) = text.get(open + 1..close) else {
                continue;
            };
            if after.starts_with(':') {
                keys.entry(raw.to_string()).or_insert(open);
            }
            if let Some(paren) = text[..open].trim_end().strip_suffix('(') {
                let paren = paren.trim_end();
                let ident = paren
                    .bytes()
                    .rev()
                    .take_while(|c| c.is_ascii_alphanumeric() || *c == b'_')
                    .count();
                if ident > 0 {
                    let at = paren.len() - ident;
                    calls
                        .entry((paren[at..].to_string(), raw.to_string()))
                        .or_insert(at);
                }
            }
        }
        TextIndex {
            line_starts,
            ascii,
            keys,
            calls,
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_skip_comments_and_values() {
        let text = "// \"a\": no\n{ \"b\": \"a\", /* \"a\": */ \"a\" :\n 1 }";
        let comments = [0..10, 22..33];
        assert_eq!(&text[comments[1].clone()], "/* \"a\": */");
        let ix = TextIndex::new(text, &comments);
        assert_eq!(ix.key("b"), Some(13));
        assert_eq!(ix.key("a"), Some(34));
        assert_eq!(ix.line_col(text, 34), (2, 24));
        assert_eq!(ix.line_col(text, text.len()), (3, 4));
        let text = "ab\n«é» x";
        let ix = TextIndex::new(text, &[]);
        assert_eq!(ix.line_col(text, text.find('x').unwrap()), (2, 5));
        assert_eq!(ix.line_col(text, 1), (1, 2));
        assert_eq!(ix.key("c"), None);
        let ix = TextIndex::new(
            "x: Material (\"a\"), /* Map(\"b\") */ Map( \"b\")",
            &[20..35],
        );
        assert_eq!(ix.call("Material", "a"), Some(3));
        assert_eq!(ix.call("Map", "b"), Some(36));
        assert_eq!(ix.call("Map", "a"), None);
    }
}
