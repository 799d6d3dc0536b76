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

use cellrt_cia402::controlword::Controlword;
use cellrt_cia402::controlword::{CHANGE_SET_IMMEDIATELY, NEW_SET_POINT};
use cellrt_cia402::drive_scaling::DriveScaling;
use cellrt_cia402::pdo::objects::PROFILE_OBJECTS;
use cellrt_cia402::pdo::RxPdo;
use cellrt_cia402::statusword::Statusword;
use cellrt_cia402::statusword::{SET_POINT_ACKNOWLEDGE, TARGET_REACHED};

use crate::handoff::ProfileMotion;
use cellrt_config::{ProfileMode, ProfileObjects};

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
    /// The value of each profile object's latest SDO write, from the cycle it was posted (what
    /// the recording shows and `cellrt replay` writes again).
    posted: [u32; 4],
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
    /// pp: a set-point replaced one not yet acknowledged; bit 4 goes low for a cycle first,
    /// so the drive sees a new rising edge.
    rearm: bool,
    /// The feed override on the drive's velocity (MC_SetOverride), 0..=1.
    feed: f64,
    /// The velocity the move (6081h) or jog (60FFh) was commanded with, in the drive's unit,
    /// before the override; `None` without one.
    commanded_velocity: Option<i64>,
    /// 0 % override: the move or jog waits (pp: under HALT) without ending.
    feed_hold: bool,
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
            posted: [0; 4],
            phase: Phase::Idle,
            settle: 0,
            fresh: false,
            ramp_left: 0,
            immediate: false,
            halt: false,
            dropped: false,
            rearm: false,
            feed: 1.0,
            commanded_velocity: None,
            feed_hold: false,
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
        self.rearm = self.phase == Phase::SetPoint;
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
                self.commanded_velocity = Some(i64::from(v.unsigned_abs()));
                self.next.profile[0] = self.scaled_profile_velocity();
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
                let v = units
                    .velocity_to_drive(velocity)
                    .map_err(|_| ProfileRefusal::OutOfRange)?;
                self.commanded_velocity = Some(i64::from(v));
                self.next.target_velocity = self.scaled_target_velocity();
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
                self.commanded_velocity = None;
            }
            (ProfileMotion::Halt(on), _) => {
                self.set_halt(on, position, period_s);
                return Ok(());
            }
            _ => return Err(ProfileRefusal::WrongMode),
        }
        self.dropped = false;
        self.feed_hold = self.feed == 0.0 && self.commanded_velocity.is_some();
        if self.feed_hold {
            // Held at 0 % override: it starts when the override rises.
            self.phase = Phase::Running;
            return Ok(());
        }
        self.send_next();
        Ok(())
    }

    /// Sends the staged objects: by SDO first where the RxPDO lacks them.
    fn send_next(&mut self) {
        self.phase = if self.next_sdo_object().is_some() {
            Phase::WritingObjects
        } else {
            self.after_objects()
        };
    }

    /// 6081h for the commanded move at the current override (at least 1 above 0 %).
    fn scaled_profile_velocity(&self) -> u32 {
        let v = self.commanded_velocity.unwrap_or(0) as f64 * self.feed;
        (v.round() as u32).max(u32::from(self.feed > 0.0))
    }

    /// 60FFh for the commanded jog at the current override.
    fn scaled_target_velocity(&self) -> i32 {
        (self.commanded_velocity.unwrap_or(0) as f64 * self.feed).round() as i32
    }

    /// Sets the feed override (0..=1): a move in progress gets 6081h scaled as a new set-point
    /// to the same target at once (controlword bit 5); 0 % holds it under HALT without ending
    /// it, and a rise resumes it. A jog's 60FFh is scaled (0 %: the drive ramps to 0 and waits).
    /// tq has no velocity to scale.
    pub fn set_feed(&mut self, feed: f64) {
        if feed == self.feed {
            return;
        }
        self.feed = feed;
        if self.commanded_velocity.is_none() || self.dropped {
            return;
        }
        match self.objects.mode {
            ProfileMode::Position => {
                if self.phase == Phase::Idle {
                    return; // the move is over
                }
                if feed == 0.0 {
                    self.halt = true;
                    self.feed_hold = true;
                    return;
                }
                self.next.profile[0] = self.scaled_profile_velocity();
                if self.phase != Phase::WritingObjects {
                    self.rearm = self.phase == Phase::SetPoint;
                    self.immediate = true;
                    self.feed_hold = false;
                    self.send_next();
                }
            }
            ProfileMode::Velocity => {
                let v = self.scaled_target_velocity();
                self.next.target_velocity = v;
                if self.feed_hold {
                    self.feed_hold = false;
                    self.send_next();
                } else if self.phase != Phase::WritingObjects {
                    self.out.target_velocity = v;
                }
            }
            ProfileMode::Torque => {}
        }
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
        self.feed_hold = false;
        self.set_halt(true, position, period_s);
        self.dropped = true;
        match self.objects.mode {
            ProfileMode::Position => {}
            ProfileMode::Velocity => self.out.target_velocity = 0,
            ProfileMode::Torque => self.out.target_torque = 0,
        }
    }

    /// The drive is not in Operation enabled: what it holds from SDO writes is not relied on
    /// (a drive that reinitialises on leaving OP forgets them), so the next motion writes its
    /// objects again.
    pub fn forget_written(&mut self) {
        self.written = [None; 4];
    }

    /// The drive left Operation enabled: the motion is gone (the drive restarts its profile
    /// at servo on), nothing is held.
    pub fn cancel(&mut self) {
        self.phase = Phase::Idle;
        self.feed_hold = false;
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
        PROFILE_OBJECTS
            .iter()
            .enumerate()
            .filter(|(_, index)| mode.profile_objects().contains(index))
            .filter(|(_, index)| !self.objects.is_cyclic(**index))
            .find(|(k, _)| self.written[*k] != Some(self.next.profile[*k]))
            .map(|(k, index)| (*index, self.next.profile[k]))
    }

    /// The SDO write of `value` to `index` was posted.
    pub fn posted(&mut self, index: u16, value: u32) {
        if let Some(k) = PROFILE_OBJECTS.iter().position(|i| *i == index) {
            self.posted[k] = value;
        }
    }

    /// 6081h, 6083h, 6084h, 6087h as the drive has them: those in the RxPDO as sent this
    /// cycle, the others as last posted by SDO (0: never written).
    pub fn held(&self) -> [u32; 4] {
        std::array::from_fn(|k| {
            if self.objects.is_cyclic(PROFILE_OBJECTS[k]) {
                self.out.profile[k]
            } else {
                self.posted[k]
            }
        })
    }

    /// Whether the channel waits for its profile objects to be written.
    pub fn writing_objects(&self) -> bool {
        self.phase == Phase::WritingObjects
    }

    /// The SDO write of `index` ended (`taken`: downloaded). A refusal ends the motion.
    pub fn object_written(&mut self, index: u16, taken: bool) -> Option<ProfileEnd> {
        let k = PROFILE_OBJECTS.iter().position(|i| *i == index)?;
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
        if self.phase == Phase::SetPoint && !self.rearm {
            cw |= NEW_SET_POINT;
        }
        self.rearm = false;
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
                    // The drive took the set-point: its bits answer it from now on.
                    self.phase = Phase::Running;
                    self.settle = 0;
                }
                None
            }
            Phase::Running if self.feed_hold => None,
            Phase::Running => {
                if self.fresh {
                    self.fresh = false;
                    return None;
                }
                self.ramp_left = self.ramp_left.saturating_sub(elapsed);
                self.settle = self.settle.saturating_sub(elapsed);
                if self.settle > 0 {
                    return None;
                }
                let done = match self.objects.mode {
                    ProfileMode::Position if !self.halt => {
                        bits & TARGET_REACHED != 0 && bits & SET_POINT_ACKNOWLEDGE == 0
                    }
                    ProfileMode::Position | ProfileMode::Velocity => bits & TARGET_REACHED != 0,
                    ProfileMode::Torque => self.ramp_left == 0,
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

#[cfg(test)]
mod tests {
    use super::*;
    use cellrt_cia402::drive_scaling::Motor;
    use cellrt_cia402::profiles::{profile, DriveModel, MotorKind, VelocityUnit};

    /// An MR-J5-G-N1 axis (profile objects by SDO) at 10000 counts/rev, 0.01 r/min, rated
    /// 3000 r/min = 500000 counts/s.
    fn j5(mode: ProfileMode) -> (ProfileChannel, DriveScaling) {
        let p = profile(DriveModel::MrJ5GN1);
        let units = DriveScaling::new(
            &p.units,
            VelocityUnit::CENTI_RPM,
            Some(Motor {
                kind: MotorKind::Rotary,
                counts_per: 10_000.0,
            }),
        )
        .unwrap();
        let objects = ProfileObjects::of_profile(mode, p);
        (ProfileChannel::new(objects, Some(500_000.0), 0), units)
    }

    fn cycle(p: &mut ProfileChannel, sw: u16) -> RxPdo {
        let mut rx = RxPdo::default();
        p.cycle(Statusword(sw), &mut rx, 1);
        rx
    }

    #[test]
    fn pp_writes_its_objects_then_hands_over_the_set_point() {
        let (mut p, units) = j5(ProfileMode::Position);
        let mv = |target| ProfileMotion::Move {
            target,
            velocity: 50_000.0,        // 300 r/min = 30000 × 0.01 r/min
            acceleration: 1_000_000.0, // 500000 counts/s in 0.5 s: 500 ms
            deceleration: 250_000.0,   // 2000 ms
            immediate: true,
        };
        p.start(mv(30_000), &units, 0, 1e-3).unwrap();
        // 6081h, 6083h, 6084h by SDO first (not in the J5's 1600h), the target held back.
        let mut written = Vec::new();
        while let Some((index, value)) = p.next_sdo_object() {
            assert_eq!(cycle(&mut p, 0).controlword.0 & NEW_SET_POINT, 0);
            written.push((index, value));
            assert_eq!(p.object_written(index, true), None);
        }
        assert_eq!(written, [(0x6081, 30_000), (0x6083, 500), (0x6084, 2000)]);
        let rx = cycle(&mut p, 0);
        assert_eq!(rx.target_position, 30_000);
        assert_eq!(
            rx.controlword.0 & (NEW_SET_POINT | CHANGE_SET_IMMEDIATELY),
            0x30
        );
        // Bit 12 acknowledges: bit 4 drops; done at bit 10 with bit 12 = 0 after the settle.
        assert_eq!(
            cycle(&mut p, SET_POINT_ACKNOWLEDGE).controlword.0 & NEW_SET_POINT,
            0
        );
        let mut rx = RxPdo::default();
        let running = SET_POINT_ACKNOWLEDGE;
        assert_eq!(
            p.cycle(Statusword(running), &mut rx, 1),
            None,
            "positioning"
        );
        assert_eq!(
            p.cycle(Statusword(TARGET_REACHED), &mut rx, 1),
            Some(ProfileEnd::Done)
        );
        // The same profile again: nothing to write, the set-point goes out at once.
        p.start(mv(0), &units, 30_000, 1e-3).unwrap();
        assert_eq!(p.next_sdo_object(), None);
        assert_ne!(cycle(&mut p, 0).controlword.0 & NEW_SET_POINT, 0);
        // Replaced before the drive acknowledged it: bit 4 low for a cycle, then a new edge.
        p.start(mv(5_000), &units, 30_000, 1e-3).unwrap();
        let rx = cycle(&mut p, 0);
        assert_eq!(rx.controlword.0 & NEW_SET_POINT, 0);
        let rx = cycle(&mut p, 0);
        assert_ne!(rx.controlword.0 & NEW_SET_POINT, 0);
        assert_eq!(rx.target_position, 5_000);
    }

    /// Writes every pending SDO object as taken.
    fn write_objects(p: &mut ProfileChannel) -> Vec<(u16, u32)> {
        let mut written = Vec::new();
        while let Some((index, value)) = p.next_sdo_object() {
            written.push((index, value));
            p.object_written(index, true);
        }
        written
    }

    /// MC_SetOverride on a pp move in progress: 50 % rewrites 6081h (by SDO on the J5) and
    /// sends a new set-point to the same target at once; 0 % holds it under HALT and it does
    /// not end at standstill; the rise resumes it; it ends once, at its target.
    #[test]
    fn the_override_scales_a_pp_move_holds_it_at_zero_and_resumes_it() {
        let (mut p, units) = j5(ProfileMode::Position);
        let mv = ProfileMotion::Move {
            target: 30_000,
            velocity: 50_000.0,
            acceleration: 1_000_000.0,
            deceleration: 1_000_000.0,
            immediate: true,
        };
        p.start(mv, &units, 0, 1e-3).unwrap();
        assert_eq!(write_objects(&mut p)[0], (0x6081, 30_000));
        cycle(&mut p, 0);
        cycle(&mut p, SET_POINT_ACKNOWLEDGE);
        cycle(&mut p, 0);
        p.set_feed(0.5);
        assert_eq!(write_objects(&mut p), [(0x6081, 15_000)]);
        let rx = cycle(&mut p, 0);
        assert_eq!(rx.target_position, 30_000);
        assert_eq!(
            rx.controlword.0 & (NEW_SET_POINT | CHANGE_SET_IMMEDIATELY),
            NEW_SET_POINT | CHANGE_SET_IMMEDIATELY
        );
        cycle(&mut p, SET_POINT_ACKNOWLEDGE);
        // 0 %: HALT, and standstill (bit 10) does not end the move.
        p.set_feed(0.0);
        let mut rx = RxPdo::default();
        for _ in 0..5 {
            assert_eq!(p.cycle(Statusword(TARGET_REACHED), &mut rx, 1), None);
            assert_ne!(rx.controlword.0 & 0x100, 0, "HALT");
        }
        assert!(p.busy());
        // Back to 100 %: 6081h as commanded, HALT released, a new set-point.
        p.set_feed(1.0);
        assert_eq!(write_objects(&mut p), [(0x6081, 30_000)]);
        rx = cycle(&mut p, 0);
        assert_eq!(rx.controlword.0 & 0x100, 0, "HALT released");
        assert_ne!(rx.controlword.0 & NEW_SET_POINT, 0);
        cycle(&mut p, SET_POINT_ACKNOWLEDGE);
        let mut ends = 0;
        for _ in 0..4 {
            ends += usize::from(p.cycle(Statusword(TARGET_REACHED), &mut rx, 1).is_some());
        }
        assert_eq!(ends, 1);
        // Over: a later override change leaves the axis alone.
        p.set_feed(0.3);
        assert!(!p.writing_objects() && !p.busy());
    }

    /// A pv jog follows the override in 60FFh; a jog started at 0 % waits until it rises.
    #[test]
    fn the_override_scales_a_pv_jog_and_a_jog_at_zero_waits() {
        let (mut p, units) = j5(ProfileMode::Velocity);
        let jog = ProfileMotion::Jog {
            velocity: 50_000.0,
            acceleration: 1_000_000.0,
            deceleration: 1_000_000.0,
        };
        p.start(jog, &units, 0, 1e-3).unwrap();
        write_objects(&mut p);
        assert_eq!(cycle(&mut p, 0).target_velocity, 30_000);
        p.set_feed(0.25);
        assert_eq!(cycle(&mut p, 0).target_velocity, 7_500);
        p.set_feed(0.0);
        assert_eq!(cycle(&mut p, 0).target_velocity, 0);
        p.set_feed(1.0);
        assert_eq!(cycle(&mut p, 0).target_velocity, 30_000);

        let (mut p, units) = j5(ProfileMode::Velocity);
        p.set_feed(0.0);
        p.start(jog, &units, 0, 1e-3).unwrap();
        assert!(!p.writing_objects(), "nothing sent while held");
        let mut rx = RxPdo::default();
        assert_eq!(p.cycle(Statusword(TARGET_REACHED), &mut rx, 1), None);
        assert_eq!(rx.target_velocity, 0);
        p.set_feed(0.5);
        write_objects(&mut p);
        assert_eq!(cycle(&mut p, 0).target_velocity, 15_000);
    }

    #[test]
    fn a_refused_object_ends_the_motion_and_wrong_modes_are_refused() {
        let (mut p, units) = j5(ProfileMode::Velocity);
        let jog = ProfileMotion::Jog {
            velocity: 10_000.0,
            acceleration: 100_000.0,
            deceleration: 100_000.0,
        };
        p.start(jog, &units, 0, 1e-3).unwrap();
        let (index, value) = p.next_sdo_object().unwrap();
        assert_eq!(
            (index, value),
            (0x6083, 5_000),
            "500000 / 100000 s = 5000 ms"
        );
        assert_eq!(p.object_written(index, false), Some(ProfileEnd::Refused));
        assert!(!p.busy());
        assert_eq!(cycle(&mut p, 0).target_velocity, 0, "never sent");
        let torque = ProfileMotion::Torque {
            torque: 10.0,
            slope: 100.0,
        };
        assert_eq!(
            p.start(torque, &units, 0, 1e-3),
            Err(ProfileRefusal::WrongMode)
        );
    }

    #[test]
    fn tq_ends_after_its_ramp_counting_skipped_cycles() {
        let (mut p, units) = j5(ProfileMode::Torque);
        let tq = ProfileMotion::Torque {
            torque: 20.0,
            slope: 200.0,
        };
        p.start(tq, &units, 0, 1e-3).unwrap();
        assert_eq!(p.next_sdo_object(), Some((0x6087, 2_000)));
        p.object_written(0x6087, true);
        let mut rx = RxPdo::default();
        // 200 (0.1 %) at 2000 (0.1 %/s): 100 cycles; the entering cycle does not count.
        assert_eq!(p.cycle(Statusword(0), &mut rx, 1), None);
        assert_eq!(rx.target_torque, 200);
        assert_eq!(p.cycle(Statusword(0), &mut rx, 60), None);
        assert_eq!(p.cycle(Statusword(0), &mut rx, 39), None);
        assert_eq!(p.cycle(Statusword(0), &mut rx, 1), Some(ProfileEnd::Done));
        // A stop halts it: bit 8, the torque ramps to 0 in 100 cycles, 6071h 0 afterwards.
        p.stop(1e-3);
        assert!(p.busy());
        assert_ne!(cycle(&mut p, 0).controlword.0 & (1 << 8), 0);
        assert_eq!(p.cycle(Statusword(0), &mut rx, 100), Some(ProfileEnd::Done));
        assert_eq!(rx.target_torque, 0);
        assert!(p.at_rest());
    }
}
