//! Lock-free hand-offs between the RT thread and the non-RT threads: preallocated bounded
//! queues (crossbeam `ArrayQueue`) for records, events and commands, and atomics for status.

use std::sync::atomic::{
    AtomicBool, AtomicI32, AtomicU16, AtomicU32, AtomicU64, AtomicU8, Ordering,
};

use cellrt_axes::cia402::fsa::FsaState;
use cellrt_axes::cia402::homing::{HomeProcedure, HomeSettingEdge};
use crossbeam::queue::ArrayQueue;

use crate::setpoints::MAX_AXES;

/// What a non-RT thread asks of the cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq, strum::IntoStaticStr)]
#[strum(serialize_all = "snake_case")]
pub enum CellCommand {
    /// Bring every axis to Operation enabled (MC_Power on).
    PowerOn,
    /// Clean shutdown of every axis: Shutdown by controlword (MC_Power off).
    PowerOff,
    /// Controlled stop of any motion; the cell returns to Idle (MC_Stop).
    Stop,
    /// Clear a Stopped or Faulted cell (MC_Reset).
    Reset,
    /// Leave the RT loop (after PowerOff).
    Quit,
    /// The planner's node died or left: stop any motion (the link thread sends this).
    PlannerLost,
    /// Bring one axis (index) to Operation enabled, the others as they are (MC_Power on one
    /// axis).
    PowerOnAxis(u16),
    /// Clean shutdown of one axis (index); the cell powers off when no axis stays powered.
    PowerOffAxis(u16),
}

/// First code of [`CellCommand::PowerOnAxis`] (plus the axis index).
const POWER_ON_AXIS_CODE: i64 = 0x200;
/// First code of [`CellCommand::PowerOffAxis`] (plus the axis index).
const POWER_OFF_AXIS_CODE: i64 = 0x300;

impl CellCommand {
    /// Short name for events and messages.
    pub fn as_str(self) -> &'static str {
        self.into()
    }

    fn code(self) -> i64 {
        match self {
            CellCommand::PowerOn => 0,
            CellCommand::PowerOff => 1,
            CellCommand::Stop => 2,
            CellCommand::Reset => 3,
            CellCommand::Quit => 4,
            CellCommand::PlannerLost => 5,
            CellCommand::PowerOnAxis(a) => POWER_ON_AXIS_CODE + i64::from(a),
            CellCommand::PowerOffAxis(a) => POWER_OFF_AXIS_CODE + i64::from(a),
        }
    }

    /// Inverse of the event value the RT thread records for a command.
    pub fn from_code(v: i64) -> Option<CellCommand> {
        let axis = |base: i64| {
            u16::try_from(v - base)
                .ok()
                .filter(|&a| usize::from(a) < MAX_AXES)
        };
        Some(match v {
            0 => CellCommand::PowerOn,
            1 => CellCommand::PowerOff,
            2 => CellCommand::Stop,
            3 => CellCommand::Reset,
            4 => CellCommand::Quit,
            5 => CellCommand::PlannerLost,
            _ if (POWER_ON_AXIS_CODE..POWER_OFF_AXIS_CODE).contains(&v) => {
                CellCommand::PowerOnAxis(axis(POWER_ON_AXIS_CODE)?)
            }
            _ if (POWER_OFF_AXIS_CODE..POWER_OFF_AXIS_CODE + 0x100).contains(&v) => {
                CellCommand::PowerOffAxis(axis(POWER_OFF_AXIS_CODE)?)
            }
            _ => return None,
        })
    }

    /// The axis a per-axis command names.
    pub fn axis(self) -> Option<u16> {
        match self {
            CellCommand::PowerOnAxis(a) | CellCommand::PowerOffAxis(a) => Some(a),
            _ => None,
        }
    }

    /// Value recorded with command events.
    pub fn event_value(self) -> i64 {
        self.code()
    }
}

/// State of the cell as a whole, owned by the RT thread.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, strum::IntoStaticStr, strum::FromRepr)]
#[strum(serialize_all = "snake_case")]
#[repr(u8)]
pub enum CellState {
    /// Axes not enabled.
    #[default]
    Disabled = 1,
    /// Powering up through the controlword sequence.
    Enabling = 2,
    /// Enabled and holding position; accepts motion.
    Idle = 3,
    /// Following a setpoint stream.
    Moving = 4,
    /// Ramping to a stop on the RT thread's own (controlled stop).
    Stopping = 5,
    /// Stopped after an underrun or a rejected setpoint; refuses motion until reset.
    Stopped = 6,
    /// Shutting the axes down.
    Disabling = 7,
    /// A drive faulted or did not answer; needs reset.
    Faulted = 8,
    /// One axis runs its drive's homing mode (hm); refuses motion.
    Homing = 9,
}

