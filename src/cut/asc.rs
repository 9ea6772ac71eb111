//! GemCad `.asc` designs: the text format faceting diagrams are exchanged in, read and written.
//!
//! The format (GemCad for Windows user's manual, "ASC file" records; GemCad 5): a first line
//! `GemCad <version>`, then one record per line, its kind the first word —
//!
//! - `g <gear> <location>`: the index gear's tooth count and its location (an offset of index 0,
//!   in degrees);
//! - `y <n> <y|n>`: the rotational symmetry and whether it is mirrored (descriptive: every facet is
//!   listed in its tier);
//! - `I <index>`: the refractive index the design was made for;
//! - `H <text>` header lines, `F <text>` footnotes;
//! - `a <angle> <distance> <index> … [n <name>] [G <instructions>]`: one tier — its angle to the
//!   table plane in degrees (positive on the crown, negative on the pavilion, 0 the table, −0 a
//!   culet, ±90 the girdle), the facets' distance from the stone's centre, and the gear index of
//!   each facet (fractional indices allowed); `n` names the tier, `G` starts its cutting
//!   instructions (the rest of the line). A line that starts with a number continues the previous
//!   tier's indices; a line that starts with `G` continues its instructions.
//!
//! Files are Windows-1252 text (UTF-8 is accepted too) with CRLF or LF line ends. Each tier gives
//! one half-space per index: the facet's outward normal is tilted from `+y` (crown) or `−y`
//! (pavilion) by the angle toward the index's azimuth — index 0 toward `−z`, increasing clockwise
//! seen from above (toward `+x` at a quarter of the gear) — and the plane lies `distance` from the
//! centre.

use super::Builder;
use glam::DVec3;
use std::fmt::Write as _;

/// One tier of facets.
#[derive(Clone, Debug, PartialEq)]
pub struct Tier {
    /// Angle to the table plane, degrees (−90 ..= 90; −0 is a pavilion facet).
    pub angle: f64,
    /// Distance of the facets from the centre (design units).
    pub distance: f64,
    /// Gear index of each facet.
    pub indices: Vec<f64>,
    /// Names given with `n`.
    pub names: Vec<String>,
    /// Cutting instructions given with `G`.
    pub instructions: Vec<String>,
    /// Line of the record in its file (1-based).
    pub line: usize,
}

/// A GemCad design.
#[derive(Clone, Debug, PartialEq)]
pub struct Design {
    /// The version line (`GemCad 5.0`).
    pub version: String,
    /// Index gear teeth.
    pub gear: u32,
    /// Gear location, degrees.
    pub location: f64,
    /// Rotational symmetry.
    pub symmetry: u32,
    /// Mirror symmetry.
    pub mirror: bool,
    /// Refractive index the design was made for.
    pub ior: f64,
    /// Header lines.
    pub headers: Vec<String>,
    /// The tiers, in file order.
    pub tiers: Vec<Tier>,
    /// Footnotes.
    pub footnotes: Vec<String>,
}

/// A position in a `.asc` file and what is wrong there.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{line}:{col}: {message}")]
pub struct AscError {
    /// Line, 1-based.
    pub line: usize,
    /// Column (characters), 1-based.
    pub col: usize,
    /// What is wrong, with the allowed range.
    pub message: String,
}

/// Most tiers and facets a design may have (GemCad designs have tens to a few hundred facets).
pub const MAX_FACETS: usize = 4096;

/// Decodes Windows-1252 bytes (UTF-8 when the bytes are valid UTF-8). The 32 codes 0x80–0x9F
/// differ from Latin-1 (Microsoft's code page table); written out here rather than pulling in an
/// encoding crate for one table.
pub fn decode(bytes: &[u8]) -> String {
    if let Ok(s) = std::str::from_utf8(bytes) {
        return s.trim_start_matches('\u{feff}').to_string();
    }
    const HIGH: [char; 32] = [
        '€', '\u{81}', '‚', 'ƒ', '„', '…', '†', '‡', 'ˆ', '‰', 'Š', '‹', 'Œ', '\u{8d}', 'Ž',
        '\u{8f}', '\u{90}', '‘', '’', '“', '”', '•', '–', '—', '˜', '™', 'š', '›', 'œ', '\u{9d}',
        'ž', 'Ÿ',
    ];
    bytes
        .iter()
        .map(|&b| match b {
            0x80..=0x9f => HIGH[usize::from(b - 0x80)],
            _ => char::from(b),
        })
        .collect()
}

