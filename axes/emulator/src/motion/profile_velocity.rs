//! Profile velocity mode (pv) of every emulated drive: the drive's own velocity ramp toward 60FFh
//! and the statusword bits 10 / 12. The simulated EtherCAT drives (MR-J4-TM manual §5.4.7;
//! MR-JET-G-N1 and MR-J5-G-N1 state only "pv: a target velocity" with 6083h/6084h, their bits
//! as CiA 402 [background]) run [`PvModel::ETHERCAT`], described below; the MR-JE-C runs
//! [`PvModel::MR_JE_C`] on its own trapezoid (`ProfileVelocity::advance`).
//!
//! * The ramp is linear: the generator velocity (606Bh velocity demand) rises at 6083h and
//!   falls at 6084h, both time constants in ms from 0 to the rated speed (§5.4.7(4), units as
//!   pp, `motion::profile_position`). Reversing decelerates to 0 at 6084h, then accelerates at
//!   6083h. 0 ms means the plant's maximum acceleration.
//! * Statusword bit 10 **target reached**: with HALT = 0, |606Ch − 60FFh| has stayed within
//!   606Dh for at least 606Eh; with HALT = 1, the velocity is 0.
//! * Statusword bit 12 **speed**: 0 once |606Ch| has stayed above 606Fh for at least 6070h,
//!   1 otherwise ("speed = 0"); the MR-JE-C's "for longer than 6070h" is
//!   [`ThresholdTime::LongerThan`]. Both window times are the shared timer
//!   (`motion::window_time`), counted over whole cycles ([`HeldFrom::WholeCycle`]).
//! * Bit 8 **HALT** ramps the generator to 0 at the drive's halt deceleration (605Dh).
//!
//! Velocities are in counts/s of the plant; the drive converts the objects from the model's
//! velocity unit. The ramp is the shared one (`motion::ramp`). Allocation-free: plain copies
//! only.

use super::generator::{Generator, NoTorque};
use super::ramp::{Reversal, VelocityRamp};
pub use super::window_time::ThresholdTime;
use super::window_time::{Held, HeldFrom};

pub use cellrt_cia402::statusword::{SPEED_ZERO, TARGET_REACHED};

/// Where the ramp lands on its goal.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Landing {
    /// Within 1e-6 units/s, the float error of the cycle sums: the simulated EtherCAT drives
    /// (an emulator choice).
    WithinFloatError,
    /// Exactly: the MR-JE-C (an emulator choice; its steps are the message intervals).
    Exact,
}

impl Landing {
    /// The distance (units/s) within which the ramp lands on its goal.
    pub fn units(self) -> f64 {
        match self {
            Landing::WithinFloatError => RAMP_LANDING,
            Landing::Exact => 0.0,
        }
    }
}

/// Statusword bit 10 in pv.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PvReachedRule {
    /// HALT = 0: |606Ch − 60FFh| ≤ 606Dh for at least 606Eh, bit 12 after 6070h, both timed
    /// here over whole cycles; HALT = 1: generator and motor at 0, untimed (MR-J4-TM manual
    /// §5.4.7): the simulated EtherCAT drives.
    Timed,
    /// |606Ch − 60FFh| ≤ 606Dh, 60FFh read as 0 under HALT, judged now: the drive times 606Eh
    /// and 6070h, also under HALT (MR-JE-C manual §7.3 606Dh–6070h; HALT not stated there).
    JudgedNow,
}

/// Where a model's pv differs, chosen by each model: [`PvModel::ETHERCAT`] (MR-J4-TM manual
/// §5.4.7) and [`PvModel::MR_JE_C`] (MR-JE-C manual §7.3). The torque gate and the HALT
/// deceleration are data the caller passes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PvModel {
    /// A ramp through zero ([`Reversal`]).
    pub reversal: Reversal,
    /// Where the ramp lands.
    pub landing: Landing,
    /// Bit 10.
    pub target_reached: PvReachedRule,
    /// How 6070h is compared (bit 12).
    pub threshold_time: ThresholdTime,
}

impl PvModel {
    /// The simulated EtherCAT drives: stop at zero (§5.4.7(4)), "for at least 6070h" (§5.4.7;
    /// MR-JET, MR-J5: CiA 402 [background]).
    pub const ETHERCAT: PvModel = PvModel {
        reversal: Reversal::StopAtZero,
        landing: Landing::WithinFloatError,
        target_reached: PvReachedRule::Timed,
        threshold_time: ThresholdTime::AtLeast,
    };

    /// The MR-JE-C: through zero (§7.3 6083h/6084h give no stop), "for longer than 6070h"
    /// (§7.3 6070h).
    pub const MR_JE_C: PvModel = PvModel {
        reversal: Reversal::Through,
        landing: Landing::Exact,
        target_reached: PvReachedRule::JudgedNow,
        threshold_time: ThresholdTime::LongerThan,
    };
}

