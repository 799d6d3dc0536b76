//! A counting global allocator for the checks that the RT path does not touch the heap in
//! steady state: every heap call (allocation, zeroed allocation, reallocation, free) is
//! forwarded to the system allocator and counted.
//!
//! A test binary installs it with
//! `#[global_allocator] static GLOBAL: CountingAllocator = CountingAllocator;` — only the
//! binaries that check allocations do, the others keep the system allocator. Two counts:
//! [`thread_heap_calls`], this thread's calls (for code the test runs on its own thread; tests
//! running in parallel do not disturb each other), and [`marked_heap_calls`], the calls of
//! every thread between [`mark_this_thread`]`(true)` and `(false)` (for a thread the test does
//! not run itself, e.g. the RT thread marked from the executive's phase hook).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicU64, Ordering};

/// The system allocator, counting heap calls.
pub struct CountingAllocator;

thread_local! {
    static THREAD_CALLS: Cell<u64> = const { Cell::new(0) };
    static MARKED: Cell<bool> = const { Cell::new(false) };
}

/// Heap calls made on marked threads.
static MARKED_CALLS: AtomicU64 = AtomicU64::new(0);

/// Counts one heap call. `try_with`: thread-local storage may already be gone while a thread
/// exits, and its destructors still free memory.
fn count() {
    let _ = THREAD_CALLS.try_with(|c| c.set(c.get() + 1));
    if MARKED.try_with(Cell::get).unwrap_or(false) {
        MARKED_CALLS.fetch_add(1, Ordering::Relaxed);
    }
}

// SAFETY: every call is forwarded unchanged to the system allocator; counting allocates nothing.
unsafe impl GlobalAlloc for CountingAllocator {
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

/// Heap calls this thread has made so far.
pub fn thread_heap_calls() -> u64 {
    THREAD_CALLS.with(Cell::get)
}

/// Starts (`true`) or stops (`false`) counting this thread's heap calls in
/// [`marked_heap_calls`].
pub fn mark_this_thread(on: bool) {
    MARKED.with(|m| m.set(on));
}

/// Heap calls made so far on threads while they were marked ([`mark_this_thread`]).
pub fn marked_heap_calls() -> u64 {
    MARKED_CALLS.load(Ordering::Relaxed)
}
