//! A profile axis (pp/pv/tq) on the RT thread: its drive-side motion turned into the drive's
//! objects and controlword bits, and followed by the statusword (MR-J4-TM manual §5.4.6–§5.4.8;
//! the bits as CiA 402 on MR-JET / MR-J5 [background]).
//!
//! * pp: 607Ah, 6081h, 6083h/6084h; controlword bit 4 (new set-point) rises and is held until
//!   the drive acknowledges with statusword bit 12, bit 5 for a single set-point; the move is
//!   done once bit 10 (target reached) is 1 and bit 12 (Mitsubishi: positioning running) 0.
//! * pv: 60FFh with 6083h/6084h; done once bit 10 (velocity reached) is 1.
//! * tq: 6071h with 6087h; the drive reports no target reached in tq (MR-J4-TM manual §5.4.8),
//!   so the ramp is done after its own duration, |Δ6071h| / 6087h.
//! * HALT (bit 8) stops per the drive's 605Dh and is done at bit 10 (pp/pv: velocity 0) or
//!   after the ramp to 0 (tq). A controlled stop of the cell is a HALT that also drops the
//!   motion: the next motion's set-point (or the release of HALT) starts from where it stopped.
//!
//! Profile objects the RxPDO lacks go by SDO before the motion starts (`ProfileObjects`), one
//! at a time, each only when its value changed. Plain copies only: allocation-free.

use cellrt_axes::cia402::controlword::Controlword;
use cellrt_axes::cia402::statusword::Statusword;
use cellrt_axes::drive_scaling::DriveScaling;
use cellrt_axes::pdo::objects::{
    PROFILE_ACCELERATION, PROFILE_DECELERATION, PROFILE_VELOCITY, TORQUE_SLOPE,
};
use cellrt_axes::pdo::RxPdo;
use cellrt_axes::sim::profile_position::{
    CHANGE_SET_IMMEDIATELY, NEW_SET_POINT, SET_POINT_ACKNOWLEDGE, TARGET_REACHED,
};

use crate::config::{ProfileMode, ProfileObjects};
use crate::handoff::ProfileMotion;

/// Cycles after a change of the command in which the statusword still answers the old one
/// (the exchange's round trip, one cycle on the in-process bus, up to two on EtherCAT).
const SETTLE_CYCLES: u32 = 2;

/// Why a profile motion was not started.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProfileRefusal {
    /// The command does not fit the axis' mode (e.g. a jog on a pp axis).
    WrongMode,
    /// A value is outside the drive object's range in the drive's unit.
    OutOfRange,
}

/// The drive objects of the profile axis, in the drive's units, as sent.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Objects {
    /// 607Ah, raw counts.
    target_position: i32,
    /// 60FFh.
    target_velocity: i32,
    /// 6071h, 0.1 %.
    target_torque: i16,
    /// 6081h, 6083h, 6084h, 6087h as `[velocity, acceleration, deceleration, slope]`.
    profile: [u32; 4],
}

/// The indexes of `Objects::profile`.
const PROFILE_INDEXES: [u16; 4] = [
    PROFILE_VELOCITY,
    PROFILE_ACCELERATION,
    PROFILE_DECELERATION,
    TORQUE_SLOPE,
];

/// Where the axis' motion is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    /// No motion (held).
    Idle,
    /// Writing the profile objects the RxPDO lacks, by SDO.
    WritingObjects,
    /// pp: bit 4 is up, waiting for bit 12.
    SetPoint,
    /// Running; done by the mode's rule, `settle` cycles after the change at the earliest.
    Running,
}

/// How a profile motion ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProfileEnd {
    /// Done by the mode's rule.
    Done,
    /// A drive object write was refused.
    Refused,
}

