//! A process-wide memo of values that depend only on their key (tables of a component that
//! several materials repeat). Sharing a value changes no result: the value is a deterministic
//! function of the key. The memo is bounded: past its capacity it starts afresh.
//!
//! Nothing ever waits for another thread's build: a request for a key that is not there yet
//! builds it, even while another thread builds the same key (both results are the same value;
//! the first one stored is kept). Builders use rayon, and waiting inside rayon jobs deadlocks:
//! a blocking wait takes a worker away from the builder's parallel loop, and a waiter that runs
//! other jobs while it waits can suspend, beneath itself, the very work the builder needs (both
//! observed in `tests/adding.rs`). The price is that the first wave of parallel requests builds a
//! key at most once per thread.

use std::collections::HashMap;
use std::hash::Hash;
use std::sync::{Mutex, OnceLock};

/// A bounded, thread-safe memo (see the module docs).
pub struct Memo<K, V> {
    map: OnceLock<Mutex<HashMap<K, V>>>,
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

    /// The value for `key`, computed by `build` unless it is stored already.
    pub fn get_or_build(&self, key: K, build: impl FnOnce() -> V) -> V {
        let map = self.map.get_or_init(|| Mutex::new(HashMap::new()));
        if let Some(v) = map.lock().ok().and_then(|m| m.get(&key).cloned()) {
            return v;
        }
        let v = build();
        if let Ok(mut m) = map.lock() {
            if let Some(first) = m.get(&key) {
                // Another thread stored it meanwhile: keep one value for everybody.
                return first.clone();
            }
            if m.len() >= self.capacity {
                m.clear();
            }
            m.insert(key, v.clone());
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    #[test]
    fn builds_once_and_stays_bounded() {
        static MEMO: Memo<u32, u64> = Memo::new(2);
        let mut calls = 0;
        assert_eq!(
            MEMO.get_or_build(1, || {
                calls += 1;
                10
            }),
            10
        );
        assert_eq!(
            MEMO.get_or_build(1, || {
                calls += 1;
                99
            }),
            10
        );
        assert_eq!(calls, 1);
        MEMO.get_or_build(2, || 20);
        MEMO.get_or_build(3, || 30);
        assert_eq!(MEMO.get_or_build(1, || 11), 11, "evicted past capacity");
    }

    #[test]
    fn parallel_requests_whose_builders_use_rayon_finish() {
        // Every rayon worker asks for the same keys while their builders run parallel loops (a
        // waiting memo deadlocks here).
        static MEMO: Memo<u32, u64> = Memo::new(64);
        let total: u64 = (0..64u32)
            .into_par_iter()
            .map(|i| {
                MEMO.get_or_build(i % 4, || {
                    (0..10_000u64).into_par_iter().map(|x| x % 7).sum::<u64>()
                })
            })
            .sum();
        let one: u64 = (0..10_000u64).map(|x| x % 7).sum();
        assert_eq!(total, 64 * one);
    }

    #[test]
    fn a_panicking_builder_stores_nothing() {
        static MEMO: Memo<u32, u64> = Memo::new(8);
        let r = std::panic::catch_unwind(|| MEMO.get_or_build(7, || panic!("no")));
        assert!(r.is_err());
        assert_eq!(MEMO.get_or_build(7, || 5), 5);
    }
}
