//! The RT thread's end of the hand-off: lock-free and allocation-free by its type (it holds
//! only the shared lanes, never the host end's lock).

use std::sync::atomic::Ordering;
use std::sync::Arc;

use super::lanes::Lanes;
use super::{
    AxisRecord, CellCommand, CellStatus, CycleRecord, EventRecord, HomeRequest, ProfileCommand,
    UserSdo, UserSdoOutcome,
};

/// What the RT thread may touch: the command queue's consumer side, the record and event
/// queues' producer side, the pending homing and SDO requests and the status atomics.
///
/// It cannot reach the host end's recent events (a `Mutex`):
///
/// ```compile_fail
/// fn on_the_rt_thread(rt: &cellrt_runtime::handoff::RtEnd) {
///     rt.remember_event("a lock on the RT thread");
/// }
/// ```
#[derive(Debug)]
pub struct RtEnd {
    lanes: Arc<Lanes>,
}

impl RtEnd {
    pub(super) fn new(lanes: Arc<Lanes>) -> Self {
        RtEnd { lanes }
    }

    /// The next command from the non-RT side, if any.
    #[inline]
    pub fn next_command(&self) -> Option<CellCommand> {
        self.lanes.commands.pop()
    }

    /// The next profile axis' drive-side motion from the non-RT side, if any.
    #[inline]
    pub fn next_profile_command(&self) -> Option<ProfileCommand> {
        self.lanes.profile_commands.pop()
    }

    /// Takes the pending homing request, if any (the slot is empty afterwards).
    #[inline]
    pub fn take_home_request(&self) -> Option<HomeRequest> {
        HomeRequest::decode(self.lanes.home_request.swap(0, Ordering::AcqRel))
    }

    /// Takes the pending operator SDO request, if any (the slot is empty afterwards).
    #[inline]
    pub fn take_sdo_request(&self) -> Option<UserSdo> {
        self.lanes.sdo_request.take()
    }

    /// Publishes how the operator SDO request `seq` ended.
    #[inline]
    pub fn publish_sdo_outcome(&self, seq: u16, outcome: UserSdoOutcome) {
        self.lanes.sdo_outcome.publish(seq, outcome);
    }

    /// The feed override for the profile axes' drives, ‰ (1000: none).
    #[inline]
    pub fn feed_override_permille(&self) -> u32 {
        self.lanes.feed_override.load(Ordering::Acquire)
    }

    /// Whether the recorder drains the per-cycle record queues (if not, skip building records).
    #[inline]
    pub fn per_cycle_records_taken(&self) -> bool {
        self.lanes.per_cycle == super::PerCycleRecords::Taken
    }

    /// Hands a cycle record to the recorder; false if its queue is full.
    #[inline]
    pub fn push_cycle(&self, record: CycleRecord) -> bool {
        self.lanes.cycles.push(record).is_ok()
    }

    /// Hands an axis record to the recorder; false if its queue is full.
    #[inline]
    pub fn push_axis(&self, record: AxisRecord) -> bool {
        self.lanes.axes.push(record).is_ok()
    }

    /// Hands an event to the recorder; false if its queue is full.
    #[inline]
    pub fn push_event(&self, event: EventRecord) -> bool {
        self.lanes.events.push(event).is_ok()
    }

    /// The status the RT thread publishes.
    #[inline]
    pub fn status(&self) -> &CellStatus {
        &self.lanes.status
    }
}
