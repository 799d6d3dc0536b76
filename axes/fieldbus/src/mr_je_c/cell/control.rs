//! The controller's side of one MR-JE-C axis, one step per exchange: the CiA 402 power
//! sequence (MR-JE-C manual §7.6.2: Shutdown → Switch on → Enable operation), a pp move (607Ah
//! and the profile out one exchange before New set-point, then bit 4 held until Set-point
//! acknowledge, done at Target reached, §7.6.3), a pv velocity (§7.6.4), a homing in hm (the
//! drive's 6098h method on a Homing Operation Start edge, done at Homing attained and Target
//! reached, failed at Homing error: §7.4 bits 10, 12, 13), a tq torque (6071h ramped by the
//! drive at 6087h, §7.6.3; the manual gives tq no Target reached, so the job is done once the
//! ramp's time |Δ6071h| / 6087h has passed, and a Halt in tq once the ramp to 0 has), Halt
//! (bit 8), fault reset (bit 7 edge), and the master's communication watchdog: `limit` exchanges in a row without an
//! answer stop the axis with the configured reaction. In the positioning modes (SW A4+,
//! §7.6.3): a point table (pt) or a station (idx) started by a bit 4 edge with 2D60h, and a jog
//! (jg) that runs while bit 4 is on; pt and idx have no Set-point acknowledge, so their job is
//! judged by Target reached ([`START_GRACE`]).

use super::io::{ExchangeError, Inputs, Outputs};
use cellrt_cia402::fsa::FsaState;
use cellrt_cia402::statusword::Statusword;

/// 6060h pp.
const PP: i8 = 1;
/// 6060h pv.
const PV: i8 = 3;
/// 6060h tq.
const TQ: i8 = 4;
/// 6060h hm.
const HM: i8 = 6;
/// 6060h jg (SW A4+).
const JG: i8 = -100;
/// 6060h pt (SW A4+).
const PT: i8 = -101;
/// 6060h idx (SW A4+).
const IDX: i8 = -103;
pub use crate::mr_je_c::JOG_REVERSE;
/// Exchanges after a pt or idx start edge in which Target reached may stay on before the
/// positioning counts as done with nothing to move (the axis stood at the table's position or
/// station). pt and idx have no Set-point acknowledge (§7.4), so a start that moves is seen
/// by Target reached going off; the drive answers within 10 ms (§2.2.1), one exchange, and
/// this allows two more.
pub const START_GRACE: u8 = 3;
/// Controlword bit 4: New set-point in pp, Homing Operation Start in hm.
use cellrt_cia402::controlword::{HALT, NEW_SET_POINT};
use cellrt_cia402::statusword::{SET_POINT_ACKNOWLEDGE as SET_POINT_ACK, TARGET_REACHED};
/// Statusword bit 12 in hm: Homing attained (§7.4, [EXT: CiA 402]).
const HOMING_ATTAINED: u16 = 1 << 12;
/// Statusword bit 13 in hm: Homing error (§7.4, [EXT: CiA 402]).
pub const HOMING_ERROR: u16 = 1 << 13;
/// The feed override at 100 %, ‰.
pub const FULL_FEED: u16 = 1000;
/// A fault reset's exchanges: bit 7 off, on (the edge), then two to let the alarm clear.
const RESET_EXCHANGES: u8 = 4;

