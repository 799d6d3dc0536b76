//! The controller's side of one MR-JE-C axis, one step per exchange: the CiA 402 power
//! sequence (MR-JE-C manual §7.6.2: Shutdown → Switch on → Enable operation), a pp move (607Ah
//! and the profile out one exchange before New set-point, then bit 4 held until Set-point
//! acknowledge, done at Target reached, §7.6.3), a pv velocity (§7.6.4), a homing in hm (the
//! drive's 6098h method on a Homing Operation Start edge, done at Homing attained and Target
//! reached, failed at Homing error: §7.4 bits 10, 12, 13), Halt (bit 8), fault reset (bit 7
//! edge), and the master's communication watchdog: `limit` exchanges in a row without an
//! answer stop the axis with the configured reaction.

use super::io::{ExchangeError, Inputs, Outputs};
use crate::cia402::fsa::FsaState;
use crate::cia402::statusword::Statusword;

/// 6060h pp.
const PP: i8 = 1;
/// 6060h pv.
const PV: i8 = 3;
/// 6060h hm.
const HM: i8 = 6;
/// Controlword bit 4: New set-point in pp, Homing Operation Start in hm.
const NEW_SET_POINT: u16 = 1 << 4;
const HALT: u16 = 1 << 8;
const SET_POINT_ACK: u16 = 1 << 12;
const TARGET_REACHED: u16 = 1 << 10;
/// Statusword bit 12 in hm: Homing attained (§7.4, [EXT: CiA 402]).
const HOMING_ATTAINED: u16 = 1 << 12;
/// Statusword bit 13 in hm: Homing error (§7.4, [EXT: CiA 402]).
pub const HOMING_ERROR: u16 = 1 << 13;
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
    /// Home in hm with the drive's method (6098h; the MR-JE-C's default 37 sets the home
    /// where the motor stands): done at Homing attained, failed at Homing error.
    Home,
    /// Halt (bit 8): decelerate with 6084h; done at standstill.
    Halt,
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
    Velocity,
    Halting,
    /// hm out with bit 4 off, the start edge next exchange.
    HomePrepare,
    /// Bit 4 on (held while the drive homes) until Homing attained or Homing error.
    Homing,
}

/// The controller's state of one axis.
#[derive(Debug, Clone)]
pub struct AxisControl {
    out: Outputs,
    want_on: bool,
    job: Job,
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
        }
    }

    /// The same, starting in pv (6060h = 3) instead of pp.
    pub fn starting_in_pv(mut self) -> AxisControl {
        self.out.mode = PV;
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
            AxisCommand::Move { .. } | AxisCommand::Velocity { .. } | AxisCommand::Home
        );
        if moving && (self.stopped.is_some() || !self.want_on) {
            self.failed += 1;
            return false;
        }
        if self.busy() {
            // A halt ends a velocity job as asked; anything else cuts the job short.
            self.end(c == AxisCommand::Halt && self.job == Job::Velocity);
        }
        if moving {
            self.halted = false;
        }
        match c {
            AxisCommand::PowerOn => self.want_on = self.stopped.is_none(),
            AxisCommand::PowerOff => self.want_on = false,
            AxisCommand::Move {
                target,
                velocity,
                acceleration_ms,
                deceleration_ms,
            } => {
                self.out.mode = PP;
                self.out.target_position = target;
                self.out.profile_velocity = velocity;
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
                self.out.target_velocity = velocity;
                self.out.acceleration_ms = acceleration_ms;
                self.out.deceleration_ms = deceleration_ms;
                self.job = Job::Velocity;
            }
            AxisCommand::Home => {
                self.out.mode = HM;
                self.job = Job::HomePrepare;
            }
            AxisCommand::Halt => {
                self.out.target_velocity = 0;
                self.halted = true;
                self.job = Job::Halting;
            }
            AxisCommand::Reset => {
                self.stopped = None;
                self.missed_in_row = 0;
                self.reset = RESET_EXCHANGES;
            }
        }
        true
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
            if matches!(self.job, Job::Prepare | Job::HomePrepare) {
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
            Job::Moving if sw & SET_POINT_ACK == 0 && sw & TARGET_REACHED != 0 => self.end(true),
            Job::Moving => {}
            Job::Velocity | Job::Halting if sw & TARGET_REACHED != 0 => self.end(true),
            Job::Velocity | Job::Halting => {}
            Job::HomePrepare => self.job = Job::Homing,
            // The answer to an exchange that carried the start edge or bit 4 held after it.
            Job::Homing if sw & HOMING_ERROR != 0 => self.end(false),
            Job::Homing if sw & HOMING_ATTAINED != 0 && sw & TARGET_REACHED != 0 => self.end(true),
            Job::Homing => {}
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
            return 0x00;
        }
        let base = match state {
            Some(FsaState::SwitchOnDisabled) => 0x06,
            Some(FsaState::ReadyToSwitchOn) => 0x07,
            _ => 0x0F,
        };
        let halt = if self.halted { HALT } else { 0 };
        match self.job {
            Job::Start | Job::Homing => base | NEW_SET_POINT | halt,
            _ => base | halt,
        }
    }
}
