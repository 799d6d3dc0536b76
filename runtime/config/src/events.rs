//! The events of a cell: what the RT thread reports in its event records, what the recording's
//! event channel holds and what a capture trigger names. The records themselves are the
//! runtime's (`cellrt_runtime::handoff`); the vocabulary lives here, below the configuration
//! that names it.

/// What an event says; the meaning of `EventRecord::value` (the runtime's event record) depends on it.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, strum::IntoStaticStr, strum::FromRepr, strum::EnumString,
)]
#[strum(serialize_all = "snake_case")]
pub enum EventKind {
    /// Cell state changed (value: new `CellState` as u8).
    CellState,
    /// An axis' FSA state changed (value: `FsaState` index).
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
    /// A setpoint was rejected (value: `RejectReason` as u8).
    SetpointRejected,
    /// A fault reaction or commanded stop started (value: `StopReason` as u8 × 16 +
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
    /// A scheduled fault was injected (value: its [`FaultKind`](cellrt_config::FaultKind)
    /// code).
    FaultInjected,
    /// A planner's iceoryx2 node appeared.
    PlannerConnected,
    /// The planner's iceoryx2 node died or left.
    PlannerLost,
    /// A communication watchdog tripped on an axis, or on the segment with `NO_AXIS` (value:
    /// [`CommWatchdog`](cellrt_config::CommWatchdog) code).
    CommunicationError,
    /// Homing started on an axis (value: `HomeRequest::procedure_code`).
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
    /// [`AlStatus::encode`]: cellrt_ethercat::register::AlStatus::encode
    AlStatus,
    /// An axis' drive sent a CoE Emergency (EtherCAT, ETG.1000.6 §5.6.2.1; value:
    /// `encode_emergency`: error code, error register, manufacturer bytes).
    Emergency,
    /// A SubDevice's mailbox held a message nobody asked for that is not an Emergency; it was
    /// discarded (value: mailbox type | CoE service << 8).
    MailboxDiscarded,
    /// Bring-up skipped an optional setting of an axis' SubDevice that refused it (pushed by
    /// the controller before the loop starts; value: `encode_refused_sdo`).
    BringUpWarning,
    /// A motion's first block reached the RT thread late, within `setpoints.max_start_slip_ms`:
    /// the motion started from rest that many cycles late, all of it shifted (value: cycles).
    StartSlipped,
    /// A profile axis' drive-side motion started (value: `ProfileMotion::code`).
    ProfileStarted,
    /// A profile axis' drive-side motion ended (value: 0 done — pp target reached, pv
    /// velocity reached, tq ramp over; 1 refused — not enabled, no such profile axis, or an
    /// object the drive refused; 2 cancelled — the drive left Operation enabled, or a stop came
    /// before its start cycle; 3 superseded
    /// by the axis' next motion).
    ProfileFinished,
    /// An axis' run-time mode switch ended: 6061h shows the new mode (value: the new 6060h).
    ModeSwitched,
    /// An axis' run-time mode switch failed and was withdrawn (value: 1 — 6061h did not show
    /// the mode in time, 2 — the drive faulted).
    ModeSwitchFailed,
}

impl EventKind {
    /// Lower-case name used on the events channel.
    pub fn as_str(self) -> &'static str {
        self.into()
    }
}
