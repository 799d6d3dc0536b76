//! Evaluating a planned move does not allocate (counting global allocator, this thread only).

use cellrt_test_support::counting_alloc::{thread_heap_calls, CountingAllocator};
use cellrt_trajectory::{plan_move, AxisState, KinematicLimits, MoveAxis, MoveSampler};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

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
    let before_plan = thread_heap_calls();
    let plan = plan_move(&axes).unwrap();
    assert!(
        thread_heap_calls() > before_plan,
        "counter must see the planner's allocations"
    );
    let sampler = MoveSampler::new(plan, 125e-6).unwrap();
    let mut out = [AxisState::default(); 6];
    let mut checksum = 0.0;
    let before = thread_heap_calls();
    for k in 0..=sampler.cycles() + 10 {
        sampler.fill(k, &mut out);
        checksum += out[5].position;
    }
    sampler.plan().state_at(f64::NAN, &mut out);
    assert_eq!(thread_heap_calls(), before);
    assert!(checksum.is_finite());
}
