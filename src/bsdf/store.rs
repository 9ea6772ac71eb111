//! A persistent store of measured tables on disk: the material tables that take a render's setup
//! (the Corrected model's calibration, a coat's albedo tables, an interface's energy tables) are
//! kept between runs, as Dr.Jit keeps its compiled kernels and Cycles its kernels and textures.
//!
//! A table is a deterministic function of its inputs and of the code that measures it, so reading
//! it back changes no result: the key of a stored table is a 128-bit hash of what it is, the
//! `Debug` text of every input (Rust prints each float as the shortest decimal that reads back to
//! the same bits, so the text is exact), and the identity of the running program (its version, its
//! path, its size and modification time: any rebuild measures afresh). A file holds its key and a
//! checksum of its values; one that does not match, is truncated or holds a value that is not
//! finite is measured again.
//!
//! **Where**: the `tables` folder in lapidary's cache folder (`$LAPIDARY_CACHE_DIR`, else
//! `$XDG_CACHE_HOME/lapidary`, else `~/.cache/lapidary`, as the spectral coefficient table);
//! `LAPIDARY_CACHE_DIR=off`, or no such folder, measures the tables on every run, as before.
//!
//! **Safety**: the store only creates files whose names it derives from keys (`<32 hex>.tab`),
//! writes each to a fresh temporary file of its own first (`create_new`: it never opens a file it
//! did not make for writing) and renames it into place, and never deletes anything but its own
//! temporary file
//! after a failed write or its own oldest table files when the folder reaches [`MAX_FILES`]
//! (those whose name is a key's and whose contents start with the store's magic; down to three
//! quarters of the bound). A full disk or a read-only folder only means the tables are measured.
//! Failures are silent: the store only saves time.

use super::table::{ENTRIES, Table};
use crate::spectrum::RgbSample;
use std::fmt::{Debug, Write as _};
use std::hash::{DefaultHasher, Hasher};
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};

/// The environment variable that places the store's folder (`off`: no store); the same as the
/// spectral coefficient table's cache ([`crate::spectrum::rgb2spec`]).
pub const ENV: &str = "LAPIDARY_CACHE_DIR";

/// Most files the store lets its folder hold (a file is ~1–3 KB): a write that finds this many
/// first removes the oldest of the store's own table files, down to three quarters of it.
pub const MAX_FILES: usize = 16_384;

const MAGIC: &[u8; 8] = b"LAPTAB01";
const CHANNELS: usize = crate::spectrum::rgb::CHANNELS;
const HEADER: usize = 8 + 3 * 4 + 16;

/// A store in one folder, for one build of the program.
#[derive(Debug)]
pub struct Store {
    dir: PathBuf,
    build: u64,
    /// Files in the folder when the store was opened (or last pruned), plus those it wrote since.
    files: AtomicUsize,
    /// The bound ([`MAX_FILES`] but in tests).
    max_files: usize,
    /// Held while the folder is pruned (one thread prunes; the others skip their write).
    pruning: std::sync::Mutex<()>,
    /// Tables read back and tables measured (and offered to the folder).
    hits: AtomicU64,
    misses: AtomicU64,
}

/// The process's store, placed by the environment (module docs); `None` when there is none.
pub fn global() -> Option<&'static Store> {
    static STORE: OnceLock<Option<Store>> = OnceLock::new();
    STORE
        .get_or_init(|| {
            let dir = crate::spectrum::rgb2spec::cache::folder()?.join("tables");
            Some(Store::open(dir, build_identity()?))
        })
        .as_ref()
}

/// Whether the process's store reads tables back (on unless [`measure_always`] was called).
static READ: AtomicBool = AtomicBool::new(true);

/// Makes the process's store measure every table (and still keep it): for `lapidary tradeoff`,
/// whose setup column is the cost of measuring a setting's tables.
pub fn measure_always() {
    READ.store(false, Ordering::Relaxed);
}

/// The tables `build` measures, read from the process's store when they are there (module docs).
/// `what` names the kind of table, `key` holds every input of `build`.
pub fn tables<const N: usize>(
    what: &str,
    key: &dyn Debug,
    build: impl FnOnce() -> [Table; N],
) -> [Table; N] {
    match global() {
        Some(store) => store.tables(what, key, build),
        None => build(),
    }
}

/// One table through [`tables`].
pub fn table(what: &str, key: &dyn Debug, build: impl FnOnce() -> Table) -> Table {
    let [t] = tables(what, key, || [build()]);
    t
}