impl CellState {
    /// Inverse of `as u8`.
    pub fn from_u8(v: u8) -> Option<CellState> {
        Self::from_repr(v)
    }

    /// Lower-case name.
    pub fn as_str(self) -> &'static str {
        self.into()
    }
}

/// Why a controlled stop was started.
#[derive(Debug, Clone, Copy, PartialEq, Eq, strum::IntoStaticStr, strum::FromRepr)]
#[strum(serialize_all = "snake_case")]
#[repr(u8)]
pub enum StopReason {
    /// A Stop command (or SIGINT/SIGTERM).
    Command = 1,
    /// The setpoint stream ran dry during motion.
    Underrun = 2,
    /// A setpoint broke a limit or the stream's continuity.
    SetpointRejected = 3,
    /// A drive faulted; the other axes stop too.
    DriveFault = 4,
    /// Too many consecutive overruns: the loop cannot keep time.
    Overrun = 5,
    /// The planner's node died or left during motion.
    PlannerLost = 6,
    /// The incremental counter check failed (continuous or intermittent errors).
    Communication = 7,
}

impl StopReason {
    /// Lower-case name.
    pub fn as_str(self) -> &'static str {
        self.into()
    }

    /// Inverse of `as u8`.
    pub fn from_u8(v: u8) -> Option<StopReason> {
        Self::from_repr(v)
    }
}

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

/// What an event says; the meaning of [`EventRecord::value`] depends on it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, strum::IntoStaticStr, strum::FromRepr)]
#[strum(serialize_all = "snake_case")]
pub enum EventKind {
    /// Cell state changed (value: new [`CellState`] as u8).
    CellState,
    /// An axis' FSA state changed (value: [`FsaState`] index).
    FsaState,
    /// A command was taken (value: command code).
    Command,
    /// A command was refused in the current state (value: command code).
    CommandRefused,
    /// A motion started (value: motion id).
    MotionStarted,
    /// A motion ended normally (value: motion id).
    MotionFinished,
    /// Setpoints missing during motion (value: motion id).
    Underrun,
    /// A setpoint was rejected (value: [`RejectReason`] as u8).
    SetpointRejected,
    /// A fault reaction or commanded stop started (value: [`StopReason`] as u8 × 16 +
    /// reaction: 0 controlled stop, 1 quick stop, 2 disable).
    StopStarted,
    /// A controlled stop ended.
    StopFinished,
    /// Deadlines missed (value: how late the wakeup was, ns; the count is in the cycle record).
    Overrun,
    /// An axis' drive reports a fault (value: 603Fh error code).
    DriveFault,
    /// An axis' master gave up waiting for the drive.
    MasterTimeout,
    /// Records were dropped because the recorder queue was full (value: count so far).
    RecordsDropped,
    /// The bus exchange failed (value: axis index).
    BusError,
    /// A scheduled fault was injected (value: its [`FaultKind`](crate::config::FaultKind)
    /// code).
    FaultInjected,
    /// A planner's iceoryx2 node appeared.
    PlannerConnected,
    /// The planner's iceoryx2 node died or left.
    PlannerLost,
    /// An axis' incremental counter check failed (value: 1 continuous, 2 intermittent).
    CommunicationError,
    /// Homing started on an axis (value: [`HomeRequest::procedure_code`]).
    HomingStarted,
    /// Homing ended on an axis (value: 0 attained, else the `HomingFailure` code).
    HomingFinished,
    /// A scheduled wire fault is due, but the cell runs on a network interface: the emulated
    /// segment on the far end injects it on its own clock, not the master (value: as
    /// [`EventKind::FaultInjected`]).
    FaultLeftToSegment,
    /// The AL status of an axis' SubDevice changed (EtherCAT; value: [`AlStatus::encode`]:
    /// state and error bit, AL status code). Leaving OP is a communication fault of the axis.
    ///
    /// [`AlStatus::encode`]: cellrt_axes::ethercat::register::AlStatus::encode
    AlStatus,
    /// An axis' drive sent a CoE Emergency (EtherCAT, ETG.1000.6 §5.6.2.1; value:
    /// [`encode_emergency`]: error code, error register, manufacturer bytes).
    Emergency,
    /// A SubDevice's mailbox held a message nobody asked for that is not an Emergency; it was
    /// discarded (value: mailbox type | CoE service << 8).
    MailboxDiscarded,
}

/// The value of an `emergency` event: error code (bits 0–15), error register (16–23), the 5
/// manufacturer bytes (24–63, byte 0 lowest).
pub fn encode_emergency(e: &cellrt_axes::ethercat::emergency::Emergency) -> i64 {
    let mut v = u64::from(e.error_code) | u64::from(e.error_register) << 16;
    for (i, b) in e.data.iter().enumerate() {
        v |= u64::from(*b) << (24 + 8 * i);
    }
    v as i64
}