/// A command from the cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AxisCommand {
    /// Enable operation.
    PowerOn,
    /// Servo off (Disable voltage).
    PowerOff,
    /// pp to `target` (pos units) with the profile speed and ramps.
    Move {
        /// 607Ah.
        target: i32,
        /// 6081h, 0.01 r/min.
        velocity: u32,
        /// 6083h, ms.
        acceleration_ms: u32,
        /// 6084h, ms.
        deceleration_ms: u32,
    },
    /// pv at `velocity` (0.01 r/min); done at the speed.
    Velocity {
        /// 60FFh.
        velocity: i32,
        /// 6083h, ms.
        acceleration_ms: u32,
        /// 6084h, ms.
        deceleration_ms: u32,
    },
    /// tq to `torque` (6071h, 0.1 % of rated torque) at `slope` (6087h, 0.1 %/s; 0: a step),
    /// with the motor's speed limited to `velocity_limit` (2D20h, 0.01 r/min); done once the
    /// ramp's time has passed. The drive holds the torque until a Halt or another command.
    Torque {
        /// 6071h.
        torque: i16,
        /// 6087h.
        slope: u32,
        /// 2D20h.
        velocity_limit: u32,
    },
    /// pt: run point table `table` (2D60h, 1–255) to its position at its own speed and ramps
    /// (2801h–28FFh); done at Target reached.
    PointTable {
        /// 2D60h.
        table: i16,
    },
    /// idx: turn to station `station` (2D60h, 0 … [Pr. PT28] − 1) at `velocity` with the
    /// ramps; done at Target reached. The Halt bit is disabled in idx (§7.6.3).
    Station {
        /// 2D60h.
        station: i16,
        /// 6081h, 0.01 r/min.
        velocity: u32,
        /// 6083h, ms.
        acceleration_ms: u32,
        /// 6084h, ms.
        deceleration_ms: u32,
    },
    /// jg: run at `velocity` (6081h, 0.01 r/min) forward, or in reverse ([`JOG_REVERSE`]),
    /// while bit 4 is on; the job is done when a Halt ends it.
    Jog {
        /// 6081h.
        velocity: u32,
        /// The address-decreasing direction.
        reverse: bool,
        /// 6083h, ms.
        acceleration_ms: u32,
        /// 6084h, ms.
        deceleration_ms: u32,
    },
    /// The feed override, ‰ of the commanded speeds (0–1000): 6081h of pp, jg and idx and 60FFh
    /// of pv are scaled, a running pp move gets the new 6081h as a new set-point to the same
    /// target; at 0 pp, jg and pt hold under Halt without ending their job, and an idx start
    /// waits (its Halt bit is disabled, §7.6.3). Not a job.
    Override {
        /// 0–1000.
        permille: u16,
    },
    /// Home in hm with the drive's method (6098h; the MR-JE-C's default 37 sets the home
    /// where the motor stands): done at Homing attained, failed at Homing error.
    Home,
    /// Halt (bit 8): decelerate with 6084h; done at standstill.
    Halt,
    /// Quick stop (controlword 0002h): the drive decelerates with 6085h and, with option code
    /// 2, ends in Switch on disabled (§7.6.2); the stop for an idx axis, whose Halt bit is
    /// disabled (§7.6.3). The servo stays off until the next PowerOn.
    QuickStop,
    /// Clear a watchdog stop and the drive's alarm.
    Reset,
}

/// How the watchdog stops the axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StopReaction {
    /// Halt (6084h), the servo stays on.
    Halt,
    /// Quick stop (6085h; option code 2 ends in Switch on disabled).
    QuickStop,
    /// Disable voltage: servo off at once.
    Disable,
}

/// Why the axis was stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stopped {
    /// The master's watchdog: this many exchanges in a row without an answer.
    CommunicationLost(u32),
    /// The drive raised an alarm (2A42h).
    DriveAlarm(u16),
    /// Seen through a detached handle: the process that runs the axis' thread stopped
    /// publishing its feedback (an external planner whose controller is gone).
    ControllerLost,
}

/// The job the axis runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Job {
    Idle,
    /// Targets out, bit 4 next exchange.
    Prepare,
    /// Bit 4 on until acknowledged.
    Start,
    /// Acknowledged: until target reached.
    Moving,
    /// pv: until Target reached (the speed), judged by [`StartWatch`]: an answer to an
    /// exchange before the drive took the new speed (or before 6061h showed pv) may still
    /// carry the old mode's Target reached.
    Velocity(StartWatch),
    Halting,
    /// hm out with bit 4 off, the start edge next exchange.
    HomePrepare,
    /// Bit 4 on (held while the drive homes) until Homing attained or Homing error.
    Homing,
    /// tq: exchanges left of the drive's torque ramp (to the target, or to 0 under Halt).
    TorqueRamp(u32),
    /// pt/idx: 2D60h out with bit 4 off, the start edge next exchange.
    PositioningPrepare,
    /// pt/idx: bit 4 on, until Target reached as [`StartWatch`] judges it.
    Positioning(StartWatch),
    /// jg: the speed and direction out with bit 4 off, bit 4 on next exchange.
    JogPrepare,
    /// jg: bit 4 on until a Halt.
    Jogging,
}

/// Target reached after a start: the job is done when it comes back on after going off since
/// the start, or after [`START_GRACE`] answers with it on (nothing to move).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) struct StartWatch {
    /// Target reached has gone off since the start.
    left: bool,
    /// Answers with it on before it did.
    standing: u8,
}

impl StartWatch {
    /// One answer's Target reached; true: the job is done.
    fn done(&mut self, reached: bool) -> bool {
        match (reached, self.left) {
            (true, true) => true,
            (true, false) => {
                self.standing += 1;
                self.standing >= START_GRACE
            }
            (false, _) => {
                self.left = true;
                false
            }
        }
    }
}

