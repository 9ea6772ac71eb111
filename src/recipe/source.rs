//! A description file's text and the positions of things in it.
//!
//! The RON parser reports positions for syntax and range errors it finds while reading (a range
//! error does not stop it: [`recover`] records it and locates it by parsing again). Errors found
//! after parsing (an unknown material name, an include that is missing, a bad coat) are located by
//! searching the text for the tokens that name them, skipping comments and the insides of other
//! strings, so a name quoted in a comment never attracts an error.

use super::RecipeError;
use std::ops::Range;

pub mod index;
mod odd;
pub mod recover;

/// Largest description file read (bytes): recipes are hand-written text, and the limit keeps a
/// mistaken include of a huge or endless file (`/dev/zero`) from exhausting memory.
pub const MAX_FILE_BYTES: u64 = 16 << 20;

/// A file's name (as given, for messages) and text.
#[derive(Clone, Debug)]
pub struct Source {
    /// File name as given.
    pub file: String,
    /// The text.
    pub text: String,
    /// Byte ranges of comments, in order.
    comments: Vec<Range<usize>>,
    /// Line starts and key positions.
    index: index::TextIndex,
}

impl Source {
    /// A source over `text`, named `file` in messages; a leading UTF-8 byte-order mark is
    /// dropped, so positions count from the character after it.
    pub fn new(file: &str, text: &str) -> Self {
        let text = odd::strip_bom(text);
        let comments = comment_ranges(text);
        Source {
            file: file.to_string(),
            text: text.to_string(),
            index: index::TextIndex::new(text, &comments),
            comments,
        }
    }

    /// Reads a file: a regular file of at most [`MAX_FILE_BYTES`], valid UTF-8.
    pub fn read(path: &std::path::Path) -> Result<Self, RecipeError> {
        let file = path.display().to_string();
        let fail = |message: String| RecipeError {
            file: file.clone(),
            line: 0,
            col: 0,
            message,
        };
        // The type first, without opening: says "is a directory", "is a FIFO", … (a FIFO would
        // block the read).
        let meta = crate::image::input_kind::regular_file(path).map_err(|e| {
            use crate::image::input_kind::NotAFile;
            match e {
                NotAFile::Missing | NotAFile::Io(_) => fail(format!("cannot read the file: {e}")),
                e => fail(e.to_string()),
            }
        })?;
        if meta.len() > MAX_FILE_BYTES {
            return Err(fail(format!(
                "the file has {} bytes; description files may have at most {MAX_FILE_BYTES}",
                meta.len()
            )));
        }
        if meta.len() == 0 {
            // Nothing to read (and never read pseudo-files such as /proc/kmsg, which report size
            // 0 and can block).
            return Ok(Source::new(&file, ""));
        }
        let mut bytes = Vec::with_capacity(meta.len() as usize);
        std::fs::File::open(path)
            .and_then(|f| {
                std::io::Read::read_to_end(&mut std::io::Read::take(f, MAX_FILE_BYTES), &mut bytes)
            })
            .map_err(|e| fail(format!("cannot read the file: {e}")))?;
        let text = String::from_utf8(bytes).map_err(|e| {
            let (line, col) = line_col_bytes(e.as_bytes(), e.utf8_error().valid_up_to());
            RecipeError {
                file: file.clone(),
                line,
                col,
                message: "the file is not valid UTF-8 text".into(),
            }
        })?;
        Ok(Source::new(&file, &text))
    }

    /// An error at byte offset `at` (or with no position when `at` is `None`).
    pub fn error(&self, at: Option<usize>, message: impl Into<String>) -> RecipeError {
        let (line, col) = at.map_or((0, 0), |p| self.line_col(p));
        RecipeError {
            file: self.file.clone(),
            line,
            col,
            message: message.into(),
        }
    }

    /// An error from the RON parser, moved onto the value it is about: the parser reports type
    /// errors just after the `:` (on the blank before the value), and checks made once a whole
    /// tuple or struct was read (`finite3`, a `Switch`'s thresholds) at its closing parenthesis.
    pub fn ron_error(&self, e: &ron::error::SpannedError) -> RecipeError {
        let mut error = self.value_error(e);
        if let Some(open) = self.unclosed() {
            let (l, c) = line_col(&self.text, open);
            let ch = &self.text[open..=open];
            error.message += &format!(" (note: the `{ch}` at {l}:{c} is never closed)");
        }
        error
    }

