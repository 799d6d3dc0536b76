//! What the RT thread hands to the recorder: one cycle record per cycle, one axis record per
//! axis and cycle, and events (with the codes of their values).

use cellrt_cia402::fsa::FsaState;

use super::CellState;

/// Why a setpoint was rejected (the `value` of a `SetpointRejected` event).
#[derive(Debug, Clone, Copy, PartialEq, Eq, strum::IntoStaticStr, strum::FromRepr)]
#[strum(serialize_all = "snake_case")]
#[repr(u8)]
pub enum RejectReason {
    /// The block's first cycle had already passed when it arrived.
    LateBlock = 1,
    /// A step between consecutive setpoints above the velocity limit.
    VelocityStep = 2,
    /// A setpoint outside the axis' position range.
    OutsideRange = 3,
    /// A block for another motion or with a gap in cycles.
    Discontinuous = 4,
    /// NaN, infinity, or a malformed header.
    Malformed = 5,
    /// Motion sent while the cell does not accept it.
    NotAccepting = 6,
    /// A cst torque setpoint above the axis' `limits.torque`.
    TorqueLimit = 7,
    /// A cst torque change faster than the axis' `limits.torque_slope`.
    TorqueStep = 8,
    /// Motion for an axis that is not powered (MC_Power off for that axis).
    AxisNotPowered = 9,
    /// A command the drive's object cannot represent in its unit (60FFh beyond I32, 6071h
    /// beyond I16); the load check keeps the configured limits inside, so only a position
    /// correction past the following-error limit gets here.
    DriveRange = 10,
}

impl RejectReason {
    /// Lower-case name.
    pub fn as_str(self) -> &'static str {
        self.into()
    }

    /// Inverse of `as u8`.
    pub fn from_u8(v: u8) -> Option<RejectReason> {
        Self::from_repr(v)
    }
}

pub use cellrt_config::events::EventKind;

/// The value of a `bring_up_warning` event: abort code (bits 0–31), sub-index (32–39), index
/// (40–55).
pub fn encode_refused_sdo(r: &cellrt_ethercat::master::RefusedSdo) -> i64 {
    i64::from(r.abort) | i64::from(r.sub) << 32 | i64::from(r.index) << 40
}

/// Inverse of [`encode_refused_sdo`].
pub fn decode_refused_sdo(v: i64) -> cellrt_ethercat::master::RefusedSdo {
    cellrt_ethercat::master::RefusedSdo {
        index: (v >> 40) as u16,
        sub: (v >> 32) as u8,
        abort: v as u32,
    }
}

/// The value of an `emergency` event: error code (bits 0–15), error register (16–23), the 5
/// manufacturer bytes (24–63, byte 0 lowest).
pub fn encode_emergency(e: &cellrt_ethercat::emergency::Emergency) -> i64 {
    let mut v = u64::from(e.error_code) | u64::from(e.error_register) << 16;
    for (i, b) in e.data.iter().enumerate() {
        v |= u64::from(*b) << (24 + 8 * i);
    }
    v as i64
}

/// Inverse of [`encode_emergency`].
pub fn decode_emergency(v: i64) -> cellrt_ethercat::emergency::Emergency {
    let v = v as u64;
    let mut data = [0u8; 5];
    for (i, b) in data.iter_mut().enumerate() {
        *b = (v >> (24 + 8 * i)) as u8;
    }
    cellrt_ethercat::emergency::Emergency {
        error_code: v as u16,
        error_register: (v >> 16) as u8,
        data,
    }
}

/// Axis index for cell-wide events.
pub const NO_AXIS: u16 = u16::MAX;

/// An event, as handed from the RT thread to the recorder.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EventRecord {
    /// Cycle it happened in.
    pub cycle: u64,
    /// What happened.
    pub kind: EventKind,
    /// Axis index, or [`NO_AXIS`].
    pub axis: u16,
    /// Kind-specific value.
    pub value: i64,
}

/// Timing of one executed cycle.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CycleRecord {
    /// Cycle number (deadline index since start).
    pub cycle: u64,
    /// Absolute deadline, CLOCK_MONOTONIC ns.
    pub deadline_ns: u64,
    /// Wakeup minus deadline, ns.
    pub wakeup_latency_ns: u32,
    /// Loop body time, ns.
    pub loop_time_ns: u32,
    /// Missed deadlines so far.
    pub overruns: u64,
    /// Cell state at the end of the cycle.
    pub cell_state: CellState,
    /// Records dropped so far.
    pub dropped_records: u64,
    /// The bus clock's phase error of this cycle's frame, ns (EtherCAT DC; `None` elsewhere).
    pub dc_phase_error_ns: Option<i32>,
}

/// One axis in one executed cycle (drive units: counts).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct AxisRecord {
    /// Cycle number.
    pub cycle: u64,
    /// Axis index.
    pub axis: u16,
    /// Setpoint position, counts (fractional, before rounding).
    pub setpoint: f64,
    /// Setpoint velocity, counts/s.
    pub setpoint_velocity: f64,
    /// Target position written to the RxPDO, counts.
    pub target_position: i32,
    /// Position actual value (6064h), counts.
    pub position_actual: i32,
    /// Velocity actual value (606Ch), counts/s.
    pub velocity_actual: i32,
    /// Following error actual value (60F4h), counts.
    pub following_error: i32,
    /// Controlword sent (6040h).
    pub controlword: u16,
    /// Statusword received (6041h).
    pub statusword: u16,
    /// Decoded FSA state.
    pub fsa_state: Option<FsaState>,
    /// Modes of operation display (6061h).
    pub mode_display: i8,
    /// Error code (603Fh).
    pub error_code: u16,
    /// Target torque sent (6071h), 0.1 % of rated torque (0 in csp).
    pub target_torque: i16,
    /// 6060h sent.
    pub mode: i8,
    /// 60FFh sent, counts/s.
    pub target_velocity: i32,
    /// Torque actual value (6077h), 0.1 % of rated torque.
    pub torque_actual: i16,
    /// Incremental counter sent (2020h), 0 where the drive has none.
    pub counter_sent: u8,
    /// Controlword2 sent (2001h / 2D01h), 0 where the drive has none.
    pub controlword2: u16,
    /// Incremental counter echoed (2021h), 0 where the drive has none.
    pub counter_received: u8,
    /// Status DO 1–3 received (2D11h–2D13h), 0 where the drive does not map them.
    pub status_do: [u16; 3],
    /// 6081h, 6083h, 6084h, 6087h as the drive has them (in the RxPDO, or as last written by
    /// SDO, from the cycle the write was posted); 0 on streamed axes and before a write.
    pub profile: [u32; 4],
}
