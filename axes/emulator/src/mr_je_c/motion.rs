//! The simulated MR-JE-C's motor (MR-JE-C manual §7.3, §7.6.2–§7.6.4): the shared integrator
//! here; pp and pv through the shared modules (`motion::profile_position` with
//! [`PpModel::MR_JE_C`]: bit 12 follows bit 4, a new set-point replaces the running one;
//! `motion::profile_velocity` with [`PvModel::MR_JE_C`]: the ramp runs through zero toward
//! 60FFh); hm, jg, tq, pt and idx in their own modules (`homing`, `jog`, `torque`,
//! `point_table`, `indexer`). Speeds are limited by 6081h (pp) and 607Fh, acceleration and
//! deceleration are time constants from 0 to the rated speed (6083h, 6084h; 0 steps at once),
//! Halt (bit 8) decelerates with 6084h (605Dh = 1, §7.6.3); the position unit is 6092h:1 feed
//! per motor revolution.
//!
//! In the position control modes (pp, hm, jg, pt, idx) the command runs in three stages:
//! 1. the trapezoid of the ramps above;
//! 2. the S-pattern filter of [Pr. PC03] ([`SPattern`]: a moving average over the trapezoid,
//!    so every move of these modes, a halt and a quick stop included, is smoothed the same way
//!    and takes PC03 longer, as §6.1's stroke-end table has a stop "continue for the delay of
//!    the S-pattern"). PC03 is not a `*` parameter (§5.1.1), so it needs no power cycle; the
//!    emulator takes a new value once the filtered command stands (the manual does not say
//!    when; 60F2h has setting changes during a motion take effect at the next start: an
//!    emulator choice of the same kind);
//! 3. the position loop: the motor follows the filtered command as a first-order lag,
//!    d(actual)/dt = Kp × droop, droop = command − actual, so a constant speed v leaves a
//!    steady droop of v / Kp. Kp is the emulator's [`super::MrJeCParams::position_loop_gain`]
//!    (the network manual names the gains [Pr. PB06], [Pr. PB08]–[Pr. PB10] only in §7.5.8
//!    C_RTCDP and gives no value). Position actual value 6064h is the motor's position;
//!    Following error actual value 60F4h and Droop pulses 2B03h the droop.
//!
//! pv, tq and the −20/−21/−22 modes have no position loop and no S-pattern here: the motor is
//! where the command is (droop 0). Velocity actual value 606Ch reads the filtered command's
//! speed (the motor reaches it within about 1 / Kp): an emulator choice that keeps the speed
//! windows judging the commanded speed.

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
use crate::motion::generator::{Arrival, Braking, Generator, NoTorque, Positioning};
use crate::motion::profile_position::{PpCommand, PpFeedback, PpModel, ProfilePosition, HALT};
use crate::motion::profile_velocity::{ProfileVelocity, PvCommand, PvModel};
use crate::motion::ramp::VelocityRamp;
use crate::motion::s_pattern::{SPattern, MAX_MS, SAMPLE};
use cellrt_cia402::controlword::Controlword;

/// Controlword bit 4: New set-point (pp, jg), Homing Operation Start (hm), start (pt).
use cellrt_cia402::controlword::NEW_SET_POINT;

/// The modes under position control: the S-pattern filter and the position loop run.
fn position_control(mode: i64) -> bool {
    matches!(
        mode,
        PROFILE_POSITION | HOMING | JOG | POINT_TABLE | INDEXER
    )
}

/// What moves the motor in a step.
#[derive(Debug, Clone, Copy)]
enum Drive {
    /// The mode's command; `halted`: Controlword bit 8.
    Mode { halted: bool },
    /// Quick stop with this deceleration time constant, ms.
    QuickStop(i64),
}

/// What moves the trapezoid in a step.
#[derive(Debug, Clone, Copy)]
enum Mover {
    /// A mode's (or the quick stop's) command.
    Command(Command),
    /// pp's set-point (`motion::profile_position`); `halted`: Controlword bit 8.
    ProfilePosition { halted: bool },
    /// pv's ramp (`motion::profile_velocity`); `halted`: Controlword bit 8.
    ProfileVelocity { halted: bool },
}

/// The motor's state.
#[derive(Debug, Clone, Default)]
pub struct Motion {
    /// The trapezoid's position, pos units.
    position: f64,
    /// The trapezoid's velocity, pos units/s.
    velocity: f64,
    /// [Pr. PC03]'s filter over the trapezoid.
    s_pattern: SPattern,
    /// Filtered command − motor position, pos units (0 without a position loop).
    droop: f64,
    /// pp: the shared set-point handshake ([`PpModel::MR_JE_C`]).
    pp: ProfilePosition,
    /// hm.
    homing: Homing,
    /// jg.
    jog: Jog,
    /// tq.
    torque: Torque,
    /// pt.
    point_table: PointTableRun,
    /// How far homing has moved 6064h's origin, pos units (what [`Motion::travel`] adds back).
    home_shift: f64,
}

