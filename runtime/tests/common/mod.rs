//! A counting global allocator for the RT-allocation tests: counts only on a thread that the
//! executive's phase hook marks (the RT thread, between `SteadyState` and `Exit`).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicU64, Ordering};

use cellrt_runtime::rt::executive::RtPhase;

struct Counting;

/// Allocations, reallocations and frees counted on marked threads.
pub static ALLOCATIONS: AtomicU64 = AtomicU64::new(0);
/// How many RT loops reached their `Exit` hook.
pub static LOOPS_EXITED: AtomicU64 = AtomicU64::new(0);

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
}

fn counting() -> bool {
    COUNTING.try_with(|c| c.get()).unwrap_or(false)
}

fn count() {
    if counting() {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
    }
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        count();
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// The executive's phase hook: counting on from steady state to exit.
pub fn hook(phase: RtPhase) {
    match phase {
        RtPhase::SteadyState => COUNTING.with(|c| c.set(true)),
        RtPhase::Exit => {
            COUNTING.with(|c| c.set(false));
            LOOPS_EXITED.fetch_add(1, Ordering::Relaxed);
        }
    }
}
