//! The cyclic link on a non-RT I/O thread of its own (MR-JE-C manual §2.2.1, §2.5.1): every
//! link period one request of the group's [`GroupMaster`] with each station's latest command,
//! each station's answer (or its absence) published as feedback. The controller's threads
//! exchange commands and feedback with it through lock-free cells, never waiting for the
//! network; the thread allocates nothing per cycle (buffers made once).
//!
//! A station is transmitted to only once it has answered a request that does not transmit to
//! it (how a drive takes a new master); a station that misses an answer is dropped to that
//! state again, so a drive that has meanwhile dropped the master (its supervision time) takes
//! it back at the next cycle.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crossbeam::atomic::AtomicCell;

use super::frame::{EndCode, LINK_BITS_BYTES, LINK_WORDS_BYTES, MAX_STATIONS};
use super::master::{GroupMaster, MasterError};

/// What the controller wants of one station.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StationCommand {
    /// Transmit to the station (its cyclic transmission bit).
    pub transmit: bool,
    /// RWw.
    pub rww: [u8; LINK_WORDS_BYTES],
    /// RY.
    pub ry: [u8; LINK_BITS_BYTES],
}

impl Default for StationCommand {
    fn default() -> Self {
        StationCommand {
            transmit: false,
            rww: [0; LINK_WORDS_BYTES],
            ry: [0; LINK_BITS_BYTES],
        }
    }
}

/// What came back from one station.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StationFeedback {
    /// Cycles run.
    pub cycles: u64,
    /// Cycles the station answered.
    pub answered: u64,
    /// Cycles in a row without an answer (the controller's communication watchdog).
    pub missed_in_row: u32,
    /// The station is transmitted to (it took the master).
    pub connected: bool,
    /// The last answer's end code.
    pub end_code: EndCode,
    /// The last round trip, ns.
    pub round_trip_ns: u64,
    /// RWr of the last answer.
    pub rwr: [u8; LINK_WORDS_BYTES],
    /// RX of the last answer.
    pub rx: [u8; LINK_BITS_BYTES],
}

impl Default for StationFeedback {
    fn default() -> Self {
        StationFeedback {
            cycles: 0,
            answered: 0,
            missed_in_row: 0,
            connected: false,
            end_code: EndCode::Normal,
            round_trip_ns: 0,
            rwr: [0; LINK_WORDS_BYTES],
            rx: [0; LINK_BITS_BYTES],
        }
    }
}

/// The cells the I/O thread and the controller share.
struct Cells {
    commands: Vec<AtomicCell<StationCommand>>,
    feedback: Vec<AtomicCell<StationFeedback>>,
    stop: AtomicBool,
}

/// The link's cycle: the master, the shared cells and the per-cycle state.
pub struct CyclicIo {
    master: GroupMaster,
    cells: Arc<Cells>,
    connected: [bool; MAX_STATIONS],
    feedback: [StationFeedback; MAX_STATIONS],
    responses: [Option<super::CyclicResponse>; MAX_STATIONS],
}

impl CyclicIo {
    /// The link of `master`'s stations.
    pub fn new(master: GroupMaster) -> CyclicIo {
        let n = master.stations();
        CyclicIo {
            master,
            cells: Arc::new(Cells {
                commands: (0..n).map(|_| AtomicCell::default()).collect(),
                feedback: (0..n).map(|_| AtomicCell::default()).collect(),
                stop: AtomicBool::new(false),
            }),
            connected: [false; MAX_STATIONS],
            feedback: [StationFeedback::default(); MAX_STATIONS],
            responses: [None; MAX_STATIONS],
        }
    }

    /// The controller's handle on the cells (before the link moves to its thread).
    pub fn handle(&self) -> LinkHandle {
        LinkHandle {
            cells: self.cells.clone(),
        }
    }

    /// One cycle: the commands in, one exchange, the feedback out. Allocation-free.
    pub fn cycle(&mut self) -> Result<(), MasterError> {
        let n = self.master.stations();
        let mut transmit = 0u16;
        for k in 0..n {
            let c = self.cells.commands[k].load();
            self.master.set_station(k, &c.rww, &c.ry);
            if c.transmit && self.connected[k] {
                transmit |= 1 << k;
            }
        }
        let t = Instant::now();
        let result = self.master.exchange(transmit, &mut self.responses);
        let rtt = t.elapsed().as_nanos() as u64;
        for k in 0..n {
            let f = &mut self.feedback[k];
            f.cycles += 1;
            match self.responses[k] {
                Some(r) => {
                    f.answered += 1;
                    f.missed_in_row = 0;
                    f.end_code = r.end_code;
                    f.round_trip_ns = rtt;
                    f.rwr = r.station.words;
                    f.rx = r.station.bits;
                    self.connected[k] = r.end_code == EndCode::Normal;
                }
                None => {
                    f.missed_in_row = f.missed_in_row.saturating_add(1);
                    self.connected[k] = false;
                }
            }
            f.connected = self.connected[k];
            self.cells.feedback[k].store(*f);
        }
        result.map(|_| ())
    }

    /// Runs the link on a thread of its own, one cycle every `period` (absolute deadlines;
    /// a late cycle is not made up).
    pub fn spawn(mut self, period: Duration) -> std::io::Result<LinkThread> {
        let cells = self.cells.clone();
        let thread = std::thread::Builder::new()
            .name("cellrt-cclink".into())
            .spawn(move || {
                let mut next = Instant::now();
                while !self.cells.stop.load(Ordering::Acquire) {
                    let _ = self.cycle();
                    next += period;
                    let now = Instant::now();
                    match next.checked_duration_since(now) {
                        Some(wait) => std::thread::sleep(wait),
                        None => next = now,
                    }
                }
            })?;
        Ok(LinkThread {
            handle: LinkHandle { cells },
            thread: Some(thread),
        })
    }
}

/// The controller's side of the cells: commands in, feedback out, never waiting.
#[derive(Clone)]
pub struct LinkHandle {
    cells: Arc<Cells>,
}

impl LinkHandle {
    /// Station `k`'s (0-based) command from the next cycle on.
    pub fn command(&self, k: usize, c: StationCommand) {
        if let Some(cell) = self.cells.commands.get(k) {
            cell.store(c);
        }
    }

    /// Station `k`'s latest feedback.
    pub fn feedback(&self, k: usize) -> Option<StationFeedback> {
        self.cells.feedback.get(k).map(AtomicCell::load)
    }
}

/// The link running on its thread; stopped and joined on drop.
pub struct LinkThread {
    /// Commands and feedback.
    pub handle: LinkHandle,
    thread: Option<JoinHandle<()>>,
}

impl Drop for LinkThread {
    fn drop(&mut self) {
        self.handle.cells.stop.store(true, Ordering::Release);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}