impl Motion {
    /// The motor's position since power-on, pos units, whatever homing did to 6064h: the
    /// encoder's count (2B01h Cumulative feedback pulses, in pulses).
    pub fn travel(&self) -> f64 {
        self.actual() + self.home_shift
    }

    /// The motor's position, pos units.
    fn actual(&self) -> f64 {
        self.s_pattern.output(self.position) - self.droop
    }

    /// Position actual value (6064h).
    pub fn position(&self) -> i64 {
        self.actual().round() as i64
    }

    /// 6064h in the mode of `p`: within 0 … PT28 − 1 in idx (607Bh).
    pub fn position_in(&self, p: &Profile) -> i64 {
        match p.mode {
            INDEXER => self.position().rem_euclid(p.units_per_rev.max(1)),
            _ => self.position(),
        }
    }

    /// Velocity actual value (606Ch), 0.01 r/min: the filtered command's speed.
    pub fn velocity(&self, p: &Profile) -> i64 {
        let v = self.s_pattern.velocity(self.position, self.velocity);
        (v / p.units_per_rev as f64 * 60.0 * 100.0).round() as i64
    }

    /// The droop (command − motor position), pos units: 60F4h.
    pub fn droop(&self) -> f64 {
        self.droop
    }

    /// The command has stopped: the trapezoid stands and the S-pattern filter has caught up.
    fn standing(&self) -> bool {
        self.velocity == 0.0 && self.s_pattern.drained(self.position)
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

    /// pp's inputs from the objects of `p` with the controlword `cw` (only bit 8 outside a
    /// controlword write): [`PpModel::MR_JE_C`], 6081h/6083h/6084h in pos units, Halt at 6084h.
    fn pp_command(p: &Profile, cw: u16) -> PpCommand {
        let deceleration = p.rate(p.deceleration_ms);
        PpCommand {
            model: PpModel::MR_JE_C,
            controlword: cw,
            target: p.target_position as i32,
            velocity: p.units_per_s(p.profile_velocity).abs(),
            acceleration: p.rate(p.acceleration_ms),
            deceleration,
            halt_deceleration: deceleration,
            window: p.position_window.clamp(0, i64::from(u32::MAX)) as u32,
            // 6068h is timed by the drive, as in jg, pt and idx.
            window_time_s: 0.0,
            relative_refused: None,
            limits: None,
        }
    }

    /// pv's inputs from the objects of `p`, `halted`: Controlword bit 8: [`PvModel::MR_JE_C`],
    /// the ramp in pos units, bit 10 in 606Ch's 0.01 r/min; Halt at 6084h (§7.6.3).
    fn pv_command(p: &Profile, halted: bool) -> PvCommand {
        let deceleration = p.rate(p.deceleration_ms);
        PvCommand {
            model: PvModel::MR_JE_C,
            halt: halted,
            target: p.target_velocity as f64,
            limited_target: p.units_per_s(p.target_velocity),
            acceleration: p.rate(p.acceleration_ms),
            deceleration,
            halt_deceleration: deceleration,
            window: p.velocity_window as f64,
            // 606Eh, 606Fh and 6070h are timed by the drive (`MrJeC::timed`).
            window_time_s: 0.0,
            threshold: 0.0,
            threshold_time_s: 0.0,
        }
    }

    /// The motor as pp judges it: pos units, the filtered command's speed, the droop.
    fn pp_feedback(&self) -> PpFeedback {
        PpFeedback {
            actual: self.position() as i32,
            position: self.actual(),
            velocity: self.s_pattern.velocity(self.position, self.velocity),
            droop: self.droop,
            command_standing: self.standing(),
        }
    }

    /// A controlword write in Operation enabled: bit 4 edges start what the mode starts
    /// (pp 607Ah, hm the homing, jg the jog, pt the point table).
    pub fn controlword(&mut self, cw: Controlword, prev: Controlword, p: &Profile) {
        let bit4 = cw.0 & NEW_SET_POINT != 0;
        let rising = bit4 && prev.0 & NEW_SET_POINT == 0;
        match p.mode {
            PROFILE_POSITION => {
                let fb = self.pp_feedback();
                self.pp.controlword(&Self::pp_command(p, cw.0), prev.0, fb);
            }
            HOMING if rising && !cw.halt() => {
                if let Some(home) = self.homing.start(p) {
                    // The home position is where the motor is: no droop, nothing to filter.
                    self.home_shift += self.actual() - home as f64;
                    self.position = home as f64;
                    self.droop = 0.0;
                    self.s_pattern
                        .reset(self.s_pattern.len() as i64, self.position);
                    self.pp.cancel();
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
        self.pp.leave();
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
            self.droop *= k;
            self.home_shift *= k;
            self.s_pattern.scale(k);
        }
    }

    /// Statusword bits 10, 12 and 13 in Operation enabled. Target reached also needs the
    /// droop within the position window 6067h (§7.3 6067h; 0 outside position control);
    /// 6067h = 4294967295 ("the Position window is disabled") is taken as "every droop is
    /// within it": Target reached follows the completion alone (the manual gives no more).
    pub fn status_bits(&self, p: &Profile, halted: bool) -> u16 {
        if p.mode == PROFILE_POSITION {
            // The shared rule (`motion::profile_position`, TargetReachedRule::CommandAndDroop).
            let c = Self::pp_command(p, if halted { HALT } else { 0 });
            let reached = self.pp.target_reached(&c, self.pp_feedback());
            let ack = self.pp.acknowledged(&c.model);
            return (u16::from(reached) << 10) | (u16::from(ack) << 12);
        }
        let standing = self.standing();
        let window = p.position_window as f64;
        let reached = match p.mode {
            PROFILE_VELOCITY => {
                // The shared rule (`motion::profile_velocity`, PvReachedRule::JudgedNow).
                ProfileVelocity::reached_now(&Self::pv_command(p, halted), self.velocity(p) as f64)
            }
            HOMING => return self.homing.status_bits(standing),
            PROFILE_TORQUE => self.torque.reached(p, halted),
            JOG => self.jog.reached(standing),
            POINT_TABLE | INDEXER => self.point_table.reached(standing),
            _ => standing,
        };
        let reached = (reached || (halted && standing)) && self.droop.abs() <= window;
        u16::from(reached) << 10
    }

    /// The servo is off (or the drive stopped): the motor stands where it is (dynamic brake),
    /// the droop and the filter's delay are dropped, and a set-point is forgotten.
    pub fn stand(&mut self) {
        self.release();
        self.velocity = 0.0;
        self.pp.cancel();
        self.jog = Jog::default();
        self.torque.stand();
        self.point_table.cancel();
    }

    /// Leaves position control: the command is where the motor is, at the filtered speed.
    fn release(&mut self) {
        if self.s_pattern.len() > 0 || self.droop != 0.0 {
            let x = self.actual();
            self.velocity = self.s_pattern.velocity(self.position, self.velocity);
            self.position = x;
            self.droop = 0.0;
            self.s_pattern.reset(0, x);
        }
    }

    /// Quick stop (option code 2, MR-JE-C manual §7.6.2): decelerates by `dt` with the time
    /// constant `deceleration_ms` from the rated speed (through the S-pattern filter in
    /// position control); true once the command stands.
    pub fn quick_stop(&mut self, dt: Duration, p: &Profile, deceleration_ms: i64) -> bool {
        self.run(dt, p, Drive::QuickStop(deceleration_ms));
        self.standing()
    }

    /// Advances the motor by `dt` with servo on; `halted`: Controlword bit 8.
    pub fn advance(&mut self, dt: Duration, p: &Profile, halted: bool) {
        self.run(dt, p, Drive::Mode { halted });
    }

    /// Advances the motor by `dt` under `drive`. In position control the trapezoid is stepped
    /// to every sample of the S-pattern filter while one runs (else in one step, as it stands
    /// then), the motor following through the position loop.
    fn run(&mut self, dt: Duration, p: &Profile, drive: Drive) {
        if dt.is_zero() {
            return;
        }
        if !position_control(p.mode) {
            self.release();
            let secs = dt.as_secs_f64();
            match self.mover(p, drive) {
                None => {
                    self.velocity = self.torque.advance(secs, p, drive.halted(), self.velocity);
                    self.position += self.velocity * secs;
                }
                Some(mover) => {
                    if self.follow(mover, secs, p).arrived {
                        self.arrived(p);
                    }
                }
            }
            return;
        }
        let length = p.s_pattern_ms.clamp(0, MAX_MS);
        if self.s_pattern.len() as i64 != length && self.standing() {
            self.s_pattern.reset(length, self.position);
        }
        let mut wrap = false;
        let mut left = dt;
        while !left.is_zero() {
            let Some(mover) = self.mover(p, drive) else {
                return;
            };
            let stays = self.standing() && self.holds(mover, p);
            let h = if self.s_pattern.len() == 0 || stays {
                left
            } else {
                (SAMPLE - self.s_pattern.since()).min(left)
            };
            let before = self.s_pattern.output(self.position);
            let secs = h.as_secs_f64();
            let step = self.follow(mover, secs, p);
            if step.arrived {
                wrap |= self.arrived(p);
            }
            self.s_pattern.elapse(h, self.position);
            let moved = self.s_pattern.output(self.position) - before;
            if self.s_pattern.len() == 0 {
                // The trapezoid moved for `moving` and stood for the rest.
                self.settle(step.moving, moved, p);
                self.settle(secs - step.moving, 0.0, p);
            } else {
                self.settle(secs, moved, p);
            }
            left -= h;
        }
        if wrap {
            // idx: the position back into one revolution, the filter and droop with it.
            let n = p.units_per_rev.max(1) as f64;
            let d = self.position.rem_euclid(n) - self.position;
            self.position += d;
            self.s_pattern.shift(d);
        }
    }

    /// The position loop over `secs` in which the filtered command moved by `moved` at a
    /// constant speed v: the droop e solves de/dt = v − Kp·e exactly, so any step is stable
    /// and a constant speed settles at v / Kp.
    fn settle(&mut self, secs: f64, moved: f64, p: &Profile) {
        let kp = p.position_loop_gain;
        if !(kp > 0.0 && kp.is_finite()) {
            self.droop = 0.0;
            return;
        }
        if secs <= 0.0 {
            self.droop += moved;
            return;
        }
        let steady = moved / secs / kp;
        self.droop = steady + (self.droop - steady) * (-kp * secs).exp();
    }

    /// What moves the trapezoid under `drive` in the mode of `p` (`None`: tq).
    fn mover(&self, p: &Profile, drive: Drive) -> Option<Mover> {
        match drive {
            Drive::Mode { halted } if p.mode == PROFILE_POSITION => {
                Some(Mover::ProfilePosition { halted })
            }
            Drive::Mode { halted } if p.mode == PROFILE_VELOCITY => {
                Some(Mover::ProfileVelocity { halted })
            }
            _ => self.command(p, drive).map(Mover::Command),
        }
    }

    /// Whether `mover` leaves a trapezoid standing at its position where it is.
    fn holds(&self, mover: Mover, p: &Profile) -> bool {
        match mover {
            Mover::Command(c) => c.holds(self.position),
            Mover::ProfilePosition { halted } => self.pp.holds(self.position, halted),
            Mover::ProfileVelocity { halted } => halted || p.target_velocity == 0,
        }
    }

    /// The command of `drive` in the mode of `p` (`None`: tq, which has no speed command; pp
    /// and pv are [`Mover::ProfilePosition`], [`Mover::ProfileVelocity`] but for a quick stop).
    fn command(&self, p: &Profile, drive: Drive) -> Option<Command> {
        let halted = match drive {
            Drive::QuickStop(ms) => return Some(Command::stop(ms)),
            Drive::Mode { halted } => halted,
        };
        Some(match p.mode {
            PROFILE_TORQUE => return None,
            HOMING => Command::stop(self.homing.deceleration_ms(p)),
            JOG => self.jog.command(p, halted),
            POINT_TABLE => self.point_table.command(p, halted),
            INDEXER => self.point_table.command(p, false),
            _ => Command::stop(p.deceleration_ms),
        })
    }

    /// The trapezoid arrived at a positioning's target; true in idx, whose position then
    /// goes back into one revolution.
    fn arrived(&mut self, p: &Profile) -> bool {
        match p.mode {
            POINT_TABLE => self.point_table.complete(),
            INDEXER => {
                self.point_table.complete();
                return true;
            }
            _ => {}
        }
        false
    }

    /// One step of `mover` of the trapezoid: the shared generator (`motion::generator`)
    /// with the MR-JE-C's [`Braking::Continuous`] curve and its 60E0h/60E1h gate.
    fn follow(&mut self, mover: Mover, dt: f64, p: &Profile) -> Arrival {
        let mut g = Generator {
            position: self.position,
            velocity: self.velocity,
        };
        let no_torque = NoTorque {
            forward: p.positive_torque_limit <= 0,
            reverse: p.negative_torque_limit <= 0,
        };
        let step = match mover {
            Mover::ProfilePosition { halted } => {
                let c = Self::pp_command(p, if halted { HALT } else { 0 });
                self.pp.advance(&mut g, &c, no_torque, dt)
            }
            Mover::ProfileVelocity { halted } => {
                ProfileVelocity::advance(&mut g, &Self::pv_command(p, halted), no_torque, dt);
                Arrival {
                    arrived: false,
                    moving: dt,
                }
            }
            Mover::Command(Command::Speed { speed, ramp }) => {
                g.run_at(speed, &velocity_ramp(ramp, p), no_torque, dt);
                Arrival {
                    arrived: false,
                    moving: dt,
                }
            }
            Mover::Command(Command::Position {
                target,
                speed,
                ramp,
            }) => {
                let positioning = Positioning {
                    target: target as f64,
                    speed,
                    ramp: velocity_ramp(ramp, p),
                    braking: Braking::Continuous,
                };
                g.position_to(&positioning, no_torque, dt)
            }
        };
        self.position = g.position;
        self.velocity = g.velocity;
        step
    }
}

/// The time constants of `ramp` as the shared velocity ramp (0 ms: a step), passing through 0.
fn velocity_ramp(ramp: Ramp, p: &Profile) -> VelocityRamp {
    VelocityRamp::new(p.rate(ramp.acceleration_ms), p.rate(ramp.deceleration_ms))
}

impl Drive {
    /// Controlword bit 8 (a quick stop is no halt).
    fn halted(self) -> bool {
        matches!(self, Drive::Mode { halted: true })
    }
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

    /// Runs pp from 0 to 607Ah in steps of 1 ms until the command stands: 606Ch after each
    /// step. Target reached never comes before the filtered command has arrived.
    fn pp_speeds(p: &Profile) -> (Vec<i64>, Motion) {
        let mut m = Motion::default();
        m.controlword(cw(0x1F), cw(0x0F), p);
        m.controlword(cw(0x0F), cw(0x1F), p);
        let mut speeds = vec![];
        for _ in 0..1000 {
            m.advance(Duration::from_millis(1), p, false);
            speeds.push(m.velocity(p));
            let reached = m.status_bits(p, false) & (1 << 10) != 0;
            assert!(!reached || m.standing(), "reached before the command stood");
            if m.standing() {
                break;
            }
        }
        (speeds, m)
    }

    /// The change of `v` per ms.
    fn differences(v: &[i64]) -> Vec<i64> {
        v.windows(2).map(|w| w[1] - w[0]).collect()
    }

    fn largest(v: &[i64]) -> i64 {
        v.iter().map(|x| x.abs()).max().unwrap_or(0)
    }

    #[test]
    fn pc03_smooths_the_trapezoid_into_an_s_and_takes_pc03_longer() {
        let (trapezoid, _) = pp_speeds(&pp());
        let p = Profile {
            s_pattern_ms: 50,
            ..pp()
        };
        let (s, mut ms) = pp_speeds(&p);
        assert_eq!(ms.position, 131_072.0, "the command ends exactly at 607Ah");
        assert!(
            ms.status_bits(&p, false) & (1 << 10) != 0,
            "droop within 6067h"
        );
        run(&mut ms, &p, 20);
        assert_eq!(
            (ms.position(), ms.velocity(&p)),
            (131_072, 0),
            "the motor too"
        );
        assert_eq!((largest(&trapezoid), largest(&s)), (60_000, 60_000));
        // The trapezoid accelerates at 3000 r/min per 100 ms = 3000 (0.01 r/min) per ms for
        // the 20 ms to 600 r/min; the 50 ms average spreads that speed step over 50 ms:
        // 60000 / 50 = 1200 per ms at most (±1 of rounding), the end of the deceleration
        // (where the trapezoid's last step drops the speed at once) included.
        let (a, a_s) = (differences(&trapezoid), differences(&s));
        assert_eq!(a.iter().max(), Some(&3000));
        assert!(largest(&a) > 3000, "the trapezoid's arrival step: {a:?}");
        assert!((1199..=1201).contains(&largest(&a_s)), "{a_s:?}");
        // Jerk: the trapezoid's acceleration jumps from one ms to the next; the average
        // divides each jump by the 50 samples it spreads it over (±2 of rounding).
        let (j, j_s) = (largest(&differences(&a)), largest(&differences(&a_s)));
        assert!(j >= 3000, "{a:?}");
        assert!(j_s <= j / 50 + 2, "{j_s} against {j}: {a_s:?}");
        // 1 revolution: about 20 + 80 + 20 ms (116 steps of 1 ms: the trapezoid starts
        // braking on its v² = 2·d·s curve), 50 ms more with the S-pattern (within one step).
        assert_eq!(trapezoid.len(), 116);
        assert!(
            (49..=51).contains(&(s.len() - trapezoid.len())),
            "{} ms",
            s.len()
        );
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
