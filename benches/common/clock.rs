//! Clocks for criterion, shared by the benches (`#[path]`-included): on 64-bit Linux a measurement
//! that reads, through `clock_gettime`, the clock selected with [`select`] (default: the benchmark
//! thread's CPU time); elsewhere criterion's wall time. Not every bench uses every clock.
#![allow(dead_code, unused_imports)]

/// Which time a benchmark measures.
#[derive(Clone, Copy)]
pub enum Kind {
    /// CPU time of the benchmark thread (per-call benchmarks).
    Thread,
    /// CPU time of all threads of the process (parallel table builds: total work).
    Process,
    /// Wall time (parallel table builds: latency).
    Wall,
}

#[cfg(all(target_os = "linux", target_pointer_width = "64"))]
pub use linux::{CPU_CLOCKS, Clock, select};

/// The measurement criterion is configured with.
pub fn measurement() -> Clock {
    #[cfg(all(target_os = "linux", target_pointer_width = "64"))]
    return Clock;
    #[cfg(not(all(target_os = "linux", target_pointer_width = "64")))]
    return criterion::measurement::WallTime;
}

#[cfg(all(target_os = "linux", target_pointer_width = "64"))]
mod linux {
    use super::Kind;
    use criterion::measurement::{Measurement, ValueFormatter, WallTime};
    use std::ffi::{c_int, c_long};
    use std::sync::atomic::{AtomicI32, Ordering};
    use std::time::Duration;

    /// Whether CPU-time clocks are available.
    pub const CPU_CLOCKS: bool = true;

    /// `struct timespec` of 64-bit Linux.
    #[repr(C)]
    struct Timespec {
        tv_sec: c_long,
        tv_nsec: c_long,
    }

    /// Linux clock ids (`<linux/time.h>`).
    const CLOCK_MONOTONIC: c_int = 1;
    const CLOCK_PROCESS_CPUTIME_ID: c_int = 2;
    const CLOCK_THREAD_CPUTIME_ID: c_int = 3;

    unsafe extern "C" {
        fn clock_gettime(clock: c_int, tp: *mut Timespec) -> c_int;
    }

    /// The clock every [`Clock`] reads.
    static SELECTED: AtomicI32 = AtomicI32::new(CLOCK_THREAD_CPUTIME_ID);

    /// Makes every following measurement read `kind` (benchmarks run one after another).
    pub fn select(kind: Kind) {
        let id = match kind {
            Kind::Thread => CLOCK_THREAD_CPUTIME_ID,
            Kind::Process => CLOCK_PROCESS_CPUTIME_ID,
            Kind::Wall => CLOCK_MONOTONIC,
        };
        SELECTED.store(id, Ordering::SeqCst);
    }

    fn now() -> Duration {
        let id = SELECTED.load(Ordering::SeqCst);
        let mut t = Timespec {
            tv_sec: 0,
            tv_nsec: 0,
        };
        // SAFETY: `t` is a valid, writable `timespec`; the call only writes into it.
        let rc = unsafe { clock_gettime(id, &mut t) };
        assert_eq!(rc, 0, "clock_gettime({id}) failed");
        Duration::new(t.tv_sec as u64, t.tv_nsec as u32)
    }

    /// Durations are formatted as wall time is.
    static FORMAT: WallTime = WallTime;

    /// The selected clock as a criterion measurement.
    pub struct Clock;

    impl Measurement for Clock {
        type Intermediate = Duration;
        type Value = Duration;
        fn start(&self) -> Duration {
            now()
        }
        fn end(&self, start: Duration) -> Duration {
            now().saturating_sub(start)
        }
        fn add(&self, a: &Duration, b: &Duration) -> Duration {
            *a + *b
        }
        fn zero(&self) -> Duration {
            Duration::ZERO
        }
        fn to_f64(&self, v: &Duration) -> f64 {
            v.as_nanos() as f64
        }
        fn formatter(&self) -> &dyn ValueFormatter {
            FORMAT.formatter()
        }
    }
}

/// Wall time only.
#[cfg(not(all(target_os = "linux", target_pointer_width = "64")))]
pub const CPU_CLOCKS: bool = false;

/// Wall time only.
#[cfg(not(all(target_os = "linux", target_pointer_width = "64")))]
pub type Clock = criterion::measurement::WallTime;

/// Wall time only: nothing to select.
#[cfg(not(all(target_os = "linux", target_pointer_width = "64")))]
pub fn select(_kind: Kind) {}