    /// [`Source::ron_error`] without the note on a bracket never closed: for a value error
    /// located while recovering ([`recover`]), which is not where the parser stopped.
    pub(crate) fn value_error(&self, e: &ron::error::SpannedError) -> RecipeError {
        let message = e.code.to_string();
        let reported = self.offset(e.span.start.line, e.span.start.col);
        let mut pos = self.skip_blank(reported);
        if pos >= self.text.len() {
            pos = reported; // nothing follows: keep the parser's position
        }
        if pos > 0
            && matches!(self.text.as_bytes()[pos - 1], b'-' | b'+')
            && self.text[pos..].starts_with(|c: char| c.is_ascii_digit())
        {
            pos -= 1; // a number's sign is part of it (the parser reports after it)
        }
        if matches!(e.code, ron::Error::Message(_)) {
            let before = self.text[..pos].trim_end();
            let close = if self.text[pos..].starts_with(')') {
                Some(pos)
            } else if before.ends_with(')') {
                Some(before.len() - 1)
            } else {
                None
            };
            if let Some(open) = close.and_then(|c| self.matching_open(c)) {
                pos = self.item_start(open);
                pos = self.refine(pos, &message).unwrap_or(pos);
            }
        }
        let mut message = self.integer_detail(&e.code, pos).unwrap_or(message);
        if message.starts_with("Expected") && pos < self.text.len() {
            // Say what was found instead.
            let token: String = self.text[pos..]
                .chars()
                .take_while(|c| !matches!(c, ',' | ')' | ']' | '}' | '\n'))
                .take(40)
                .collect();
            if !token.trim().is_empty() {
                message += &format!(", found `{}`", token.trim());
            }
        }
        let (line, col) = line_col(&self.text, pos);
        RecipeError {
            file: self.file.clone(),
            line,
            col,
            message,
        }
    }

    /// The last bracket left open at the end of the text, if the brackets do not balance.
    fn unclosed(&self) -> Option<usize> {
        let b = self.text.as_bytes();
        let mut stack = vec![];
        let mut i = 0;
        while i < b.len() {
            if self.in_comment(i) {
                i += 1;
                continue;
            }
            match b[i] {
                b'"' => {
                    i += 1;
                    while i < b.len() && b[i] != b'"' {
                        i += if b[i] == b'\\' { 2 } else { 1 };
                    }
                }
                b'(' | b'[' | b'{' => stack.push(i),
                b')' | b']' | b'}' => {
                    stack.pop()?;
                }
                _ => {}
            }
            i += 1;
        }
        stack.pop()
    }

    /// Within the item starting at `pos`, the field a check's message names, if it can be found.
    fn refine(&self, pos: usize, message: &str) -> Option<usize> {
        if message.contains("blend =") {
            let key = self.find_from(pos, &["blend", ":"])?;
            let colon = key + self.text[key..].find(':')?;
            return Some(self.skip_blank(colon + 1));
        }
        // "… but stops[i] = … ≥ stops[j] = …": the later, out-of-order stop.
        let j = message
            .rsplit("stops[")
            .next()
            .filter(|_| message.contains("strictly ascending") || message.contains("not finite"))
            .and_then(|r| r.split(']').next())
            .and_then(|n| n.parse::<usize>().ok())?;
        let stops = self.find_from(pos, &["stops", ":"])?;
        self.nth_element(stops, j)
    }

    /// Byte offset of 1-based `line` and character column `col`.
    fn offset(&self, line: usize, col: usize) -> usize {
        let start: usize = self
            .text
            .split_inclusive('\n')
            .take(line.saturating_sub(1))
            .map(str::len)
            .sum();
        let rest = &self.text[start.min(self.text.len())..];
        start
            + rest
                .char_indices()
                .nth(col.saturating_sub(1))
                .map_or(rest.len(), |(i, _)| i)
    }

    /// The first byte at or after `pos` that is neither blank nor inside a comment.
    pub(crate) fn skip_blank(&self, mut pos: usize) -> usize {
        while let Some(c) = self.text[pos..].chars().next() {
            if c.is_whitespace() || self.in_comment(pos) {
                pos += c.len_utf8();
            } else {
                break;
            }
        }
        pos
    }

