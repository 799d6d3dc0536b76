//! One MR-JE-C axis on a non-RT thread of its own: one exchange every link period (absolute
//! deadlines, a late period is not made up), commands in through a lock-free queue, the
//! feedback out through a lock-free cell, so the cell's other threads never wait for the
//! network. Start-up parameters (the drive-side time-outs) are written before the first cycle.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crossbeam::atomic::AtomicCell;
use crossbeam::queue::ArrayQueue;

use super::control::{AxisCommand, AxisControl, Stopped};
use super::io::{DriveIo, ExchangeError, Inputs};
use crate::mr_je_c::objects::ObjectId;
use crate::mr_je_c::value::Value;

/// Commands waiting for the axis' thread.
const QUEUE: usize = 16;

/// What the axis' thread publishes after each exchange.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct AxisFeedback {
    /// Exchanges run.
    pub cycles: u64,
    /// The last answer.
    pub inputs: Inputs,
    /// The servo is on (Operation enabled).
    pub enabled: bool,
    /// A job runs.
    pub busy: bool,
    /// Jobs ended done.
    pub done: u32,
    /// Jobs ended failed.
    pub failed: u32,
    /// The stop in force.
    pub stopped: Option<Stopped>,
    /// Exchanges without an answer, in all.
    pub missed: u64,
    /// Misses in a row now.
    pub missed_in_row: u32,
    /// Exchanges the drive refused.
    pub refused: u64,
    /// The last round trip, ns.
    pub round_trip_ns: u64,
    /// The longest round trip, ns.
    pub max_round_trip_ns: u64,
}

struct Cells {
    commands: ArrayQueue<AxisCommand>,
    feedback: AtomicCell<AxisFeedback>,
    stop: AtomicBool,
}

/// The cell's handle on one axis' thread.
#[derive(Clone)]
pub struct AxisHandle {
    cells: Arc<Cells>,
}

impl AxisHandle {
    /// Queues `c` for the next exchange; `false`: the queue is full.
    pub fn command(&self, c: AxisCommand) -> bool {
        self.cells.commands.push(c).is_ok()
    }

    /// The latest feedback.
    pub fn feedback(&self) -> AxisFeedback {
        self.cells.feedback.load()
    }
}

/// The axis' thread; stopped and joined on drop.
pub struct AxisThread {
    /// Commands and feedback.
    pub handle: AxisHandle,
    thread: Option<JoinHandle<()>>,
}

/// Why the axis' thread could not start.
#[derive(Debug, thiserror::Error)]
pub enum StartError {
    /// A start-up parameter was not written.
    #[error("{0}: {1}")]
    Parameter(ObjectId, ExchangeError),
    /// The thread could not be spawned.
    #[error("thread: {0}")]
    Spawn(#[from] std::io::Error),
}

impl AxisThread {
    /// Writes `parameters` through `io`, then runs `control` on a thread named `name`, one
    /// exchange every `period`.
    pub fn start(
        name: &str,
        mut io: Box<dyn DriveIo>,
        parameters: &[(ObjectId, Value)],
        mut control: AxisControl,
        period: Duration,
    ) -> Result<AxisThread, StartError> {
        for (id, v) in parameters {
            io.write_object(*id, v)
                .map_err(|e| StartError::Parameter(*id, e))?;
        }
        let cells = Arc::new(Cells {
            commands: ArrayQueue::new(QUEUE),
            feedback: AtomicCell::new(AxisFeedback::default()),
            stop: AtomicBool::new(false),
        });
        let mine = cells.clone();
        let thread = std::thread::Builder::new()
            .name(format!("cellrt-jec-{name}"))
            .spawn(move || run(&mine, io.as_mut(), &mut control, period))?;
        Ok(AxisThread {
            handle: AxisHandle { cells },
            thread: Some(thread),
        })
    }
}

fn run(cells: &Cells, io: &mut dyn DriveIo, control: &mut AxisControl, period: Duration) {
    let mut f = AxisFeedback::default();
    let mut next = Instant::now();
    while !cells.stop.load(Ordering::Acquire) {
        while let Some(c) = cells.commands.pop() {
            control.command(c);
        }
        let answer = io.exchange(&control.outputs());
        control.step(answer);
        let rtt = io.round_trip().as_nanos() as u64;
        f.cycles += 1;
        f.inputs = control.inputs;
        f.enabled = crate::cia402::statusword::Statusword(control.inputs.statusword).state()
            == Some(crate::cia402::fsa::FsaState::OperationEnabled);
        f.busy = control.busy();
        f.done = control.done;
        f.failed = control.failed;
        f.stopped = control.stopped;
        f.missed = control.missed;
        f.missed_in_row = control.missed_in_row();
        f.refused = control.refused;
        f.round_trip_ns = rtt;
        f.max_round_trip_ns = f.max_round_trip_ns.max(rtt);
        cells.feedback.store(f);
        next += period;
        let now = Instant::now();
        match next.checked_duration_since(now) {
            Some(wait) => std::thread::sleep(wait),
            None => next = now,
        }
    }
}

impl Drop for AxisThread {
    fn drop(&mut self) {
        self.handle.cells.stop.store(true, Ordering::Release);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}
