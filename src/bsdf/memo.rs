//! A process-wide memo of values that depend only on their key (tables of a component that
//! several materials repeat). Sharing a value changes no result: the value is a deterministic
//! function of the key. The memo is bounded: past its capacity it starts afresh.
//!
//! Materials are built in parallel, so the first requests for a key usually arrive together: one
//! thread builds the value while the others wait for it (a per-key `OnceLock`), instead of every
//! thread building it. A build closure must not ask its own memo for its own key.

use std::collections::HashMap;
use std::hash::Hash;
use std::sync::{Arc, Mutex, OnceLock};

/// A bounded, thread-safe memo (see the module docs).
pub struct Memo<K, V> {
    map: OnceLock<Mutex<HashMap<K, Arc<OnceLock<V>>>>>,
    capacity: usize,
}

impl<K: Eq + Hash, V: Clone> Memo<K, V> {
    /// An empty memo that keeps at most `capacity` entries.
    pub const fn new(capacity: usize) -> Self {
        Memo {
            map: OnceLock::new(),
            capacity,
        }
    }

    /// The value for `key`, computed by `build` the first time; a thread asking while another
    /// builds it waits for that value.
    pub fn get_or_build(&self, key: K, build: impl FnOnce() -> V) -> V {
        let map = self.map.get_or_init(|| Mutex::new(HashMap::new()));
        let cell = match map.lock() {
            Ok(mut m) => {
                if m.len() >= self.capacity && !m.contains_key(&key) {
                    m.clear();
                }
                Arc::clone(m.entry(key).or_default())
            }
            // A poisoned lock (a panic elsewhere while holding it): build without sharing.
            Err(_) => return build(),
        };
        cell.get_or_init(build).clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builds_once_and_stays_bounded() {
        static MEMO: Memo<u32, u64> = Memo::new(2);
        let mut calls = 0;
        assert_eq!(MEMO.get_or_build(1, || { calls += 1; 10 }), 10);
        assert_eq!(MEMO.get_or_build(1, || { calls += 1; 99 }), 10);
        assert_eq!(calls, 1);
        MEMO.get_or_build(2, || 20);
        MEMO.get_or_build(3, || 30);
        assert_eq!(MEMO.get_or_build(1, || 11), 11, "evicted past capacity");
    }
}
