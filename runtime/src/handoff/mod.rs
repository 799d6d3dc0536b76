//! The only way in and out of the RT thread: preallocated lock-free lanes (bounded queues and
//! status atomics) seen through two ends. [`new`] builds both from one allocation; the RT
//! thread gets the [`RtEnd`] (no lock, no allocation), the non-RT threads share the
//! [`HostEnd`] (which also keeps the recent event lines behind a `Mutex`).

mod commands;
mod host_end;
mod lanes;
mod profile;
mod records;
mod rt_end;
mod sdo;
mod status;

use std::sync::Arc;

pub use commands::{CellCommand, HomeRequest, HOME_BY_C_CR, HOME_BY_C_CR2};
pub use host_end::{HostEnd, RECENT_EVENTS};
pub use profile::{ProfileCommand, ProfileMotion, SwitchableMode};
pub use records::{
    decode_emergency, decode_refused_sdo, encode_emergency, encode_refused_sdo, AxisRecord,
    CycleRecord, EventKind, EventRecord, RejectReason, NO_AXIS,
};
pub use rt_end::RtEnd;
pub use sdo::{SdoSlotBusy, UserSdo, UserSdoOutcome};
pub use status::{AxisLive, CellState, CellStatus, HomingStatus, StopReason};

/// Whether anything on the non-RT side takes the RT thread's per-cycle records (cycle and axis
/// records; events are always taken).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PerCycleRecords {
    /// The recorder thread drains them: for a recording file, a triggered capture's ring or the
    /// live view — any one of them is enough.
    Taken,
    /// Nothing takes them: the RT thread does not build them and their queues hold one record.
    Skipped,
}

impl PerCycleRecords {
    /// Taken when the run writes a recording (`file`, continuous or triggered) or serves the
    /// live view (`live`): the live view needs every cycle whether or not a file is written.
    pub fn for_run(file: Option<&std::path::Path>, live: Option<std::net::SocketAddr>) -> Self {
        if file.is_some() || live.is_some() {
            PerCycleRecords::Taken
        } else {
            PerCycleRecords::Skipped
        }
    }
}

/// The two ends of one hand-off, with queues for `queue_cycles` cycles (at least 64) of `axes`
/// axes; `per_cycle`: whether the per-cycle record queues are drained (if not, the RT thread
/// skips them).
pub fn new(axes: usize, queue_cycles: usize, per_cycle: PerCycleRecords) -> (RtEnd, HostEnd) {
    let lanes = Arc::new(lanes::Lanes::new(axes, queue_cycles, per_cycle));
    (RtEnd::new(lanes.clone()), HostEnd::new(lanes))
}

#[cfg(test)]
mod tests {
    use super::*;
    use cellrt_cia402::homing::{HomeProcedure, HomeSettingEdge};

    #[test]
    fn names_and_codes_round_trip() {
        // These names are part of the recording format (event kinds and details).
        assert_eq!(CellState::Idle.as_str(), "idle");
        assert_eq!(StopReason::SetpointRejected.as_str(), "setpoint_rejected");
        assert_eq!(RejectReason::NotAccepting.as_str(), "not_accepting");
        assert_eq!(
            EventKind::CommunicationError.as_str(),
            "communication_error"
        );
        assert_eq!(CellCommand::PowerOn.as_str(), "power_on");
        for v in 0..=255u8 {
            if let Some(s) = CellState::from_u8(v) {
                assert_eq!(s as u8, v);
            }
            if let Some(r) = StopReason::from_u8(v) {
                assert_eq!(r as u8, v);
            }
        }
        assert_eq!(CellState::from_u8(0), None);
        assert_eq!(
            CellState::from_u8(CellState::Faulted as u8),
            Some(CellState::Faulted)
        );
        assert_eq!(CellCommand::PowerOffAxis(3).as_str(), "power_off_axis");
        for c in [
            CellCommand::PowerOn,
            CellCommand::PowerOff,
            CellCommand::Stop,
            CellCommand::Reset,
            CellCommand::Quit,
            CellCommand::PlannerLost,
            CellCommand::PlannerConnected,
            CellCommand::PowerOnAxis(0),
            CellCommand::PowerOnAxis(255),
            CellCommand::PowerOffAxis(0),
            CellCommand::PowerOffAxis(255),
        ] {
            assert_eq!(CellCommand::from_code(c.event_value()), Some(c));
        }
        assert_eq!(CellCommand::from_code(-1), None);
        assert_eq!(CellCommand::from_code(0x400), None);
        for procedure in [
            HomeProcedure::HomingMode(-17),
            HomeProcedure::HomingMode(35),
            HomeProcedure::Controlword2(HomeSettingEdge::Clear),
            HomeProcedure::Controlword2(HomeSettingEdge::ClearZ),
        ] {
            let r = HomeRequest {
                axis: 300,
                procedure,
            };
            assert_ne!(r.encode(), 0);
            assert_eq!(HomeRequest::decode(r.encode()), Some(r));
        }
        assert_eq!(HomeRequest::decode(0), None);
        assert_eq!(HomeRequest::decode(0x8300_0000), None, "unknown procedure");
        assert_eq!(CellCommand::from_code(7), None);
        assert_eq!(CellCommand::from_code(0x100), None);
    }
}
