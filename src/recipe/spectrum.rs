//! Spectra in recipes (issue 19): a list of `(wavelength nm, value)` points written inline, or a
//! CSV file of such points named by a path relative to the recipe's folder.
//!
//! ```ron
//! absorption_spectrum: [(400, 0.8), (550, 0.2), (700, 0.1)],
//! absorption_spectrum: "spectra/sunstone.csv",
//! absorption_spectrum: (file: "spectra/sunstone.csv", scale: 2.5),
//! albedo: Spectrum([(400, 0.1), (700, 0.6)]),
//! ```
//!
//! **CSV.** One point per row, `wavelength_nm,value`: two decimal numbers (Rust's `f32` syntax:
//! `400`, `0.25`, `.5`, `1e-3`; not `0x190`, `4_00` or a decimal comma) separated by a comma,
//! spaces around them ignored, a field may be double-quoted. `#` starts a comment to the end of
//! its line, whether the line holds nothing else or comes after a row's values (`400,0.1 # blue`):
//! a `#` cannot be part of a number, so a trailing note is unambiguous, and spectra copied from
//! annotated tables need no editing. Blank lines are skipped. The first row is a **header** (and
//! skipped) only when none of its fields begins like a number — with a digit, a sign or a `.` —
//! so `wavelength_nm,value` or `"lambda (nm)","R"` is a header while `0x190,0.1` is data that
//! does not parse and is refused, never silently dropped. The file must be a regular UTF-8 file
//! (a leading byte order mark is skipped) of at most [`MAX_FILE_BYTES`] bytes with at most
//! [`MAX_POINTS`] rows; an error names `FILE:LINE`, with the path as the user finds it (joined to
//! the recipe's folder), what was found and what is expected. The points are checked (wavelengths increasing in 200 ..= 2000 nm,
//! values in the field's range) where the recipe uses them ([`SpectrumDesc::measured`]), which
//! keeps each point's line so that those errors also name `FILE:LINE`. The file is read when the
//! recipe is parsed, so the parsed recipe holds the points and the path only for messages.

use crate::spectrum::measured::{MAX_POINTS, Measured};
use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::{Deserialize, Serialize, Serializer};
use std::cell::RefCell;
use std::fmt;
use std::io::Read;
use std::path::{Path, PathBuf};

/// Largest coefficient (per object unit) a recipe may give.
pub const SIGMA_MAX: f32 = 1e4;

/// Largest CSV file a recipe may name, bytes.
pub const MAX_FILE_BYTES: u64 = 1 << 20;
/// Largest `scale` a spectrum may be given.
pub const MAX_SCALE: f32 = 1e4;

/// A spectrum as a recipe gives it: the points (after reading a file and applying `scale`) and,
/// when they came from a file, where (for messages).
#[derive(Clone, Debug, PartialEq)]
pub struct SpectrumDesc {
    /// `(wavelength nm, value)` points, in the order given.
    pub points: Vec<(f32, f32)>,
    /// The CSV file the points were read from, `None` for inline points (boxed: most spectra in
    /// a recipe's colours are absent, and a colour stays small).
    pub csv: Option<Box<CsvSource>>,
}

/// Where a spectrum's points came from.
#[derive(Clone, Debug, PartialEq)]
pub struct CsvSource {
    /// The file as written in the recipe.
    pub file: String,
    /// The file's path as messages show it: joined to the recipe's folder, so a user finds it
    /// from the working directory.
    pub path: String,
    /// The factor the file's values were multiplied by (1 unless given).
    pub scale: f32,
    /// The line (1-based) of each point in the file.
    pub lines: Vec<usize>,
}

thread_local! {
    /// The folder relative CSV paths are read from while a recipe is parsed on this thread.
    static BASE: RefCell<Option<PathBuf>> = const { RefCell::new(None) };
}

