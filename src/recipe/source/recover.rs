//! Error recovery while parsing, so that one `lapidary check` reports every error it can find.
//!
//! A value that reads fine but is not allowed (a number out of its range, a non-finite
//! coordinate, Switch thresholds out of order, a name defined twice) does not stop the parser:
//! the check that refuses it (`refuse`) records its message and hands the parser a **stand-in**
//! (the nearest allowed value, or the field's neutral value), and parsing goes on — so the
//! values after it, and the checks made after parsing (unknown names, includes, materials, the
//! map tree, the stage), are reported too. The stand-ins never reach a render: a recipe with any
//! error compiles into no scene.
//!
//! **Positions.** The parser knows where it is only when an error is *returned*, so each recorded
//! value error is located by parsing the text again with that one error returned
//! (`Source::recovering`): the error then carries exactly the position (and message) it has when
//! it is the only one in the file. Those parses stop at their error, so locating `k` errors costs at most
//! `k` parses of the text before them: at most [`MAX_VALUE_ERRORS`] are recorded per file, and
//! in a file larger than about 1.3 MiB at most [`LOCATING_BYTES`] / its size (at least one), which
//! keeps a check within about [`LOCATING_BYTES`] of parsing.
//!
//! **What still stops the parser**: a syntax error (nothing after it can be trusted), an unknown
//! field or variant, a value of the wrong kind (a string for a number), a list that is empty or too
//! long, more value errors than are recorded (the next one), and errors the parser raises itself (an
//! integer literal too large for its field).
//!
//! Outside `Source::recovering` (a description parsed directly with `ron`), `refuse` returns
//! the error as before.

use super::Source;
use crate::recipe::RecipeError;
use std::cell::RefCell;

/// Most value errors recorded in one file: the next one stops the parser (and is reported too).
/// Each recorded error costs one more parse of the text before it.
pub const MAX_VALUE_ERRORS: usize = 50;
/// Bytes of text the parses that locate value errors may read together (a large file records
/// fewer value errors: see the module docs).
pub const LOCATING_BYTES: usize = 64 << 20;

/// How many value errors a text of `len` bytes may record before the next stops the parser.
pub fn value_error_limit(len: usize) -> usize {
    (LOCATING_BYTES / len.max(1)).clamp(1, MAX_VALUE_ERRORS)
}

/// The recording of one parse.
#[derive(Debug, Default)]
struct Recording {
    /// The value error to return as an error (its index among those met), locating it.
    stop_at: Option<usize>,
    /// How many value errors may be recorded; the next is returned as an error.
    limit: usize,
    /// Value errors met so far.
    met: usize,
    /// Their messages, in the order met.
    messages: Vec<String>,
}

thread_local! {
    /// The recording of the parse running on this thread, if it recovers.
    static RECORDING: RefCell<Option<Recording>> = const { RefCell::new(None) };
}

/// Refuses a value that was read: records `message` and returns `stand_in` (parsing goes on)
/// while [`Source::recovering`] runs on this thread; otherwise — or for the error being located,
/// or past the recording's limit ([`value_error_limit`]) — returns `message` as the deserializer's
/// error.
pub(crate) fn refuse<T, E: serde::de::Error>(message: String, stand_in: T) -> Result<T, E> {
    let recorded = RECORDING.with(|r| {
        let mut r = r.borrow_mut();
        let Some(rec) = r.as_mut() else {
            return false;
        };
        let index = rec.met;
        rec.met += 1;
        if rec.stop_at == Some(index) || index >= rec.limit {
            return false;
        }
        if rec.stop_at.is_none() {
            rec.messages.push(message.clone());
        }
        true
    });
    if recorded {
        Ok(stand_in)
    } else {
        Err(E::custom(message))
    }
}

/// Runs `parse` with a fresh recording (restoring whatever was there before); its result and the
/// value errors recorded.
fn recording<T>(
    stop_at: Option<usize>,
    limit: usize,
    parse: impl FnOnce() -> T,
) -> (T, Vec<String>) {
    let fresh = Recording {
        stop_at,
        limit,
        ..Recording::default()
    };
    let outer = RECORDING.with(|r| r.replace(Some(fresh)));
    // Restored even if `parse` panics (a bug), so a later parse on this thread is not confused.
    struct Restore(Option<Option<Recording>>);
    impl Drop for Restore {
        fn drop(&mut self) {
            let outer = self.0.take().flatten();
            RECORDING.with(|r| *r.borrow_mut() = outer);
        }
    }
    let restore = Restore(Some(outer));
    let out = parse();
    let messages = RECORDING.with(|r| r.borrow_mut().take().map(|rec| rec.messages));
    drop(restore);
    (out, messages.unwrap_or_default())
}