    /// The `(` matching the `)` at byte `close`, skipping comments and strings.
    fn matching_open(&self, close: usize) -> Option<usize> {
        let bytes = self.text.as_bytes();
        let mut depth = 0i32;
        let mut i = close + 1;
        let mut in_string = false;
        while i > 0 {
            i -= 1;
            if self.in_comment(i) {
                continue;
            }
            match bytes[i] {
                b'"' if i == 0 || bytes[i - 1] != b'\\' => in_string = !in_string,
                b')' | b']' | b'}' if !in_string => depth += 1,
                b'(' | b'[' | b'{' if !in_string => {
                    depth -= 1;
                    if depth == 0 {
                        return Some(i);
                    }
                }
                _ => {}
            }
        }
        None
    }

    /// The start of the item whose parenthesis opens at `open`: the identifier before it
    /// (`Switch(`), if any.
    fn item_start(&self, open: usize) -> usize {
        let before = &self.text[..open];
        let ident = before
            .chars()
            .rev()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .count();
        open - ident
    }

    /// 1-based line and column (in characters) of byte offset `pos`.
    pub fn line_col(&self, pos: usize) -> (usize, usize) {
        self.index.line_col(&self.text, pos)
    }

    fn in_comment(&self, pos: usize) -> bool {
        let i = self.comments.partition_point(|r| r.end <= pos);
        self.comments.get(i).is_some_and(|r| r.contains(&pos))
    }

    /// Byte offsets of every occurrence, outside comments, of the token sequence `parts` (each
    /// part may be preceded by whitespace), e.g. `["Material", "(", "\"x\""]`. Identifier-like
    /// parts must stand alone (not inside a longer identifier).
    pub fn find_all(&self, parts: &[&str]) -> Vec<usize> {
        let mut found = vec![];
        let mut from = 0;
        while let Some(at) = self.find_from(from, parts) {
            found.push(at);
            from = at + 1;
        }
        found
    }

    /// The first occurrence of `parts` at or after byte `from`, outside comments (the search
    /// starts at `from` and stops at the first match).
    pub fn find_from(&self, from: usize, parts: &[&str]) -> Option<usize> {
        let first = parts.first()?;
        let src = &self.text;
        let mut start = from.min(src.len());
        while !src.is_char_boundary(start) {
            start += 1;
        }
        while let Some(off) = src[start..].find(first) {
            let at = start + off;
            start = at + first.len();
            if self.in_comment(at) || !token_boundary(src, at, first) {
                continue;
            }
            let mut pos = at + first.len();
            let ok = parts[1..].iter().all(|p| {
                let rest = &src[pos..];
                let trimmed = rest.trim_start();
                pos += rest.len() - trimmed.len();
                if trimmed.starts_with(p) && token_boundary(src, pos, p) {
                    pos += p.len();
                    true
                } else {
                    false
                }
            });
            if ok {
                return Some(at);
            }
        }
        None
    }

    /// The first occurrence of `parts`, outside comments.
    pub fn find(&self, parts: &[&str]) -> Option<usize> {
        self.find_from(0, parts)
    }

    /// Where the key `"name":` of a map (e.g. a material in `materials`) is first written,
    /// outside comments (looked up in an index built once, so locating many keys stays linear).
    pub fn key(&self, name: &str) -> Option<usize> {
        self.index.key(name)
    }

    /// How deeply brackets, map nodes and fields nest in the text (outside comments and strings).
    pub fn nesting(&self) -> &index::Nesting {
        self.index.nesting()
    }

    /// Where the call `ident("name")` (e.g. `Material("gold")`) is first written outside
    /// comments: the identifier (looked up in an index built once).
    pub fn call(&self, ident: &str, name: &str) -> Option<usize> {
        self.index.call(ident, name)
    }