/// The positioning mode an MR-JE-C axis of a cell runs in (SW A4+; Table 2.3 on the cyclic
/// link).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PositioningMode {
    /// jg, 6060h = −100.
    Jog,
    /// pt, 6060h = −101.
    PointTable,
    /// idx, 6060h = −103.
    Indexer,
}

impl PositioningMode {
    /// Its 6060h value.
    pub const fn value(self) -> i8 {
        match self {
            PositioningMode::Jog => JG,
            PositioningMode::PointTable => PT,
            PositioningMode::Indexer => IDX,
        }
    }
}

/// The controller's state of one axis.
#[derive(Debug, Clone)]
pub struct AxisControl {
    out: Outputs,
    want_on: bool,
    job: Job,
    /// jg's direction, on bit 6 with bit 4.
    jog_reverse: bool,
    /// Servo off by a quick stop rather than Disable voltage.
    quick_stop: bool,
    /// The feed override, ‰.
    feed: u16,
    /// 6081h and 60FFh as commanded, before the feed override.
    commanded_speed: u32,
    commanded_velocity: i32,
    halted: bool,
    reset: u8,
    limit: u32,
    reaction: StopReaction,
    missed_in_row: u32,
    /// The stop in force (motion refused until a reset).
    pub stopped: Option<Stopped>,
    /// The last answer.
    pub inputs: Inputs,
    /// Jobs that ended done.
    pub done: u32,
    /// Jobs that ended failed (stop, alarm, power off).
    pub failed: u32,
    /// Exchanges without an answer, in all.
    pub missed: u64,
    /// Exchanges refused by the drive.
    pub refused: u64,
    /// The link period (the time one exchange stands for), for the tq ramp's length.
    period: std::time::Duration,
}

impl AxisControl {
    /// An axis stopped after `limit` missed answers in a row (0: never) with `reaction`.
    pub fn new(limit: u32, reaction: StopReaction) -> AxisControl {
        AxisControl {
            out: Outputs {
                mode: PP,
                ..Outputs::default()
            },
            want_on: false,
            job: Job::Idle,
            jog_reverse: false,
            quick_stop: false,
            feed: FULL_FEED,
            commanded_speed: 0,
            commanded_velocity: 0,
            halted: false,
            reset: 0,
            limit,
            reaction,
            missed_in_row: 0,
            stopped: None,
            inputs: Inputs::default(),
            done: 0,
            failed: 0,
            missed: 0,
            refused: 0,
            period: std::time::Duration::from_millis(10),
        }
    }

    /// The link period its exchanges run at (the thread sets it).
    pub fn set_link_period(&mut self, period: std::time::Duration) {
        self.period = period;
    }

    /// Exchanges the drive takes to ramp 6074h from `from` to `to` at `slope` (0.1 %/s; 0: a
    /// step), counted from the exchange that carries the new target.
    fn ramp_exchanges(&self, from: i16, to: i16, slope: u32) -> u32 {
        let delta = f64::from(i32::from(to) - i32::from(from)).abs();
        if slope == 0 || delta == 0.0 {
            return 1;
        }
        let period = self.period.as_secs_f64().max(1e-6);
        let n = (delta / f64::from(slope) / period).ceil();
        // One more: the exchange's answer shows the drive's state before the ramp's last step.
        (n.min(f64::from(u32::MAX - 1)) as u32) + 1
    }

    /// The same, starting in pv (6060h = 3) instead of pp.
    pub fn starting_in_pv(mut self) -> AxisControl {
        self.out.mode = PV;
        self
    }

    /// The same, starting in tq (6060h = 4) with the motor's speed limited to
    /// `velocity_limit` (2D20h, 0.01 r/min) instead of pp.
    pub fn starting_in_tq(mut self, velocity_limit: u32) -> AxisControl {
        self.out.mode = TQ;
        self.out.velocity_limit = velocity_limit;
        self
    }

    /// The same, starting in the positioning mode `mode`.
    pub fn starting_in_positioning(mut self, mode: PositioningMode) -> AxisControl {
        self.out.mode = mode.value();
        self
    }

    /// Whether a job runs.
    pub fn busy(&self) -> bool {
        self.job != Job::Idle
    }

    /// The outputs of the next exchange.
    pub fn outputs(&self) -> Outputs {
        self.out
    }

    /// Misses in a row now.
    pub fn missed_in_row(&self) -> u32 {
        self.missed_in_row
    }