/// The running program's identity: its version, path, size and modification time (`None` when
/// the program cannot be found: then there is no store).
fn build_identity() -> Option<u64> {
    let exe = std::env::current_exe().ok()?;
    let meta = std::fs::metadata(&exe).ok()?;
    let modified = meta
        .modified()
        .ok()?
        .duration_since(std::time::UNIX_EPOCH)
        .ok()?;
    let mut h = DefaultHasher::new();
    h.write(env!("CARGO_PKG_VERSION").as_bytes());
    h.write(exe.as_os_str().as_encoded_bytes());
    h.write_u64(meta.len());
    h.write_u128(modified.as_nanos());
    Some(h.finish())
}

impl Store {
    /// The store in `dir` for the program build `build` (the folder is made on the first write).
    pub fn open(dir: PathBuf, build: u64) -> Store {
        Store::bounded(dir, build, MAX_FILES)
    }

    /// [`Store::open`] with another bound than [`MAX_FILES`].
    fn bounded(dir: PathBuf, build: u64, max_files: usize) -> Store {
        let files = std::fs::read_dir(&dir).map_or(0, |d| d.count());
        Store {
            dir,
            build,
            files: AtomicUsize::new(files),
            max_files,
            pruning: std::sync::Mutex::new(()),
            hits: AtomicU64::new(0),
            misses: AtomicU64::new(0),
        }
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Whether the folder holds [`MAX_FILES`] files or more (the next write prunes it first).
    pub fn full(&self) -> bool {
        self.files.load(Ordering::Relaxed) >= self.max_files
    }

    /// Removes the oldest (by modification time) of the store's own table files — a name of 32
    /// lowercase hex digits and `.tab`, a regular file that starts with the store's magic — until
    /// the folder holds at most three quarters of the bound; nothing else in the folder is
    /// touched. Returns whether there is room for a file.
    fn prune(&self) -> bool {
        let Ok(_one) = self.pruning.try_lock() else {
            return false;
        };
        if !self.full() {
            return true; // another thread pruned meanwhile
        }
        let Ok(entries) = std::fs::read_dir(&self.dir) else {
            return false;
        };
        let mut total = 0;
        let mut ours = Vec::new();
        for e in entries.flatten() {
            total += 1;
            let path = e.path();
            if is_table_name(&e.file_name())
                && let Ok(meta) = std::fs::symlink_metadata(&path)
                && meta.is_file()
                && starts_with_magic(&path)
            {
                ours.push((meta.modified().unwrap_or(std::time::UNIX_EPOCH), path));
            }
        }
        ours.sort();
        let keep = self.max_files * 3 / 4;
        for (_, path) in ours {
            if total <= keep {
                break;
            }
            if std::fs::remove_file(&path).is_ok() {
                total -= 1;
            }
        }
        self.files.store(total, Ordering::Relaxed);
        total < self.max_files
    }

    /// Tables read back and tables measured so far.
    pub fn counts(&self) -> (u64, u64) {
        (
            self.hits.load(Ordering::Relaxed),
            self.misses.load(Ordering::Relaxed),
        )
    }

    /// The tables `build` measures, read back when stored (module docs).
    pub fn tables<const N: usize>(
        &self,
        what: &str,
        key: &dyn Debug,
        build: impl FnOnce() -> [Table; N],
    ) -> [Table; N] {
        let id = self.key(what, key);
        let path = self.dir.join(format!("{id:032x}.tab"));
        if READ.load(Ordering::Relaxed)
            && let Some(t) = read::<N>(&path, id)
        {
            self.hits.fetch_add(1, Ordering::Relaxed);
            return t;
        }
        self.misses.fetch_add(1, Ordering::Relaxed);
        let t = build();
        self.write(&path, &encode(id, &t));
        t
    }

    /// One table through [`Store::tables`].
    pub fn table(&self, what: &str, key: &dyn Debug, build: impl FnOnce() -> Table) -> Table {
        let [t] = self.tables(what, key, || [build()]);
        t
    }

    /// The 128-bit key of `what` with inputs `key` in this build.
    fn key(&self, what: &str, key: &dyn Debug) -> u128 {
        let mut text = String::new();
        // Writing into a String cannot fail.
        let _ = write!(text, "{what}\u{0}{key:?}");
        let half = |salt: u64| {
            let mut h = DefaultHasher::new();
            h.write_u64(salt);
            h.write_u64(self.build);
            h.write(text.as_bytes());
            h.finish()
        };
        (u128::from(half(0x7ab1e)) << 64) | u128::from(half(0x5a17))
    }

    /// Puts `bytes` at `path` through a temporary file of the store's own; any failure leaves the
    /// folder as it was.
    fn write(&self, path: &Path, bytes: &[u8]) {
        if self.full() && !self.prune() {
            return;
        }
        if std::fs::create_dir_all(&self.dir).is_err() {
            return;
        }
        static TEMPORARY: AtomicU64 = AtomicU64::new(0);
        let n = TEMPORARY.fetch_add(1, Ordering::Relaxed);
        let tmp = path.with_extension(format!("{}.{n}.tmp", std::process::id()));
        let Ok(mut file) = std::fs::File::create_new(&tmp) else {
            return;
        };
        self.files.fetch_add(1, Ordering::Relaxed);
        let written = file.write_all(bytes).is_ok() && file.flush().is_ok();
        drop(file);
        if !(written && std::fs::rename(&tmp, path).is_ok()) {
            // Our own temporary file (made by `create_new` above), never anything else.
            let _ = std::fs::remove_file(&tmp);
        }
    }
}

/// Whether `name` is a table file's: 32 lowercase hex digits and `.tab`.
fn is_table_name(name: &std::ffi::OsStr) -> bool {
    name.to_str().is_some_and(|n| {
        n.len() == 36
            && n.ends_with(".tab")
            && n[..32]
                .bytes()
                .all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b))
    })
}

