//! Profile position mode (pp, 6060h = 1) of every emulated drive: the set-point handshake and the
//! trajectory generator the drive runs itself. The simulated EtherCAT drives (MR-J4-TM manual
//! §5.4.6; MR-JET and MR-J5 state only that pp exists with 607Ah, 6081h, 6083h, 6084h:
//! MR-JET-G-N1 manual §7.4, §4.5, §6.3, MR-J5-G-N1 manual §4.5, and use the CiA 402 bit meanings
//! [background]) run [`PpModel::ETHERCAT`], described below; the MR-JE-C runs
//! [`PpModel::MR_JE_C`] (each option cites its section) on its own trapezoid, stepped per
//! S-pattern sample (`ProfilePosition::advance`).
//!
//! * Controlword bit 4 **new set-point** is taken on its rising edge only; bit 5 **change set
//!   immediately** = 1 replaces the move at once (single set-point, §4.7 "Behaviour"), = 0 queues
//!   it behind the current move (set of set-points, one buffered set-point; a newer one
//!   overwrites it: Mitsubishi's bit 12 wording "the set-point may be overwritten"). Bit 9
//!   *change on set-point* is not modelled: a queued move always starts from standstill at the
//!   previous target (bit 9 = 0 behaviour).
//! * Bit 6 **relative** adds 607Ah to the previous target (CiA 402 default [background]); with the
//!   degree position unit it raises the profile's `relative_degree_warning` (MR-J4-TM AL. F4.8)
//!   and the move does not start (§4.7 bit 6). The warning clears at the next accepted
//!   set-point, at servo on or when pp is left (the manual resets it by C_ORST, not modelled).
//! * Bit 8 **HALT** decelerates to standstill per 605Dh where the model gives or was written a
//!   value (CiA 402 codes), else per [`HaltOption`] (the values are in the MISSING §5.7,
//!   MR-J4-TM manual q2); releasing it resumes the move (CiA 402 [background]).
//! * 607Dh **software position limits** (min < max; 0/0 disables them, MR-J4-TM manual §5.4.6
//!   data path "607Ah → position limit function"): a set-point beyond one is clamped to it
//!   and statusword bit 11 (ILA) is 1 while the generator stands on that limit.
//! * 6081h is capped by 607Fh (velocity unit), 6080h (r/min) and the plant's maximum speed.
//! * Statusword bit 12 **set-point acknowledge** uses Mitsubishi's wording (§4.7): 1 while a
//!   positioning is being executed, 0 once it has completed. Bit 10 **target reached**: with
//!   HALT = 0, |6064h − target| has stayed within 6067h for at least 6068h (6067h =
//!   4294967295 disables the window: reached when the profile has ended, MR-JE-C manual 6067h);
//!   with HALT = 1, the axis velocity (606Ch) is 0.
//! * The profile is a linear (trapezoidal) ramp, 6086h = 0: 6083h/6084h are time constants in
//!   ms from 0 to [`PpParams::time_constant_speed`] (§4.7 "6083h … ms"); 0 ms means the plant's
//!   maximum acceleration. The S-pattern (6086h = −1, PT51) is not modelled.
//!
//! Positions are in the plant's counts (f64) on the EtherCAT drives, which convert 607Ah from
//! 6064h's reference ([`TargetFrame`]), in pos units on the MR-JE-C.
//! The trapezoid is the shared generator (`motion::generator`). Allocation-free: plain copies
//! only.

use super::generator::{Arrival, Braking, Generator, NoTorque, Positioning};
use super::ramp::VelocityRamp;
use super::window_time::{Held, HeldFrom};

pub use cellrt_cia402::controlword::{CHANGE_SET_IMMEDIATELY, HALT, NEW_SET_POINT};
pub use cellrt_cia402::statusword::{INTERNAL_LIMIT_ACTIVE, SET_POINT_ACKNOWLEDGE, TARGET_REACHED};
/// Controlword bit 6: relative (1) / absolute (0) target.
pub const RELATIVE: u16 = 1 << 6;

/// 6067h value that disables the position window (MR-JE-C manual, 6067h "4294967295").
pub const WINDOW_DISABLED: u32 = u32::MAX;

/// [Pr. PT01.2] position data unit, as far as the simulator acts on it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PositionUnit {
    /// Pulse (mm/inch behave alike here): relative pp allowed.
    #[default]
    Pulse,
    /// Degree: a relative pp set-point raises the profile's `relative_degree_warning` and does
    /// not start (MR-J4-TM manual §5.4.6). The 0…359999 modulo and the J5/JET degree mode table
    /// (pp/pv/tq/hm only) are not modelled.
    Degree,
}