/// Runs `f` (a parse) with relative spectrum paths resolved against `base` (the recipe's
/// folder; `None`: the working directory).
pub(crate) fn with_base<T>(base: Option<&Path>, f: impl FnOnce() -> T) -> T {
    let old = BASE.with(|b| b.replace(base.map(Path::to_path_buf)));
    let out = f();
    BASE.with(|b| *b.borrow_mut() = old);
    out
}

/// Whether a CSV field begins like a number (a digit, a sign or a decimal point): a first row
/// with such a field is data, not a header.
fn looks_numeric(field: &str) -> bool {
    field
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_digit() || matches!(c, '+' | '-' | '.'))
}

/// The fields of one CSV line with its `# comment` removed: split at commas outside double
/// quotes, each trimmed and unquoted (`""` inside quotes is one `"`). None for a blank line.
fn fields(line: &str) -> Vec<String> {
    let (mut out, mut field, mut quoted) = (Vec::new(), String::new(), false);
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                chars.next();
                field.push('"');
            }
            '"' => quoted = !quoted,
            '#' if !quoted => break,
            ',' if !quoted => out.push(std::mem::take(&mut field).trim().to_string()),
            c => field.push(c),
        }
    }
    out.push(field.trim().to_string());
    if out.len() == 1 && out[0].is_empty() {
        out.clear();
    }
    out
}

/// `(nm, value)` points, the CSV line of each, and the file's path as messages show it.
type CsvPoints = (Vec<(f32, f32)>, Vec<usize>, String);

/// Reads the CSV file `written` (relative to the recipe's folder).
fn read_csv(written: &str) -> Result<CsvPoints, String> {
    let path = BASE.with(|b| match &*b.borrow() {
        Some(base) if Path::new(written).is_relative() => base.join(written),
        _ => PathBuf::from(written),
    });
    let shown = path.display().to_string();
    let meta = std::fs::metadata(&path).map_err(|e| format!("spectrum file {shown}: {e}"))?;
    if !meta.is_file() {
        return Err(format!("spectrum file {shown}: not a regular file"));
    }
    if meta.len() > MAX_FILE_BYTES {
        return Err(format!(
            "spectrum file {shown}: {} bytes: allowed at most {MAX_FILE_BYTES}",
            meta.len()
        ));
    }
    let mut bytes = Vec::new();
    std::fs::File::open(&path)
        .and_then(|f| f.take(MAX_FILE_BYTES + 1).read_to_end(&mut bytes))
        .map_err(|e| format!("spectrum file {shown}: {e}"))?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(format!(
            "spectrum file {shown}: more than {MAX_FILE_BYTES} bytes: allowed at most \
             {MAX_FILE_BYTES}"
        ));
    }
    let text = String::from_utf8(bytes).map_err(|e| {
        let line = 1 + e.as_bytes()[..e.utf8_error().valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        format!("{shown}:{line}: not UTF-8 text: expected `wavelength_nm,value` rows")
    })?;
    const ROW: &str = "expected `wavelength_nm,value`: two decimal numbers separated by a comma, \
                       such as `400,0.25`";
    let (mut points, mut lines, mut first) = (Vec::new(), Vec::new(), true);
    // A byte order mark is not part of the first field.
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let f = fields(raw);
        if f.is_empty() {
            continue; // blank or a comment
        }
        // A first row none of whose fields begins like a number is a header.
        let was_first = std::mem::replace(&mut first, false);
        if was_first && !f.iter().any(|s| looks_numeric(s)) {
            continue;
        }
        let header_note = if was_first {
            " (a first row is a header only when no field begins with a digit, sign or `.`)"
        } else {
            ""
        };
        if f.len() != 2 {
            return Err(format!(
                "{shown}:{line}: found {} field{} `{}`; {ROW}{header_note}",
                f.len(),
                if f.len() == 1 { "" } else { "s" },
                f.join(",")
            ));
        }
        let number = |k: usize, what: &str| {
            f[k].parse::<f32>().map_err(|_| {
                let found = if f[k].is_empty() {
                    format!("{what} is missing")
                } else {
                    format!("{what} `{}` is not a decimal number", f[k])
                };
                format!("{shown}:{line}: {found}; {ROW}{header_note}")
            })
        };
        let (l, v) = (number(0, "wavelength")?, number(1, "value")?);
        if points.len() == MAX_POINTS {
            return Err(format!(
                "{shown}:{line}: more than {MAX_POINTS} points: allowed 2 ..= {MAX_POINTS}"
            ));
        }
        points.push((l, v));
        lines.push(line);
    }
    if points.is_empty() {
        return Err(format!(
            "spectrum file {shown}: no `wavelength_nm,value` rows"
        ));
    }
    Ok((points, lines, shown))
}

