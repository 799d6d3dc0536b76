//! What runs on the RT thread: the monotonic cycle clock, thread setup (affinity, SCHED_FIFO,
//! mlockall, stack prefault), preallocated latency histograms, the RT end of the setpoint
//! stream, the cell's fault-injection schedule and the cyclic executive. Allocation-free, lock-free and syscall-free in steady state
//! (but for the cycle sleep and bus I/O).

pub mod clock;
pub mod executive;
pub mod histogram;
pub mod injection;
pub mod setpoint_stream;
pub mod thread;