/// The deceleration of a pp HALT: 605Dh, whose values the seed lacks (MR-J4-TM manual, §13 q2)
/// and MR-JET/MR-J5 do not name (MR-JET-G-N1 manual §7.4, §4.5, §6.3), so a named parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum HaltOption {
    /// 605Dh = 1 (CiA 402 default [background]): slow down with 6084h profile deceleration.
    #[default]
    ProfileDeceleration,
    /// Stop at the plant's maximum deceleration (605Dh = 3/4, current limit [background]).
    MaximumDeceleration,
}

/// Statusword bit 12 in pp.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Acknowledge {
    /// 1 while a positioning is being executed, 0 once it has completed (Mitsubishi's wording,
    /// MR-J4-TM manual §4.7 bit 12): the simulated EtherCAT drives.
    Executing,
    /// Follows controlword bit 4 (the CiA 402 handshake): the MR-JE-C, whose manual does not
    /// state the bit (spec extract mr-je-c.md §7.4 "[EXT: CiA 402; not stated in manual]").
    NewSetPointBit,
}

/// What a new set-point does while one is being executed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SetPointChange {
    /// Bit 5 = 1 replaces the move at once, = 0 queues one set-point behind it (MR-J4-TM
    /// manual §4.7 "Behaviour", bit 12 "the set-point may be overwritten").
    ByBit5,
    /// Every new set-point replaces the running one, bit 5 unread: the MR-JE-C (manual §7.3
    /// 60F2h bits 3/2 = 00 "immediately reflects new Target position"; a queue is not described).
    Immediate,
}

/// Controlword bit 6 (relative) in pp.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RelativeBit {
    /// Bit 6 = 1 adds 607Ah to the previous target (CiA 402 [background], MR-J4-TM §4.7).
    Read,
    /// Every 607Ah is absolute: the MR-JE-C emulator (manual §7.3 60F2h bits 1/0 give the
    /// relative option; not modelled, an emulator choice).
    Ignored,
}

/// 607Dh software position limits in pp.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PositionLimits {
    /// A set-point beyond a limit is clamped to it, bit 11 on there (MR-J4-TM manual §5.4.6).
    Clamp,
    /// Not applied: the MR-JE-C emulator (manual §7.6.5 describes 607Dh; not modelled).
    Ignored,
}

/// The reference 607Ah is given in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TargetFrame {
    /// 6064h's reference, moved into the generator's by [`PpFeedback::actual`] and
    /// [`PpFeedback::position`]: the simulated EtherCAT drives (plant counts, homing shift).
    ActualPosition,
    /// The generator's own units: the MR-JE-C, whose command and 6064h are both pos units
    /// (manual §7.6.7).
    Command,
}

/// Statusword bit 10 in pp.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TargetReachedRule {
    /// HALT = 0: the profile has ended and |motor − accepted set-point| has stayed within 6067h
    /// for 6068h (timed here); HALT = 1: generator and motor velocity 0, untimed (MR-J4-TM
    /// manual §4.7 bit 10): the simulated EtherCAT drives.
    SetPointWindow,
    /// The MR-JE-C (manual §7.3 6067h "droop pulses below 6067h for 6068h"): HALT = 0, the
    /// set-point has arrived and |6064h − 607Ah in force| ≤ 6067h; HALT = 1, nothing more; both
    /// need the command stood (S-pattern drained) and |droop| ≤ 6067h. The caller times 6068h.
    CommandAndDroop,
}

/// Where a model's pp differs from another's, chosen by each model: [`PpModel::ETHERCAT`]
/// (MR-J4-TM manual §5.4.6, §4.7) and [`PpModel::MR_JE_C`] (MR-JE-C manual §7.3, §7.6).
///
/// The rest is data the caller passes: step lengths (the MR-JE-C steps once per S-pattern
/// sample, its position loop between), the speed cap, the HALT deceleration and the torque gate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PpModel {
    /// Bit 12.
    pub acknowledge: Acknowledge,
    /// Bit 5.
    pub set_point_change: SetPointChange,
    /// Bit 6.
    pub relative: RelativeBit,
    /// 607Dh.
    pub position_limits: PositionLimits,
    /// The reference of 607Ah.
    pub target_frame: TargetFrame,
    /// The braking curve onto the target ([`Braking`]).
    pub braking: Braking,
    /// Bit 10.
    pub target_reached: TargetReachedRule,
}

