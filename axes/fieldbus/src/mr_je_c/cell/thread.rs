//! One MR-JE-C axis on a non-RT thread of its own: one exchange every link period (absolute
//! deadlines, a late period is not made up), commands in through a lock-free queue, the
//! feedback out through a lock-free cell, so the cell's other threads never wait for the
//! network. Start-up parameters (the drive-side time-outs) are written before the first cycle.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
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
/// Exchange records waiting for the recorder (40 s at 10 ms).
const RECORDS: usize = 4096;

/// One exchange, for the recording.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ExchangeRecord {
    /// Exchange number (from 1).
    pub exchange: u64,
    /// When it ended, ns since the Unix epoch.
    pub time_ns: u64,
    /// The drive answered.
    pub answered: bool,
    /// The last answer's values.
    pub inputs: Inputs,
    /// The controlword sent.
    pub controlword: u16,
    /// Its round trip, ns.
    pub round_trip_ns: u64,
    /// Misses in a row after it.
    pub missed_in_row: u32,
    /// Misses in all.
    pub missed: u64,
    /// Refusals in all.
    pub refused: u64,
    /// The stop in force.
    pub stopped: Option<Stopped>,
}

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
    records: ArrayQueue<ExchangeRecord>,
    records_dropped: AtomicU64,
    stop: AtomicBool,
}

impl Cells {
    /// Cells holding up to `records` exchange records.
    fn new(records: usize) -> Cells {
        Cells {
            commands: ArrayQueue::new(QUEUE),
            feedback: AtomicCell::new(AxisFeedback::default()),
            records: ArrayQueue::new(records.max(1)),
            records_dropped: AtomicU64::new(0),
            stop: AtomicBool::new(false),
        }
    }
}

/// The cell's handle on one axis' thread.
#[derive(Clone)]
pub struct AxisHandle {
    cells: Arc<Cells>,
}

impl AxisHandle {
    /// A handle with no thread behind it: its commands wait for [`AxisHandle::take_command`]
    /// and its feedback is what [`AxisHandle::set_feedback`] stored, so a link to the process
    /// that runs the axis' thread can carry both (an external planner's view of the axis).
    pub fn detached() -> AxisHandle {
        // No exchanges here to record: the axis' own process records them.
        AxisHandle {
            cells: Arc::new(Cells::new(1)),
        }
    }

    /// The oldest command not yet taken: a detached handle's link forwards it.
    pub fn take_command(&self) -> Option<AxisCommand> {
        self.cells.commands.pop()
    }

    /// Stores `f` as the latest feedback: a detached handle's link, from the axis' thread.
    pub fn set_feedback(&self, f: AxisFeedback) {
        self.cells.feedback.store(f);
    }

    /// Queues `c` for the next exchange; `false`: the queue is full.
    pub fn command(&self, c: AxisCommand) -> bool {
        self.cells.commands.push(c).is_ok()
    }

    /// The latest feedback.
    pub fn feedback(&self) -> AxisFeedback {
        self.cells.feedback.load()
    }

    /// The oldest exchange record not yet taken (the recorder's).
    pub fn pop_record(&self) -> Option<ExchangeRecord> {
        self.cells.records.pop()
    }

    /// Records dropped because nobody took them in time.
    pub fn records_dropped(&self) -> u64 {
        self.cells.records_dropped.load(Ordering::Relaxed)
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
            write_retried(io.as_mut(), *id, v).map_err(|e| StartError::Parameter(*id, e))?;
        }
        control.set_link_period(period);
        let cells = Arc::new(Cells::new(RECORDS));
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

/// Tries a start-up write this often before giving up on an unanswered one.
const START_UP_TRIES: u32 = 5;

/// Writes `v` to `id`, again after an unanswered try (a busy host, a lost datagram); a refusal
/// is final.
fn write_retried(io: &mut dyn DriveIo, id: ObjectId, v: &Value) -> Result<(), ExchangeError> {
    let mut tries = 0;
    loop {
        match io.write_object(id, v) {
            Err(ExchangeError::NoAnswer(_)) if tries + 1 < START_UP_TRIES => tries += 1,
            other => return other,
        }
    }
}

fn run(cells: &Cells, io: &mut dyn DriveIo, control: &mut AxisControl, period: Duration) {
    let mut f = AxisFeedback::default();
    let mut next = Instant::now();
    while !cells.stop.load(Ordering::Acquire) {
        while let Some(c) = cells.commands.pop() {
            control.command(c);
        }
        let sent = control.outputs().controlword;
        let answer = io.exchange(&control.outputs());
        let answered = answer.is_ok();
        control.step(answer);
        let rtt = io.round_trip().as_nanos() as u64;
        f.cycles += 1;
        f.inputs = control.inputs;
        f.enabled = cellrt_cia402::statusword::Statusword(control.inputs.statusword).state()
            == Some(cellrt_cia402::fsa::FsaState::OperationEnabled);
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
        let record = ExchangeRecord {
            exchange: f.cycles,
            time_ns: std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_nanos() as u64),
            answered,
            inputs: f.inputs,
            controlword: sent,
            round_trip_ns: rtt,
            missed_in_row: f.missed_in_row,
            missed: f.missed,
            refused: f.refused,
            stopped: f.stopped,
        };
        if cells.records.push(record).is_err() {
            cells.records_dropped.fetch_add(1, Ordering::Relaxed);
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A detached handle passes its commands on in the order queued, at most a queue's worth,
    /// and shows the feedback stored last.
    #[test]
    fn a_detached_handle_hands_over_commands_in_order_and_shows_the_stored_feedback() {
        let h = AxisHandle::detached();
        let other = h.clone();
        let commands = [AxisCommand::PowerOn, AxisCommand::Home, AxisCommand::Halt];
        for c in commands {
            assert!(h.command(c));
        }
        let taken: Vec<AxisCommand> = std::iter::from_fn(|| other.take_command()).collect();
        assert_eq!(taken, commands);
        assert!((0..QUEUE).all(|_| h.command(AxisCommand::Reset)));
        assert!(!h.command(AxisCommand::Reset), "the queue is full");
        let f = AxisFeedback {
            cycles: 7,
            done: 3,
            stopped: Some(super::super::control::Stopped::ControllerLost),
            ..AxisFeedback::default()
        };
        other.set_feedback(f);
        assert_eq!(h.feedback(), f);
        assert_eq!(h.pop_record(), None);
    }
}
