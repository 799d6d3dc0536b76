//! Drive-side motions of profile axes (pp/pv/tq), from the host to the RT thread: the target
//! and profile of one axis' motion, in counts and counts/s, which the RT thread turns into the
//! drive's objects (607Ah, 6081h, 6083h/6084h, 60FFh, 6071h, 6087h) and controlword bits.

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
}

impl ProfileMotion {
    /// The event value of a motion's start: 1 move, 2 jog, 3 torque, 4 halt on, 5 halt off.
    pub const fn code(&self) -> i64 {
        match self {
            ProfileMotion::Move { .. } => 1,
            ProfileMotion::Jog { .. } => 2,
            ProfileMotion::Torque { .. } => 3,
            ProfileMotion::Halt(true) => 4,
            ProfileMotion::Halt(false) => 5,
        }
    }
}