impl PpModel {
    /// The simulated EtherCAT drives (MR-J4-TM manual §5.4.6, §4.7; MR-JET, MR-J5 as CiA 402).
    pub const ETHERCAT: PpModel = PpModel {
        acknowledge: Acknowledge::Executing,
        set_point_change: SetPointChange::ByBit5,
        relative: RelativeBit::Read,
        position_limits: PositionLimits::Clamp,
        target_frame: TargetFrame::ActualPosition,
        braking: Braking::AfterStep,
        target_reached: TargetReachedRule::SetPointWindow,
    };

    /// The emulated MR-JE-C (MR-JE-C manual §7.3 6067h/60F2h, §7.6.5, §7.6.7).
    pub const MR_JE_C: PpModel = PpModel {
        acknowledge: Acknowledge::NewSetPointBit,
        set_point_change: SetPointChange::Immediate,
        relative: RelativeBit::Ignored,
        position_limits: PositionLimits::Ignored,
        target_frame: TargetFrame::Command,
        braking: Braking::Continuous,
        target_reached: TargetReachedRule::CommandAndDroop,
    };
}

impl Default for PpModel {
    fn default() -> Self {
        PpModel::ETHERCAT
    }
}

/// pp parameters where the manual gives no value (each used only if the object is neither
/// mapped, written by SDO nor given a default by the profile).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PpParams {
    /// 6067h Position window, counts. Default 100: the MR-JE-C manual's 6067h default
    /// (seed 001), the only Mitsubishi figure in the seeds.
    pub position_window: u32,
    /// 6068h Position window time, ms. Default 10 (MR-JE-C manual 6068h).
    pub position_window_time_ms: u32,
    /// 6081h Profile velocity in the model's velocity unit, where the profile has no default
    /// (MR-JET, MR-J5). Default 10000 (100.00 r/min at 0.01 r/min), the MR-J4-TM default
    /// value (§4.7).
    pub profile_velocity: u32,
    /// The speed (counts/s) the 6083h/6084h/6085h time constants refer to ("rated speed" in
    /// the MR-JE-C wording); `None`: `PlantParams::max_velocity`, as for the PC02 slow stop.
    pub time_constant_speed: Option<f64>,
    /// 605Dh Halt option.
    pub halt: HaltOption,
    /// The pp behaviour of the model, default [`PpModel::ETHERCAT`].
    pub model: PpModel,
}

impl Default for PpParams {
    fn default() -> Self {
        PpParams {
            position_window: 100,
            position_window_time_ms: 10,
            profile_velocity: 10_000,
            time_constant_speed: None,
            halt: HaltOption::default(),
            model: PpModel::ETHERCAT,
        }
    }
}

/// One cycle's pp inputs, resolved by the drive from the RxPDO, SDO values, profile defaults and
/// [`PpParams`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PpCommand {
    /// The model's behaviour.
    pub model: PpModel,
    /// 6040h.
    pub controlword: u16,
    /// 607Ah as received.
    pub target: i32,
    /// Profile velocity (6081h after the model's caps), units/s, > 0.
    pub velocity: f64,
    /// From 6083h, units/s² (`None`: a step, the MR-JE-C's 0 ms).
    pub acceleration: Option<f64>,
    /// From 6084h, units/s² (`None`: a step).
    pub deceleration: Option<f64>,
    /// HALT deceleration, units/s² (605Dh on the EtherCAT drives, 6084h on the MR-JE-C).
    pub halt_deceleration: Option<f64>,
    /// 6067h, units.
    pub window: u32,
    /// 6068h, s.
    pub window_time_s: f64,
    /// The warning a relative set-point raises (degree unit on a model with the rule).
    pub relative_refused: Option<u16>,
    /// 607Dh:1/2 software position limits in 6064h's reference, where enabled.
    pub limits: Option<(i32, i32)>,
}

/// The drive's feedback for one pp cycle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PpFeedback {
    /// 6064h before the cycle.
    pub actual: i32,
    /// Motor position, the generator's units, before the cycle.
    pub position: f64,
    /// Motor velocity, units/s.
    pub velocity: f64,
    /// Command − motor position (read by [`TargetReachedRule::CommandAndDroop`]).
    pub droop: f64,
    /// The command has stood still, any filter drained ([`TargetReachedRule::CommandAndDroop`]).
    pub command_standing: bool,
}

