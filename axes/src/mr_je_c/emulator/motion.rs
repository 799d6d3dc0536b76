//! The simulated MR-JE-C's motor (MR-JE-C manual §7.3, §7.6.2–§7.6.4): pp, pv and the shared
//! integrator here, hm, jg, tq, pt and idx in their own modules (`homing`, `jog`, `torque`,
//! `point_table`, `indexer`). pp takes 607Ah at a New set-point edge (Controlword bit 4) and answers
//! Set-point acknowledge (Statusword bit 12) while bit 4 stays on; pv follows 60FFh. Speeds are
//! limited by 6081h (pp) and 607Fh, acceleration and deceleration are time constants from 0 to
//! the rated speed (6083h, 6084h; 0 steps at once), Halt (bit 8) decelerates with 6084h. Target
//! reached (bit 10): pp at the target within the position window 6067h, pv at the speed within
//! the velocity window 606Dh. The profile is trapezoidal (the drive's S-pattern smoothing is
//! not emulated) and a new set-point replaces the running one at once (the
//! "change immediately" behaviour); the position unit is 6092h:1 feed per motor revolution.

use std::time::Duration;

use super::homing::Homing;
use super::indexer;
use super::jog::Jog;
use super::point_table::PointTableRun;
use super::profile::{Command, Profile, Ramp};
use super::profile::{
    HOMING, INDEXER, JOG, POINT_TABLE, PROFILE_POSITION, PROFILE_TORQUE, PROFILE_VELOCITY,
};
use super::torque::Torque;
use crate::cia402::controlword::Controlword;

/// Controlword bit 4: New set-point (pp, jg), Homing Operation Start (hm), start (pt).
const NEW_SET_POINT: u16 = 1 << 4;

/// The motor's state.
#[derive(Debug, Clone, Default)]
pub struct Motion {
    /// Position, pos units.
    position: f64,
    /// Velocity, pos units/s.
    velocity: f64,
    /// The pp set-point being run.
    set_point: Option<i64>,
    /// Statusword bit 12 in pp.
    acknowledged: bool,
    /// hm.
    homing: Homing,
    /// jg.
    jog: Jog,
    /// tq.
    torque: Torque,
    /// pt.
    point_table: PointTableRun,
}

impl Motion {
    /// Position actual value (6064h).
    pub fn position(&self) -> i64 {
        self.position.round() as i64
    }

    /// 6064h in the mode of `p`: within 0 … PT28 − 1 in idx (607Bh).
    pub fn position_in(&self, p: &Profile) -> i64 {
        match p.mode {
            INDEXER => self.position().rem_euclid(p.units_per_rev.max(1)),
            _ => self.position(),
        }
    }

    /// Velocity actual value (606Ch), 0.01 r/min.
    pub fn velocity(&self, p: &Profile) -> i64 {
        (self.velocity / p.units_per_rev as f64 * 60.0 * 100.0).round() as i64
    }

    /// Whether a home position return has completed since power-on (S_ZP2).
    pub fn homed(&self) -> bool {
        self.homing.homed()
    }

    /// The torque (tq).
    pub fn torque(&self) -> &Torque {
        &self.torque
    }

    /// The point table run (pt).
    pub fn point_table(&self) -> &PointTableRun {
        &self.point_table
    }

    /// A controlword write in Operation enabled: bit 4 edges start what the mode starts
    /// (pp 607Ah, hm the homing, jg the jog, pt the point table); pp's acknowledge follows bit 4.
    pub fn controlword(&mut self, cw: Controlword, prev: Controlword, p: &Profile) {
        let bit4 = cw.0 & NEW_SET_POINT != 0;
        let rising = bit4 && prev.0 & NEW_SET_POINT == 0;
        match p.mode {
            PROFILE_POSITION => {
                if rising {
                    self.set_point = Some(p.target_position);
                }
                self.acknowledged = bit4;
            }
            HOMING if rising && !cw.halt() => {
                if let Some(home) = self.homing.start(p) {
                    self.position = home as f64;
                    self.set_point = None;
                    self.point_table.homed();
                }
            }
            JOG => self.jog.controlword(cw, rising, p),
            POINT_TABLE if rising => self.point_table.start(p, self.homing.homed()),
            INDEXER if rising => self
                .point_table
                .begin(indexer::positioning(p, self.position)),
            _ => {}
        }
    }