    /// Takes a command; `false`: refused (stopped: only reset and power off are taken).
    pub fn command(&mut self, c: AxisCommand) -> bool {
        let moving = matches!(
            c,
            AxisCommand::Move { .. }
                | AxisCommand::Velocity { .. }
                | AxisCommand::Torque { .. }
                | AxisCommand::PointTable { .. }
                | AxisCommand::Station { .. }
                | AxisCommand::Jog { .. }
                | AxisCommand::Home
        );
        if moving && (self.stopped.is_some() || !self.want_on) {
            self.failed += 1;
            return false;
        }
        if self.busy() && !matches!(c, AxisCommand::Override { .. }) {
            // A halt ends a velocity job as asked, a torque command a torque ramp; anything
            // else cuts the job short.
            let replaced = match c {
                AxisCommand::Halt => matches!(self.job, Job::Velocity(_) | Job::Jogging),
                AxisCommand::Torque { .. } => matches!(self.job, Job::TorqueRamp(_)),
                _ => false,
            };
            self.end(replaced);
        }
        let was_halted = self.halted;
        if moving {
            self.halted = false;
        }
        match c {
            AxisCommand::PowerOn => {
                self.want_on = self.stopped.is_none();
                self.quick_stop = false;
            }
            AxisCommand::PowerOff => self.want_on = false,
            AxisCommand::QuickStop => {
                self.want_on = false;
                self.quick_stop = true;
            }
            AxisCommand::Move {
                target,
                velocity,
                acceleration_ms,
                deceleration_ms,
            } => {
                self.out.mode = PP;
                self.out.target_position = target;
                self.commanded_speed = velocity;
                self.out.acceleration_ms = acceleration_ms;
                self.out.deceleration_ms = deceleration_ms;
                self.job = Job::Prepare;
            }
            AxisCommand::Velocity {
                velocity,
                acceleration_ms,
                deceleration_ms,
            } => {
                self.out.mode = PV;
                self.commanded_velocity = velocity;
                self.out.acceleration_ms = acceleration_ms;
                self.out.deceleration_ms = deceleration_ms;
                self.job = Job::Velocity(StartWatch::default());
            }
            AxisCommand::Torque {
                torque,
                slope,
                velocity_limit,
            } => {
                // From the drive's demand: the last target, or 0 after a Halt or another mode.
                let from = if self.out.mode == TQ && !was_halted {
                    self.out.target_torque
                } else {
                    0
                };
                self.out.mode = TQ;
                self.out.target_torque = torque;
                self.out.torque_slope = slope;
                self.out.velocity_limit = velocity_limit;
                self.job = Job::TorqueRamp(self.ramp_exchanges(from, torque, slope));
            }
            AxisCommand::PointTable { table } => {
                self.out.mode = PT;
                self.out.target_point_table = Some(table);
                self.job = Job::PositioningPrepare;
            }
            AxisCommand::Station {
                station,
                velocity,
                acceleration_ms,
                deceleration_ms,
            } => {
                self.out.mode = IDX;
                self.out.target_point_table = Some(station);
                self.commanded_speed = velocity;
                self.out.acceleration_ms = acceleration_ms;
                self.out.deceleration_ms = deceleration_ms;
                self.job = Job::PositioningPrepare;
            }
            AxisCommand::Jog {
                velocity,
                reverse,
                acceleration_ms,
                deceleration_ms,
            } => {
                self.out.mode = JG;
                self.commanded_speed = velocity;
                self.out.acceleration_ms = acceleration_ms;
                self.out.deceleration_ms = deceleration_ms;
                self.jog_reverse = reverse;
                self.job = Job::JogPrepare;
            }
            AxisCommand::Home => {
                self.out.mode = HM;
                self.job = Job::HomePrepare;
            }
            AxisCommand::Halt if self.out.mode == TQ => {
                // 6074h ramps to 0 at 6087h, whatever 605Dh says (§7.3).
                let from = if self.halted {
                    0
                } else {
                    self.out.target_torque
                };
                self.halted = true;
                self.job = Job::TorqueRamp(self.ramp_exchanges(from, 0, self.out.torque_slope));
            }
            AxisCommand::Halt => {
                self.commanded_velocity = 0;
                self.halted = true;
                self.job = Job::Halting;
            }
            AxisCommand::Override { permille } => {
                let before = self.feed;
                self.feed = permille.min(FULL_FEED);
                // A running pp move takes the new speed as a new set-point to its target.
                if matches!(self.job, Job::Start | Job::Moving)
                    && self.feed != before
                    && self.feed != 0
                {
                    // Bit 4 off in the next exchange, its edge in the one after.
                    self.out.controlword &= !NEW_SET_POINT;
                    self.job = Job::Prepare;
                }
            }
            AxisCommand::Reset => {
                self.stopped = None;
                self.missed_in_row = 0;
                self.reset = RESET_EXCHANGES;
            }
        }
        self.apply_feed();
        true
    }