/// The pp state of one axis.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct ProfilePosition {
    /// Generator position (the position demand) of [`ProfilePosition::step`], units.
    pos: f64,
    /// Generator velocity of [`ProfilePosition::step`], units/s.
    vel: f64,
    /// The set-point being processed, units.
    target: f64,
    /// The generator is being moved onto `target` (cleared when it arrives or is cancelled).
    running: bool,
    /// A queued set-point (bit 5 = 0 during a move).
    pending: Option<f64>,
    /// Positioning being executed ([`Acknowledge::Executing`]).
    executing: bool,
    /// Controlword bit 4 as last written ([`Acknowledge::NewSetPointBit`]).
    bit4: bool,
    /// Bit 10 ([`TargetReachedRule::SetPointWindow`]).
    reached: bool,
    /// Time |actual − target| has stayed within the window at the end of the profile.
    in_window: Held,
    /// Controlword of the previous cycle (edge detection of bit 4 in [`ProfilePosition::step`]).
    prev_cw: u16,
    /// Latched relative-in-degree warning.
    warning: Option<u16>,
    /// The set-point being processed was clamped to a 607Dh limit.
    limited: bool,
}

impl ProfilePosition {
    /// Restarts at rest at `position` (servo on, entering pp); `cw` is the controlword in
    /// force, so a bit 4 already set is not an edge (OMS bits are ignored until the mode switch
    /// has finished, §4.1).
    pub(crate) fn reset(&mut self, position: f64, cw: u16) {
        *self = ProfilePosition {
            pos: position,
            target: position,
            prev_cw: cw,
            ..ProfilePosition::default()
        };
    }

    /// Forgets the set-point (and a queued one): the generator then stops at 6084h (MR-JE-C
    /// servo off, homing start).
    pub(crate) fn cancel(&mut self) {
        self.running = false;
        self.pending = None;
        self.executing = false;
    }

    /// pp is left (MR-JE-C 6061h change): [`ProfilePosition::cancel`] and bit 12 off.
    pub(crate) fn leave(&mut self) {
        self.cancel();
        self.bit4 = false;
    }

    /// The latched warning, if any.
    pub(crate) fn warning(&self) -> Option<u16> {
        self.warning
    }

    /// Statusword bit 12 as `model` answers it.
    pub(crate) fn acknowledged(&self, model: &PpModel) -> bool {
        match model.acknowledge {
            Acknowledge::Executing => self.executing,
            Acknowledge::NewSetPointBit => self.bit4,
        }
    }

    /// Statusword bits 10, 11 and 12 as of the last [`ProfilePosition::step`].
    pub(crate) fn status_bits(&self, model: &PpModel) -> u16 {
        (if self.reached { TARGET_REACHED } else { 0 })
            | (if self.limited && self.pos == self.target {
                INTERNAL_LIMIT_ACTIVE
            } else {
                0
            })
            | (if self.acknowledged(model) {
                SET_POINT_ACKNOWLEDGE
            } else {
                0
            })
    }

    /// The generator velocity (units/s), for the velocity feed-forward.
    pub(crate) fn velocity(&self) -> f64 {
        self.vel
    }

    /// Whether the generator standing at `position` stays there this step.
    pub(crate) fn holds(&self, position: f64, halt: bool) -> bool {
        halt || !self.running || self.target == position
    }

    /// One cycle of `dt` s on the generator of this state: takes a new set-point on the bit 4
    /// edge, advances the profile and updates bits 10/12. Returns the position demand.
    pub(crate) fn step(&mut self, cmd: &PpCommand, fb: PpFeedback, dt: f64) -> f64 {
        let prev = std::mem::replace(&mut self.prev_cw, cmd.controlword);
        self.controlword(cmd, prev, fb);
        if dt > 0.0 && dt.is_finite() {
            let mut g = Generator {
                position: self.pos,
                velocity: self.vel,
            };
            self.advance(&mut g, cmd, NoTorque::default(), dt);
            self.pos = g.position;
            self.vel = g.velocity;
        }
        self.update_reached(cmd, fb, dt);
        self.pos
    }

    /// A controlword `cmd.controlword` after `prev`: a new set-point on the bit 4 edge.
    pub(crate) fn controlword(&mut self, cmd: &PpCommand, prev: u16, fb: PpFeedback) {
        let cw = cmd.controlword;
        self.bit4 = cw & NEW_SET_POINT != 0;
        if self.bit4 && prev & NEW_SET_POINT == 0 {
            self.new_set_point(cmd, fb);
        }
    }