    /// 6061h changed: what ran in the old mode ends (the motor decelerates in the new one).
    pub fn mode_changed(&mut self) {
        self.set_point = None;
        self.acknowledged = false;
        self.jog = Jog::default();
        self.point_table.cancel();
    }

    /// The position unit changed from `before` to `after` pos units per revolution (into or
    /// out of idx): the motor stays where it is.
    pub fn rescale(&mut self, before: i64, after: i64) {
        if before > 0 && after > 0 && before != after {
            let k = after as f64 / before as f64;
            self.position *= k;
            self.velocity *= k;
        }
    }

    /// Statusword bits 10, 12 and 13 in Operation enabled.
    pub fn status_bits(&self, p: &Profile, halted: bool) -> u16 {
        let standing = self.velocity == 0.0;
        let reached = match p.mode {
            PROFILE_POSITION => {
                self.set_point.is_none()
                    && (self.position - p.target_position as f64).abs() <= p.position_window as f64
            }
            PROFILE_VELOCITY => {
                let want = if halted { 0 } else { p.target_velocity };
                (self.velocity(p) - want).abs() <= p.velocity_window
            }
            HOMING => return self.homing.status_bits(standing),
            PROFILE_TORQUE => self.torque.reached(p, halted),
            JOG => self.jog.reached(standing),
            POINT_TABLE | INDEXER => self.point_table.reached(standing),
            _ => standing,
        };
        let reached = reached || (halted && standing);
        let ack = p.mode == PROFILE_POSITION && self.acknowledged;
        (u16::from(reached) << 10) | (u16::from(ack) << 12)
    }

    /// The servo is off (or the drive stopped): the motor stands (dynamic brake) and a
    /// set-point is forgotten.
    pub fn stand(&mut self) {
        self.velocity = 0.0;
        self.set_point = None;
        self.jog = Jog::default();
        self.torque.stand();
        self.point_table.cancel();
    }

    /// Quick stop (option code 2, MR-JE-C manual §7.6.2): decelerates by `dt` with the time
    /// constant `deceleration_ms` from the rated speed; true once the motor stands.
    pub fn quick_stop(&mut self, dt: Duration, p: &Profile, deceleration_ms: i64) -> bool {
        let dt = dt.as_secs_f64();
        if dt > 0.0 {
            self.follow(Command::stop(deceleration_ms), dt, p);
        }
        self.velocity == 0.0
    }

    /// Advances the motor by `dt` with servo on; `halted`: Controlword bit 8.
    pub fn advance(&mut self, dt: Duration, p: &Profile, halted: bool) {
        let dt = dt.as_secs_f64();
        if dt <= 0.0 {
            return;
        }
        let profile_ramp = Ramp {
            acceleration_ms: p.acceleration_ms,
            deceleration_ms: p.deceleration_ms,
        };
        let command = match p.mode {
            PROFILE_TORQUE => {
                self.velocity = self.torque.advance(dt, p, halted, self.velocity);
                self.position += self.velocity * dt;
                return;
            }
            HOMING => Command::stop(self.homing.deceleration_ms(p)),
            JOG => self.jog.command(p, halted),
            POINT_TABLE => self.point_table.command(p, halted),
            INDEXER => self.point_table.command(p, false),
            _ if halted => Command::stop(p.deceleration_ms),
            PROFILE_POSITION => match self.set_point {
                Some(target) => Command::Position {
                    target,
                    speed: p.units_per_s(p.profile_velocity).abs(),
                    ramp: profile_ramp,
                },
                None => Command::stop(p.deceleration_ms),
            },
            PROFILE_VELOCITY => Command::Speed {
                speed: p.units_per_s(p.target_velocity),
                ramp: profile_ramp,
            },
            _ => Command::stop(p.deceleration_ms),
        };
        if self.follow(command, dt, p) {
            match p.mode {
                PROFILE_POSITION => self.set_point = None,
                POINT_TABLE => self.point_table.complete(),
                INDEXER => {
                    self.point_table.complete();
                    self.position = self.position.rem_euclid(p.units_per_rev as f64);
                }
                _ => {}
            }
        }
    }