/// The words of a line with their 1-based columns.
fn words(line: &str) -> Vec<(usize, &str)> {
    let mut out = vec![];
    let mut start = None;
    for (col, (i, c)) in line.char_indices().enumerate() {
        match (c.is_whitespace(), start) {
            (false, None) => start = Some((col + 1, i)),
            (true, Some((sc, si))) => {
                out.push((sc, &line[si..i]));
                start = None;
            }
            _ => {}
        }
    }
    if let Some((sc, si)) = start {
        out.push((sc, &line[si..]));
    }
    out
}

fn err(line: usize, col: usize, message: impl Into<String>) -> AscError {
    AscError {
        line,
        col,
        message: message.into(),
    }
}

fn number(line: usize, (col, w): (usize, &str), what: &str) -> Result<f64, AscError> {
    w.parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or_else(|| err(line, col, format!("{what}: `{w}` is not a number")))
}

impl Design {
    /// Parses a design (the text of a `.asc` file, already decoded).
    pub fn parse(text: &str) -> Result<Design, AscError> {
        let mut d = Design {
            version: String::new(),
            gear: 96,
            location: 0.0,
            symmetry: 1,
            mirror: false,
            ior: 1.54,
            headers: vec![],
            tiers: vec![],
            footnotes: vec![],
        };
        let mut facets = 0usize;
        for (k, raw) in text.lines().enumerate() {
            let line = k + 1;
            let raw = raw.trim_end_matches('\r');
            let w = words(raw);
            let Some(&(col, kind)) = w.first() else {
                continue;
            };
            if d.version.is_empty() {
                if kind != "GemCad" {
                    return Err(err(
                        line,
                        col,
                        "not a GemCad design: the first line must be `GemCad <version>`",
                    ));
                }
                d.version = raw.trim().to_string();
                continue;
            }
            let rest = |from: usize| -> String {
                w.get(from).map_or(String::new(), |&(c, _)| {
                    raw.chars()
                        .skip(c - 1)
                        .collect::<String>()
                        .trim_end()
                        .to_string()
                })
            };
            match kind {
                "g" => {
                    let gear = number(
                        line,
                        *w.get(1).ok_or_else(|| {
                            err(line, col, "g: the gear's tooth count is missing")
                        })?,
                        "gear",
                    )?;
                    if !((1.0..=400.0).contains(&gear) && gear.fract() == 0.0) {
                        return Err(err(
                            line,
                            w[1].0,
                            format!("gear = {gear}: a whole number of teeth, 1 ..= 400"),
                        ));
                    }
                    d.gear = gear as u32;
                    if let Some(&l) = w.get(2) {
                        d.location = number(line, l, "gear location")?;
                    }
                }
                "y" => {
                    let n = number(
                        line,
                        *w.get(1)
                            .ok_or_else(|| err(line, col, "y: the symmetry is missing"))?,
                        "symmetry",
                    )?;
                    if !((1.0..=400.0).contains(&n) && n.fract() == 0.0) {
                        return Err(err(
                            line,
                            w[1].0,
                            format!("symmetry = {n}: a whole number, 1 ..= 400"),
                        ));
                    }
                    d.symmetry = n as u32;
                    d.mirror = w.get(2).is_some_and(|&(_, m)| m.eq_ignore_ascii_case("y"));
                }
                "I" => {
                    let n = number(
                        line,
                        *w.get(1)
                            .ok_or_else(|| err(line, col, "I: the refractive index is missing"))?,
                        "refractive index",
                    )?;
                    if !(1.0..=5.0).contains(&n) {
                        return Err(err(
                            line,
                            w[1].0,
                            format!("refractive index = {n}: allowed 1 ..= 5"),
                        ));
                    }
                    d.ior = n;
                }
                "H" => d.headers.push(rest(1)),
                "F" => d.footnotes.push(rest(1)),
                "a" => {
                    if w.len() < 3 {
                        return Err(err(line, col, "a: a tier needs an angle and a distance"));
                    }
                    let angle = number(line, w[1], "angle")?;
                    if !(-90.0..=90.0).contains(&angle) {
                        return Err(err(
                            line,
                            w[1].0,
                            format!("angle = {angle}: allowed −90 ..= 90 degrees"),
                        ));
                    }
                    let distance = number(line, w[2], "distance")?;
                    let mut tier = Tier {
                        angle,
                        distance,
                        indices: vec![],
                        names: vec![],
                        instructions: vec![],
                        line,
                    };
                    tier_words(&mut tier, &w[3..], raw, line, d.gear)?;
                    d.tiers.push(tier);
                }
                "G" => {
                    let tier = d
                        .tiers
                        .last_mut()
                        .ok_or_else(|| err(line, col, "G: instructions before any tier"))?;
                    tier.instructions.push(rest(1));
                }
                _ if kind.starts_with(|c: char| c.is_ascii_digit() || c == '-' || c == '.') => {
                    // A continuation of the previous tier's indices.
                    let gear = d.gear;
                    let tier = d
                        .tiers
                        .last_mut()
                        .ok_or_else(|| err(line, col, "an index line before any tier"))?;
                    tier_words(tier, &w, raw, line, gear)?;
                }
                _ => {
                    return Err(err(
                        line,
                        col,
                        format!("unknown record `{kind}`: expected g, y, I, H, F, a or G"),
                    ));
                }
            }
            if let Some(t) = d.tiers.last() {
                facets = d.tiers.iter().map(|t| t.indices.len().max(1)).sum();
                if facets > MAX_FACETS {
                    return Err(err(t.line, 1, format!("more than {MAX_FACETS} facets")));
                }
            }
        }
        if d.version.is_empty() {
            return Err(err(1, 1, "empty file: expected `GemCad <version>`"));
        }
        if d.tiers.is_empty() {
            return Err(err(
                text.lines().count().max(1),
                1,
                "the design has no tiers (`a` lines)",
            ));
        }
        for t in &d.tiers {
            if t.indices.is_empty() && t.angle != 0.0 {
                return Err(err(
                    t.line,
                    1,
                    format!(
                        "the tier at {}° has no facet indices (only a table or culet, at 0°, may have none)",
                        t.angle
                    ),
                ));
            }
        }
        let _ = facets;
        Ok(d)
    }