    fn new_set_point(&mut self, cmd: &PpCommand, fb: PpFeedback) {
        let model = cmd.model;
        let relative = model.relative == RelativeBit::Read && cmd.controlword & RELATIVE != 0;
        if relative {
            if let Some(code) = cmd.relative_refused {
                self.warning = Some(code);
                return;
            }
        }
        self.warning = None;
        let target = match model.target_frame {
            // Relative to the previous target (the last queued one when a move is pending).
            _ if relative => self.pending.unwrap_or(self.target) + f64::from(cmd.target),
            // 607Ah in 6064h's reference, moved into the plant's (wrapping like the wire values).
            TargetFrame::ActualPosition => {
                fb.position + f64::from(cmd.target.wrapping_sub(fb.actual))
            }
            TargetFrame::Command => f64::from(cmd.target),
        };
        let (target, limited) = match (model.position_limits, cmd.limits) {
            (PositionLimits::Clamp, Some((min, max))) => {
                let lo = fb.position + f64::from(min.wrapping_sub(fb.actual));
                let hi = fb.position + f64::from(max.wrapping_sub(fb.actual));
                let clamped = target.clamp(lo, hi);
                (clamped, clamped != target)
            }
            _ => (target, false),
        };
        self.limited = limited;
        let at_once = match model.set_point_change {
            SetPointChange::ByBit5 => {
                cmd.controlword & CHANGE_SET_IMMEDIATELY != 0 || !self.executing
            }
            SetPointChange::Immediate => true,
        };
        if at_once {
            self.pending = None;
            self.start(target);
        } else {
            self.pending = Some(target);
        }
    }

    fn start(&mut self, target: f64) {
        self.target = target;
        self.running = true;
        self.executing = true;
        self.reached = false;
        self.in_window.clear();
    }

    /// One step of `dt` s of the generator `g` (the caller's trapezoid): HALT ramps it to 0 at
    /// the halt deceleration, a set-point positions it ([`PpModel::braking`], gated by
    /// `no_torque`), none stops it at 6084h. A queued set-point starts on arrival.
    pub(crate) fn advance(
        &mut self,
        g: &mut Generator,
        cmd: &PpCommand,
        no_torque: NoTorque,
        dt: f64,
    ) -> Arrival {
        let moving = Arrival {
            arrived: false,
            moving: dt,
        };
        let stop = |g: &mut Generator, rate: Option<f64>| {
            g.run_at(0.0, &VelocityRamp::new(rate, rate), no_torque, dt);
            moving
        };
        if cmd.controlword & HALT != 0 {
            return stop(g, cmd.halt_deceleration);
        }
        if !self.running {
            return stop(g, cmd.deceleration);
        }
        let positioning = Positioning {
            target: self.target,
            speed: cmd.velocity,
            ramp: VelocityRamp::new(cmd.acceleration, cmd.deceleration),
            braking: cmd.model.braking,
        };
        let step = g.position_to(&positioning, no_torque, dt);
        if step.arrived {
            self.running = false;
            if let Some(next) = self.pending.take() {
                self.start(next);
            }
        }
        step
    }

    /// Statusword bit 10 by the model's [`TargetReachedRule`]: as of the last
    /// [`ProfilePosition::step`], or judged now from `fb` (untimed).
    pub(crate) fn target_reached(&self, cmd: &PpCommand, fb: PpFeedback) -> bool {
        match cmd.model.target_reached {
            TargetReachedRule::SetPointWindow => self.reached,
            TargetReachedRule::CommandAndDroop => {
                let within =
                    |x: f64| cmd.window == WINDOW_DISABLED || x.abs() <= f64::from(cmd.window);
                let arrived = cmd.controlword & HALT != 0
                    || (!self.running
                        && self.pending.is_none()
                        && within(fb.position - f64::from(cmd.target)));
                arrived && fb.command_standing && within(fb.droop)
            }
        }
    }

