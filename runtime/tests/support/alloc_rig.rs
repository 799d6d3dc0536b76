//! The hand-off side of the RT-allocation tests that drive a cell through commands: the start
//! into steady state, waiting on the cell status, and the end that powers off, quits and
//! checks the count.

use std::sync::atomic::{AtomicU64, Ordering};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use cellrt_config::CellConfig;
use cellrt_runtime::handoff::{self, CellCommand, CellState, HostEnd};
use cellrt_runtime::rt::executive::{PhaseHook, RtStats, WARMUP_CYCLES};
use cellrt_runtime::services;

use super::rt_thread;

/// What the test's counting allocator (its `common` module) gives the rig.
#[derive(Clone, Copy)]
pub struct Counting {
    /// The executive's phase hook that marks the RT thread.
    pub hook: PhaseHook,
    /// Heap calls counted on marked threads so far.
    pub heap_calls: fn() -> u64,
    /// The count of RT loops that reached their `Exit` hook.
    pub loops_exited: &'static AtomicU64,
}

/// A cell powered on and in steady state, counting the RT thread's heap calls.
pub struct Steady {
    /// The host end of the hand-off.
    pub h: HostEnd,
    /// The RT thread.
    pub rt: JoinHandle<RtStats>,
    /// Heap calls counted when steady state was reached.
    pub before: u64,
    /// The counting allocator.
    pub counting: Counting,
    _publisher: services::SetpointPublisher,
    _node: iceoryx2::node::Node<iceoryx2::prelude::ipc::Service>,
}

impl Counting {
    /// The counting allocator's phase `hook`, its count of `heap_calls` and of the RT loops
    /// that reached their `Exit` hook.
    pub fn new(hook: PhaseHook, heap_calls: fn() -> u64, loops_exited: &'static AtomicU64) -> Self {
        Counting {
            hook,
            heap_calls,
            loops_exited,
        }
    }
}

/// Starts `cell`'s RT executive with the counting hook, powers it on and waits for steady
/// state.
pub fn start_steady(cell: &CellConfig, counting: Counting) -> Steady {
    let (rt_end, h) = handoff::new(
        cell.axes.on_loop().len(),
        1000,
        handoff::PerCycleRecords::Skipped,
    );
    let node = services::node(&cell.name, "test").unwrap();
    let publisher =
        services::setpoint_publisher(&node, &cell.name, cell.axes.on_loop().len()).unwrap();
    let rt = rt_thread::spawn_rt(cell, rt_end, Some(counting.hook));
    h.send_command(CellCommand::PowerOn).unwrap();
    wait(&h, |h| h.status().state() == CellState::Idle, "idle");
    wait(
        &h,
        |h| h.status().cycle() > WARMUP_CYCLES + 50,
        "steady state",
    );
    Steady {
        h,
        rt,
        before: (counting.heap_calls)(),
        counting,
        _publisher: publisher,
        _node: node,
    }
}

/// Waits up to 20 s for `done`.
pub fn wait(h: &HostEnd, done: impl Fn(&HostEnd) -> bool, what: &str) {
    let end = Instant::now() + Duration::from_secs(20);
    while !done(h) {
        assert!(Instant::now() < end, "never {what}");
        std::thread::sleep(Duration::from_millis(1));
    }
}

/// From idle: power off, quit, join the RT thread; no heap call counted since steady state.
/// The setpoint publisher and the node live until here (a publisher gone would be a change
/// the RT loop reacts to).
pub fn power_off_and_check(steady: Steady) {
    let Steady {
        h,
        rt,
        before,
        counting,
        _publisher: publisher,
        _node: node,
    } = steady;
    let h = &h;
    wait(h, |h| h.status().state() == CellState::Idle, "idle again");
    h.send_command(CellCommand::PowerOff).unwrap();
    wait(h, |h| h.status().state() == CellState::Disabled, "disabled");
    h.send_command(CellCommand::Quit).unwrap();
    rt.join().unwrap();
    assert_eq!(
        (counting.heap_calls)() - before,
        0,
        "the RT loop allocated in steady state"
    );
    assert_eq!(counting.loops_exited.load(Ordering::Relaxed), 1);
    drop((publisher, node));
}
