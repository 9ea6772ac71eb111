//! The coefficient table kept on disk between runs: building it costs about a second of both
//! cores (`super::RES`), which every spectral render from the command line would otherwise pay.
//!
//! **Where.** `$LAPIDARY_CACHE_DIR`, else `$XDG_CACHE_HOME/lapidary`, else
//! `$HOME/.cache/lapidary`; `LAPIDARY_CACHE_DIR=off` (or no such variable at all) keeps the
//! table in memory only. The file is `rgb2spec-KEY.bin`, where `KEY` is a hash of everything
//! the table depends on: the sources of the fit, the sigmoid, the table layout and the CIE
//! module (included into the binary as text), the CIE and D65 data, the resolution and the dark
//! limit. A change to any of them names a new file, so a stale table is never read.
//!
//! **Safety.** The file holds a magic word, the key, the entry count, the entries and a checksum
//! of them; anything else (short, corrupt, another key) is ignored and the table rebuilt. A new
//! table is written to a temporary file in the same folder and renamed over the name, so a
//! reader never sees half a file, and nothing but this cache's own files is ever written.
//! Failures to read or write are silent: the cache only saves time. Rust's floating point is
//! deterministic (no reassociation or contraction), so a table read back is bit for bit the
//! table the same sources would compute.

use std::io::Read;
use std::path::{Path, PathBuf};

const MAGIC: &[u8; 8] = b"LAPRGB2S";

/// FNV-1a, 64 bits.
fn fnv(bytes: &[u8], mut h: u64) -> u64 {
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}
const FNV_START: u64 = 0xcbf2_9ce4_8422_2325;

/// The hash of everything the table is computed from (hashed once per process).
fn key() -> u64 {
    static KEY: std::sync::OnceLock<u64> = std::sync::OnceLock::new();
    *KEY.get_or_init(compute_key)
}

fn compute_key() -> u64 {
    let parts: [&[u8]; 7] = [
        include_str!("fit.rs").as_bytes(),
        include_str!("sigmoid.rs").as_bytes(),
        include_str!("../rgb2spec.rs").as_bytes(),
        include_str!("../cie.rs").as_bytes(),
        include_str!("../data/cie1931_2deg.csv").as_bytes(),
        include_str!("../data/d65.csv").as_bytes(),
        env!("CARGO_PKG_VERSION").as_bytes(),
    ];
    let mut h = FNV_START;
    for p in parts {
        h = fnv(p, h);
        h = fnv(&(p.len() as u64).to_le_bytes(), h);
    }
    h = fnv(&(super::RES as u64).to_le_bytes(), h);
    fnv(&super::Z_DARK.to_bits().to_le_bytes(), h)
}

/// The cache folder, or `None` when caching is off or no folder is known (the material tables'
/// store, `crate::bsdf::store`, keeps its files in a `tables` folder inside it).
pub(crate) fn folder() -> Option<PathBuf> {
    let var = |k: &str| std::env::var_os(k).filter(|v| !v.is_empty());
    if let Some(d) = var("LAPIDARY_CACHE_DIR") {
        return (d != "off").then(|| PathBuf::from(d));
    }
    if let Some(d) = var("XDG_CACHE_HOME") {
        return Some(PathBuf::from(d).join("lapidary"));
    }
    var("HOME").map(|h| PathBuf::from(h).join(".cache").join("lapidary"))
}

fn file_in(dir: &Path) -> PathBuf {
    dir.join(format!("rgb2spec-{:016x}.bin", key()))
}

/// The bytes of a table: entries then the largest fit error, little-endian `f32`s.
fn payload(coeffs: &[[f32; 3]], max_fit_error: f32) -> Vec<u8> {
    let mut out = Vec::with_capacity(coeffs.len() * 12 + 4);
    for c in coeffs.iter().flatten() {
        out.extend_from_slice(&c.to_le_bytes());
    }
    out.extend_from_slice(&max_fit_error.to_le_bytes());
    out
}

/// The table of `entries` entries from the cache, if a valid one is there.
pub(super) fn load(entries: usize) -> Option<(Vec<[f32; 3]>, f32)> {
    load_from(&folder()?, entries)
}

/// Stores a table for later runs (silently does nothing if it cannot).
pub(super) fn store(coeffs: &[[f32; 3]], max_fit_error: f32) {
    if let Some(dir) = folder() {
        store_in(&dir, coeffs, max_fit_error);
    }
}

fn load_from(dir: &Path, entries: usize) -> Option<(Vec<[f32; 3]>, f32)> {
    let path = file_in(dir);
    let want = 8 + 8 + 8 + entries * 12 + 4 + 8;
    let meta = std::fs::metadata(&path).ok()?;
    if !meta.is_file() || meta.len() != want as u64 {
        return None;
    }
    let mut bytes = Vec::with_capacity(want);
    std::fs::File::open(&path)
        .ok()?
        .take(want as u64)
        .read_to_end(&mut bytes)
        .ok()?;
    let word = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().expect("8 bytes"));
    if bytes.len() != want || &bytes[..8] != MAGIC || word(8) != key() || word(16) != entries as u64
    {
        return None;
    }
    let body = &bytes[24..want - 8];
    if fnv(body, FNV_START) != word(want - 8) {
        return None;
    }
    let f = |i: usize| f32::from_le_bytes(body[4 * i..4 * i + 4].try_into().expect("4 bytes"));
    let coeffs = (0..entries)
        .map(|e| [f(3 * e), f(3 * e + 1), f(3 * e + 2)])
        .collect();
    Some((coeffs, f(3 * entries)))
}

fn store_in(dir: &Path, coeffs: &[[f32; 3]], max_fit_error: f32) {
    let path = file_in(dir);
    if std::fs::create_dir_all(dir).is_err() {
        return;
    }
    let body = payload(coeffs, max_fit_error);
    let mut bytes = Vec::with_capacity(body.len() + 32);
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&key().to_le_bytes());
    bytes.extend_from_slice(&(coeffs.len() as u64).to_le_bytes());
    bytes.extend_from_slice(&body);
    bytes.extend_from_slice(&fnv(&body, FNV_START).to_le_bytes());
    let tmp = dir.join(format!(
        ".rgb2spec-{:016x}.{}.tmp",
        key(),
        std::process::id()
    ));
    if std::fs::write(&tmp, &bytes).is_ok() && std::fs::rename(&tmp, &path).is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stored_table_reads_back_exactly_and_damage_is_ignored() {
        let dir = std::env::temp_dir().join(format!("lapidary-cache-{}", std::process::id()));
        let coeffs: Vec<[f32; 3]> = (0..10)
            .map(|i| [i as f32, -0.5, f32::MIN_POSITIVE])
            .collect();
        assert_eq!(load_from(&dir, 10), None);
        store_in(&dir, &coeffs, 0.25);
        assert_eq!(load_from(&dir, 10), Some((coeffs.clone(), 0.25)));
        // Another size is not this table; one flipped bit fails the checksum; a short file is
        // ignored. Nothing but the cache file is left in the folder.
        assert_eq!(load_from(&dir, 11), None);
        let path = file_in(&dir);
        let mut b = std::fs::read(&path).unwrap();
        b[30] ^= 1;
        std::fs::write(&path, &b).unwrap();
        assert_eq!(load_from(&dir, 10), None);
        std::fs::write(&path, &b[..40]).unwrap();
        assert_eq!(load_from(&dir, 10), None);
        let names: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names.len(), 1, "{names:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
