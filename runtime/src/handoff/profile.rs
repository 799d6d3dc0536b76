//! Drive-side motions of profile axes (pp/pv/tq), from the host to the RT thread: the target
//! and profile of one axis' motion, in counts and counts/s, which the RT thread turns into the
//! drive's objects (607Ah, 6081h, 6083h/6084h, 60FFh, 6071h, 6087h) and controlword bits.

use cellrt_cia402::mode::ModeOfOperation;

/// One drive-side motion of one profile axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProfileCommand {
    /// Axis index.
    pub axis: u16,
    /// What the drive is to do.
    pub motion: ProfileMotion,
    /// The cycle it starts in (with the streamed motion it goes with); 0 or a past cycle: at
    /// once.
    pub start_cycle: u64,
}

/// What a profile axis' drive is to do.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ProfileMotion {
    /// pp: position to `target` (counts) at `velocity` (counts/s), ramping at `acceleration` /
    /// `deceleration` (counts/s²). `immediate`: a set-point during a move replaces it at once
    /// (controlword bit 5), else it is queued behind it.
    Move {
        /// 607Ah, counts.
        target: i32,
        /// 6081h, counts/s.
        velocity: f64,
        /// 6083h, counts/s².
        acceleration: f64,
        /// 6084h, counts/s².
        deceleration: f64,
        /// Controlword bit 5 (change set immediately).
        immediate: bool,
    },
    /// pv: run at `velocity` (counts/s, signed), ramping at `acceleration` / `deceleration`.
    Jog {
        /// 60FFh, counts/s.
        velocity: f64,
        /// 6083h, counts/s².
        acceleration: f64,
        /// 6084h, counts/s².
        deceleration: f64,
    },
    /// tq: ramp to `torque` (% of rated torque) at `slope` (%/s).
    Torque {
        /// 6071h, %.
        torque: f64,
        /// 6087h, %/s.
        slope: f64,
    },
    /// Controlword bit 8 (HALT) on or off: the drive stops per 605Dh and holds; off resumes.
    Halt(bool),
    /// Switch a csp axis to pp or back, at standstill, by the drive's mode-switch rules
    /// (`cellrt_cia402::mode_switch`); ends when 6061h shows the new mode.
    SwitchMode(SwitchableMode),
}

/// The modes an axis configured in csp switches between at run time.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SwitchableMode {
    /// Cyclic synchronous position: the setpoint stream moves the axis.
    Csp,
    /// Profile position: the drive positions by its own profile.
    Pp,
}

impl SwitchableMode {
    /// The mode of operation (6060h).
    pub const fn mode(self) -> ModeOfOperation {
        match self {
            SwitchableMode::Csp => ModeOfOperation::CyclicSyncPosition,
            SwitchableMode::Pp => ModeOfOperation::ProfilePosition,
        }
    }

    /// The mode's name, as in an axis' `mode` key.
    pub fn as_str(self) -> &'static str {
        self.mode().as_str()
    }

    /// The switchable mode called `name` ("csp" or "pp").
    pub fn parse(name: &str) -> Option<SwitchableMode> {
        [SwitchableMode::Csp, SwitchableMode::Pp]
            .into_iter()
            .find(|m| m.as_str() == name)
    }
}

impl ProfileMotion {
    /// The event value of a motion's start: 1 move, 2 jog, 3 torque, 4 halt on, 5 halt off, 6
    /// switch to pp, 7 switch to csp.
    pub const fn code(&self) -> i64 {
        match self {
            ProfileMotion::Move { .. } => 1,
            ProfileMotion::Jog { .. } => 2,
            ProfileMotion::Torque { .. } => 3,
            ProfileMotion::Halt(true) => 4,
            ProfileMotion::Halt(false) => 5,
            ProfileMotion::SwitchMode(SwitchableMode::Pp) => 6,
            ProfileMotion::SwitchMode(SwitchableMode::Csp) => 7,
        }
    }
}
