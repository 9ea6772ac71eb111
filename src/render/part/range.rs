//! Sample ranges `A..B` of a render's samples per pixel, as `--samples` and part files give them.

use std::ops::Range;

/// Formats a sample range as `A..B`.
pub fn format_range(r: &Range<u32>) -> String {
    format!("{}..{}", r.start, r.end)
}

/// Most samples per pixel a render takes (`--spp`, a recipe's `spp`): the largest bound of a
/// sample range.
pub const MAX_SPP: u32 = 1 << 20;

/// Parses `A..B` (`A < B` ≤ [`MAX_SPP`]); the error says what was expected.
pub fn parse_range(s: &str) -> Result<Range<u32>, String> {
    let err = || format!("`{s}`: expected a sample range A..B with A < B, e.g. 0..64");
    let (a, b) = s.split_once("..").ok_or_else(err)?;
    let bound = |t: &str| -> Result<u32, String> {
        let t = t.trim();
        if t.is_empty() || !t.bytes().all(|c| c.is_ascii_digit()) {
            return Err(err());
        }
        match t.parse::<u32>() {
            Ok(v) if v <= MAX_SPP => Ok(v),
            _ => Err(format!(
                "`{s}`: {t} is too large: a sample range lies within 0..{MAX_SPP} (the most \
                 samples per pixel)"
            )),
        }
    };
    let (a, b) = (bound(a)?, bound(b)?);
    if a >= b {
        return Err(err());
    }
    Ok(a..b)
}
