//! What a render will need in memory, estimated before anything large is allocated, so that a
//! render too big for the machine is refused with the figure ("needs 66.6 GiB, 22.9 GiB allowed")
//! instead of being killed half way.
//!
//! The figures are measured, not derived from first principles (release build, `lapidary render`
//! peak resident size): the film costs [`FILM_BYTES_PER_PIXEL`] a pixel (the tiles'
//! accumulated [`PixelSums`] and the film assembled from them, or a part's copy of its tiles'
//! sums from before a pass), an environment
//! map [`MAP_BYTES_PER_TEXEL`] a texel while it is decoded and its tables built, a material's
//! tables about [`MATERIAL_BYTES`], a mesh about [`MESH_BYTES_PER_FILE_BYTE`] times its OBJ file.

use super::film::PixelSums;
use crate::scene::Scene;
use crate::scene::stage::{Environment, Shape};
use std::fmt;

/// Film bytes per pixel: two [`PixelSums`] (the tiles' sums and the film assembled from them,
/// 2 × 192 bytes of fixed-point sums) and room for the outputs' channels; measured 377 bytes a
/// pixel at 2048×2048 (peak resident size of a 1-spp render, process included; the same before
/// and after the tiles kept their sums across passes: 1 582 944 and 1 583 000 KiB).
pub const FILM_BYTES_PER_PIXEL: u64 = 2 * std::mem::size_of::<PixelSums>() as u64 + 16;
/// More film bytes per pixel with the Stokes AOVs (`--stokes`): two [`super::film::StokesSums`].
pub const STOKES_BYTES_PER_PIXEL: u64 = 2 * std::mem::size_of::<super::film::StokesSums>() as u64;
/// Environment-map bytes per texel at the peak of its setup: the decoded channels and the RGB
/// image (12 + 12), then pixels and sampling tables (12 + 4); measured 23.6 at 16384×8192.
pub const MAP_BYTES_PER_TEXEL: u64 = 28;
/// Bytes of the BSDF tables of one used material (measured about 7 KiB with two coats).
pub const MATERIAL_BYTES: u64 = 16 << 10;
/// Mesh bytes (triangles, normals, BVH) per byte of its OBJ file, a generous bound.
pub const MESH_BYTES_PER_FILE_BYTE: u64 = 8;
/// The limit when the memory available cannot be read (no `/proc/meminfo`): 4 GiB.
pub const FALLBACK_LIMIT: u64 = 4 << 30;
/// The process itself, its code and small tables.
const BASE_BYTES: u64 = 16 << 20;

/// What a render of a scene will need, by part (bytes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MemoryEstimate {
    /// The film and the pass buffers.
    pub film: u64,
    /// The BSDF tables of the used materials.
    pub materials: u64,
    /// An environment map being decoded and its sampling tables (0 without a map).
    pub environment: u64,
    /// A mesh stone (0 for the analytic shapes).
    pub mesh: u64,
}

impl MemoryEstimate {
    /// The estimate for `scene` at its own render settings (read the environment map's header and
    /// the mesh's file size; a file that cannot be read counts 0 here and fails later with its
    /// own message).
    pub fn of(scene: &Scene) -> MemoryEstimate {
        let r = &scene.stage.render;
        let pixels = u64::from(r.width) * u64::from(r.height);
        let used = scene.surface.used.iter().filter(|u| **u).count() as u64;
        let environment = match &scene.stage.environment {
            Environment::Map { path, .. } => map_texels(path).saturating_mul(MAP_BYTES_PER_TEXEL),
            _ => 0,
        };
        let mesh = match &scene.stage.shape {
            Shape::Mesh { path, .. } => std::fs::metadata(path)
                .ok()
                .filter(std::fs::Metadata::is_file)
                .map_or(0, |m| m.len().saturating_mul(MESH_BYTES_PER_FILE_BYTE)),
            _ => 0,
        };
        MemoryEstimate {
            film: pixels.saturating_mul(if scene.stage.stokes {
                FILM_BYTES_PER_PIXEL + STOKES_BYTES_PER_PIXEL
            } else {
                FILM_BYTES_PER_PIXEL
            }),
            materials: used.saturating_mul(MATERIAL_BYTES),
            environment,
            mesh,
        }
    }

    /// Everything, with the process's own share.
    pub fn total(&self) -> u64 {
        [self.film, self.materials, self.environment, self.mesh]
            .iter()
            .fold(BASE_BYTES, |a, b| a.saturating_add(*b))
    }

    /// `Ok` when the total is within `limit` bytes, else what is needed against what is allowed.
    pub fn check(&self, limit: u64) -> Result<(), TooBig> {
        if self.total() <= limit {
            Ok(())
        } else {
            Err(TooBig {
                estimate: *self,
                limit,
            })
        }
    }
}

/// A render that would need more memory than allowed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub struct TooBig {
    /// What it would need.
    pub estimate: MemoryEstimate,
    /// What is allowed (bytes).
    pub limit: u64,
}

