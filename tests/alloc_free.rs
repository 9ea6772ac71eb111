//! Proof that map lookups never allocate: a counting global allocator (test-only; the library
//! itself forbids `unsafe`) counts heap allocations made by this thread while lookups run.

use glam::Vec3;
use lapidary::recipe::GemRecipe;
use lapidary::sampler::Rng;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::Path;

struct Counting;

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
    static COUNT: Cell<usize> = const { Cell::new(0) };
}

// SAFETY: forwards every call to the system allocator unchanged; the bookkeeping touches only
// const-initialised thread-locals, which never allocate.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if COUNTING.with(Cell::get) {
            COUNT.with(|c| c.set(c.get() + 1));
        }
        // SAFETY: the caller upholds `GlobalAlloc::alloc`'s contract, passed on unchanged.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from `System.alloc` with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

#[test]
fn lookups_of_the_shipped_gems_do_not_allocate() {
    for gem in ["lepidolite.ron", "sunstone.ron"] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("gems").join(gem);
        let map = GemRecipe::load(&path)
            .unwrap()
            .compile()
            .unwrap()
            .surface
            .map;
        let mut rng = Rng::new(1);
        let points: Vec<(Vec3, f32)> = (0..20_000)
            .map(|_| {
                let p = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 4.0 - 2.0;
                (p, rng.uniform())
            })
            .collect();
        let mut materials = 0u64;
        COUNTING.with(|c| c.set(true));
        for &(p, u) in &points {
            let hit = map.lookup(p, u);
            materials += u64::from(hit.material) + hit.trail.ids().len() as u64;
        }
        COUNTING.with(|c| c.set(false));
        assert!(materials > 0);
        assert_eq!(COUNT.with(Cell::get), 0, "{gem}: lookups allocated");
        // The counter works: an allocation on this thread is seen.
        COUNTING.with(|c| c.set(true));
        let v: Vec<u64> = std::hint::black_box(vec![1, 2, 3]);
        COUNTING.with(|c| c.set(false));
        assert_eq!(COUNT.with(Cell::get), 1, "{v:?}");
        COUNT.with(|c| c.set(0));
    }
}