/// Inverse of [`encode_emergency`].
pub fn decode_emergency(v: i64) -> cellrt_axes::ethercat::emergency::Emergency {
    let v = v as u64;
    let mut data = [0u8; 5];
    for (i, b) in data.iter_mut().enumerate() {
        *b = (v >> (24 + 8 * i)) as u8;
    }
    cellrt_axes::ethercat::emergency::Emergency {
        error_code: v as u16,
        error_register: (v >> 16) as u8,
        data,
    }
}

/// A homing request from the non-RT side, packed for [`Handoff::home_request`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HomeRequest {
    /// Axis index.
    pub axis: u16,
    /// hm with a 6098h method, or a Controlword2 edge.
    pub procedure: HomeProcedure,
}

/// [`HomeRequest::procedure_code`] of a C_CR home setting (outside the i8 range of 6098h).
pub const HOME_BY_C_CR: i64 = 0x100;
/// [`HomeRequest::procedure_code`] of a C_CR2 home setting.
pub const HOME_BY_C_CR2: i64 = 0x101;

impl HomeRequest {
    /// Packed form (never 0): bit 31 set, bits 24–25 the procedure (0 hm, 1 C_CR, 2 C_CR2),
    /// bits 8–23 the axis, bits 0–7 the 6098h method.
    pub fn encode(self) -> u32 {
        let (kind, method) = match self.procedure {
            HomeProcedure::HomingMode(m) => (0, m),
            HomeProcedure::Controlword2(HomeSettingEdge::Clear) => (1, 0),
            HomeProcedure::Controlword2(HomeSettingEdge::ClearZ) => (2, 0),
        };
        0x8000_0000 | (kind << 24) | (u32::from(self.axis) << 8) | u32::from(method as u8)
    }

    /// Inverse of [`HomeRequest::encode`]; `None` for 0 (no request) or an unknown procedure.
    pub fn decode(v: u32) -> Option<HomeRequest> {
        if v & 0x8000_0000 == 0 {
            return None;
        }
        let procedure = match (v >> 24) & 0x7F {
            0 => HomeProcedure::HomingMode((v & 0xFF) as u8 as i8),
            1 => HomeProcedure::Controlword2(HomeSettingEdge::Clear),
            2 => HomeProcedure::Controlword2(HomeSettingEdge::ClearZ),
            _ => return None,
        };
        Some(HomeRequest {
            axis: ((v >> 8) & 0xFFFF) as u16,
            procedure,
        })
    }

    /// Value of the `HomingStarted` event: the 6098h method, or [`HOME_BY_C_CR`] /
    /// [`HOME_BY_C_CR2`].
    pub fn procedure_code(self) -> i64 {
        match self.procedure {
            HomeProcedure::HomingMode(m) => i64::from(m),
            HomeProcedure::Controlword2(HomeSettingEdge::Clear) => HOME_BY_C_CR,
            HomeProcedure::Controlword2(HomeSettingEdge::ClearZ) => HOME_BY_C_CR2,
        }
    }
}

/// Where the latest homing stands, packed for [`CellStatus::homing`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct HomingStatus {
    /// Homings started since the RT loop began (0: none yet).
    pub seq: u32,
    /// Axis index.
    pub axis: u16,
    /// Still running.
    pub running: bool,
    /// Failure code (`HomingFailure as u8`); 0 = attained (when not running).
    pub failure: u8,
}

impl HomingStatus {
    /// Packed form.
    pub fn encode(self) -> u64 {
        (u64::from(self.seq) << 32)
            | (u64::from(self.running) << 24)
            | (u64::from(self.failure) << 16)
            | u64::from(self.axis)
    }

    /// Inverse of [`HomingStatus::encode`].
    pub fn decode(v: u64) -> HomingStatus {
        HomingStatus {
            seq: (v >> 32) as u32,
            running: (v >> 24) & 1 == 1,
            failure: ((v >> 16) & 0xFF) as u8,
            axis: (v & 0xFFFF) as u16,
        }
    }
}

impl EventKind {
    /// Lower-case name used on the events channel.
    pub fn as_str(self) -> &'static str {
        self.into()
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
    /// Incremental counter echoed (2021h), 0 where the drive has none.
    pub counter_received: u8,
}