    /// The design as `.asc` text (LF line ends); [`Design::parse`] reads it back equal.
    pub fn to_text(&self) -> String {
        let mut s = format!("{}\n", self.version);
        let _ = writeln!(s, "g {} {}", self.gear, self.location);
        let _ = writeln!(
            s,
            "y {} {}",
            self.symmetry,
            if self.mirror { "y" } else { "n" }
        );
        let _ = writeln!(s, "I {}", self.ior);
        for h in &self.headers {
            let _ = writeln!(s, "H {h}");
        }
        for t in &self.tiers {
            let angle = if t.angle == 0.0 && t.angle.is_sign_negative() {
                "-0".to_string()
            } else {
                t.angle.to_string()
            };
            let _ = write!(s, "a {angle} {}", t.distance);
            for i in &t.indices {
                let _ = write!(s, " {i}");
            }
            for n in &t.names {
                let _ = write!(s, " n {n}");
            }
            s.push('\n');
            for g in &t.instructions {
                let _ = writeln!(s, "G {g}");
            }
        }
        for f in &self.footnotes {
            let _ = writeln!(s, "F {f}");
        }
        s
    }

    /// The design's facets as named half-spaces (design units) with a point inside: the centre.
    pub(crate) fn builder(&self) -> Result<Builder, AscError> {
        let mut f = Builder::new(DVec3::ZERO);
        for (k, t) in self.tiers.iter().enumerate() {
            let tier = t
                .names
                .first()
                .cloned()
                .unwrap_or_else(|| format!("tier {}", k + 1));
            let pavilion = t.angle < 0.0 || (t.angle == 0.0 && t.angle.is_sign_negative());
            let theta = t.angle.abs().to_radians();
            let vertical = if pavilion { -theta.cos() } else { theta.cos() };
            let indices: Vec<Option<f64>> = if t.indices.is_empty() {
                vec![None]
            } else {
                t.indices.iter().copied().map(Some).collect()
            };
            for i in indices {
                let (u, name) = match i {
                    Some(i) => {
                        let phi = (360.0 * i / f64::from(self.gear) + self.location).to_radians();
                        (
                            DVec3::new(phi.sin(), 0.0, -phi.cos()),
                            format!("{tier} @ {i}"),
                        )
                    }
                    None => (DVec3::ZERO, tier.clone()),
                };
                let n = u * theta.sin() + DVec3::Y * vertical;
                f.with_normal(n, n.normalize() * t.distance, name)
                    .map_err(|e| err(t.line, 1, e.0))?;
            }
        }
        Ok(f)
    }
}

