//! The objects one step of the simulated MR-JE-C's motor reads, in the drive's units (MR-JE-C
//! manual §7.3, §7.6): the mode, the targets, ramps and limits of each mode, the point table a
//! start selects, and the emulator's torque plant. Every mode module reads them; none of them
//! depends on another.

use std::time::Duration;

use crate::motion::ramp::time_constant_rate;

/// 6060h/6061h values of the profile modes.
pub const PROFILE_POSITION: i64 = 1;
/// Profile velocity mode.
pub const PROFILE_VELOCITY: i64 = 3;
/// Profile torque mode (tq).
pub const PROFILE_TORQUE: i64 = 4;
/// Homing mode (hm).
pub const HOMING: i64 = 6;
/// Jog mode (jg, SW A4+).
pub const JOG: i64 = -100;
/// Point table mode (pt, SW A4+).
pub const POINT_TABLE: i64 = -101;
/// Indexer mode (idx, SW A4+).
pub const INDEXER: i64 = -103;

/// The objects a step of the motion reads, in the drive's units.
#[derive(Debug, Clone, Copy)]
pub struct Profile {
    /// 6061h.
    pub mode: i64,
    /// 607Ah, pos units.
    pub target_position: i64,
    /// 60FFh, 0.01 r/min.
    pub target_velocity: i64,
    /// min(6081h, 607Fh), 0.01 r/min.
    pub profile_velocity: i64,
    /// 6083h, ms from 0 to rated speed.
    pub acceleration_ms: i64,
    /// 6084h, ms from rated speed to 0.
    pub deceleration_ms: i64,
    /// Rated speed, 0.01 r/min.
    pub rated_speed: i64,
    /// Maximum motor speed 6080h, 0.01 r/min.
    pub max_speed: i64,
    /// Pos units per motor revolution (6092h:1; [Pr. PT28] stations in idx).
    pub units_per_rev: i64,
    /// 6067h, pos units.
    pub position_window: i64,
    /// 606Dh, 0.01 r/min.
    pub velocity_window: i64,
    /// 6098h.
    pub homing_method: i64,
    /// 609Ah, ms from 0 to rated speed.
    pub homing_acceleration_ms: i64,
    /// 6099h:1 speed during search for switch, 0.01 r/min.
    pub homing_speed: i64,
    /// 607Ch home position, pos units.
    pub home_offset: i64,
    /// 6071h, 0.1 %.
    pub target_torque: i64,
    /// 6087h, 0.1 %/s (0: a step).
    pub torque_slope: i64,
    /// min(60E0h, 6072h), 0.1 %.
    pub positive_torque_limit: i64,
    /// min(60E1h, 6072h), 0.1 %.
    pub negative_torque_limit: i64,
    /// 2D20h, 0.01 r/min.
    pub velocity_limit: i64,
    /// The motor and load under torque control.
    pub plant: TorquePlant,
    /// The point table 2D60h selects (with 2DD1h's speed, acceleration and deceleration).
    pub point: Target,
    /// 2D60h as the next station (idx).
    pub indexer_station: i64,
    /// 6083h/6084h, or [Pr. PC30]/[Pr. PC31] with C_RT (idx).
    pub indexer_ramp: Ramp,
    /// [Pr. PC03] S-pattern acceleration/deceleration time constant, ms (0: none).
    pub s_pattern_ms: i64,
    /// The position loop gain of the motor model, rad/s (0: no droop).
    pub position_loop_gain: f64,
}

impl Profile {
    /// 0.01 r/min → pos units/s.
    pub(super) fn units_per_s(&self, speed: i64) -> f64 {
        speed as f64 / 100.0 / 60.0 * self.units_per_rev as f64
    }

    /// A ramp of `ms` from 0 to the rated speed as pos units/s² (`None`: a step).
    pub(super) fn rate(&self, ms: i64) -> Option<f64> {
        time_constant_rate(self.units_per_s(self.rated_speed), ms)
    }
}

/// Acceleration and deceleration time constants, ms from 0 to the rated speed and back.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Ramp {
    /// Acceleration, ms.
    pub acceleration_ms: i64,
    /// Deceleration, ms.
    pub deceleration_ms: i64,
}

/// What the motor is to do in one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Command {
    /// Run at `speed` pos units/s.
    Speed {
        /// Pos units/s, signed.
        speed: f64,
        /// The ramps.
        ramp: Ramp,
    },
    /// Position at `target` with at most `speed` pos units/s.
    Position {
        /// Pos units.
        target: i64,
        /// Pos units/s.
        speed: f64,
        /// The ramps.
        ramp: Ramp,
    },
}

impl Command {
    /// Whether the command leaves a motor standing at `position` where it is.
    pub fn holds(&self, position: f64) -> bool {
        match *self {
            Command::Speed { speed, .. } => speed == 0.0,
            Command::Position { target, .. } => target as f64 == position,
        }
    }

    /// Decelerate to a stop with `deceleration_ms`.
    pub fn stop(deceleration_ms: i64) -> Command {
        Command::Speed {
            speed: 0.0,
            ramp: Ramp {
                acceleration_ms: deceleration_ms,
                deceleration_ms,
            },
        }
    }
}

/// One point table (2801h–28FFh), as a start takes it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PointTable {
    /// The table No., 1–255.
    pub number: i64,
    /// Sub 1, pos units.
    pub position: i64,
    /// Sub 2 (or 2DD1h's table), 0.01 r/min.
    pub speed: i64,
    /// Subs 3 and 4 (or 2DD1h's table), ms.
    pub ramp: Ramp,
    /// Sub 7.
    pub m_code: i64,
}

/// What Target point table 2D60h selects.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Target {
    /// 0: no operation.
    #[default]
    None,
    /// 1–255: that table.
    Table(PointTable),
    /// −1: high-speed home position return.
    HomeReturn,
}

/// The motor and its load under torque: the manual gives no inertia or friction, so both are
/// emulator parameters, not drive facts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TorquePlant {
    /// Time the motor and load take from 0 to the rated speed at the rated torque (100 %)
    /// without friction: the inertia. Default 50 ms.
    pub rated_acceleration_time: Duration,
    /// Friction torque, 0.1 % of the rated torque, against the motion; a torque of at most
    /// this leaves a standing motor standing. Default 30 (3 %).
    pub friction: i64,
}

impl Default for TorquePlant {
    fn default() -> Self {
        TorquePlant {
            rated_acceleration_time: Duration::from_millis(50),
            friction: 30,
        }
    }
}