impl fmt::Display for TooBig {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let e = &self.estimate;
        write!(
            f,
            "the render needs {}, {} allowed (film {}",
            gib(e.total()),
            gib(self.limit),
            gib(e.film)
        )?;
        for (what, bytes) in [
            ("environment map", e.environment),
            ("materials", e.materials),
            ("mesh", e.mesh),
        ] {
            if bytes >= 1 << 20 {
                write!(f, ", {what} {}", gib(bytes))?;
            }
        }
        write!(
            f,
            "); render a smaller --size, or raise --max-memory if the machine has more"
        )
    }
}

/// Texels of the EXR at `path` from its header (0 when it cannot be read as a regular file).
fn map_texels(path: &std::path::Path) -> u64 {
    if !std::fs::metadata(path).is_ok_and(|m| m.is_file()) {
        return 0;
    }
    exr::meta::MetaData::read_from_file(path, false).map_or(0, |m| {
        m.headers
            .iter()
            .map(|h| (h.layer_size.0 as u64).saturating_mul(h.layer_size.1 as u64))
            .max()
            .unwrap_or(0)
    })
}

/// The memory available to a new allocation: `MemAvailable` of `/proc/meminfo`, if it can be read.
pub fn available() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    mem_available(&info)
}

/// `MemAvailable` (in kB in the file) of a `/proc/meminfo` text, in bytes.
fn mem_available(info: &str) -> Option<u64> {
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kb.checked_mul(1024)
}

/// The default `--max-memory`: the memory available, else [`FALLBACK_LIMIT`].
pub fn default_limit() -> u64 {
    available().unwrap_or(FALLBACK_LIMIT)
}

/// Bytes as GiB with one decimal (`12.3 GiB`), or MiB below one GiB.
pub fn gib(bytes: u64) -> String {
    if bytes >= 1 << 30 {
        format!("{:.1} GiB", bytes as f64 / f64::from(1u32 << 30))
    } else {
        format!("{:.1} MiB", bytes as f64 / f64::from(1u32 << 20))
    }
}

/// Smallest `--max-memory` accepted.
pub const MIN_LIMIT: u64 = 64 << 20;
/// Largest `--max-memory` accepted (1 PiB).
pub const MAX_LIMIT: u64 = 1 << 50;

/// Parses a memory size: a number with a unit `K`, `M`, `G`, `T` (powers of 1024; `KiB`, `MB`,
/// … and lower case accepted), e.g. `8G`, `512M`, `1.5GiB`; a bare number is bytes. Allowed 64 MiB
/// ..= 1 PiB.
pub fn parse_size(s: &str) -> Result<u64, String> {
    let err = || format!("`{s}`: expected a memory size like 8G or 512M, from 64M to 1P");
    let t = s.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let value: f64 = num.parse().map_err(|_| err())?;
    let unit = unit.trim().to_ascii_lowercase();
    let unit = unit.trim_end_matches('b').trim_end_matches('i');
    let scale: f64 = match unit {
        "" => 1.0,
        "k" => 1024.0,
        "m" => 1024.0 * 1024.0,
        "g" => 1024.0 * 1024.0 * 1024.0,
        "t" => 1024f64.powi(4),
        "p" => 1024f64.powi(5),
        _ => return Err(err()),
    };
    let bytes = value * scale;
    if bytes.is_finite() && bytes >= MIN_LIMIT as f64 && bytes <= MAX_LIMIT as f64 {
        Ok(bytes as u64)
    } else {
        Err(err())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_with_units_and_bounds() {
        assert_eq!(parse_size("8G"), Ok(8 << 30));
        assert_eq!(parse_size("512MiB"), Ok(512 << 20));
        assert_eq!(parse_size("1.5g"), Ok(3 << 29));
        assert_eq!(parse_size("1T"), Ok(1 << 40));
        assert_eq!(parse_size("134217728"), Ok(128 << 20));
        for bad in ["", "G", "8X", "-1G", "1M", "2P", "nanG", "1e3G"] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn mem_available_is_read_in_bytes() {
        let info = "MemTotal:       24000000 kB\nMemFree:  100 kB\nMemAvailable:   23000000 kB\n";
        assert_eq!(mem_available(info), Some(23_000_000 * 1024));
        assert_eq!(mem_available("MemTotal: 5 kB\n"), None);
    }

    #[test]
    fn the_film_dominates_and_the_message_gives_the_figures() {
        assert_eq!(FILM_BYTES_PER_PIXEL, 400);
        let e = MemoryEstimate {
            film: 16384 * 16384 * FILM_BYTES_PER_PIXEL,
            materials: 3 * MATERIAL_BYTES,
            environment: 0,
            mesh: 0,
        };
        let m = e.check(8 << 30).unwrap_err().to_string();
        assert!(
            m.starts_with("the render needs 100.0 GiB, 8.0 GiB allowed (film 100.0 GiB)"),
            "{m}"
        );
        assert!(e.check(128 << 30).is_ok());
    }
}