/// Whether the file at `path` starts with the store's magic.
fn starts_with_magic(path: &Path) -> bool {
    use std::io::Read as _;
    let mut head = [0u8; 8];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok()
        && &head == MAGIC
}

/// A file's checksum of its values.
fn checksum(values: &[u8]) -> u64 {
    let mut h = DefaultHasher::new();
    h.write(values);
    h.finish()
}

/// The file for tables `t` under key `id`: magic, counts, key, the values (f32, little-endian),
/// checksum.
fn encode<const N: usize>(id: u128, t: &[Table; N]) -> Vec<u8> {
    let mut bytes = Vec::with_capacity(HEADER + N * ENTRIES * CHANNELS * 4 + 8);
    bytes.extend_from_slice(MAGIC);
    for n in [N, ENTRIES, CHANNELS] {
        bytes.extend_from_slice(&(n as u32).to_le_bytes());
    }
    bytes.extend_from_slice(&id.to_le_bytes());
    for table in t {
        for v in table.values() {
            for c in v.0 {
                bytes.extend_from_slice(&c.to_le_bytes());
            }
        }
    }
    let sum = checksum(&bytes[HEADER..]);
    bytes.extend_from_slice(&sum.to_le_bytes());
    bytes
}

/// The tables stored at `path` under key `id`, if the file is whole and holds them.
fn read<const N: usize>(path: &Path, id: u128) -> Option<[Table; N]> {
    let bytes = std::fs::read(path).ok()?;
    decode(&bytes, id)
}

