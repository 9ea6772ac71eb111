//! Loading OBJ files (through tobj), with line numbers for their errors.
//!
//! tobj reports *what* is wrong ("face vertex index out of bounds") but never *where*: it reads
//! line by line without counting, and checks face indices only when a whole object is assembled,
//! long after the face's line. So once tobj (or the loader's own finiteness check) has refused a
//! file, a light pre-scan reads the text again, applying the same rules as tobj 4 to each line,
//! and names the first line that breaks one. It runs only on failure, so a good file is read once.

use super::{GeometryError, Mesh};
use glam::Vec3;
use std::path::Path;

impl Mesh {
    /// Loads the OBJ file at `path` (all models merged, polygons triangulated) with its
    /// coordinates multiplied by `scale` (finite, positive), and builds its BVH. Vertex normals,
    /// if the file has them, become shading normals. Degenerate triangles are skipped.
    pub fn load(path: &Path, scale: f32) -> Result<Mesh, GeometryError> {
        if !(scale > 0.0 && scale.is_finite()) {
            return Err(GeometryError::Degenerate {
                shape: "mesh",
                detail: format!(
                    "scale must be finite and positive, got {scale} ({})",
                    path.display()
                ),
            });
        }
        let read_error = |source: std::io::Error| GeometryError::Read {
            path: path.to_owned(),
            source,
        };
        // The file type first, without opening: a FIFO would block, a directory or a device is
        // named as such.
        crate::image::input_kind::regular_file(path).map_err(|e| read_error(e.into()))?;
        let bytes = std::fs::read(path).map_err(read_error)?;
        let parse_error = |message: String| GeometryError::Parse {
            path: path.to_owned(),
            message,
        };
        // Triangulated, one index for positions and normals, points and lines ignored.
        let options = tobj::GPU_LOAD_OPTIONS;
        // Materials are not used: `mtllib` lines are answered with an error tobj keeps aside.
        // The parser is third-party code fed untrusted input; a panic in it becomes an error.
        let parse = std::panic::catch_unwind(|| {
            tobj::load_obj_buf(&mut &bytes[..], &options, |_| {
                Err(tobj::LoadError::OpenFileFailed)
            })
        });
        let models = match parse {
            Ok(Ok((models, _))) => Ok(models),
            Ok(Err(e)) => Err(e.to_string()),
            Err(_) => Err("the OBJ parser failed".to_string()),
        }
        .map_err(|message| {
            parse_error(match first_bad_line(&bytes) {
                Some(l) => format!("line {}: {} ({message})", l.line, l.detail),
                None => message,
            })
        })?;
        let (mut tris, mut normals) = (Vec::new(), Vec::new());
        for model in &models {
            let m = &model.mesh;
            let vertex = |i: u32, data: &[f32]| -> Option<Vec3> {
                let i = i as usize * 3;
                Some(Vec3::from_slice(data.get(i..i + 3)?))
            };
            let has_normals = !m.normals.is_empty() && m.normals.len() == m.positions.len();
            for f in m.indices.chunks_exact(3) {
                let p = [f[0], f[1], f[2]].map(|i| vertex(i, &m.positions).map(|v| v * scale));
                let [Some(a), Some(b), Some(c)] = p else {
                    continue;
                };
                if !(a.is_finite() && b.is_finite() && c.is_finite()) {
                    return Err(match first_non_finite_vertex(&bytes, scale) {
                        Some(l) => parse_error(format!("line {}: {}", l.line, l.detail)),
                        None => GeometryError::NonFinite {
                            path: path.to_owned(),
                            scale,
                        },
                    });
                }
                tris.push([a, b, c]);
                let n = [f[0], f[1], f[2]].map(|i| vertex(i, &m.normals).unwrap_or(Vec3::ZERO));
                normals.push(if has_normals { n } else { [Vec3::ZERO; 3] });
            }
        }
        Mesh::build(tris, normals, path)
    }
}

