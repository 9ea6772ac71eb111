//! Odd text that RON would misread or report badly, refused before parsing with a positioned
//! message that shows the offending characters escaped:
//!
//! - a carriage return not followed by a line feed (old Mac line endings): RON treats it as a
//!   blank, so every line number after it would be wrong, and a `//` comment would swallow the
//!   rest of the file;
//! - a control character (U+0000 … U+001F, U+007F … U+009F) written raw outside comments, or held
//!   by a string literal raw or through an escape (`"ab\u{7}c"`): names and file names never need
//!   one, and printed raw it would garble the message that quotes it.
//!
//! A UTF-8 byte-order mark at the start of a file is not odd: [`strip_bom`] drops it before
//! anything is indexed, so positions count from the first character after it.
//!
//! Also here: [`Source::integer_detail`], the project's words for the parser's integer errors.

use super::Source;
use crate::recipe::RecipeError;

/// `text` without a leading UTF-8 byte-order mark (U+FEFF), which editors on Windows write.
pub(super) fn strip_bom(text: &str) -> &str {
    text.strip_prefix('\u{feff}').unwrap_or(text)
}

/// A control character other than the line breaks and tabs that text files hold.
fn odd_control(c: char) -> bool {
    c.is_control() && !matches!(c, '\n' | '\t' | '\r')
}

impl Source {
    /// Parses the text as `T` with the project's RON options, after [`Source::check_text`];
    /// errors are positioned ([`Source::ron_error`]).
    pub fn parse<T: serde::de::DeserializeOwned>(&self) -> Result<T, RecipeError> {
        self.check_text()?;
        crate::recipe::ron_options()
            .from_str(&self.text)
            .map_err(|e| self.ron_error(&e))
    }

    /// Refuses lone carriage returns and control characters (see the module docs), at the first
    /// one found.
    pub fn check_text(&self) -> Result<(), RecipeError> {
        let t = &self.text;
        let b = t.as_bytes();
        if let Some(cr) = (0..b.len()).find(|&i| b[i] == b'\r' && b.get(i + 1) != Some(&b'\n')) {
            return Err(self.error(
                Some(cr),
                "a carriage return (`\\r`) that is not followed by a line feed: lines must end \
                 in LF or CRLF (old Mac line endings would make every position after it wrong)",
            ));
        }
        // One pass; the comments are sorted, so the next one is all that needs looking at.
        let mut comments = self.comments.iter().peekable();
        let mut i = 0;
        while i < t.len() {
            while comments.peek().is_some_and(|c| c.end <= i) {
                comments.next();
            }
            if let Some(c) = comments.peek()
                && c.contains(&i)
            {
                i = c.end;
                continue;
            }
            let Some(c) = t[i..].chars().next() else {
                break;
            };
            if c == '"' {
                let (end, value) = string_literal(t, i);
                if let Some(bad) = value.chars().find(|&c| c.is_control()) {
                    return Err(self.error(
                        Some(i),
                        format!(
                            "the string {value:?} holds a control character (U+{:04X}): names and \
                             file names may not",
                            bad as u32
                        ),
                    ));
                }
                i = end;
                continue;
            }
            if odd_control(c) {
                return Err(self.error(
                    Some(i),
                    format!(
                        "control character {:?} (U+{:04X}) in the text",
                        c.escape_debug().to_string(),
                        c as u32
                    ),
                ));
            }
            i += c.len_utf8();
        }
        Ok(())
    }

