//! Evaluating a planned move does not allocate (counting global allocator, this thread only).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use cellrt_trajectory::{plan_move, AxisState, KinematicLimits, MoveAxis, MoveSampler};

struct Counting;

thread_local! {
    static ALLOCS: Cell<u64> = const { Cell::new(0) };
}

// SAFETY: forwards to the system allocator; only counts calls.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocs() -> u64 {
    ALLOCS.with(|c| c.get())
}

#[test]
fn sampling_does_not_allocate() {
    let limits = KinematicLimits {
        velocity: 1.0,
        acceleration: 5.0,
        jerk: 50.0,
    };
    let axes: Vec<_> = (0..6)
        .map(|i| MoveAxis {
            start: AxisState {
                position: 0.0,
                velocity: 0.2,
                acceleration: -0.5,
            },
            target: i as f64 - 2.0,
            limits,
        })
        .collect();
    let before_plan = allocs();
    let plan = plan_move(&axes).unwrap();
    assert!(
        allocs() > before_plan,
        "counter must see the planner's allocations"
    );
    let sampler = MoveSampler::new(plan, 125e-6).unwrap();
    let mut out = [AxisState::default(); 6];
    let mut checksum = 0.0;
    let before = allocs();
    for k in 0..=sampler.cycles() + 10 {
        sampler.fill(k, &mut out);
        checksum += out[5].position;
    }
    sampler.plan().state_at(f64::NAN, &mut out);
    assert_eq!(allocs(), before);
    assert!(checksum.is_finite());
}
