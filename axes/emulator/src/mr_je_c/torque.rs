//! Profile torque mode (tq, 6060h = 4; MR-JE-C manual §7.3 6071h–6087h, 2D20h, §7.6.3): the
//! torque demand 6074h follows Target torque 6071h, limited by 60E0h/60E1h and the motor's
//! maximum torque 6072h, with Torque slope 6087h (0.1 %/s; 0 = a step; the shared slope of
//! `motion::profile_torque`). Halt (bit 8) ramps the
//! demand to 0 with 6087h; the operation restarts once it is 0 (§7.6.3). The speed comes from
//! the torque through [`TorquePlant`] and is limited by Velocity limit value 2D20h.

use super::profile::Profile;
use crate::motion::profile_torque::{HaltRelease, ProfileTorque, TqCommand, ZeroSlope};

/// tq's state, torques in 0.1 %.
#[derive(Debug, Clone, Copy, Default)]
pub struct Torque {
    /// 6074h from the shared torque slope (`motion::profile_torque`).
    slope: ProfileTorque,
    /// 6077h.
    actual: f64,
}

impl Torque {
    /// Torque demand value 6074h, 0.1 %.
    pub fn demand(&self) -> i64 {
        self.slope.demand().round() as i64
    }

    /// Torque actual value 6077h, 0.1 %: the demand, or the friction torque while the speed
    /// limit holds the motor.
    pub fn actual(&self) -> i64 {
        self.actual.round() as i64
    }

    /// Servo off: no torque.
    pub fn stand(&mut self) {
        *self = Torque::default();
    }

    /// 6071h within the torque limits.
    fn target(p: &Profile) -> f64 {
        let t = p
            .target_torque
            .clamp(-p.negative_torque_limit, p.positive_torque_limit);
        t as f64
    }

    /// Target reached (bit 10) in tq: the demand is at the target torque (0 with Halt)
    /// [EXT: CiA 402; the manual gives tq no bit 10 condition].
    pub fn reached(&self, p: &Profile, halted: bool) -> bool {
        let want = if halted || self.slope.halting() {
            0.0
        } else {
            Torque::target(p)
        };
        (self.slope.demand() - want).abs() < 0.5
    }

    /// One step of `dt` s from `velocity` (pos units/s); the new velocity. 6087h = 0 is a step
    /// (§7.3 6087h) and a released Halt restarts once the demand is 0 (§7.6.3).
    pub fn advance(&mut self, dt: f64, p: &Profile, halted: bool, velocity: f64) -> f64 {
        let command = TqCommand {
            halt: halted,
            target: Torque::target(p),
            slope: p.torque_slope as f64,
            zero_slope: ZeroSlope::Step,
            halt_release: HaltRelease::AfterZero,
        };
        self.slope.step(&command, dt);
        self.plant(dt, p, velocity)
    }

    /// The motor under the demand: dv/dt = (torque − friction) / inertia, at most 2D20h.
    fn plant(&mut self, dt: f64, p: &Profile, velocity: f64) -> f64 {
        let limit = p.units_per_s(p.velocity_limit.min(p.max_speed)).abs();
        let secs = p.plant.rated_acceleration_time.as_secs_f64().max(1e-6);
        let per_tenth_percent = p.units_per_s(p.rated_speed) / secs / 1000.0;
        let friction = p.plant.friction as f64;
        let t = self.slope.demand();
        let net = if velocity != 0.0 {
            t - friction * velocity.signum()
        } else if t.abs() > friction {
            t - friction * t.signum()
        } else {
            0.0
        };
        let mut v = velocity + net * per_tenth_percent * dt;
        if velocity != 0.0 && v * velocity < 0.0 {
            v = 0.0;
        }
        self.actual = t;
        if v.abs() >= limit {
            v = limit * v.signum();
            if t.abs() > friction {
                self.actual = friction * v.signum();
            }
        }
        v
    }
}