    /// For the parser's integer errors (a number too large or negative for its field, a float
    /// where a whole number belongs), a message naming the field, quoting the literal at byte
    /// `pos`, and giving the range of a seed (the only whole-number fields whose range is their
    /// type's); other fields check their own range when read (see `ranged::whole`).
    pub(super) fn integer_detail(&self, code: &ron::Error, pos: usize) -> Option<String> {
        let what = match code {
            ron::Error::IntegerOutOfBounds => "is out of range",
            ron::Error::InvalidIntegerDigit { .. }
            | ron::Error::ExpectedInteger
            | ron::Error::UnderscoreAtBeginning => "is not a whole number",
            _ => return None,
        };
        let t = &self.text;
        let number = |c: char| c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '+' | '-');
        let start = t[..pos.min(t.len())]
            .char_indices()
            .rev()
            .take_while(|&(_, c)| number(c))
            .last()
            .map_or(pos, |(i, _)| i);
        let literal: String = t[start..].chars().take_while(|&c| number(c)).collect();
        let before = t[..start].trim_end().strip_suffix(':')?.trim_end();
        let field: String = before
            .chars()
            .rev()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect::<Vec<_>>()
            .into_iter()
            .rev()
            .collect();
        if field.is_empty() {
            return None;
        }
        let range = if field == "seed" {
            format!(
                ": allowed 0 ..= {} (a whole number)",
                crate::recipe::ranged::whole_bound(u64::MAX)
            )
        } else {
            String::from(" for the field (see its range in docs/recipes.md)")
        };
        Some(format!("{field} = {literal} {what}{range}"))
    }
}

/// The string literal opening at byte `open` (a `"`): the byte after its closing quote, and its
/// value with RON's escapes (`\n`, `\t`, `\0`, `\xHH`, `\u{…}`, …) decoded. An unknown escape is
/// kept as written (the parser reports it).
fn string_literal(t: &str, open: usize) -> (usize, String) {
    let mut value = String::new();
    let mut chars = t[open + 1..].char_indices();
    while let Some((off, c)) = chars.next() {
        match c {
            '"' => return (open + 1 + off + 1, value),
            '\\' => {
                let Some((_, e)) = chars.next() else { break };
                let simple = match e {
                    'n' => Some('\n'),
                    'r' => Some('\r'),
                    't' => Some('\t'),
                    '0' => Some('\0'),
                    '\\' | '"' | '\'' => Some(e),
                    _ => None,
                };
                if let Some(s) = simple {
                    value.push(s);
                    continue;
                }
                let rest = chars.as_str();
                let (code, used) = match e {
                    'x' => (
                        rest.get(..2).and_then(|h| u32::from_str_radix(h, 16).ok()),
                        2,
                    ),
                    'u' => match rest.strip_prefix('{').and_then(|r| r.split_once('}')) {
                        Some((h, _)) => (u32::from_str_radix(h, 16).ok(), h.len() + 2),
                        None => (None, 0),
                    },
                    _ => (None, 0),
                };
                match code.and_then(char::from_u32) {
                    Some(c) => {
                        value.push(c);
                        for _ in 0..used {
                            chars.next();
                        }
                    }
                    None => {
                        value.push('\\');
                        value.push(e);
                    }
                }
            }
            c => value.push(c),
        }
    }
    (t.len(), value)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decodes_escapes() {
        let t = r#"x "a\u{7}b\x01\n\"q" y"#;
        let (end, v) = string_literal(t, 2);
        assert_eq!(v, "a\u{7}b\u{1}\n\"q");
        assert_eq!(&t[end..], " y");
    }

    #[test]
    fn odd_characters_are_refused_where_they_are() {
        let err = |t: &str| Source::new("x", t).check_text().unwrap_err();
        let e = err("(\n  a: \"ab\u{7}c\",\n)");
        assert_eq!((e.line, e.col), (2, 6));
        assert!(e.message.contains(r#""ab\u{7}c""#), "{}", e.message);
        let e = err("(\n  a: \"ab\\u{1b}c\",\n)");
        assert!(e.message.contains(r#""ab\u{1b}c""#), "{}", e.message);
        let e = err("(a: 1,\r b: 2)");
        assert!(
            (e.line, e.col) == (1, 7) && e.message.contains("`\\r`"),
            "{e}"
        );
        let e = err("(a:\u{1} 1)");
        assert!(
            (e.line, e.col) == (1, 4) && e.message.contains("\\u{1}"),
            "{}",
            e.message
        );
        // Comments, CRLF and tabs are fine; a BOM is dropped by `Source::new`.
        let ok = "// \u{7}\r\n(\ta: \"x\")\r\n";
        assert!(Source::new("x", ok).check_text().is_ok());
        assert_eq!(strip_bom("\u{feff}(a)"), "(a)");
    }
}