/// A problem found on one line: 1-based line number and what is wrong there.
pub(super) struct Located {
    /// 1-based line number.
    pub line: usize,
    /// What is wrong, quoting the line's offending token.
    pub detail: String,
}

/// Splits into lines as Rust's `BufRead::lines` (what tobj uses) does: at `\n`, dropping a `\r`
/// before it. Each line with its 1-based number.
fn lines(bytes: &[u8]) -> impl Iterator<Item = (usize, &[u8])> {
    bytes
        .split(|&b| b == b'\n')
        .map(|l| l.strip_suffix(b"\r").unwrap_or(l))
        .enumerate()
        .map(|(i, l)| (i + 1, l))
}

/// The first line of `bytes` that tobj would refuse, with what is wrong. `None` when every line
/// follows the rules this scan knows (the caller then reports tobj's own message).
pub(super) fn first_bad_line(bytes: &[u8]) -> Option<Located> {
    let at = |line: usize, detail: String| Some(Located { line, detail });
    if let Some(cr) = bytes.iter().position(|&b| b == b'\r')
        && bytes.get(cr + 1) != Some(&b'\n')
    {
        let line = bytes[..cr].iter().filter(|&&b| b == b'\n').count() + 1;
        return at(
            line,
            "the line ends in a lone carriage return (`\\r`): OBJ lines must end in LF or CRLF"
                .into(),
        );
    }
    // Totals first: tobj resolves positive face indices against the whole object's vertices.
    let mut total = [0usize; 3];
    for (_, l) in lines(bytes) {
        match String::from_utf8_lossy(l).split_whitespace().next() {
            Some("v") => total[0] += 1,
            Some("vt") => total[1] += 1,
            Some("vn") => total[2] += 1,
            _ => {}
        }
    }
    let mut count = [0usize; 3];
    for (n, l) in lines(bytes) {
        let Ok(text) = std::str::from_utf8(l) else {
            return at(n, "the line is not valid UTF-8 text".into());
        };
        let mut words = text.split_whitespace();
        let floats = |words: &mut std::str::SplitWhitespace, k: usize, what: &str| {
            let got: Vec<&str> = words.take(k).collect();
            match got.iter().find(|w| w.parse::<f32>().is_err()) {
                Some(bad) => Err(format!("{what}: `{bad}` is not a number")),
                None if got.len() < k => {
                    Err(format!("{what}: expected {k} numbers, found {}", got.len()))
                }
                None => Ok(()),
            }
        };
        let problem = match words.next() {
            Some("v") => {
                count[0] += 1;
                floats(&mut words, 3, "vertex").and_then(|()| {
                    let rest: Vec<&str> = words.collect();
                    match rest.as_slice() {
                        [] | [_, _, _] => Ok(()),
                        [w] => match w.parse::<f32>() {
                            Ok(w) if w != 0.0 => Ok(()),
                            Ok(_) => Err("vertex: the weight w is 0".into()),
                            Err(_) => Err(format!("vertex: `{w}` is not a number")),
                        },
                        _ => Err(format!(
                            "vertex: expected 3 coordinates, then a weight or 3 colour values; found {} more values",
                            rest.len()
                        )),
                    }
                })
            }
            Some("vt") => {
                count[1] += 1;
                floats(&mut words, 2, "texture coordinate")
            }
            Some("vn") => {
                count[2] += 1;
                floats(&mut words, 3, "normal")
            }
            Some("f") => {
                let corners: Vec<&str> = words.collect();
                if corners.is_empty() {
                    Err("face: no vertices".into())
                } else {
                    corners
                        .iter()
                        .find_map(|c| corner_problem(c, count, total).err())
                        .map_or(Ok(()), Err)
                }
            }
            Some("usemtl") if words.next().is_none() => Err("usemtl: no material name".into()),
            _ => Ok(()),
        };
        if let Err(detail) = problem {
            return at(n, detail);
        }
    }
    None
}

