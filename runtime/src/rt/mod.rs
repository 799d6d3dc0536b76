//! The RT thread's building blocks: the monotonic cycle clock, thread setup (affinity,
//! SCHED_FIFO, mlockall, stack prefault) and preallocated latency histograms.

pub mod clock;
pub mod histogram;
pub mod thread;