impl Default for PvModel {
    fn default() -> Self {
        PvModel::ETHERCAT
    }
}

/// pv objects the MR-JET / MR-J5 manuals do not give (used where the model's object dictionary
/// has no default and the object was not written by SDO). Defaults: the MR-J4-TM manual §5.4.7
/// object table, in the model's velocity unit (LSBs) and ms.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PvParams {
    /// 606Dh Velocity window, velocity-unit LSBs (2000 = 20.00 r/min at 0.01 r/min).
    pub velocity_window: u32,
    /// 606Eh Velocity window time, ms.
    pub velocity_window_time_ms: u32,
    /// 606Fh Velocity threshold, velocity-unit LSBs (5000 = 50.00 r/min at 0.01 r/min).
    pub velocity_threshold: u32,
    /// 6070h Velocity threshold time, ms.
    pub velocity_threshold_time_ms: u32,
    /// The pv behaviour of the model, default [`PvModel::ETHERCAT`].
    pub model: PvModel,
}

impl Default for PvParams {
    fn default() -> Self {
        PvParams {
            velocity_window: 2_000,
            velocity_window_time_ms: 0,
            velocity_threshold: 5_000,
            velocity_threshold_time_ms: 10,
            model: PvModel::ETHERCAT,
        }
    }
}

/// One cycle's pv inputs, resolved by the drive: the ramp in the generator's units (counts/s,
/// counts/s² on the EtherCAT drives), bit 10 and 12 in the unit of the motor velocity passed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PvCommand {
    /// The model's behaviour.
    pub model: PvModel,
    /// HALT (controlword bit 8).
    pub halt: bool,
    /// 60FFh as received, counts/s (what bit 10 compares with).
    pub target: f64,
    /// 60FFh after the model's caps (607Fh / 6080h / the plant's maximum speed), the ramp's goal.
    pub limited_target: f64,
    /// From 6083h, counts/s² (`None`: a step, the MR-JE-C's 0 ms).
    pub acceleration: Option<f64>,
    /// From 6084h, counts/s² (`None`: a step).
    pub deceleration: Option<f64>,
    /// HALT deceleration, counts/s² (605Dh on the EtherCAT drives, 6084h on the MR-JE-C).
    pub halt_deceleration: Option<f64>,
    /// 606Dh, counts/s.
    pub window: f64,
    /// 606Eh, s.
    pub window_time_s: f64,
    /// 606Fh, counts/s.
    pub threshold: f64,
    /// 6070h, s.
    pub threshold_time_s: f64,
}

/// The pv state of one axis.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct ProfileVelocity {
    /// Generator velocity (606Bh), counts/s.
    vel: f64,
    /// Time |606Ch − 60FFh| has stayed within 606Dh.
    in_window: Held,
    /// Time |606Ch| has stayed above 606Fh.
    over_threshold: Held,
    reached: bool,
    moving: bool,
}

/// Distance (counts/s) within which the ramp lands on its end: float error.
const RAMP_LANDING: f64 = 1e-6;

impl ProfileVelocity {
    /// Restarts with the generator at `velocity` (counts/s): servo on or entering pv.
    pub(crate) fn reset(&mut self, velocity: f64) {
        *self = ProfileVelocity {
            vel: velocity,
            ..ProfileVelocity::default()
        };
    }

    /// The generator velocity (606Bh), counts/s.
    pub(crate) fn velocity(&self) -> f64 {
        self.vel
    }

    /// Statusword bits 10 and 12.
    pub(crate) fn status_bits(&self) -> u16 {
        (if self.reached { TARGET_REACHED } else { 0 }) | (if self.moving { 0 } else { SPEED_ZERO })
    }

    /// One cycle of `dt` s: ramps the generator and updates bits 10/12 from the motor's
    /// `actual` velocity (counts/s). Returns the generator velocity.
    pub(crate) fn step(&mut self, cmd: &PvCommand, actual: f64, dt: f64) -> f64 {
        if dt > 0.0 && dt.is_finite() {
            let mut g = Generator {
                position: 0.0,
                velocity: self.vel,
            };
            Self::advance(&mut g, cmd, NoTorque::default(), dt);
            self.vel = g.velocity;
        }
        self.update_bits(cmd, actual, dt.max(0.0));
        self.vel
    }

    /// One step of `dt` s of the generator `g` toward 60FFh (0 under HALT): 6083h while the
    /// speed grows in the same direction (unless `no_torque` that way), 6084h (or the halt
    /// rate) while it falls, through zero by [`PvModel::reversal`].
    pub(crate) fn advance(g: &mut Generator, cmd: &PvCommand, no_torque: NoTorque, dt: f64) {
        let (goal, deceleration) = if cmd.halt {
            (0.0, cmd.halt_deceleration)
        } else {
            (cmd.limited_target, cmd.deceleration)
        };
        let ramp = VelocityRamp {
            acceleration: cmd.acceleration,
            deceleration,
            reversal: cmd.model.reversal,
            landing: cmd.model.landing.units(),
        };
        g.run_at(goal, &ramp, no_torque, dt);
    }

