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
//! **CSV.** One point per row, `wavelength_nm,value` (comma-separated; spaces around the fields
//! are ignored); lines starting with `#` are comments; a first row that is not two numbers is a
//! header and is skipped. The file must be a regular file of at most [`MAX_FILE_BYTES`] bytes with
//! at most [`MAX_POINTS`] rows; an error names `file.csv:line` and what is wrong. The points are
//! checked (wavelengths increasing in 200 ..= 2000 nm, values in the field's range) where the
//! recipe uses them ([`crate::spectrum::measured::Measured::from_points`]). The file is read when
//! the recipe is parsed, so the parsed recipe holds the points and the path only for messages.

use crate::spectrum::measured::MAX_POINTS;
use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::{Deserialize, Serialize, Serializer};
use std::cell::RefCell;
use std::fmt;
use std::io::Read;
use std::path::{Path, PathBuf};

/// Largest CSV file a recipe may name, bytes.
pub const MAX_FILE_BYTES: u64 = 1 << 20;
/// Largest `scale` a spectrum may be given.
pub const MAX_SCALE: f32 = 1e4;

/// A spectrum as a recipe gives it: the points (after reading a file and applying `scale`) and,
/// when they came from a file, its path as written.
#[derive(Clone, Debug, PartialEq)]
pub struct SpectrumDesc {
    /// `(wavelength nm, value)` points, in the order given.
    pub points: Vec<(f32, f32)>,
    /// The CSV file the points were read from, as written in the recipe.
    pub file: Option<String>,
    /// The factor the file's values were multiplied by (1 unless given).
    pub scale: f32,
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

/// Reads the CSV file `written` (relative to the recipe's folder) as `(nm, value)` points.
fn read_csv(written: &str) -> Result<Vec<(f32, f32)>, String> {
    let path = BASE.with(|b| match &*b.borrow() {
        Some(base) if Path::new(written).is_relative() => base.join(written),
        _ => PathBuf::from(written),
    });
    let shown = path.display();
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
    let mut text = String::new();
    std::fs::File::open(&path)
        .and_then(|f| f.take(MAX_FILE_BYTES + 1).read_to_string(&mut text))
        .map_err(|e| format!("spectrum file {shown}: {e}"))?;
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .flexible(true)
        .from_reader(text.as_bytes());
    let mut points = Vec::new();
    for (i, row) in reader.records().enumerate() {
        let row = row.map_err(|e| format!("spectrum file {shown}: {e}"))?;
        let line = row.position().map_or(0, |p| p.line());
        let number = |k: usize| row.get(k).and_then(|s| s.parse::<f32>().ok());
        match (row.len(), number(0), number(1)) {
            (2, Some(l), Some(v)) => points.push((l, v)),
            // A first row that is not two numbers is a header.
            _ if i == 0 => {}
            _ => {
                return Err(format!(
                    "{shown}:{line}: expected `wavelength_nm,value` (two numbers), found {:?}",
                    row.iter().collect::<Vec<_>>().join(",")
                ));
            }
        }
        if points.len() > MAX_POINTS {
            return Err(format!(
                "{shown}:{line}: more than {MAX_POINTS} points: allowed 2 ..= {MAX_POINTS}"
            ));
        }
    }
    if points.is_empty() {
        return Err(format!(
            "spectrum file {shown}: no `wavelength_nm,value` rows"
        ));
    }
    Ok(points)
}

impl SpectrumDesc {
    /// The points of the CSV file `file` times `scale`.
    fn from_file(file: String, scale: f32) -> Result<SpectrumDesc, String> {
        if !(scale.is_finite() && scale > 0.0 && scale <= MAX_SCALE) {
            return Err(format!(
                "spectrum scale {scale} is out of range: allowed 0 <.. {MAX_SCALE:e}"
            ));
        }
        let points = read_csv(&file)?
            .into_iter()
            .map(|(l, v)| (l, v * scale))
            .collect();
        Ok(SpectrumDesc {
            points,
            file: Some(file),
            scale,
        })
    }

    /// A spectrum given inline.
    pub fn inline(points: Vec<(f32, f32)>) -> SpectrumDesc {
        SpectrumDesc {
            points,
            file: None,
            scale: 1.0,
        }
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
        assert_eq!(s.file, None);
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
        assert_eq!(s.file.as_deref(), Some("s.csv"));
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

    #[test]
    fn too_many_inline_points_are_refused() {
        let text = format!("[{}]", vec!["(500, 1)"; MAX_POINTS + 1].join(","));
        assert!(parse(&text).unwrap_err().contains("more than"));
    }
}