impl SpectrumDesc {
    /// The points of the CSV file `file` times `scale`.
    fn from_file(file: String, scale: f32) -> Result<SpectrumDesc, String> {
        if !(scale.is_finite() && scale > 0.0 && scale <= MAX_SCALE) {
            return Err(format!(
                "spectrum scale {scale} is out of range: allowed 0 <.. {MAX_SCALE:e}"
            ));
        }
        let (points, lines, path) = read_csv(&file)?;
        Ok(SpectrumDesc {
            points: points.into_iter().map(|(l, v)| (l, v * scale)).collect(),
            csv: Some(Box::new(CsvSource {
                file,
                path,
                scale,
                lines,
            })),
        })
    }

    /// A spectrum given inline.
    pub fn inline(points: Vec<(f32, f32)>) -> SpectrumDesc {
        SpectrumDesc { points, csv: None }
    }

    /// The spectrum on the 10 nm grid, values checked within `0 ..= max`
    /// ([`Measured::from_points`]), or what is wrong: for points from a CSV file
    /// `FILE:LINE: what` (the offending row's line; `FILE: what` for the list as a whole, with the
    /// scale when one multiplied the file's values), for inline points `spectrum point I: what`.
    pub fn measured(&self, max: f32) -> Result<Measured, String> {
        Measured::try_from_points(&self.points, max).map_err(|e| {
            let Some(csv) = &self.csv else {
                return e.to_string();
            };
            let path = &csv.path;
            let scaled = if csv.scale == 1.0 {
                String::new()
            } else {
                format!(" (the file's values × scale {})", csv.scale)
            };
            match e.point.and_then(|i| csv.lines.get(i)) {
                Some(line) => format!("{path}:{line}: {}{scaled}", e.message),
                None => format!("{path}: {}", e.message),
            }
        })
    }
}

struct SpectrumVisitor;

