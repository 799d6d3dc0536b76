//! Point table mode (pt, 6060h = −101, SW A4+; MR-JE-C manual §7.3 2801h–28FFh, 2D60h–2D6Ah,
//! 2DD1h, §7.6.3): a rising edge of Controlword bit 4 runs the point table that Target point
//! table 2D60h selects to its position (sub 1) at its speed (sub 2, 0.01 r/min) with its
//! acceleration and deceleration time constants (subs 3, 4); Target speed No. 2DD1h (1–255)
//! takes speed, acceleration and deceleration from another table. Halt (bit 8) decelerates with
//! the table's deceleration and releasing it restarts at once (§7.6.3). Feedback: Point demand
//! value 2D68h, Point actual value 2D69h (the completed table, 0 after homing), M code actual
//! value 2D6Ah (the completed table's sub 7).
//!
//! The meaning of the auxiliary function (sub 6) and the dwell (sub 5) is in the Positioning
//! Mode manual, which the emulator does not have: every table positions to an absolute
//! address and ends there (no incremental or continuous operation, no dwell).

use super::profile::{Command, Profile, Ramp, Target};

/// 2D60h = −1, high-speed home position return: the manual gives only the name. The emulator
/// positions to the home position 607Ch at 6099h:1 with 609Ah once a home position return has
/// completed, and ignores the start before (an emulator choice).
pub const HIGH_SPEED_HOME_RETURN: i64 = -1;

/// A positioning under way (pt, idx).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Positioning {
    /// Table No. (0: high-speed home return) or station No.
    pub number: i64,
    /// Pos units.
    pub target: i64,
    /// 0.01 r/min.
    pub speed: i64,
    /// The ramps.
    pub ramp: Ramp,
    /// The M code 2D6Ah reads on completion.
    pub m_code: i64,
}

/// pt's state.
#[derive(Debug, Clone, Copy, Default)]
pub struct PointTableRun {
    run: Option<Positioning>,
    /// 2D69h.
    actual: i64,
    /// 2D6Ah.
    m_code: i64,
}

impl PointTableRun {
    /// Bit 4 rising edge: runs what 2D60h selects.
    pub fn start(&mut self, p: &Profile, homed: bool) {
        self.run = match p.point {
            Target::None => None,
            Target::Table(t) => Some(Positioning {
                number: t.number,
                target: t.position,
                speed: t.speed,
                ramp: t.ramp,
                m_code: t.m_code,
            }),
            Target::HomeReturn if homed => Some(Positioning {
                number: 0,
                target: p.home_offset,
                speed: p.homing_speed,
                ramp: Ramp {
                    acceleration_ms: p.homing_acceleration_ms,
                    deceleration_ms: p.homing_acceleration_ms,
                },
                m_code: 0,
            }),
            Target::HomeReturn => None,
        };
    }

    /// Starts `positioning` (idx).
    pub fn begin(&mut self, positioning: Option<Positioning>) {
        self.run = positioning;
    }

    /// What the motor does in pt (and idx, never halted).
    pub fn command(&self, p: &Profile, halted: bool) -> Command {
        match self.run {
            Some(r) if halted => Command::stop(r.ramp.deceleration_ms),
            Some(r) => Command::Position {
                target: r.target,
                speed: p.units_per_s(r.speed.min(p.max_speed)).abs(),
                ramp: r.ramp,
            },
            None => Command::stop(p.deceleration_ms),
        }
    }

    /// The positioning arrived.
    pub fn complete(&mut self) {
        if let Some(r) = self.run.take() {
            self.actual = r.number;
            self.m_code = r.m_code;
        }
    }

    /// A home position return completed: 2D69h reads 0.
    pub fn homed(&mut self) {
        self.actual = 0;
    }

    /// Servo off or another mode: the positioning is dropped.
    pub fn cancel(&mut self) {
        self.run = None;
    }

    /// Point demand value 2D68h: the table under way, else 2D60h (`selected`).
    pub fn demand(&self, selected: i64) -> i64 {
        self.run.map_or(selected.max(0), |r| r.number)
    }

    /// Point actual value 2D69h.
    pub fn actual(&self) -> i64 {
        self.actual
    }

    /// M code actual value 2D6Ah.
    pub fn m_code(&self) -> i64 {
        self.m_code
    }

    /// Target reached (bit 10, §7.3 6067h): no positioning under way and the command standing
    /// (the droop within 6067h is judged by the motor, `motion`).
    pub fn reached(&self, standing: bool) -> bool {
        self.run.is_none() && standing
    }
}