impl Source {
    /// Parses the text with `parse` (a RON parse of `self.text`), recovering from value errors
    /// (module docs): the value, when the parser reached the end, and every error found, in the
    /// order met — each recorded value error at its own position, then the error that stopped the
    /// parser, if one did. A value comes with errors when only value errors were found.
    pub(crate) fn recovering<T>(
        &self,
        parse: impl Fn(&str) -> Result<T, ron::error::SpannedError>,
    ) -> (Option<T>, Vec<RecipeError>) {
        let limit = value_error_limit(self.text.len());
        let (result, messages) = recording(None, limit, || parse(&self.text));
        let mut errors = Vec::with_capacity(messages.len() + 1);
        for (i, message) in messages.into_iter().enumerate() {
            let (again, _) = recording(Some(i), limit, || parse(&self.text));
            errors.push(match again {
                Err(e) if matches!(&e.code, ron::Error::Message(m) if *m == message) => {
                    self.value_error(&e)
                }
                // The same text parses the same way, so this is not expected; the message is
                // still right.
                _ => self.error(None, message),
            });
        }
        match result {
            Ok(value) => (Some(value), errors),
            Err(e) => {
                errors.push(self.ron_error(&e));
                (None, errors)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(v: i32) -> Result<i32, ron::Error> {
        if v < 0 {
            refuse(format!("{v} < 0"), 0)
        } else {
            Ok(v)
        }
    }

    #[test]
    fn refusals_are_errors_outside_a_recording() {
        assert_eq!(check(1), Ok(1));
        assert!(matches!(check(-1), Err(ron::Error::Message(m)) if m == "-1 < 0"));
    }

    #[test]
    fn a_recording_keeps_messages_and_stops_where_asked() {
        let run = || (check(-1), check(2), check(-3));
        let ((a, b, c), messages) = recording(None, 9, run);
        assert_eq!((a, b, c), (Ok(0), Ok(2), Ok(0)));
        assert_eq!(messages, ["-1 < 0", "-3 < 0"]);
        let ((a, _, c), messages) = recording(Some(1), 9, run);
        assert!(a.is_ok() && c.is_err() && messages.is_empty());
        // Nested recordings do not disturb the outer one, which ends with its own.
        let ((_, inner), messages) = recording(None, 9, || (check(-5), recording(None, 9, run).1));
        assert_eq!((inner.len(), messages), (2, vec!["-5 < 0".to_string()]));
        assert!(check(-1).is_err());
    }

    #[test]
    fn at_most_the_limit_is_recorded() {
        let limit = value_error_limit(1000);
        assert_eq!(limit, MAX_VALUE_ERRORS);
        let (results, messages) = recording(None, limit, || {
            (0..limit + 2)
                .map(|_| check(-1).is_ok())
                .collect::<Vec<_>>()
        });
        assert_eq!(messages.len(), limit);
        assert!(results[..limit].iter().all(|&ok| ok));
        assert!(!results[limit]);
        // A large file records fewer, and at least one.
        assert_eq!(value_error_limit(16 << 20), 4);
        assert_eq!(value_error_limit(usize::MAX), 1);
    }

    #[test]
    fn every_value_error_is_located_as_if_alone() {
        #[derive(Debug, serde::Deserialize)]
        #[allow(dead_code)]
        struct P {
            #[serde(deserialize_with = "positive")]
            a: i32,
            #[serde(deserialize_with = "positive")]
            b: i32,
        }
        fn positive<'de, D: serde::Deserializer<'de>>(d: D) -> Result<i32, D::Error> {
            let v = <i32 as serde::Deserialize>::deserialize(d)?;
            if v > 0 {
                Ok(v)
            } else {
                refuse(format!("{v} ≤ 0"), 1)
            }
        }
        let parse = |t: &str| ron::from_str::<P>(t);
        let s = Source::new("p.ron", "(\n a: -1,\n b: 0,\n)");
        let (p, errors) = s.recovering(parse);
        assert!(p.is_some());
        let at: Vec<_> = errors
            .iter()
            .map(|e| (e.line, e.col, &*e.message))
            .collect();
        assert_eq!(at, [(2, 5, "-1 ≤ 0"), (3, 5, "0 ≤ 0")]);
        // A syntax error after them stops the parser; the value errors before it are kept.
        let s = Source::new("p.ron", "(\n a: -1,\n b: 0 x)");
        let (p, errors) = s.recovering(parse);
        assert!(p.is_none() && errors.len() == 3, "{errors:?}");
        assert_eq!((errors[2].line, errors[2].col), (3, 7));
    }
}