    /// 6081h and 60FFh from the commanded ones at the feed override (6081h stays while held:
    /// Halt holds the motion, a profile speed of 0 would not be a speed).
    fn apply_feed(&mut self) {
        let scale = |v: i64| v * i64::from(self.feed) / i64::from(FULL_FEED);
        if self.feed > 0 {
            self.out.profile_velocity = scale(i64::from(self.commanded_speed)) as u32;
        }
        self.out.target_velocity = scale(i64::from(self.commanded_velocity)) as i32;
    }

    /// The feed override holds the job under Halt (pp, jg, pt) or keeps its start waiting
    /// (idx).
    fn feed_hold(&self) -> bool {
        self.feed == 0
            && matches!(
                self.job,
                Job::Prepare
                    | Job::Start
                    | Job::Moving
                    | Job::JogPrepare
                    | Job::Jogging
                    | Job::PositioningPrepare
                    | Job::Positioning(_)
            )
    }

    fn end(&mut self, ok: bool) {
        if self.job != Job::Idle {
            if ok {
                self.done += 1;
            } else {
                self.failed += 1;
            }
        }
        self.job = Job::Idle;
    }

    fn stop(&mut self, why: Stopped) {
        if self.stopped.is_none() {
            self.stopped = Some(why);
            self.end(false);
            self.want_on = self.reaction == StopReaction::Halt;
        }
    }

    /// One exchange's outcome: the watchdog, the job, the next controlword.
    pub fn step(&mut self, answer: Result<Inputs, ExchangeError>) {
        match answer {
            Ok(i) => {
                self.missed_in_row = 0;
                self.inputs = i;
            }
            Err(ExchangeError::NotReady) => {}
            Err(ExchangeError::Refused(_)) => self.refused += 1,
            Err(ExchangeError::NoAnswer(_)) => {
                self.missed += 1;
                self.missed_in_row = self.missed_in_row.saturating_add(1);
                if self.limit > 0 && self.missed_in_row >= self.limit {
                    self.stop(Stopped::CommunicationLost(self.missed_in_row));
                }
            }
        }
        let sw = self.inputs.statusword;
        let state = Statusword(sw).state();
        let alarm = self.inputs.alarm != 0 || state == Some(FsaState::Fault);
        if alarm && self.reset == 0 {
            self.stop(Stopped::DriveAlarm(self.inputs.alarm));
        }
        self.advance_job(sw, state);
        self.out.controlword = self.controlword(state);
    }

    fn advance_job(&mut self, sw: u16, state: Option<FsaState>) {
        if self.job != Job::Idle && state != Some(FsaState::OperationEnabled) {
            if matches!(
                self.job,
                Job::Prepare | Job::HomePrepare | Job::PositioningPrepare | Job::JogPrepare
            ) {
                return; // waits for the power sequence
            }
            self.end(false);
            return;
        }
        match self.job {
            Job::Idle => {}
            Job::Prepare => self.job = Job::Start,
            Job::Start if sw & SET_POINT_ACK != 0 => self.job = Job::Moving,
            Job::Start => {}
            Job::Moving if self.feed_hold() => {}
            Job::Moving if sw & SET_POINT_ACK == 0 && sw & TARGET_REACHED != 0 => self.end(true),
            Job::Moving => {}
            Job::Velocity(mut watch) => {
                if watch.done(sw & TARGET_REACHED != 0) {
                    self.end(true);
                } else {
                    self.job = Job::Velocity(watch);
                }
            }
            Job::Halting if sw & TARGET_REACHED != 0 => self.end(true),
            Job::Halting => {}
            Job::HomePrepare => self.job = Job::Homing,
            // The answer to an exchange that carried the start edge or bit 4 held after it.
            Job::Homing if sw & HOMING_ERROR != 0 => self.end(false),
            Job::Homing if sw & HOMING_ATTAINED != 0 && sw & TARGET_REACHED != 0 => self.end(true),
            Job::Homing => {}
            Job::TorqueRamp(0 | 1) => self.end(true),
            Job::TorqueRamp(n) => self.job = Job::TorqueRamp(n - 1),
            // idx cannot be held by Halt: its start waits for a feed.
            Job::PositioningPrepare if self.feed == 0 && self.out.mode == IDX => {}
            Job::PositioningPrepare => self.job = Job::Positioning(StartWatch::default()),
            // The answer to the exchange that carried the start edge, or bit 4 held after it.
            Job::Positioning(_) if self.feed_hold() => {}
            Job::Positioning(mut watch) => {
                if watch.done(sw & TARGET_REACHED != 0) {
                    self.end(true);
                } else {
                    self.job = Job::Positioning(watch);
                }
            }
            Job::JogPrepare => self.job = Job::Jogging,
            Job::Jogging => {}
        }
    }

