//! The counting global allocator of the RT-allocation tests, counting only on a thread that
//! the executive's phase hook marks (the RT thread, between `SteadyState` and `Exit`).

use std::sync::atomic::{AtomicU64, Ordering};

use cellrt_runtime::rt::executive::RtPhase;
pub use cellrt_test_support::counting_alloc::marked_heap_calls;
use cellrt_test_support::counting_alloc::{mark_this_thread, CountingAllocator};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

/// How many RT loops reached their `Exit` hook.
pub static LOOPS_EXITED: AtomicU64 = AtomicU64::new(0);

/// The executive's phase hook: counting on from steady state to exit.
pub fn hook(phase: RtPhase) {
    match phase {
        RtPhase::SteadyState => mark_this_thread(true),
        RtPhase::Exit => {
            mark_this_thread(false);
            LOOPS_EXITED.fetch_add(1, Ordering::Relaxed);
        }
    }
}