    /// One step of `command`; true when a positioning arrived at its target.
    fn follow(&mut self, command: Command, dt: f64, p: &Profile) -> bool {
        let (want, ramp) = match command {
            Command::Speed { speed, ramp } => (speed, ramp),
            Command::Position {
                target,
                speed,
                ramp,
            } => (self.braking_speed(target as f64, speed, ramp, p), ramp),
        };
        let speeding_up = want.abs() > self.velocity.abs() && want * self.velocity >= 0.0;
        if speeding_up && no_torque_toward(want, p) {
            // Held where it is: the speed it has, no more.
            self.position += self.velocity * dt;
            return false;
        }
        let rate = if speeding_up {
            p.rate(ramp.acceleration_ms)
        } else {
            p.rate(ramp.deceleration_ms)
        };
        let dv = want - self.velocity;
        self.velocity = match rate {
            Some(r) if dv.abs() > r * dt => self.velocity + r * dt * dv.signum(),
            _ => want,
        };
        let step = self.velocity * dt;
        if let Command::Position { target, .. } = command {
            let left = target as f64 - self.position;
            if left.abs() <= step.abs() || left == 0.0 {
                self.position = target as f64;
                self.velocity = 0.0;
                return true;
            }
        }
        self.position += step;
        false
    }

    /// The speed toward `target`: `vmax`, or less where the deceleration must start
    /// (v² = 2·d·s).
    fn braking_speed(&self, target: f64, vmax: f64, ramp: Ramp, p: &Profile) -> f64 {
        let left = target - self.position;
        let braking = p
            .rate(ramp.deceleration_ms)
            .map_or(vmax, |d| (2.0 * d * left.abs()).sqrt());
        left.signum() * vmax.min(braking)
    }
}

/// Whether the torque limit in the direction of `speed` is 0 (60E0h forward, 60E1h reverse,
/// each within the motor's maximum torque): the motor has no torque to speed up with. The
/// emulator has no inertia to scale the acceleration by a limit, so a limit only gates it (a
/// named choice where the manual gives no motor model; §7.3 60E0h/60E1h: 0 = 0.0 %).
fn no_torque_toward(speed: f64, p: &Profile) -> bool {
    let limit = if speed > 0.0 {
        p.positive_torque_limit
    } else {
        p.negative_torque_limit
    };
    limit <= 0
}

#[cfg(test)]
mod tests {
    use super::super::fixture::{cw, pp, run};
    use super::*;

    #[test]
    fn pp_reaches_the_target_at_the_profile_velocity() {
        let p = pp();
        let mut m = Motion::default();
        m.controlword(cw(0x1F), cw(0x0F), &p);
        assert_eq!(
            m.status_bits(&p, false),
            1 << 12,
            "acknowledged, not reached"
        );
        let peak = run(&mut m, &p, 60);
        // The 100 ms time constant to 3000 r/min reaches 600 r/min in 20 ms.
        assert_eq!(peak, 60_000);
        assert!(
            m.position() < 131_072 * 6 / 10,
            "one revolution takes > 100 ms"
        );
        let peak = run(&mut m, &p, 200).max(peak);
        assert_eq!(peak, 60_000);
        assert_eq!(m.position(), 131_072);
        m.controlword(cw(0x0F), cw(0x1F), &p);
        assert_eq!(m.status_bits(&p, false), 1 << 10);
    }

    #[test]
    fn no_torque_in_a_direction_leaves_the_motor_standing_that_way() {
        let mut p = pp();
        p.positive_torque_limit = 0;
        let mut m = Motion::default();
        m.controlword(cw(0x1F), cw(0x0F), &p);
        run(&mut m, &p, 100);
        assert_eq!(
            (m.position(), m.velocity(&p)),
            (0, 0),
            "60E0h = 0: no forward torque"
        );
        p.mode = PROFILE_VELOCITY;
        p.target_velocity = -30_000;
        run(&mut m, &p, 50);
        assert_eq!(m.velocity(&p), -30_000, "60E1h = 10000: reverse as before");
    }

    #[test]
    fn pv_follows_the_target_velocity_and_halt_stops() {
        let mut p = pp();
        p.mode = PROFILE_VELOCITY;
        p.target_velocity = -30_000;
        let mut m = Motion::default();
        run(&mut m, &p, 50);
        assert_eq!(m.velocity(&p), -30_000);
        assert!(m.status_bits(&p, false) & (1 << 10) != 0);
        for _ in 0..50 {
            m.advance(Duration::from_millis(1), &p, true);
        }
        assert_eq!(m.velocity(&p), 0);
        assert!(m.position() < 0);
    }
}
