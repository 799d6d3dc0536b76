//! The lock-free lanes both ends of the hand-off share: preallocated bounded queues (crossbeam
//! `ArrayQueue`) and status atomics, in one allocation. Only the two ends see the fields.

use std::sync::atomic::AtomicU32;

use crossbeam::queue::ArrayQueue;

use super::sdo::{SdoOutcomeSlot, SdoRequestSlot};
use super::{
    AxisRecord, CellCommand, CellStatus, CycleRecord, EventRecord, PerCycleRecords, ProfileCommand,
};

/// Commands the queue holds before a sender is refused.
const COMMAND_QUEUE: usize = 64;
/// [`Lanes::feed_override`] without override.
pub(super) const FEED_OVERRIDE_FULL: u32 = 1000;
/// Events the queue holds before the RT thread drops one.
const EVENT_QUEUE: usize = 8192;

/// Queues and atomics shared by the RT end and the host end.
#[derive(Debug)]
pub(super) struct Lanes {
    /// Commands to the RT thread.
    pub(super) commands: ArrayQueue<CellCommand>,
    /// Drive-side motions of profile axes to the RT thread.
    pub(super) profile_commands: ArrayQueue<ProfileCommand>,
    /// Per-cycle timing records to the recorder.
    pub(super) cycles: ArrayQueue<CycleRecord>,
    /// Per-cycle, per-axis records to the recorder.
    pub(super) axes: ArrayQueue<AxisRecord>,
    /// Events to the recorder.
    pub(super) events: ArrayQueue<EventRecord>,
    /// Status for the non-RT side.
    pub(super) status: CellStatus,
    /// Whether the recorder drains the per-cycle record queues (if not, the RT thread skips
    /// pushing).
    pub(super) per_cycle: PerCycleRecords,
    /// A pending homing request (`HomeRequest` packed; 0 = none), taken by the RT thread.
    pub(super) home_request: AtomicU32,
    /// A pending operator SDO request, taken by the RT thread.
    pub(super) sdo_request: SdoRequestSlot,
    /// The outcome of the latest operator SDO request.
    pub(super) sdo_outcome: SdoOutcomeSlot,
    /// The feed override (MC_SetOverride) for the profile axes' drives, ‰ (1000: none).
    pub(super) feed_override: AtomicU32,
}

impl Lanes {
    /// Preallocates queues for `queue_cycles` cycles (at least 64) of `axes` axes; without a
    /// recorder the record queues hold one record.
    pub(super) fn new(axes: usize, queue_cycles: usize, per_cycle: PerCycleRecords) -> Self {
        let queue_cycles = queue_cycles.max(64);
        let taken = per_cycle == PerCycleRecords::Taken;
        Lanes {
            commands: ArrayQueue::new(COMMAND_QUEUE),
            profile_commands: ArrayQueue::new(COMMAND_QUEUE),
            cycles: ArrayQueue::new(if taken { queue_cycles } else { 1 }),
            axes: ArrayQueue::new(if taken { queue_cycles * axes.max(1) } else { 1 }),
            events: ArrayQueue::new(EVENT_QUEUE),
            status: CellStatus::default(),
            per_cycle,
            home_request: AtomicU32::new(0),
            sdo_request: SdoRequestSlot::default(),
            sdo_outcome: SdoOutcomeSlot::default(),
            feed_override: AtomicU32::new(FEED_OVERRIDE_FULL),
        }
    }
}