/// RT state of one profile axis.
#[derive(Debug, Clone, Copy)]
pub struct ProfileChannel {
    objects: ProfileObjects,
    /// `motor.rated_speed`, counts/s (the time constants' reference).
    rated_speed: Option<f64>,
    out: Objects,
    /// The objects of a starting motion, sent once its SDO objects are written (the drive must
    /// not see a new target with the old ramps).
    next: Objects,
    /// The profile objects' values the drive holds from an SDO write.
    written: [Option<u32>; 4],
    phase: Phase,
    /// Cycles left before the statusword answers the current command.
    settle: u32,
    /// Running was entered in this cycle: its time counts from the next one.
    fresh: bool,
    /// tq: cycles left of the torque ramp.
    ramp_left: u32,
    /// Controlword bit 5 for the current set-point.
    immediate: bool,
    /// Controlword bit 8.
    halt: bool,
    /// A stop dropped the motion: pp releases HALT with a set-point where the axis stands.
    dropped: bool,
}

impl ProfileChannel {
    /// A channel at rest holding `position` (raw counts).
    pub fn new(objects: ProfileObjects, rated_speed: Option<f64>, position: i32) -> Self {
        ProfileChannel {
            objects,
            rated_speed,
            out: Objects {
                target_position: position,
                ..Objects::default()
            },
            next: Objects::default(),
            written: [None; 4],
            phase: Phase::Idle,
            settle: 0,
            fresh: false,
            ramp_left: 0,
            immediate: false,
            halt: false,
            dropped: false,
        }
    }

    /// The axis' profile mode.
    pub fn mode(&self) -> ProfileMode {
        self.objects.mode
    }

    /// Whether a motion (or a halt) is in progress.
    pub fn busy(&self) -> bool {
        self.phase != Phase::Idle
    }

    /// At rest for a stop: no change in progress (a halt is over: bit 10, or the tq ramp to 0).
    pub fn at_rest(&self) -> bool {
        self.phase == Phase::Idle
    }

    /// While no change is in progress, 607Ah follows the axis (`raw` counts): no bit 4 edge is
    /// sent then, and a later set-point starts from a current value.
    pub fn follow(&mut self, raw: i32) {
        if self.phase == Phase::Idle {
            self.out.target_position = raw;
        }
    }

    /// Starts `motion`: its values in the drive's units. `position` is where the axis stands
    /// (raw counts), `period_s` the cycle.
    pub fn start(
        &mut self,
        motion: ProfileMotion,
        units: &DriveScaling,
        position: i32,
        period_s: f64,
    ) -> Result<(), ProfileRefusal> {
        let release = self.halt;
        self.next = self.out;
        match (motion, self.objects.mode) {
            (
                ProfileMotion::Move {
                    target,
                    velocity,
                    acceleration,
                    deceleration,
                    immediate,
                },
                ProfileMode::Position,
            ) => {
                let v = units
                    .velocity_to_drive(velocity.abs())
                    .map_err(|_| ProfileRefusal::OutOfRange)?;
                self.next.profile[0] = v.unsigned_abs();
                self.next.profile[1] = self.time_constant(acceleration)?;
                self.next.profile[2] = self.time_constant(deceleration)?;
                self.next.target_position = target;
                // A set-point after a stop or halt replaces the old move at once.
                self.immediate = immediate || release || self.dropped;
            }
            (
                ProfileMotion::Jog {
                    velocity,
                    acceleration,
                    deceleration,
                },
                ProfileMode::Velocity,
            ) => {
                self.next.target_velocity = units
                    .velocity_to_drive(velocity)
                    .map_err(|_| ProfileRefusal::OutOfRange)?;
                self.next.profile[1] = self.time_constant(acceleration)?;
                self.next.profile[2] = self.time_constant(deceleration)?;
            }
            (ProfileMotion::Torque { torque, slope }, ProfileMode::Torque) => {
                let t = units
                    .torque_to_drive(torque)
                    .map_err(|_| ProfileRefusal::OutOfRange)?;
                let s = slope * 10.0;
                if !(s.is_finite() && s > 0.0 && s <= f64::from(u32::MAX)) {
                    return Err(ProfileRefusal::OutOfRange);
                }
                self.next.profile[3] = s.round() as u32;
                let from = if self.halt { 0 } else { self.out.target_torque };
                self.ramp_left = ramp_cycles(from, t, s, period_s);
                self.next.target_torque = t;
            }
            (ProfileMotion::Halt(on), _) => {
                self.set_halt(on, position, period_s);
                return Ok(());
            }
            _ => return Err(ProfileRefusal::WrongMode),
        }
        self.dropped = false;
        self.phase = if self.next_sdo_object().is_some() {
            Phase::WritingObjects
        } else {
            self.after_objects()
        };
        Ok(())
    }