    /// Bit 10 by [`PvReachedRule::JudgedNow`]: |`actual` − 60FFh (0 under HALT)| ≤ 606Dh.
    pub(crate) fn reached_now(cmd: &PvCommand, actual: f64) -> bool {
        let want = if cmd.halt { 0.0 } else { cmd.target };
        (actual - want).abs() <= cmd.window
    }

    /// Bits 10/12 by [`PvReachedRule::Timed`] after a step of `dt` s.
    fn update_bits(&mut self, cmd: &PvCommand, actual: f64, dt: f64) {
        if cmd.model.target_reached != PvReachedRule::Timed {
            return;
        }
        self.over_threshold
            .update(actual.abs() > cmd.threshold, dt, HeldFrom::WholeCycle);
        self.moving = self
            .over_threshold
            .exceeds(cmd.threshold_time_s, cmd.model.threshold_time);
        if cmd.halt {
            // "HALT = 1: 1 = velocity 0" (606Ch, rounded counts/s).
            self.in_window.clear();
            self.reached = self.vel == 0.0 && actual.abs() < 0.5;
            return;
        }
        self.in_window.update(
            (actual - cmd.target).abs() <= cmd.window,
            dt,
            HeldFrom::WholeCycle,
        );
        self.reached = self.in_window.at_least(cmd.window_time_s);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 3000 counts/s per ms of ramp: 6083h = 100 ms and 6084h = 50 ms to 300 000 counts/s.
    fn cmd(target: f64) -> PvCommand {
        PvCommand {
            model: PvModel::ETHERCAT,
            halt: false,
            target,
            limited_target: target,
            acceleration: Some(300_000.0 * 1000.0 / 100.0),
            deceleration: Some(300_000.0 * 1000.0 / 50.0),
            halt_deceleration: Some(300_000.0 * 1000.0 / 50.0),
            window: 1_000.0,
            window_time_s: 0.0,
            threshold: 2_000.0,
            threshold_time_s: 0.010,
        }
    }

    /// Cycles (1 ms) until the generator equals `goal`, the motor ideal (actual = generator).
    fn cycles_to(pv: &mut ProfileVelocity, c: &PvCommand, goal: f64) -> u32 {
        for k in 1..=10_000 {
            let v = pv.vel;
            pv.step(c, v, 1e-3);
            if pv.vel == goal {
                return k;
            }
        }
        panic!("never reached {goal}: {}", pv.vel);
    }

    #[test]
    fn ramps_take_the_time_constant_share_of_the_rated_speed() {
        let mut pv = ProfileVelocity::default();
        // 150 000 counts/s is half the rated speed: half of 6083h = 100 ms → 50 cycles.
        assert_eq!(cycles_to(&mut pv, &cmd(150_000.0), 150_000.0), 50);
        // Down to 0 at half of 6084h = 50 ms → 25 cycles.
        assert_eq!(cycles_to(&mut pv, &cmd(0.0), 0.0), 25);
        // A reversal: 25 cycles down at 6084h, then 50 up at 6083h (the zero-crossing cycle
        // stops at 0).
        pv.reset(150_000.0);
        assert_eq!(cycles_to(&mut pv, &cmd(-150_000.0), -150_000.0), 75);
    }

    #[test]
    fn bit_12_needs_the_threshold_time_and_halt_ramps_to_zero() {
        let mut pv = ProfileVelocity::default();
        let c = cmd(150_000.0);
        let mut first_moving = None;
        for k in 1..=60 {
            let v = pv.vel;
            pv.step(&c, v, 1e-3);
            if pv.status_bits() & SPEED_ZERO == 0 && first_moving.is_none() {
                first_moving = Some(k);
            }
        }
        // The generator passes 2000 counts/s in cycle 1 (3000 counts/s); the motor reported
        // at the start of cycle k is the generator of cycle k − 1: over the threshold from
        // cycle 2, bit 12 = 0 once 10 ms have elapsed there, in cycle 11.
        assert_eq!(first_moving, Some(11));
        assert_ne!(pv.status_bits() & TARGET_REACHED, 0);
        let h = PvCommand { halt: true, ..c };
        let mut k = 0;
        while pv.vel != 0.0 {
            let v = pv.vel;
            pv.step(&h, v, 1e-3);
            assert_eq!(pv.status_bits() & TARGET_REACHED, 0, "decelerating");
            k += 1;
        }
        assert_eq!(k, 25, "halt at 6084h");
        pv.step(&h, 0.0, 1e-3);
        assert_eq!(pv.status_bits(), TARGET_REACHED | SPEED_ZERO);
    }

    /// `c` under `model`.
    fn on(model: PvModel, c: PvCommand) -> PvCommand {
        PvCommand { model, ..c }
    }

    const MODELS: [PvModel; 2] = [PvModel::ETHERCAT, PvModel::MR_JE_C];

    #[test]
    fn a_reversal_stops_at_zero_on_ethercat_and_runs_through_on_the_mr_je_c() {
        let mut n = [0; 2];
        for (k, model) in MODELS.into_iter().enumerate() {
            let mut pv = ProfileVelocity::default();
            pv.reset(151_000.0);
            n[k] = cycles_to(&mut pv, &on(model, cmd(-150_000.0)), -150_000.0);
        }
        // 26 cycles down at 6000 per ms; the EtherCAT drives stop at 0 in the 26th, then
        // take 50 up at 3000 per ms; the MR-JE-C's 26th ends at −5000, 145000 more take 49.
        assert_eq!(n, [76, 75]);
        assert_eq!(PvModel::ETHERCAT.reversal, Reversal::StopAtZero);
        assert_eq!(PvModel::MR_JE_C.reversal, Reversal::Through);
    }

    #[test]
    fn the_ramp_lands_within_float_error_on_ethercat_and_exactly_on_the_mr_je_c() {
        for model in MODELS {
            let mut pv = ProfileVelocity::default();
            // 5e-7 more than one step of 3000 below the goal.
            pv.reset(150_000.0 - 3_000.0 - 5e-7);
            pv.step(&on(model, cmd(150_000.0)), 0.0, 1e-3);
            match model.landing {
                Landing::WithinFloatError => assert_eq!(pv.vel, 150_000.0),
                Landing::Exact => assert!(pv.vel < 150_000.0, "{}", pv.vel),
            }
        }
    }

    #[test]
    fn no_torque_holds_the_speed_that_way() {
        let c = on(PvModel::MR_JE_C, cmd(150_000.0));
        let mut g = Generator::default();
        let forward = NoTorque {
            forward: true,
            reverse: false,
        };
        ProfileVelocity::advance(&mut g, &c, forward, 1e-3);
        assert_eq!(g.velocity, 0.0, "60E0h = 0");
        ProfileVelocity::advance(&mut g, &c, NoTorque::default(), 1e-3);
        assert_eq!(g.velocity, 3_000.0);
    }

    /// The MR-JE-C manual's 606Dh–6070h defaults (§7.3): 2000 and 5000 (0.01 r/min, here one
    /// count/s each), 10 ms and 10 ms.
    #[test]
    fn bit_10_is_timed_here_on_ethercat_and_judged_now_on_the_mr_je_c() {
        let c = PvCommand {
            window: 2_000.0,
            window_time_s: 0.010,
            threshold: 5_000.0,
            threshold_time_s: 0.010,
            ..cmd(150_000.0)
        };
        // EtherCAT: 606Eh timed over whole cycles.
        let mut pv = ProfileVelocity::default();
        pv.reset(150_000.0);
        let mut k = 0;
        while pv.status_bits() & TARGET_REACHED == 0 {
            pv.step(&c, 150_000.0, 1e-3);
            k += 1;
        }
        assert_eq!(k, 10);
        // HALT: the generator at 0, however close the motor is.
        let halted = PvCommand {
            halt: true,
            halt_deceleration: Some(1_000_000.0),
            ..c
        };
        pv.reset(1_500.0);
        pv.step(&halted, 1_500.0, 1e-3);
        assert_eq!(pv.status_bits() & TARGET_REACHED, 0, "500 left");
        // The MR-JE-C: |606Ch − 60FFh| ≤ 606Dh now, 60FFh read as 0 under HALT.
        let m = on(PvModel::MR_JE_C, c);
        assert!(ProfileVelocity::reached_now(&m, 148_000.0));
        assert!(!ProfileVelocity::reached_now(&m, 147_999.0));
        let mh = on(PvModel::MR_JE_C, halted);
        assert!(ProfileVelocity::reached_now(&mh, 1_500.0));
        assert!(ProfileVelocity::reached_now(&mh, -2_000.0));
        assert!(!ProfileVelocity::reached_now(&mh, 2_001.0));
    }

    #[test]
    fn threshold_time_is_at_least_on_ethercat_and_longer_than_on_the_mr_je_c() {
        let mut held = Held::default();
        held.update(true, 0.0, HeldFrom::Seen);
        held.update(true, 0.010, HeldFrom::Seen);
        // Over 606Fh for exactly 6070h = 10 ms.
        assert!(held.exceeds(0.010, PvModel::ETHERCAT.threshold_time));
        assert!(!held.exceeds(0.010, PvModel::MR_JE_C.threshold_time));
    }
}
