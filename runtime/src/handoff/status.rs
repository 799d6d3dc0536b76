//! Status the RT thread publishes for the non-RT side every cycle: the cell state, why it
//! stopped, the homing in progress, hold positions and each axis' latest feedback, as atomics.

use std::sync::atomic::{
    AtomicBool, AtomicI32, AtomicI8, AtomicU16, AtomicU32, AtomicU64, AtomicU8, Ordering,
};

use crate::setpoints::MAX_AXES;

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
    /// Id of the last motion whose first block was refused: it never started.
    pub motion_refused: AtomicU32,
    /// Cycles the motion `motion_id` started later than its first block said (stored before
    /// `motion_id`): its blocks are due that much later.
    pub motion_slip: AtomicU32,
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
    pub mode_display: AtomicI8,
    /// MC_Power is on for the axis.
    pub powered: AtomicBool,
    /// The mode (6060h) the RT thread runs the axis in (configured, or after a run-time switch).
    pub mode: AtomicI8,
    /// 2D11h–2D13h Status DO 1–3 (0 where the drive does not map them).
    pub status_do: [AtomicU16; 3],
    /// Drive-side motions of a profile axis that have ended (any outcome), counted.
    pub profile_finished: AtomicU32,
    /// Of those, the ones refused or cancelled.
    pub profile_failed: AtomicU32,
}

impl Default for CellStatus {
    fn default() -> Self {
        CellStatus {
            cycle: AtomicU64::new(0),
            state: AtomicU8::new(CellState::Disabled as u8),
            stop_reason: AtomicU8::new(0),
            motion_id: AtomicU32::new(0),
            motion_done: AtomicU32::new(0),
            motion_refused: AtomicU32::new(0),
            motion_slip: AtomicU32::new(0),
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