/// Reads a tier's words after its angle and distance: indices, `n NAME`, `G instructions…`.
fn tier_words(
    tier: &mut Tier,
    w: &[(usize, &str)],
    raw: &str,
    line: usize,
    gear: u32,
) -> Result<(), AscError> {
    let mut k = 0;
    while k < w.len() {
        let (col, word) = w[k];
        match word {
            "n" => {
                let &(_, name) = w
                    .get(k + 1)
                    .ok_or_else(|| err(line, col, "n: the name is missing"))?;
                tier.names.push(name.to_string());
                k += 2;
            }
            "G" => {
                let text: String = w.get(k + 1).map_or(String::new(), |&(c, _)| {
                    raw.chars()
                        .skip(c - 1)
                        .collect::<String>()
                        .trim_end()
                        .to_string()
                });
                tier.instructions.push(text);
                return Ok(());
            }
            _ => {
                let i = number(line, (col, word), "facet index")?;
                if !(0.0..=f64::from(gear)).contains(&i) {
                    return Err(err(
                        line,
                        col,
                        format!("index {i}: allowed 0 ..= {gear} (the gear)"),
                    ));
                }
                tier.indices.push(i);
                k += 1;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A test design written for this crate (not from a published diagram): an 8-fold round with
    /// a table, crown mains, girdle, pavilion mains and a culet.
    pub(crate) const OCTAGON: &str = "GemCad 5.0\r\ng 96 0.0\r\ny 8 y\r\nI 1.54\r\nH Test octagon\r\nH lapidary's own\r\na 0 0.42 n T\r\na 35 0.62 0 12 24 36 48 60 72 84 n C G Cut to meet\r\nG at the table.\r\na 90 0.75 0 12 24 36\r\n 48 60 72 84 n Girdle\r\na -41 0.62 0 12 24 36 48 60 72 84 n P\r\na -0 0.76 n Culet\r\nF Footnote \u{2014} dashes\r\n";

    #[test]
    fn reads_writes_and_reads_again() {
        let d = Design::parse(OCTAGON).unwrap();
        assert_eq!((d.gear, d.symmetry, d.mirror, d.ior), (96, 8, true, 1.54));
        assert_eq!(d.headers, ["Test octagon", "lapidary's own"]);
        assert_eq!(d.tiers.len(), 5);
        assert_eq!(d.tiers[1].instructions, ["Cut to meet", "at the table."]);
        assert_eq!(d.tiers[2].indices.len(), 8, "continued indices");
        assert!(d.tiers[4].angle == 0.0 && d.tiers[4].angle.is_sign_negative());
        let again = Design::parse(&d.to_text()).unwrap();
        // Lines move in the rewrite; everything else is equal.
        let strip = |d: &Design| {
            let mut d = d.clone();
            d.tiers.iter_mut().for_each(|t| t.line = 0);
            d
        };
        assert_eq!(strip(&again), strip(&d));
        // Windows-1252: the em dash is byte 0x97.
        let mut bytes = OCTAGON.replace('\u{2014}', "").into_bytes();
        let at = bytes.len() - 8;
        bytes.insert(at, 0x97);
        assert!(decode(&bytes).contains('—'));
    }

    #[test]
    fn broken_designs_are_refused_at_their_position() {
        for (text, line, col, want) in [
            ("Gem 5\n", 1, 1, "not a GemCad design"),
            ("GemCad 5.0\ng 0 0\n", 2, 3, "1 ..= 400"),
            ("GemCad 5.0\na 95 1.0 0\n", 2, 3, "−90 ..= 90"),
            ("GemCad 5.0\na 40 x 0\n", 2, 6, "not a number"),
            ("GemCad 5.0\na 40 1.0 0 97\n", 2, 12, "0 ..= 96"),
            ("GemCad 5.0\na 40 1.0\n", 2, 1, "no facet indices"),
            ("GemCad 5.0\nq 1\n", 2, 1, "unknown record"),
            ("GemCad 5.0\n 12 24\n", 2, 2, "before any tier"),
            ("GemCad 5.0\nI 9\na 0 1\n", 2, 3, "1 ..= 5"),
            ("GemCad 5.0\n", 1, 1, "no tiers"),
        ] {
            let e = Design::parse(text).unwrap_err();
            assert_eq!((e.line, e.col), (line, col), "{text:?}: {e}");
            assert!(e.message.contains(want), "{text:?}: {e}");
        }
    }
}