impl<'de> Visitor<'de> for SpectrumVisitor {
    type Value = SpectrumDesc;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(
            "a spectrum: a list of (nm, value) points, a CSV file name, or (file: \"…\", scale: s)",
        )
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<SpectrumDesc, A::Error> {
        let mut points = Vec::new();
        while let Some(p) = seq.next_element::<(f32, f32)>()? {
            if points.len() == MAX_POINTS {
                return Err(de::Error::custom(format!(
                    "a spectrum has more than {MAX_POINTS} points: allowed 2 ..= {MAX_POINTS}"
                )));
            }
            points.push(p);
        }
        Ok(SpectrumDesc::inline(points))
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<SpectrumDesc, E> {
        SpectrumDesc::from_file(v.to_string(), 1.0).map_err(E::custom)
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<SpectrumDesc, A::Error> {
        let (mut file, mut scale) = (None::<String>, None::<f32>);
        while let Some(key) = map.next_key::<String>()? {
            match key.as_str() {
                "file" if file.is_none() => file = Some(map.next_value()?),
                "scale" if scale.is_none() => scale = Some(map.next_value()?),
                "file" | "scale" => {
                    return Err(de::Error::custom(format!("spectrum: `{key}` given twice")));
                }
                other => {
                    return Err(de::Error::custom(format!(
                        "spectrum: unknown field `{other}`: expected `file` or `scale`"
                    )));
                }
            }
        }
        let file = file.ok_or_else(|| de::Error::custom("spectrum: `file` is required"))?;
        SpectrumDesc::from_file(file, scale.unwrap_or(1.0)).map_err(de::Error::custom)
    }
}

impl<'de> Deserialize<'de> for SpectrumDesc {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<SpectrumDesc, D::Error> {
        d.deserialize_any(SpectrumVisitor)
    }
}

impl Serialize for SpectrumDesc {
    /// The points, inline (a file's points are written out, so the output stands alone).
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.points.serialize(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<SpectrumDesc, String> {
        crate::recipe::ron_options()
            .from_str::<SpectrumDesc>(text)
            .map_err(|e| e.to_string())
    }

    #[test]
    fn inline_points_parse() {
        let s = parse("[(400, 0.5), (700.5, 1)]").unwrap();
        assert_eq!(s.points, vec![(400.0, 0.5), (700.5, 1.0)]);
        assert_eq!(s.csv, None);
    }

    #[test]
    fn csv_files_read_relative_to_the_base_with_scale_and_header() {
        let dir = std::env::temp_dir().join(format!("lapidary-spectrum-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(
            dir.join("s.csv"),
            "# a comment\nwavelength_nm,value\n400, 0.25\n# another\n700,0.5\n",
        )
        .unwrap();
        let s = with_base(Some(&dir), || parse("\"s.csv\"")).unwrap();
        assert_eq!(s.points, vec![(400.0, 0.25), (700.0, 0.5)]);
        let s = with_base(Some(&dir), || parse("(file: \"s.csv\", scale: 4)")).unwrap();
        assert_eq!(s.points, vec![(400.0, 1.0), (700.0, 2.0)]);
        assert_eq!(s.csv.as_ref().map(|c| c.file.as_str()), Some("s.csv"));
        // Errors name the file and line, or what is wrong.
        std::fs::write(dir.join("bad.csv"), "400,0.25\n500,x\n").unwrap();
        let e = with_base(Some(&dir), || parse("\"bad.csv\"")).unwrap_err();
        assert!(e.contains("bad.csv:2"), "{e}");
        let e = with_base(Some(&dir), || parse("\"missing.csv\"")).unwrap_err();
        assert!(e.contains("missing.csv"), "{e}");
        let e = with_base(Some(&dir), || parse("(file: \"s.csv\", scale: -1)")).unwrap_err();
        assert!(e.contains("allowed 0 <.."), "{e}");
        let e = with_base(Some(&dir), || parse("(file: \"s.csv\", colour: 1)")).unwrap_err();
        assert!(e.contains("unknown field"), "{e}");
        // A directory or a device is not read.
        let e = with_base(Some(&dir), || parse("\".\"")).unwrap_err();
        assert!(e.contains("not a regular file"), "{e}");
        let e = parse("\"/dev/zero\"").unwrap_err();
        assert!(e.contains("not a regular file"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A scratch folder for one test's CSV files.
    fn scratch(test: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("lapidary-spectrum-{test}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn a_first_row_is_a_header_only_when_it_is_not_numbers() {
        let dir = scratch("header");
        let read = |text: &str| {
            std::fs::write(dir.join("x.csv"), text).unwrap();
            with_base(Some(&dir), || parse("\"x.csv\""))
        };
        // Data that does not parse is refused at its line, naming what was found.
        for (text, found) in [
            (
                "0x190,0.1\n500,0.2\n",
                "wavelength `0x190` is not a decimal number",
            ),
            (
                "4_00,0.1\n500,0.2\n",
                "wavelength `4_00` is not a decimal number",
            ),
            ("400;0.1\n500;0.2\n", "found 1 field `400;0.1`"),
            ("400,0.1,7\n500,0.2\n", "found 3 fields `400,0.1,7`"),
            ("400,\n500,0.2\n", "value is missing"),
            ("# notes\n\n  # more\n+400,x\n", "x.csv:4: value `x`"),
        ] {
            let e = read(text).unwrap_err();
            let want = format!("{}:", dir.join("x.csv").display());
            assert!(e.contains(&want) && e.contains(found), "{text:?}: {e}");
            assert!(
                e.contains("`wavelength_nm,value`") && e.contains("header"),
                "{e}"
            );
        }
        let e = read("# notes\n\n  # more\n4_00,0.1\n").unwrap_err();
        assert!(e.contains("x.csv:4: wavelength `4_00`"), "{e}");
        // A later row of names is not a header.
        let e = read("nm,R\n400,0.1\nnm,R\n").unwrap_err();
        assert!(e.contains("x.csv:3: wavelength `nm`"), "{e}");
        // Trailing comments, indented comments, quoted header fields and blank lines.
        let s =
            read("  # measured\n\"lambda (nm), air\",\"R # %\"\n\n400,0.1 # blue\r\n\"500\", .5\n")
                .unwrap();
        assert_eq!(s.points, vec![(400.0, 0.1), (500.0, 0.5)]);
        assert_eq!(s.csv.unwrap().lines, vec![4, 5]);
        // A byte order mark before data or a header.
        assert_eq!(
            read("\u{feff}400,0.1\n500,0.2\n")
                .unwrap()
                .csv
                .unwrap()
                .lines,
            vec![1, 2]
        );
        assert_eq!(
            read("\u{feff}nm,R\n400,0.1\n500,0.2\n")
                .unwrap()
                .csv
                .unwrap()
                .lines,
            vec![2, 3]
        );
        // A header alone is no spectrum.
        let e = read("wavelength_nm,value\n").unwrap_err();
        assert!(e.contains("no `wavelength_nm,value` rows"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn point_errors_name_the_csv_file_and_line() {
        let dir = scratch("lines");
        std::fs::write(
            dir.join("x.csv"),
            "wavelength_nm,value\n# note\n400,0.1\n510,0.2\n\n500,0.3\n",
        )
        .unwrap();
        let shown = dir.join("x.csv").display().to_string();
        let s = with_base(Some(&dir), || parse("\"x.csv\"")).unwrap();
        assert_eq!(
            s.measured(1.0).unwrap_err(),
            format!("{shown}:6: wavelength 500 nm does not increase (after 510 nm)")
        );
        std::fs::write(dir.join("y.csv"), "400,0.1\n500,0.3\n").unwrap();
        let s = with_base(Some(&dir), || parse("(file: \"y.csv\", scale: 4)")).unwrap();
        let e = s.measured(1.0).unwrap_err();
        assert!(
            e.starts_with(&format!(
                "{}:2: value 1.2 at 500 nm",
                dir.join("y.csv").display()
            )) && e.ends_with("allowed 0 ..= 1 (the file's values × scale 4)"),
            "{e}"
        );
        std::fs::write(dir.join("z.csv"), "400,0.1\n").unwrap();
        let s = with_base(Some(&dir), || parse("\"z.csv\"")).unwrap();
        let e = s.measured(1.0).unwrap_err();
        assert!(
            e.starts_with(&format!(
                "{}: a spectrum has 1 points",
                dir.join("z.csv").display()
            )),
            "{e}"
        );
        // Inline points are named by their index.
        let e = parse("[(400, 0.1), (500, 2)]")
            .unwrap()
            .measured(1.0)
            .unwrap_err();
        assert_eq!(
            e,
            "spectrum point 1: value 2 at 500 nm is out of range: allowed 0 ..= 1"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn too_many_inline_points_are_refused() {
        let text = format!("[{}]", vec!["(500, 1)"; MAX_POINTS + 1].join(","));
        assert!(parse(&text).unwrap_err().contains("more than"));
    }
}