/// [`encode`]'s inverse; `None` for anything else.
fn decode<const N: usize>(bytes: &[u8], id: u128) -> Option<[Table; N]> {
    let values = N * ENTRIES * CHANNELS * 4;
    if bytes.len() != HEADER + values + 8 || &bytes[..8] != MAGIC {
        return None;
    }
    let word = |i: usize| u32::from_le_bytes(bytes[8 + 4 * i..12 + 4 * i].try_into().unwrap());
    if [word(0), word(1), word(2)] != [N as u32, ENTRIES as u32, CHANNELS as u32] {
        return None;
    }
    if u128::from_le_bytes(bytes[20..36].try_into().ok()?) != id {
        return None;
    }
    let body = &bytes[HEADER..HEADER + values];
    if u64::from_le_bytes(bytes[HEADER + values..].try_into().ok()?) != checksum(body) {
        return None;
    }
    let floats: Vec<f32> = body
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
        .collect();
    if !floats.iter().all(|v| v.is_finite()) {
        return None;
    }
    let mut tables = floats.chunks_exact(ENTRIES * CHANNELS).map(|t| {
        Table::from_values(
            t.chunks_exact(CHANNELS)
                .map(|c| RgbSample(std::array::from_fn(|i| c[i])))
                .collect(),
        )
    });
    let out: [Table; N] = std::array::from_fn(|_| tables.next().expect("N tables in the body"));
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample_table(seed: f32) -> Table {
        Table::build(|mu| RgbSample([mu * seed, mu.sqrt() + seed, 1.0 / (1.0 + mu + seed)]))
    }

    fn temp_dir(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("lapidary-store-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    #[test]
    fn tables_come_back_bit_for_bit_and_are_measured_once() {
        let dir = temp_dir("round-trip");
        let store = Store::open(dir.clone(), 7);
        let mut built = 0;
        let want = [sample_table(0.3), sample_table(1.7)];
        let a = store.tables("pair", &(1.5f32, "x"), || {
            built += 1;
            want.clone()
        });
        let b = store.tables("pair", &(1.5f32, "x"), || {
            built += 1;
            want.clone()
        });
        assert_eq!(built, 1, "the second request reads the file");
        for t in [&a, &b] {
            for (x, y) in t.iter().zip(&want) {
                let bits = |t: &Table| -> Vec<u32> {
                    t.values()
                        .iter()
                        .flat_map(|v| v.0.map(f32::to_bits))
                        .collect()
                };
                assert_eq!(bits(x), bits(y));
            }
        }
        assert_eq!(store.counts(), (1, 1));
        // Another input, another kind or another build is another table.
        store.tables("pair", &(1.5000001f32, "x"), || {
            built += 1;
            want.clone()
        });
        store.tables("other", &(1.5f32, "x"), || {
            built += 1;
            want.clone()
        });
        Store::open(dir.clone(), 8).tables("pair", &(1.5f32, "x"), || {
            built += 1;
            want.clone()
        });
        assert_eq!(built, 4);
        let names: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        assert_eq!(names.len(), 4, "{names:?}");
        assert!(names.iter().all(|n| n.ends_with(".tab") && n.len() == 36));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_damaged_file_is_measured_again_and_replaced() {
        let dir = temp_dir("damaged");
        let store = Store::open(dir.clone(), 1);
        let t = sample_table(0.5);
        store.table("one", &3u8, || t.clone());
        let path = std::fs::read_dir(&dir)
            .unwrap()
            .next()
            .unwrap()
            .unwrap()
            .path();
        let good = std::fs::read(&path).unwrap();
        // A flipped value bit (checksum), a truncation, a wrong key, a NaN with a valid checksum.
        let mut flipped = good.clone();
        flipped[HEADER + 5] ^= 4;
        let truncated = good[..good.len() - 3].to_vec();
        let mut other_key = good.clone();
        other_key[25] ^= 1;
        let mut nan = good.clone();
        nan[HEADER..HEADER + 4].copy_from_slice(&f32::NAN.to_le_bytes());
        let sum = checksum(&nan[HEADER..nan.len() - 8]);
        let end = nan.len() - 8;
        nan[end..].copy_from_slice(&sum.to_le_bytes());
        for bad in [flipped, truncated, other_key, nan, Vec::new()] {
            std::fs::write(&path, &bad).unwrap();
            let mut built = false;
            let back = store.table("one", &3u8, || {
                built = true;
                t.clone()
            });
            assert!(built && back == t);
            assert_eq!(std::fs::read(&path).unwrap(), good, "rewritten whole");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_full_store_removes_its_oldest_tables_and_nothing_else() {
        let dir = temp_dir("full");
        // Someone else's files in the folder: one named like a table but not one, one plain.
        std::fs::create_dir_all(&dir).unwrap();
        let lookalike = dir.join(format!("{:032x}.tab", 7));
        std::fs::write(&lookalike, b"not a table at all").unwrap();
        std::fs::write(dir.join("notes.txt"), b"mine").unwrap();
        let store = Store::bounded(dir.clone(), 1, 8);
        let t = sample_table(0.1);
        for k in 0..6 {
            store.table("x", &k, || t.clone());
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 8);
        assert!(store.full());
        // The next write prunes to 6 (the two oldest tables of ours go), then writes.
        store.table("x", &6, || t.clone());
        let names: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        assert_eq!(names.len(), 7, "{names:?}");
        assert_eq!(std::fs::read(&lookalike).unwrap(), b"not a table at all");
        assert_eq!(std::fs::read(dir.join("notes.txt")).unwrap(), b"mine");
        let kept: Vec<bool> = (0..7)
            .map(|k| {
                dir.join(format!("{:032x}.tab", store.key("x", &k)))
                    .exists()
            })
            .collect();
        assert_eq!(kept, [false, false, true, true, true, true, true]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn an_unwritable_folder_only_measures() {
        let t = sample_table(0.1);
        // A folder that cannot be made (its parent is a file).
        let file = temp_dir("not-a-folder");
        std::fs::write(&file, b"mine").unwrap();
        let store = Store::open(file.join("tables"), 1);
        assert_eq!(store.table("x", &1, || t.clone()), t);
        assert_eq!(std::fs::read(&file).unwrap(), b"mine");
        std::fs::remove_file(&file).unwrap();
    }
}