/// Status the RT thread publishes every cycle for the non-RT side (planner, CLI).
#[derive(Debug)]
pub struct CellStatus {
    /// Last executed cycle.
    pub cycle: AtomicU64,
    /// [`CellState`] as u8.
    pub state: AtomicU8,
    /// Last [`StopReason`] as u8 (0: none since reset).
    pub stop_reason: AtomicU8,
    /// Id of the motion running, or last finished.
    pub motion_id: AtomicU32,
    /// Id of the last motion that finished normally.
    pub motion_done: AtomicU32,
    /// Hold position of each axis (f64 bits, counts): where its next motion must start.
    pub hold: [AtomicU64; MAX_AXES],
    /// Set by the RT thread once the loop runs.
    pub running: AtomicBool,
    /// Latest feedback of each axis, for the operator's status.
    pub live: [AxisLive; MAX_AXES],
    /// The latest homing ([`HomingStatus`] packed).
    pub homing: AtomicU64,
}

/// Latest feedback of one axis (TxPDO values), stored by the RT thread every cycle.
#[derive(Debug, Default)]
pub struct AxisLive {
    /// 6064h, counts.
    pub position_actual: AtomicI32,
    /// 606Ch, counts/s.
    pub velocity_actual: AtomicI32,
    /// 60F4h, counts.
    pub following_error: AtomicI32,
    /// 6041h.
    pub statusword: AtomicU16,
    /// 603Fh.
    pub error_code: AtomicU16,
    /// 6061h.
    pub mode_display: std::sync::atomic::AtomicI8,
    /// MC_Power is on for the axis.
    pub powered: AtomicBool,
}

impl Default for CellStatus {
    fn default() -> Self {
        CellStatus {
            cycle: AtomicU64::new(0),
            state: AtomicU8::new(CellState::Disabled as u8),
            stop_reason: AtomicU8::new(0),
            motion_id: AtomicU32::new(0),
            motion_done: AtomicU32::new(0),
            hold: std::array::from_fn(|_| AtomicU64::new(0f64.to_bits())),
            running: AtomicBool::new(false),
            live: std::array::from_fn(|_| AxisLive::default()),
            homing: AtomicU64::new(0),
        }
    }
}

impl CellStatus {
    /// Current cell state.
    pub fn state(&self) -> CellState {
        CellState::from_u8(self.state.load(Ordering::Acquire)).unwrap_or_default()
    }

    /// Hold position of `axis`, counts.
    pub fn hold(&self, axis: usize) -> f64 {
        f64::from_bits(self.hold[axis].load(Ordering::Acquire))
    }

    /// Last executed cycle.
    pub fn cycle(&self) -> u64 {
        self.cycle.load(Ordering::Acquire)
    }

    /// Last stop reason since reset.
    pub fn stop_reason(&self) -> Option<StopReason> {
        StopReason::from_u8(self.stop_reason.load(Ordering::Acquire))
    }
}

/// Everything shared between the RT thread and the rest of the process.
#[derive(Debug)]
pub struct Handoff {
    /// Commands to the RT thread.
    pub commands: ArrayQueue<CellCommand>,
    /// Per-cycle timing records to the recorder.
    pub cycles: ArrayQueue<CycleRecord>,
    /// Per-cycle, per-axis records to the recorder.
    pub axes: ArrayQueue<AxisRecord>,
    /// Events to the recorder.
    pub events: ArrayQueue<EventRecord>,
    /// Status for the non-RT side.
    pub status: CellStatus,
    /// Whether a recorder drains the record queues (if not, the RT thread skips pushing).
    pub recording: bool,
    /// A pending homing request ([`HomeRequest`] packed; 0 = none), taken by the RT thread.
    pub home_request: AtomicU32,
    /// The last [`RECENT_EVENTS`] event lines, kept by the recorder thread for the operator's
    /// status (non-RT threads only: the RT thread never touches this lock).
    recent_events: std::sync::Mutex<std::collections::VecDeque<String>>,
}

/// Event lines kept for the operator's status.
pub const RECENT_EVENTS: usize = 8;

impl Handoff {
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

    /// Preallocates queues for `queue_cycles` cycles of `axes` axes.
    pub fn new(axes: usize, queue_cycles: usize, recording: bool) -> Self {
        let queue_cycles = queue_cycles.max(64);
        Handoff {
            commands: ArrayQueue::new(64),
            home_request: AtomicU32::new(0),
            recent_events: std::sync::Mutex::new(std::collections::VecDeque::with_capacity(
                RECENT_EVENTS,
            )),
            cycles: ArrayQueue::new(if recording { queue_cycles } else { 1 }),
            axes: ArrayQueue::new(if recording {
                queue_cycles * axes.max(1)
            } else {
                1
            }),
            events: ArrayQueue::new(8192),
            status: CellStatus::default(),
            recording,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
        assert_eq!(CellCommand::from_code(6), None);
        assert_eq!(CellCommand::from_code(0x100), None);
    }
}