    /// HALT on or off (605Dh): pp/pv done at bit 10, tq after the torque ramp (to 0 or back).
    fn set_halt(&mut self, on: bool, position: i32, period_s: f64) {
        let mode = self.objects.mode;
        self.halt = on;
        if mode == ProfileMode::Torque {
            let (from, to) = if on {
                (self.out.target_torque, 0)
            } else {
                (0, self.out.target_torque)
            };
            self.ramp_left = ramp_cycles(from, to, f64::from(self.out.profile[3]), period_s);
        }
        if !on && self.dropped && mode == ProfileMode::Position {
            // The dropped move must not resume: a set-point where the axis stands.
            self.out.target_position = position;
            self.immediate = true;
            self.dropped = false;
            self.phase = Phase::SetPoint;
            return;
        }
        self.dropped = false;
        self.begin_running();
    }

    /// Whether the drive is moving the axis by a command of this channel: a change in progress,
    /// a pv velocity or a tq torque held.
    pub fn moving(&self) -> bool {
        self.phase != Phase::Idle
            || match self.objects.mode {
                ProfileMode::Position => false,
                ProfileMode::Velocity => self.out.target_velocity != 0 && !self.halt,
                ProfileMode::Torque => self.out.target_torque != 0 && !self.halt,
            }
    }

    /// A controlled stop: HALT (605Dh) where the axis moves, the motion dropped (pv: 60FFh 0,
    /// tq: 6071h 0 once released). At rest once [`ProfileChannel::at_rest`].
    pub fn stop(&mut self, period_s: f64) {
        if !self.moving() {
            return;
        }
        let position = self.out.target_position;
        self.set_halt(true, position, period_s);
        self.dropped = true;
        match self.objects.mode {
            ProfileMode::Position => {}
            ProfileMode::Velocity => self.out.target_velocity = 0,
            ProfileMode::Torque => self.out.target_torque = 0,
        }
    }

    /// The drive left Operation enabled: the motion is gone (the drive restarts its profile
    /// at servo on), nothing is held.
    pub fn cancel(&mut self) {
        self.phase = Phase::Idle;
        self.halt = false;
        self.immediate = false;
        self.dropped = false;
        self.out.target_velocity = 0;
        self.out.target_torque = 0;
    }

    fn begin_running(&mut self) {
        self.phase = Phase::Running;
        self.settle = SETTLE_CYCLES;
        self.fresh = true;
    }

    /// The phase after the objects are in place (the staged ones are sent from now on): pp
    /// raises the set-point, the others run.
    fn after_objects(&mut self) -> Phase {
        self.out = self.next;
        self.halt = false;
        if self.objects.mode == ProfileMode::Position {
            Phase::SetPoint
        } else {
            self.settle = SETTLE_CYCLES;
            self.fresh = true;
            Phase::Running
        }
    }

    /// ms time constant from 0 to the rated speed of an `acceleration` in counts/s².
    fn time_constant(&self, acceleration: f64) -> Result<u32, ProfileRefusal> {
        let rated = self.rated_speed.ok_or(ProfileRefusal::OutOfRange)?;
        let ms = (rated / acceleration * 1000.0).round();
        if !(acceleration > 0.0 && ms.is_finite() && ms >= 1.0 && ms <= f64::from(u32::MAX)) {
            return Err(ProfileRefusal::OutOfRange);
        }
        Ok(ms as u32)
    }

