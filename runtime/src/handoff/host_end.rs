//! The non-RT threads' end of the hand-off (controller, link, planner, operator, recorder):
//! everything the RT end offers from the other side, and what may block.

use std::collections::VecDeque;
use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex};

use super::lanes::{Lanes, FEED_OVERRIDE_FULL};
use super::{
    AxisRecord, CellCommand, CellStatus, CycleRecord, EventRecord, HomeRequest, ProfileCommand,
    SdoSlotBusy, UserSdo, UserSdoOutcome,
};

/// Event lines kept for the operator's status.
pub const RECENT_EVENTS: usize = 8;

/// What the non-RT threads share (behind an `Arc`): the command queue's producer side, the
/// record queues' consumer side, events both ways, the status, and the recent event lines
/// behind a lock the RT end has no way to.
#[derive(Debug)]
pub struct HostEnd {
    lanes: Arc<Lanes>,
    /// The last [`RECENT_EVENTS`] event lines, kept by the recorder for the operator's status.
    recent_events: Mutex<VecDeque<String>>,
    /// The recorder keeps a capture ring (`recording.mode = "triggered"` with a path).
    capture_armed: std::sync::atomic::AtomicBool,
    /// The operator asked for a capture; the recorder takes it.
    capture_requested: std::sync::atomic::AtomicBool,
    /// The EtherCAT segment's diagnostics, set once the bus is open (none on simulated drives).
    bus_diagnostics: std::sync::OnceLock<cellrt_ethercat::master::BusDiagnostics>,
    /// The drives' dictionaries by SDO Information, set once the bus is open (EtherCAT only).
    dictionary_reader: std::sync::OnceLock<cellrt_ethercat::master::DictionaryReader>,
}

impl HostEnd {
    pub(super) fn new(lanes: Arc<Lanes>) -> Self {
        HostEnd {
            lanes,
            recent_events: Mutex::new(VecDeque::with_capacity(RECENT_EVENTS)),
            bus_diagnostics: std::sync::OnceLock::new(),
            dictionary_reader: std::sync::OnceLock::new(),
            capture_armed: Default::default(),
            capture_requested: Default::default(),
        }
    }

    /// Sets the feed override (0..=1) the RT thread applies to the profile axes' drives (their
    /// profile velocity); the streamed axes follow it in the planner.
    pub fn set_feed_override(&self, value: f64) {
        let permille = (value.clamp(0.0, 1.0) * f64::from(FEED_OVERRIDE_FULL)).round();
        self.lanes
            .feed_override
            .store(permille as u32, Ordering::Release);
    }

    /// The recorder keeps a capture ring from now on.
    pub fn arm_capture(&self) {
        self.capture_armed.store(true, Ordering::Release);
    }

    /// Asks the recorder to write its capture ring now; false if it keeps none.
    pub fn request_capture(&self) -> bool {
        let armed = self.capture_armed.load(Ordering::Acquire);
        if armed {
            self.capture_requested.store(true, Ordering::Release);
        }
        armed
    }

    /// The recorder's side: whether a capture was asked for (the request is taken).
    pub fn take_capture_request(&self) -> bool {
        self.capture_requested.swap(false, Ordering::AcqRel)
    }

    /// Offers the bus' diagnostics to the operator (once, when the bus is open).
    pub fn set_bus_diagnostics(&self, d: cellrt_ethercat::master::BusDiagnostics) {
        let _ = self.bus_diagnostics.set(d);
    }

    /// The bus' diagnostics, on an EtherCAT cell.
    pub fn bus_diagnostics(&self) -> Option<&cellrt_ethercat::master::BusDiagnostics> {
        self.bus_diagnostics.get()
    }

    /// Offers the drives' dictionaries to the operator (once, when the bus is open).
    pub fn set_dictionary_reader(&self, r: cellrt_ethercat::master::DictionaryReader) {
        let _ = self.dictionary_reader.set(r);
    }

    /// The drives' dictionaries by SDO Information, on an EtherCAT cell.
    pub fn dictionary_reader(&self) -> Option<&cellrt_ethercat::master::DictionaryReader> {
        self.dictionary_reader.get()
    }

    /// Queues a command for the RT thread; gives it back if the queue is full.
    pub fn send_command(&self, command: CellCommand) -> Result<(), CellCommand> {
        self.lanes.commands.push(command)
    }

    /// Queues a profile axis' drive-side motion for the RT thread; gives it back if the queue
    /// is full.
    pub fn send_profile_command(&self, command: ProfileCommand) -> Result<(), ProfileCommand> {
        self.lanes.profile_commands.push(command)
    }

    /// Leaves a homing request for the RT thread (replacing one not yet taken).
    pub fn request_homing(&self, request: HomeRequest) {
        self.lanes
            .home_request
            .store(request.encode(), Ordering::Release);
    }

    /// Leaves an operator SDO request for the RT thread (one requesting thread); refused while
    /// the previous one is not yet taken.
    pub fn request_sdo(&self, sdo: UserSdo) -> Result<(), SdoSlotBusy> {
        self.lanes.sdo_request.put(sdo)
    }

    /// The outcome of the operator SDO request `seq`, once the RT thread has published it.
    pub fn sdo_outcome(&self, seq: u16) -> Option<UserSdoOutcome> {
        self.lanes.sdo_outcome.get(seq)
    }

    /// Records an event of a non-RT thread (planner, link); false if the queue is full.
    pub fn push_event(&self, event: EventRecord) -> bool {
        self.lanes.events.push(event).is_ok()
    }

    /// The next cycle record for the recorder.
    pub fn pop_cycle(&self) -> Option<CycleRecord> {
        self.lanes.cycles.pop()
    }

    /// The next axis record for the recorder.
    pub fn pop_axis(&self) -> Option<AxisRecord> {
        self.lanes.axes.pop()
    }

    /// The next event for the recorder.
    pub fn pop_event(&self) -> Option<EventRecord> {
        self.lanes.events.pop()
    }

    /// The status the RT thread publishes.
    pub fn status(&self) -> &CellStatus {
        &self.lanes.status
    }

    /// Adds an event line to the recent events (recorder thread).
    pub fn remember_event(&self, line: &str) {
        if let Ok(mut q) = self.recent_events.lock() {
            if q.len() == RECENT_EVENTS {
                q.pop_front();
            }
            q.push_back(line.to_string());
        }
    }

    /// The recent event lines, oldest first.
    pub fn recent_events(&self) -> Vec<String> {
        self.recent_events
            .lock()
            .map(|q| q.iter().cloned().collect())
            .unwrap_or_default()
    }
}
