//! Profile torque mode (tq, 6060h = 4; MR-JE-C manual §7.3 6071h–6087h, 2D20h, §7.6.3): the
//! torque demand 6074h follows Target torque 6071h, limited by 60E0h/60E1h and the motor's
//! maximum torque 6072h, with Torque slope 6087h (0.1 %/s; 0 = a step). Halt (bit 8) ramps the
//! demand to 0 with 6087h; the operation restarts once it is 0 (§7.6.3). The speed comes from
//! the torque through [`TorquePlant`] and is limited by Velocity limit value 2D20h.

use std::time::Duration;

use super::motion::Profile;

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

/// tq's state, torques in 0.1 %.
#[derive(Debug, Clone, Copy, Default)]
pub struct Torque {
    /// 6074h.
    demand: f64,
    /// 6077h.
    actual: f64,
    /// Halt ramps the demand to 0; on until it is 0 and the halt is off.
    halting: bool,
}

impl Torque {
    /// Torque demand value 6074h, 0.1 %.
    pub fn demand(&self) -> i64 {
        self.demand.round() as i64
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
        let want = if halted || self.halting {
            0.0
        } else {
            Torque::target(p)
        };
        (self.demand - want).abs() < 0.5
    }

    /// One step of `dt` s from `velocity` (pos units/s); the new velocity.
    pub fn advance(&mut self, dt: f64, p: &Profile, halted: bool, velocity: f64) -> f64 {
        self.halting = halted || (self.halting && self.demand != 0.0);
        let want = if self.halting { 0.0 } else { Torque::target(p) };
        let step = p.torque_slope as f64 * dt;
        let dt_demand = want - self.demand;
        self.demand = if p.torque_slope > 0 && dt_demand.abs() > step {
            self.demand + step * dt_demand.signum()
        } else {
            want
        };
        if self.halting && !halted && self.demand == 0.0 {
            self.halting = false;
        }
        self.plant(dt, p, velocity)
    }

    /// The motor under the demand: dv/dt = (torque − friction) / inertia, at most 2D20h.
    fn plant(&mut self, dt: f64, p: &Profile, velocity: f64) -> f64 {
        let limit = p.units_per_s(p.velocity_limit.min(p.max_speed)).abs();
        let secs = p.plant.rated_acceleration_time.as_secs_f64().max(1e-6);
        let per_tenth_percent = p.units_per_s(p.rated_speed) / secs / 1000.0;
        let friction = p.plant.friction as f64;
        let t = self.demand;
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

#[cfg(test)]
mod tests {
    use super::super::fixture::{pp, run, run_halted};
    use super::super::motion::{Motion, PROFILE_TORQUE};
    use super::*;

    fn tq() -> Profile {
        Profile {
            mode: PROFILE_TORQUE,
            target_torque: 1000,    // 100.0 %
            torque_slope: 10_000,   // 1000.0 %/s
            velocity_limit: 50_000, // 500.00 r/min, the 2D20h default
            ..pp()
        }
    }

    #[test]
    fn the_demand_ramps_with_6087h_and_the_speed_stops_at_2d20h() {
        let p = tq();
        let mut m = Motion::default();
        run(&mut m, &p, 50);
        assert_eq!(m.torque().demand(), 500, "1000.0 %/s for 50 ms");
        run(&mut m, &p, 50);
        assert_eq!(m.torque().demand(), 1000);
        assert_eq!(m.status_bits(&p, false), 1 << 10);
        run(&mut m, &p, 100);
        assert_eq!(m.velocity(&p), 50_000, "held at the speed limit");
        assert_eq!(
            m.torque().actual(),
            30,
            "the friction torque holds the speed"
        );
    }

    #[test]
    fn a_step_without_slope_and_torque_within_friction_leaves_the_motor_standing() {
        let mut p = tq();
        p.torque_slope = 0;
        p.target_torque = -30;
        let mut m = Motion::default();
        run(&mut m, &p, 1);
        assert_eq!(m.torque().demand(), -30);
        run(&mut m, &p, 100);
        assert_eq!(m.velocity(&p), 0);
        p.target_torque = -5000;
        run(&mut m, &p, 1);
        assert_eq!(m.torque().demand(), -3000, "6072h limits the demand");
    }

    #[test]
    fn the_plant_accelerates_with_the_torque_over_friction() {
        let mut p = tq();
        p.torque_slope = 0;
        p.target_torque = 530; // 53.0 %: 50 % over the 3 % friction
        p.velocity_limit = 600_000;
        let mut m = Motion::default();
        run(&mut m, &p, 10);
        // 100 % takes 50 ms to 3000 r/min: 50 % gives 300 r/min in 10 ms.
        assert_eq!(m.velocity(&p), 30_000);
    }

    #[test]
    fn halt_ramps_the_demand_to_0_and_restarts_after() {
        let p = tq();
        let mut m = Motion::default();
        run(&mut m, &p, 100);
        run_halted(&mut m, &p, 50, true);
        assert_eq!(m.torque().demand(), 500);
        run_halted(&mut m, &p, 50, true);
        assert_eq!(m.torque().demand(), 0);
        assert_eq!(m.status_bits(&p, true), 1 << 10);
        run(&mut m, &p, 10);
        assert_eq!(m.torque().demand(), 100);
    }
}