    /// Locates the field a message starts with (e.g. `coats[1].ior: …`) within the entry whose key
    /// is `name`; falls back to the key itself.
    pub fn locate_field(&self, name: &str, message: &str) -> Option<usize> {
        let key = self.key(name)?;
        let mut pos = key;
        let path = message.split([' ', ':']).next().unwrap_or("");
        for seg in path.split('.') {
            let (field, index) = match seg.split_once('[') {
                Some((f, rest)) => (f, rest.trim_end_matches(']').parse::<usize>().ok()),
                None => (seg, None),
            };
            if field.is_empty() || !field.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
                break;
            }
            let Some(p) = self.find_from(pos, &[field]) else {
                break;
            };
            pos = p;
            if let Some(i) = index {
                pos = self.nth_element(pos, i).unwrap_or(pos);
            }
        }
        Some(pos)
    }

    /// The start of the `i`-th parenthesised element of the list that follows `from`.
    pub(crate) fn nth_element(&self, from: usize, i: usize) -> Option<usize> {
        let mut depth = 0i32;
        let mut count = 0usize;
        for (off, ch) in self.text[from..].char_indices() {
            if self.in_comment(from + off) {
                continue;
            }
            match ch {
                '(' | '[' | '{' => {
                    depth += 1;
                    if depth == 2 && ch == '(' {
                        if count == i {
                            return Some(self.item_start(from + off));
                        }
                        count += 1;
                    }
                }
                ')' | ']' | '}' => {
                    depth -= 1;
                    if depth <= 0 {
                        return None;
                    }
                }
                _ => {}
            }
        }
        None
    }
}

/// Whether an identifier-like `token` at byte `at` stands alone.
fn token_boundary(src: &str, at: usize, token: &str) -> bool {
    let ident = |c: char| c.is_ascii_alphanumeric() || c == '_';
    if !token.chars().next().is_some_and(ident) {
        return true;
    }
    let before = src[..at].chars().next_back();
    let after = src[at + token.len()..].chars().next();
    !before.is_some_and(ident) && !after.is_some_and(ident)
}

/// Byte ranges of `// …` and (nested) `/* … */` comments, outside string literals.
fn comment_ranges(text: &str) -> Vec<Range<usize>> {
    let b = text.as_bytes();
    let mut out = vec![];
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'"' => {
                i += 1;
                while i < b.len() && b[i] != b'"' {
                    i += if b[i] == b'\\' { 2 } else { 1 };
                }
                i += 1;
            }
            b'/' if b.get(i + 1) == Some(&b'/') => {
                let end = text[i..].find('\n').map_or(b.len(), |e| i + e);
                out.push(i..end);
                i = end;
            }
            b'/' if b.get(i + 1) == Some(&b'*') => {
                let start = i;
                let mut depth = 0;
                while i < b.len() {
                    if b[i] == b'/' && b.get(i + 1) == Some(&b'*') {
                        depth += 1;
                        i += 2;
                    } else if b[i] == b'*' && b.get(i + 1) == Some(&b'/') {
                        depth -= 1;
                        i += 2;
                        if depth == 0 {
                            break;
                        }
                    } else {
                        i += 1;
                    }
                }
                out.push(start..i.min(b.len()));
            }
            _ => i += 1,
        }
    }
    out
}

/// 1-based line and column (in characters) of byte offset `pos`.
pub(crate) fn line_col(source: &str, pos: usize) -> (usize, usize) {
    let mut pos = pos.min(source.len());
    while !source.is_char_boundary(pos) {
        pos -= 1;
    }
    let before = &source[..pos];
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

fn line_col_bytes(bytes: &[u8], pos: usize) -> (usize, usize) {
    line_col(
        &String::from_utf8_lossy(&bytes[..pos.min(bytes.len())]),
        pos,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_tokens_outside_comments_and_strings() {
        let s = Source::new(
            "x",
            "// Material(\"a\")\n/* Material(\"a\") /* nested */ */ x: \"// not\", Material ( \"a\" )",
        );
        let at = s.find(&["Material", "(", "\"a\""]).unwrap();
        assert_eq!(line_col(&s.text, at), (2, 47));
        assert_eq!(s.find_all(&["Material", "(", "\"a\""]).len(), 1);
        // Identifiers stand alone.
        assert!(
            Source::new("x", "MaterialX(\"a\")")
                .find(&["Material"])
                .is_none()
        );
    }

    #[test]
    fn locates_fields_of_keyed_entries() {
        let s = Source::new(
            "x",
            "{\n \"m\": (\n  coats: [(ior: 1.5), (ior: 0.5)],\n ),\n}",
        );
        let at = s.locate_field("m", "coats[1].ior = 0.5").unwrap();
        assert_eq!(line_col(&s.text, at), (3, 24));
    }
}