/// Checks one face corner `v[/vt[/vn]]` against the counts so far (relative indices) and the
/// totals (absolute indices), as tobj resolves them.
fn corner_problem(corner: &str, so_far: [usize; 3], total: [usize; 3]) -> Result<(), String> {
    const WHAT: [&str; 3] = ["vertex", "texture coordinate", "normal"];
    const PLURAL: [&str; 3] = ["vertices", "texture coordinates", "normals"];
    let parts: Vec<&str> = corner.split('/').collect();
    if parts.len() > 3 {
        return Err(format!(
            "face corner `{corner}`: expected v, v/vt, v//vn or v/vt/vn"
        ));
    }
    for (k, p) in parts.iter().enumerate() {
        if p.is_empty() {
            if k == 0 {
                return Err(format!("face corner `{corner}`: no vertex index"));
            }
            continue;
        }
        let Ok(i) = p.parse::<isize>() else {
            return Err(format!(
                "face corner `{corner}`: `{p}` is not a whole number"
            ));
        };
        // tobj checks texture and normal indices only when the file has any.
        if k > 0 && total[k] == 0 {
            continue;
        }
        let ok = match i {
            0 => false,
            i if i < 0 => i.unsigned_abs() <= so_far[k],
            i => i.unsigned_abs() <= total[k],
        };
        if !ok {
            return Err(format!(
                "face corner `{corner}`: {} index {i} is out of range: the file has {} {} \
                 (indices count from 1; negative ones back from the latest)",
                WHAT[k], total[k], PLURAL[k]
            ));
        }
    }
    Ok(())
}

/// The first `v` line whose coordinates, multiplied by `scale`, are not all finite.
pub(super) fn first_non_finite_vertex(bytes: &[u8], scale: f32) -> Option<Located> {
    lines(bytes).find_map(|(n, l)| {
        let text = String::from_utf8_lossy(l);
        let mut words = text.split_whitespace();
        if words.next() != Some("v") {
            return None;
        }
        let bad = words
            .take(3)
            .find(|w| !w.parse::<f32>().is_ok_and(|x| (x * scale).is_finite()))?;
        let detail = if bad.parse::<f32>().is_ok_and(f32::is_finite) {
            format!("vertex coordinate `{bad}` × scale {scale} is not a finite number")
        } else {
            format!("vertex coordinate `{bad}` is not a finite number")
        };
        Some(Located { line: n, detail })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bad(text: &str) -> (usize, String) {
        let l = first_bad_line(text.as_bytes()).expect("a bad line");
        (l.line, l.detail)
    }

    #[test]
    fn finds_the_offending_line() {
        let ok = "v 0 0 0\nv 1 0 0\r\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 -1//1\n";
        assert!(first_bad_line(ok.as_bytes()).is_none());
        let (n, d) = bad("v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 4\n");
        assert_eq!(n, 5, "{d}");
        assert!(
            d.contains("vertex index 4") && d.contains("has 3 vertices"),
            "{d}"
        );
        assert_eq!(bad("v 0 0 0\nf -2 1 1\n").0, 2);
        assert_eq!(bad("v 0 0 0\nf 0 1 1\n").0, 2);
        assert_eq!(bad("# c\nv 0 zero 0\n").0, 2);
        assert_eq!(bad("v 0 0\n").0, 1);
        assert_eq!(bad("v 0 0 0 0\n").0, 1);
        assert_eq!(bad("v 0 0 0\nf 1/x 1 1\n").0, 2);
        assert_eq!(bad("v 0 0 0\rv 1 0 0\r").0, 1);
        let nan = first_non_finite_vertex(b"v 0 0 0\nv 1 nan 0\n", 1.0).unwrap();
        assert_eq!(nan.line, 2);
        let big = first_non_finite_vertex(b"v 0 0 0\nv 1e38 0 0\n", 1e3).unwrap();
        assert!(
            big.line == 2 && big.detail.contains("scale"),
            "{}",
            big.detail
        );
    }
}