    /// The next profile object to write by SDO while writing objects: (index, value).
    pub fn next_sdo_object(&self) -> Option<(u16, u32)> {
        let mode = self.objects.mode;
        PROFILE_INDEXES
            .iter()
            .enumerate()
            .filter(|(_, index)| mode.profile_objects().contains(index))
            .filter(|(_, index)| !self.objects.is_cyclic(**index))
            .find(|(k, _)| self.written[*k] != Some(self.next.profile[*k]))
            .map(|(k, index)| (*index, self.next.profile[k]))
    }

    /// Whether the channel waits for its profile objects to be written.
    pub fn writing_objects(&self) -> bool {
        self.phase == Phase::WritingObjects
    }

    /// The SDO write of `index` ended (`taken`: downloaded). A refusal ends the motion.
    pub fn object_written(&mut self, index: u16, taken: bool) -> Option<ProfileEnd> {
        let k = PROFILE_INDEXES.iter().position(|i| *i == index)?;
        if !taken {
            self.written[k] = None;
            self.phase = Phase::Idle;
            return Some(ProfileEnd::Refused);
        }
        self.written[k] = Some(self.next.profile[k]);
        if self.phase == Phase::WritingObjects && self.next_sdo_object().is_none() {
            self.phase = self.after_objects();
        }
        None
    }

    /// One cycle, `elapsed` cycle periods after the previous one: the statusword `sw` answers
    /// the previous cycle's command; writes this cycle's objects and controlword bits into
    /// `rx`. Returns how the motion ended, in its last cycle.
    pub fn cycle(&mut self, sw: Statusword, rx: &mut RxPdo, elapsed: u32) -> Option<ProfileEnd> {
        let end = self.advance(sw, elapsed);
        let o = &self.out;
        rx.target_position = o.target_position;
        rx.target_velocity = o.target_velocity;
        rx.target_torque = o.target_torque;
        rx.profile_velocity = o.profile[0];
        rx.profile_acceleration = o.profile[1];
        rx.profile_deceleration = o.profile[2];
        rx.torque_slope = o.profile[3];
        let mut cw =
            rx.controlword.with_halt(self.halt).0 & !(NEW_SET_POINT | CHANGE_SET_IMMEDIATELY);
        if self.phase == Phase::SetPoint {
            cw |= NEW_SET_POINT;
        }
        if self.immediate {
            cw |= CHANGE_SET_IMMEDIATELY;
        }
        rx.controlword = Controlword(cw);
        end
    }

    fn advance(&mut self, sw: Statusword, elapsed: u32) -> Option<ProfileEnd> {
        let bits = sw.0;
        match self.phase {
            Phase::Idle | Phase::WritingObjects => None,
            Phase::SetPoint => {
                if bits & SET_POINT_ACKNOWLEDGE != 0 {
                    self.begin_running();
                }
                None
            }
            Phase::Running => {
                if self.fresh {
                    self.fresh = false;
                    return None;
                }
                if self.settle > 0 {
                    self.settle = self.settle.saturating_sub(elapsed);
                    self.ramp_left = self.ramp_left.saturating_sub(elapsed);
                    return None;
                }
                let done = match self.objects.mode {
                    ProfileMode::Position if !self.halt => {
                        bits & TARGET_REACHED != 0 && bits & SET_POINT_ACKNOWLEDGE == 0
                    }
                    ProfileMode::Position | ProfileMode::Velocity => bits & TARGET_REACHED != 0,
                    ProfileMode::Torque => {
                        self.ramp_left = self.ramp_left.saturating_sub(elapsed);
                        self.ramp_left == 0
                    }
                };
                if done {
                    self.phase = Phase::Idle;
                    self.immediate = false;
                    return Some(ProfileEnd::Done);
                }
                None
            }
        }
    }
}

/// Cycles of a torque ramp from `from` to `to` (0.1 %) at `slope` (0.1 %/s).
fn ramp_cycles(from: i16, to: i16, slope: f64, period_s: f64) -> u32 {
    if slope <= 0.0 || period_s <= 0.0 {
        return 0;
    }
    let s = (f64::from(to) - f64::from(from)).abs() / slope / period_s;
    s.ceil().min(f64::from(u32::MAX)) as u32
}