    /// [`TargetReachedRule::SetPointWindow`] after a step of `dt` s.
    fn update_reached(&mut self, cmd: &PpCommand, fb: PpFeedback, dt: f64) {
        if cmd.model.target_reached != TargetReachedRule::SetPointWindow {
            return;
        }
        if cmd.controlword & HALT != 0 {
            // "HALT = 1: 1 = axis velocity is 0" (606Ch, rounded counts/s).
            self.reached = self.vel == 0.0 && fb.velocity.abs() < 0.5;
            self.in_window.clear();
            return;
        }
        let profile_done = self.pos == self.target && self.vel == 0.0 && self.pending.is_none();
        let in_window = if cmd.window == WINDOW_DISABLED {
            true
        } else {
            (fb.position.round() - self.target.round()).abs() <= f64::from(cmd.window)
        };
        self.in_window
            .update(profile_done && in_window, dt, HeldFrom::WholeCycle);
        let window_time_met =
            cmd.window == WINDOW_DISABLED || self.in_window.at_least(cmd.window_time_s);
        self.reached = profile_done && in_window && window_time_met;
        if self.reached {
            self.executing = false;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cmd(cw: u16, target: i32) -> PpCommand {
        PpCommand {
            model: PpModel::ETHERCAT,
            controlword: cw,
            target,
            velocity: 10_000.0,
            acceleration: Some(100_000.0),
            deceleration: Some(50_000.0),
            halt_deceleration: Some(50_000.0),
            window: 100,
            window_time_s: 0.01,
            relative_refused: None,
            limits: None,
        }
    }

    /// Runs the generator with an ideal plant (the motor is at the demand).
    fn run(pp: &mut ProfilePosition, c: &PpCommand, cycles: u32) -> (f64, f64) {
        let mut peak_v: f64 = 0.0;
        let mut peak_a: f64 = 0.0;
        let dt = 1e-3;
        for _ in 0..cycles {
            let v0 = pp.velocity();
            let fb = PpFeedback {
                actual: pp.pos.round() as i32,
                position: pp.pos,
                velocity: pp.vel,
                droop: 0.0,
                command_standing: pp.vel == 0.0,
            };
            pp.step(c, fb, dt);
            peak_v = peak_v.max(pp.velocity().abs());
            peak_a = peak_a.max((pp.velocity() - v0).abs() / dt);
        }
        (peak_v, peak_a)
    }

    #[test]
    fn trapezoid_respects_velocity_and_ramps_and_lands_exactly() {
        let mut pp = ProfilePosition::default();
        pp.reset(0.0, 0x0F);
        let c = cmd(0x3F, 20_000);
        let (v, a) = run(&mut pp, &c, 3_000);
        assert_eq!(pp.pos, 20_000.0);
        assert!(v <= 10_000.0 + 1e-9, "{v}");
        assert!(a <= 100_000.0 + 1e-6, "{a}");
        assert!(pp.reached && !pp.executing);
    }

    #[test]
    fn set_point_needs_an_edge_and_halt_stops() {
        let mut pp = ProfilePosition::default();
        pp.reset(0.0, 0x1F);
        run(&mut pp, &cmd(0x3F, 5_000), 50);
        assert_eq!(pp.pos, 0.0, "bit 4 held from before: no edge");
        run(&mut pp, &cmd(0x2F, 5_000), 1);
        run(&mut pp, &cmd(0x3F, 5_000), 100);
        assert!(pp.executing && pp.pos > 0.0);
        run(&mut pp, &cmd(0x13F, 5_000), 400);
        assert_eq!(pp.vel, 0.0);
        assert!(pp.reached, "halted at standstill: bit 10");
        assert!(pp.pos < 5_000.0);
        run(&mut pp, &cmd(0x3F, 5_000), 2_000);
        assert_eq!(pp.pos, 5_000.0, "halt released: the move resumes");
    }

    #[test]
    fn relative_refused_raises_the_warning_without_motion() {
        let mut pp = ProfilePosition::default();
        pp.reset(0.0, 0x0F);
        let c = PpCommand {
            relative_refused: Some(0x0F48),
            ..cmd(0x7F, 1_000)
        };
        run(&mut pp, &c, 100);
        assert_eq!(pp.warning(), Some(0x0F48));
        assert_eq!(pp.pos, 0.0);
        assert!(!pp.executing);
    }

    /// `cmd` under `model`.
    fn on(model: PpModel, c: PpCommand) -> PpCommand {
        PpCommand { model, ..c }
    }

    /// The ideal plant's feedback (the motor at the demand, no droop).
    fn ideal(pp: &ProfilePosition) -> PpFeedback {
        PpFeedback {
            actual: pp.pos.round() as i32,
            position: pp.pos,
            velocity: pp.vel,
            droop: 0.0,
            command_standing: pp.vel == 0.0,
        }
    }

    const MODELS: [PpModel; 2] = [PpModel::ETHERCAT, PpModel::MR_JE_C];

    #[test]
    fn bit_12_means_executing_on_ethercat_and_follows_bit_4_on_the_mr_je_c() {
        for model in MODELS {
            let mut pp = ProfilePosition::default();
            pp.reset(0.0, 0x0F);
            run(&mut pp, &on(model, cmd(0x1F, 5_000)), 1);
            assert!(pp.acknowledged(&model), "{model:?}: bit 4 on");
            run(&mut pp, &on(model, cmd(0x0F, 5_000)), 10);
            assert!(pp.pos > 0.0 && pp.pos < 5_000.0, "moving");
            let ack = pp.acknowledged(&model);
            match model.acknowledge {
                Acknowledge::Executing => assert!(ack, "bit 4 off, still executing"),
                Acknowledge::NewSetPointBit => assert!(!ack, "bit 4 off: bit 12 off"),
            }
        }
        assert_eq!(
            PpModel::ETHERCAT.acknowledge,
            Acknowledge::Executing,
            "MR-J4-TM manual §4.7"
        );
        assert_eq!(PpModel::MR_JE_C.acknowledge, Acknowledge::NewSetPointBit);
    }

    #[test]
    fn a_set_point_with_bit_5_off_queues_on_ethercat_and_replaces_on_the_mr_je_c() {
        for model in MODELS {
            let mut pp = ProfilePosition::default();
            pp.reset(0.0, 0x0F);
            run(&mut pp, &on(model, cmd(0x1F, 5_000)), 100);
            run(&mut pp, &on(model, cmd(0x0F, 5_000)), 1);
            // A second set-point, bit 5 = 0, back to −5000.
            run(&mut pp, &on(model, cmd(0x1F, -5_000)), 1);
            let mut peak: f64 = 0.0;
            for _ in 0..3_000 {
                run(&mut pp, &on(model, cmd(0x1F, -5_000)), 1);
                peak = peak.max(pp.pos);
            }
            assert_eq!(pp.pos, -5_000.0, "{model:?}");
            match model.set_point_change {
                SetPointChange::ByBit5 => assert_eq!(peak, 5_000.0, "queued behind 5000"),
                SetPointChange::Immediate => assert!(peak < 5_000.0, "replaced: {peak}"),
            }
        }
        assert_eq!(PpModel::MR_JE_C.set_point_change, SetPointChange::Immediate);
    }

    #[test]
    fn bit_6_and_607dh_act_on_ethercat_and_not_on_the_mr_je_c() {
        for model in MODELS {
            let limited = PpCommand {
                limits: Some((-500, 1_500)),
                ..on(model, cmd(0x5F, 1_000))
            };
            let mut pp = ProfilePosition::default();
            pp.reset(0.0, 0x0F);
            run(&mut pp, &on(model, cmd(0x1F, 1_000)), 1_000);
            run(&mut pp, &on(model, cmd(0x0F, 1_000)), 1);
            // Relative +1000 (bit 6), limits −500…1500.
            run(&mut pp, &limited, 1_000);
            let want = match (model.relative, model.position_limits) {
                (RelativeBit::Read, PositionLimits::Clamp) => 1_500.0,
                (RelativeBit::Ignored, PositionLimits::Ignored) => 1_000.0,
                other => panic!("{other:?}"),
            };
            assert_eq!(pp.pos, want, "{model:?}");
            let ila = pp.status_bits(&model) & INTERNAL_LIMIT_ACTIVE != 0;
            assert_eq!(ila, model.position_limits == PositionLimits::Clamp);
        }
    }

    #[test]
    fn target_is_moved_from_6064h_on_ethercat_and_taken_as_is_on_the_mr_je_c() {
        for model in MODELS {
            let mut pp = ProfilePosition::default();
            pp.reset(0.0, 0x0F);
            // 6064h reads 100 where the generator is at 0 (a homing shift).
            let fb = PpFeedback {
                actual: 100,
                ..ideal(&pp)
            };
            pp.controlword(&on(model, cmd(0x1F, 1_000)), 0x0F, fb);
            let want = match model.target_frame {
                TargetFrame::ActualPosition => 900.0,
                TargetFrame::Command => 1_000.0,
            };
            assert_eq!(pp.target, want, "{model:?}");
        }
    }

    #[test]
    fn braking_lands_on_the_target_after_the_step_or_continuously() {
        let mut cycles = [0; 2];
        for (k, model) in MODELS.into_iter().enumerate() {
            let mut pp = ProfilePosition::default();
            pp.reset(0.0, 0x0F);
            let c = on(model, cmd(0x1F, 20_000));
            while cycles[k] < 5_000 && !(cycles[k] > 0 && pp.pos == 20_000.0 && pp.vel == 0.0) {
                run(&mut pp, &c, 1);
                cycles[k] += 1;
            }
            assert_eq!(pp.pos, 20_000.0, "{model:?}");
        }
        // 10000 counts/s at 100000/s² and 50000/s²: 0.1 s up, 1.85 s at speed, 0.2 s down;
        // the continuous curve lands where a step reaches the target, the other after it.
        assert_eq!(cycles, [2_154, 2_136]);
        assert_eq!(PpModel::ETHERCAT.braking, Braking::AfterStep);
        assert_eq!(PpModel::MR_JE_C.braking, Braking::Continuous);
    }

    /// Cycles from the arrival of a move to 607Ah = 1000 until bit 10 (`c` after the edge).
    fn reached_after_arrival(pp: &mut ProfilePosition, c: &PpCommand) -> u32 {
        pp.reset(0.0, 0x0F);
        run(
            pp,
            &PpCommand {
                controlword: 0x1F,
                ..*c
            },
            1,
        );
        while pp.pos != 1_000.0 {
            run(pp, c, 1);
        }
        let mut k = 0;
        while !pp.target_reached(c, ideal(pp)) {
            run(pp, c, 1);
            k += 1;
        }
        k
    }

    /// The MR-JE-C manual's 6067h and 6068h defaults (§7.3): 100 pos units, 10 ms.
    #[test]
    fn target_reached_by_the_set_point_window_or_by_command_and_droop() {
        let c = cmd(0x0F, 1_000);
        assert_eq!((c.window, c.window_time_s), (100, 0.010));
        // EtherCAT: the accepted set-point, 6068h timed here over whole cycles (the arrival
        // cycle is the first of the 10 ms).
        let mut pp = ProfilePosition::default();
        assert_eq!(reached_after_arrival(&mut pp, &c), 9);
        run(&mut pp, &cmd(0x0F, 1_090), 1);
        assert!(
            pp.target_reached(&c, ideal(&pp)),
            "607Ah changed without an edge"
        );
        // The MR-JE-C: judged now, against the 607Ah in force and the droop.
        // (untimed: the drive times 6068h for pp, jg, pt and idx alike).
        let m = on(PpModel::MR_JE_C, c);
        let mut pp = ProfilePosition::default();
        assert_eq!(reached_after_arrival(&mut pp, &m), 0);
        let fb = ideal(&pp);
        let target = |t: i32| PpCommand { target: t, ..m };
        assert!(pp.target_reached(&target(1_100), fb), "|1000 − 1100| ≤ 100");
        assert!(!pp.target_reached(&target(1_101), fb));
        let droop = |d: f64| PpFeedback { droop: d, ..fb };
        assert!(pp.target_reached(&m, droop(100.0)) && !pp.target_reached(&m, droop(101.0)));
        let unfiltered = PpFeedback {
            command_standing: false,
            ..fb
        };
        assert!(!pp.target_reached(&m, unfiltered), "S-pattern not drained");
        // HALT: standing with the droop within 6067h, wherever the target is.
        let halted = PpCommand {
            controlword: 0x10F,
            ..target(5_000)
        };
        assert!(pp.target_reached(&halted, fb) && !pp.target_reached(&halted, droop(101.0)));
        let disabled = PpCommand {
            window: WINDOW_DISABLED,
            ..target(5_000)
        };
        assert!(
            pp.target_reached(&disabled, droop(1e6)),
            "6067h = 4294967295"
        );
    }

    #[test]
    fn cancel_stops_at_6084h_and_leave_drops_bit_12() {
        let m = on(PpModel::MR_JE_C, cmd(0x1F, 20_000));
        let mut pp = ProfilePosition::default();
        pp.reset(0.0, 0x0F);
        run(&mut pp, &m, 500);
        assert_eq!(pp.vel, 10_000.0);
        pp.cancel();
        assert!(pp.acknowledged(&m.model), "bit 4 still on");
        let stop = run(&mut pp, &m, 1).0;
        assert_eq!(stop, 10_000.0 - 50.0, "6084h: 50000/s² for 1 ms");
        run(&mut pp, &m, 300);
        assert_eq!(pp.vel, 0.0);
        assert!(pp.pos < 20_000.0);
        pp.leave();
        assert!(!pp.acknowledged(&m.model));
    }
}