    fn controlword(&mut self, state: Option<FsaState>) -> u16 {
        if self.reset > 0 {
            // Bit 7 off, then on: the edge resets the alarm (§7.6.2).
            self.reset -= 1;
            return if self.reset == RESET_EXCHANGES - 2 {
                0x80
            } else {
                0
            };
        }
        if self.stopped.is_some() {
            return match self.reaction {
                StopReaction::Halt => 0x0F | HALT,
                StopReaction::QuickStop => 0x02,
                StopReaction::Disable => 0x00,
            };
        }
        if !self.want_on {
            return if self.quick_stop { 0x02 } else { 0x00 };
        }
        let base = match state {
            Some(FsaState::SwitchOnDisabled) => 0x06,
            Some(FsaState::ReadyToSwitchOn) => 0x07,
            _ => 0x0F,
        };
        let held = self.feed_hold() && self.out.mode != IDX;
        let halt = if self.halted || held { HALT } else { 0 };
        match self.job {
            Job::Start | Job::Homing | Job::Positioning(_) => base | NEW_SET_POINT | halt,
            Job::Jogging if self.jog_reverse => base | NEW_SET_POINT | JOG_REVERSE | halt,
            Job::Jogging => base | NEW_SET_POINT | halt,
            Job::JogPrepare if self.jog_reverse => base | JOG_REVERSE | halt,
            _ => base | halt,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An answer in Operation enabled.
    fn enabled() -> Result<Inputs, ExchangeError> {
        Ok(Inputs {
            statusword: 0x0237,
            ..Inputs::default()
        })
    }

    /// Exchanges until the job count moves, at most 1000.
    fn exchanges_to_done(c: &mut AxisControl) -> u32 {
        let done = c.done;
        (1..=1000)
            .find(|_| {
                c.step(enabled());
                c.done > done
            })
            .unwrap_or(u32::MAX)
    }

    /// tq has no Target reached (MR-JE-C manual §7.4): a torque job is done after its ramp's
    /// time, |Δ6071h| / 6087h at the link period, one exchange more; a Halt ramps to 0 alike.
    #[test]
    fn a_torque_job_ends_after_its_ramp_and_a_halt_after_the_ramp_to_0() {
        let mut c = AxisControl::new(0, StopReaction::Halt);
        c.set_link_period(std::time::Duration::from_millis(10));
        assert!(c.command(AxisCommand::PowerOn));
        c.step(enabled());
        let torque = |torque, slope| AxisCommand::Torque {
            torque,
            slope,
            velocity_limit: 30_000,
        };
        // 0 → 10 % at 100 %/s: 0.1 s, 10 exchanges, and the one whose answer shows its end.
        assert!(c.command(torque(100, 1000)));
        let o = c.outputs();
        assert_eq!((o.mode, o.target_torque, o.torque_slope), (TQ, 100, 1000));
        assert_eq!(o.velocity_limit, 30_000);
        assert_eq!(exchanges_to_done(&mut c), 11);
        // 10 % → −5 % at 50 %/s: 0.3 s.
        assert!(c.command(torque(-50, 500)));
        assert_eq!(exchanges_to_done(&mut c), 31);
        // Halt: −5 % → 0 at 50 %/s, 0.1 s; 6071h stays, bit 8 does the ramp.
        assert!(c.command(AxisCommand::Halt));
        assert_eq!(c.outputs().target_torque, -50);
        assert_eq!(exchanges_to_done(&mut c), 11);
        assert!(c.outputs().controlword & HALT != 0);
        // After the halt the ramp starts from 0; slope 0 is a step (one exchange).
        assert!(c.command(torque(20, 0)));
        assert_eq!(exchanges_to_done(&mut c), 1);
        assert_eq!(
            c.outputs().controlword & HALT,
            0,
            "the torque command releases Halt"
        );
        assert_eq!((c.done, c.failed), (4, 0));
    }

    fn answer(statusword: u16) -> Result<Inputs, ExchangeError> {
        Ok(Inputs {
            statusword,
            ..Inputs::default()
        })
    }

    /// pt: 2D60h and 6060h = −101 out with bit 4 off, then bit 4 held; done when Target
    /// reached comes back after going off, or after [`START_GRACE`] answers with it on (the
    /// axis stood at the table's position). Bit 4 drops when the job ends, for the next edge.
    #[test]
    fn a_point_table_start_is_an_edge_and_ends_at_target_reached() {
        let mut c = AxisControl::new(0, StopReaction::Halt)
            .starting_in_positioning(PositioningMode::PointTable);
        assert_eq!(c.outputs().mode, -101);
        assert!(c.command(AxisCommand::PowerOn));
        c.step(answer(0x0637));
        assert!(c.command(AxisCommand::PointTable { table: 7 }));
        let o = c.outputs();
        assert_eq!((o.mode, o.target_point_table), (-101, Some(7)));
        assert_eq!(o.controlword & NEW_SET_POINT, 0, "prepared with bit 4 off");
        c.step(answer(0x0637));
        assert_eq!(c.outputs().controlword, 0x001F, "the edge");
        c.step(answer(0x0237)); // moving: Target reached off
        c.step(answer(0x0237));
        assert!(c.busy());
        assert_eq!(c.outputs().controlword, 0x001F, "bit 4 held");
        c.step(answer(0x0637));
        assert_eq!((c.busy(), c.done), (false, 1));
        assert_eq!(c.outputs().controlword, 0x000F);
        // Already there: Target reached never goes off.
        assert!(c.command(AxisCommand::PointTable { table: 7 }));
        c.step(answer(0x0637));
        for k in 1..START_GRACE {
            c.step(answer(0x0637));
            assert!(c.busy(), "answer {k}");
        }
        c.step(answer(0x0637));
        assert_eq!((c.busy(), c.done, c.failed), (false, 2, 0));
    }

    /// idx: the station in 2D60h with the profile speed and ramps; jg: bit 4 (and bit 6 in
    /// reverse) held until a Halt, which ends the jog done and stops at Target reached.
    #[test]
    fn a_station_and_a_jog_write_their_objects() {
        let mut c = AxisControl::new(0, StopReaction::QuickStop);
        assert!(c.command(AxisCommand::PowerOn));
        c.step(answer(0x0637));
        assert!(c.command(AxisCommand::Station {
            station: 3,
            velocity: 60_000,
            acceleration_ms: 100,
            deceleration_ms: 200,
        }));
        let o = c.outputs();
        assert_eq!(
            (o.mode, o.target_point_table, o.profile_velocity),
            (-103, Some(3), 60_000)
        );
        assert_eq!((o.acceleration_ms, o.deceleration_ms), (100, 200));
        c.step(answer(0x0637));
        c.step(answer(0x0237));
        c.step(answer(0x0637));
        assert_eq!(c.done, 1);
        assert!(c.command(AxisCommand::Jog {
            velocity: 30_000,
            reverse: true,
            acceleration_ms: 50,
            deceleration_ms: 50,
        }));
        assert_eq!(c.outputs().mode, -100);
        c.step(answer(0x0637));
        assert_eq!(
            c.outputs().controlword,
            0x000F | NEW_SET_POINT | JOG_REVERSE
        );
        c.step(answer(0x0237));
        assert!(c.busy(), "a jog runs until halted");
        assert!(c.command(AxisCommand::Halt));
        assert_eq!(c.done, 2, "the halt ends the jog done");
        c.step(answer(0x0237));
        assert_eq!(c.outputs().controlword & (NEW_SET_POINT | HALT), HALT);
        c.step(answer(0x0637));
        assert_eq!((c.done, c.failed), (3, 0));
    }

    /// The feed override scales 6081h; a running pp move gets it as a new set-point (bit 4
    /// off, then the edge); at 0 the move holds under Halt and does not end at Target
    /// reached; released, it goes on to its target.
    #[test]
    fn the_feed_override_rescales_and_holds_a_pp_move() {
        let mut c = AxisControl::new(0, StopReaction::Halt);
        assert!(c.command(AxisCommand::PowerOn));
        c.step(answer(0x0637));
        assert!(c.command(AxisCommand::Override { permille: 500 }));
        assert!(c.command(AxisCommand::Move {
            target: 1000,
            velocity: 60_000,
            acceleration_ms: 100,
            deceleration_ms: 100,
        }));
        assert_eq!(c.outputs().profile_velocity, 30_000, "started at 50 %");
        c.step(answer(0x0637));
        assert_eq!(c.outputs().controlword, 0x001F);
        c.step(answer(0x1237)); // acknowledged, moving
        assert!(c.command(AxisCommand::Override { permille: 250 }));
        assert_eq!(c.outputs().profile_velocity, 15_000);
        assert_eq!(
            c.outputs().controlword,
            0x000F,
            "bit 4 off for the new set-point"
        );
        c.step(answer(0x0237));
        assert_eq!(c.outputs().controlword, 0x001F, "the new set-point's edge");
        c.step(answer(0x1237));
        assert!(c.command(AxisCommand::Override { permille: 0 }));
        assert_eq!(
            c.outputs().profile_velocity,
            15_000,
            "6081h kept while held"
        );
        c.step(answer(0x0637)); // halted and standing: Target reached
        assert!(c.busy(), "a held move does not end");
        assert_eq!(c.outputs().controlword & HALT, HALT);
        assert!(c.command(AxisCommand::Override { permille: 1000 }));
        assert_eq!(c.outputs().profile_velocity, 60_000);
        assert_eq!(c.outputs().controlword & NEW_SET_POINT, 0);
        c.step(answer(0x0637));
        assert_eq!(
            c.outputs().controlword,
            0x001F,
            "released, the new set-point's edge"
        );
        c.step(answer(0x1237));
        c.step(answer(0x0637));
        assert_eq!((c.busy(), c.done, c.failed), (false, 1, 0));
    }

    /// pv: an answer still carrying the old mode's Target reached does not end the velocity
    /// job (it failed under load: the answer to the exchange before the drive took pv); it
    /// ends when the drive reaches the speed after leaving it, or after [`START_GRACE`]
    /// answers with it on (a speed the motor already runs at).
    #[test]
    fn a_velocity_job_ends_when_the_speed_is_reached_not_on_a_stale_answer() {
        let mut c = AxisControl::new(0, StopReaction::Halt);
        assert!(c.command(AxisCommand::PowerOn));
        c.step(answer(0x0637));
        let velocity = AxisCommand::Velocity {
            velocity: -60_000,
            acceleration_ms: 100,
            deceleration_ms: 100,
        };
        assert!(c.command(velocity));
        c.step(answer(0x0637)); // the pp move's Target reached, not yet pv
        assert_eq!((c.busy(), c.done), (true, 0));
        c.step(answer(0x0237)); // accelerating
        c.step(answer(0x0237));
        assert!(c.busy());
        c.step(answer(0x0637)); // at speed
        assert_eq!((c.busy(), c.done, c.failed), (false, 1, 0));
        assert!(c.command(velocity));
        for _ in 0..START_GRACE {
            assert!(c.busy());
            c.step(answer(0x0637));
        }
        assert_eq!((c.busy(), c.done), (false, 2), "already at that speed");
    }

    /// pv: 60FFh follows the override at once (0: ramps to 0, the job stays a velocity job).
    #[test]
    fn the_feed_override_scales_a_pv_velocity() {
        let mut c = AxisControl::new(0, StopReaction::Halt);
        assert!(c.command(AxisCommand::PowerOn));
        c.step(answer(0x0637));
        assert!(c.command(AxisCommand::Velocity {
            velocity: -40_000,
            acceleration_ms: 100,
            deceleration_ms: 100,
        }));
        assert_eq!(c.outputs().target_velocity, -40_000);
        assert!(c.command(AxisCommand::Override { permille: 750 }));
        assert_eq!(c.outputs().target_velocity, -30_000);
        assert!(c.command(AxisCommand::Override { permille: 0 }));
        assert_eq!(c.outputs().target_velocity, 0);
        assert!(c.busy());
    }

    /// MC_Stop of an indexer: the Quick stop command 0002h (CiA 402, MR-JE-C manual §7.6.2:
    /// bit 1 on, bit 2 off) from then on, the job cut short; PowerOn enables again (0006h).
    #[test]
    fn a_quick_stop_sends_0002h_until_the_next_power_on() {
        let mut c = AxisControl::new(0, StopReaction::Halt);
        assert!(c.command(AxisCommand::PowerOn));
        c.step(answer(0x0637));
        assert!(c.command(AxisCommand::Station {
            station: 2,
            velocity: 1000,
            acceleration_ms: 10,
            deceleration_ms: 10,
        }));
        c.step(answer(0x0637));
        assert!(c.command(AxisCommand::QuickStop));
        assert_eq!((c.busy(), c.failed), (false, 1));
        c.step(answer(0x0617)); // Quick stop active
        assert_eq!(c.outputs().controlword, 0x0002);
        c.step(answer(0x0250)); // Switch on disabled
        assert_eq!(c.outputs().controlword, 0x0002);
        assert!(c.command(AxisCommand::PowerOn));
        c.step(answer(0x0250));
        assert_eq!(
            c.outputs().controlword,
            0x0006,
            "Shutdown, toward Ready to switch on"
        );
    }
}
