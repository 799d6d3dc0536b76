//! The planner's side of the MR-JE-C axes: a program's power, reset and move steps command
//! them through their threads' queues and wait for their feedback. In a move that mixes
//! streamed and MR-JE-C axes, the drives get their set-points just before the streamed motion
//! is handed to the RT thread (so they start within one link period of it), and the step ends
//! when every axis is done.

use std::time::{Duration, Instant};

use cellrt_fieldbus::mr_je_c::cell::{AxisCommand, HOMING_ERROR};

use super::{Planner, ProgramError, POWER_TIMEOUT};
use crate::host::je_c::stopped_text;
use crate::host::program::{DriveMove, TorqueTarget};
use cellrt_config::AxisRef;

fn c_acc(p: &Planner<'_>, axis: usize) -> f64 {
    p.je_c.config(axis).acceleration
}

/// Slack on top of a move's own duration before it counts as stuck.
const MOVE_SLACK: Duration = Duration::from_secs(5);
/// How long an MR-JE-C torque ramp (or its halt) may take beyond its own time: bounds a drive
/// that stops answering.
const TORQUE_RAMP_TIMEOUT: Duration = Duration::from_secs(10);
/// How long an MR-JE-C homing may take: method 37 moves nothing, so this only bounds a drive
/// that never answers with Homing attained or Homing error.
const JE_C_HOME_TIMEOUT: Duration = Duration::from_secs(10);

impl Planner<'_> {
    /// Powers every MR-JE-C axis on or off and waits until each is (or is not) in Operation
    /// enabled.
    pub(super) fn je_c_power(&mut self, on: bool) -> Result<(), ProgramError> {
        if self.je_c.is_empty() {
            return Ok(());
        }
        let c = if on {
            AxisCommand::PowerOn
        } else {
            AxisCommand::PowerOff
        };
        self.je_c.command_all(c).map_err(|e| self.err(e))?;
        let end = Instant::now() + POWER_TIMEOUT;
        loop {
            let pending = (0..self.je_c.len()).find(|&k| {
                let f = self.je_c.feedback(k);
                f.enabled != on || (on && f.stopped.is_some())
            });
            let Some(k) = pending else { return Ok(()) };
            if self.aborted() {
                return Ok(());
            }
            let f = self.je_c.feedback(k);
            let name = &self.je_c.config(k).name;
            if let (true, Some(s)) = (on, f.stopped) {
                return Err(self.err(format!("MR-JE-C axis '{name}': {}", stopped_text(s))));
            }
            if Instant::now() >= end {
                return Err(self.err(format!(
                    "MR-JE-C axis '{name}' is not {} after {POWER_TIMEOUT:?} (statusword {:04X}h, {} answers missed)",
                    if on { "enabled" } else { "disabled" },
                    f.inputs.statusword,
                    f.missed
                )));
            }
            self.sleep(Duration::from_millis(5));
        }
    }

    /// Clears the MR-JE-C axes stopped by the watchdog or a drive alarm.
    pub(super) fn je_c_reset(&mut self) -> Result<(), ProgramError> {
        for k in 0..self.je_c.len() {
            if self.je_c.feedback(k).stopped.is_some() {
                self.je_c
                    .command(k, AxisCommand::Reset)
                    .map_err(|e| self.err(e))?;
            }
        }
        Ok(())
    }

    /// A jog of an MR-JE-C axis: pv (jg on a jog or point-table axis) at `velocity` for
    /// `seconds`, then Halt; the step ends when the drive stands.
    pub(super) fn je_c_jog(
        &mut self,
        axis: usize,
        velocity: f64,
        seconds: f64,
    ) -> Result<(), ProgramError> {
        let c = self.je_c.config(axis);
        let jog = c
            .jog_command(velocity, c.acceleration)
            .map_err(|e| self.err(e))?;
        let before = self.je_c_jobs(axis);
        self.je_c.command(axis, jog).map_err(|e| self.err(e))?;
        self.sleep(Duration::from_secs_f64(seconds));
        self.je_c
            .command(axis, AxisCommand::Halt)
            .map_err(|e| self.err(e))?;
        let stop = Duration::from_secs_f64(2.0 * velocity.abs() / c_acc(self, axis));
        // The velocity job ends with the halt, then the halt at standstill.
        self.je_c_until(axis, before, 2, stop + MOVE_SLACK, "jog")
    }

    /// A torque step on MR-JE-C axes: each drive ramps to its torque in tq (`commands`), holds
    /// it `seconds`, then Halt ramps it back to 0 at 6087h; the step ends when every ramp is
    /// over (the jobs count the ramps' time, tq reports no target reached).
    pub(super) fn je_c_torque(
        &mut self,
        targets: &[TorqueTarget],
        seconds: f64,
    ) -> Result<(), ProgramError> {
        let mut commands = Vec::with_capacity(targets.len());
        for t in targets {
            if let AxisRef::Link(k) = t.axis {
                let c = self.je_c.config(k).torque_command(t.torque);
                commands.push((k, c.map_err(|e| self.err(e))?));
            }
        }
        let before: Vec<(u32, u32)> = commands.iter().map(|(k, _)| self.je_c_jobs(*k)).collect();
        for (k, c) in &commands {
            self.je_c.command(*k, *c).map_err(|e| self.err(e))?;
        }
        // The longest ramp (from ±its torque) with slack.
        let ramp = commands
            .iter()
            .map(|(_, c)| match c {
                AxisCommand::Torque { torque, slope, .. } => {
                    2.0 * f64::from(torque.unsigned_abs()) / f64::from((*slope).max(1))
                }
                _ => 0.0,
            })
            .fold(0.0, f64::max);
        let limit = Duration::from_secs_f64(ramp) + TORQUE_RAMP_TIMEOUT;
        for ((k, _), b) in commands.iter().zip(&before) {
            self.je_c_until(*k, *b, 1, limit, "torque ramp")?;
        }
        self.sleep(Duration::from_secs_f64(seconds));
        for (k, _) in &commands {
            self.je_c
                .command(*k, AxisCommand::Halt)
                .map_err(|e| self.err(e))?;
        }
        for ((k, _), b) in commands.iter().zip(&before) {
            self.je_c_until(*k, *b, 2, limit, "halt of the torque")?;
        }
        Ok(())
    }

    /// Homes an MR-JE-C axis in its drive's hm and waits for Homing attained (the job done) or
    /// Homing error (failed), at most [`JE_C_HOME_TIMEOUT`].
    pub(super) fn je_c_home(&mut self, axis: usize) -> Result<(), ProgramError> {
        let before = self.je_c_jobs(axis);
        self.je_c
            .command(axis, AxisCommand::Home)
            .map_err(|e| self.err(e))?;
        self.je_c_until(axis, before, 1, JE_C_HOME_TIMEOUT, "homing")
    }

    /// Axis `axis`' (done, failed) job counts now.
    fn je_c_jobs(&self, axis: usize) -> (u32, u32) {
        let f = self.je_c.feedback(axis);
        (f.done, f.failed)
    }

    /// Waits until `jobs` more of axis `axis`' jobs are done than `(done, failed)` counted;
    /// fails when one fails, the axis is stopped, or `limit` has passed (naming `what`).
    fn je_c_until(
        &mut self,
        axis: usize,
        (done, failed): (u32, u32),
        jobs: u32,
        limit: Duration,
        what: &str,
    ) -> Result<(), ProgramError> {
        let name = self.je_c.config(axis).name.clone();
        let end = Instant::now() + limit;
        loop {
            let f = self.je_c.feedback(axis);
            if f.done >= done + jobs || self.aborted() {
                return Ok(());
            }
            if let Some(s) = f.stopped {
                return Err(self.err(format!("MR-JE-C axis '{name}': {}", stopped_text(s))));
            }
            let sw = f.inputs.statusword;
            let homing_error = if sw & HOMING_ERROR != 0 && what == "homing" {
                ", Homing error"
            } else {
                ""
            };
            if f.failed > failed {
                return Err(self.err(format!(
                    "MR-JE-C axis '{name}': the {what} failed or was cut short (statusword {sw:04X}h{homing_error})"
                )));
            }
            if Instant::now() >= end {
                return Err(self.err(format!(
                    "MR-JE-C axis '{name}': the {what} did not end within {limit:?} (statusword {sw:04X}h)"
                )));
            }
            self.sleep(Duration::from_millis(2));
        }
    }

    /// Sends each MR-JE-C axis of a move its set-point; the feedback before, to wait on.
    pub(super) fn je_c_start(
        &mut self,
        targets: &[DriveMove],
    ) -> Result<Vec<(u32, u32)>, ProgramError> {
        let before: Vec<(u32, u32)> = targets
            .iter()
            .map(|t| {
                let f = self.je_c.feedback(t.axis);
                (f.done, f.failed)
            })
            .collect();
        for t in targets {
            let c = self
                .je_c
                .config(t.axis)
                .move_command(t.goal, t.velocity, t.acceleration);
            self.je_c.command(t.axis, c).map_err(|e| self.err(e))?;
        }
        Ok(before)
    }

    /// Waits until each MR-JE-C axis of a move reports it done; fails on a stop or after the
    /// move's time with slack.
    pub(super) fn je_c_wait(
        &mut self,
        targets: &[DriveMove],
        before: &[(u32, u32)],
    ) -> Result<(), ProgramError> {
        let longest = targets
            .iter()
            .map(|t| {
                let c = self.je_c.config(t.axis);
                let from = c.units(self.je_c.feedback(t.axis).inputs.position);
                (t.target() - from).abs() / t.velocity + 2.0 * t.velocity / t.acceleration
            })
            .fold(0.0, f64::max);
        let end = Instant::now() + Duration::from_secs_f64(2.0 * longest) + MOVE_SLACK;
        for (t, &(done_before, failed_before)) in targets.iter().zip(before) {
            let name = self.je_c.config(t.axis).name.clone();
            loop {
                let f = self.je_c.feedback(t.axis);
                if f.done > done_before || self.aborted() {
                    break;
                }
                if let Some(s) = f.stopped {
                    return Err(self.err(format!("MR-JE-C axis '{name}': {}", stopped_text(s))));
                }
                if f.failed > failed_before {
                    return Err(self.err(format!(
                        "MR-JE-C axis '{name}': the move was refused or cut short (statusword {:04X}h)",
                        f.inputs.statusword
                    )));
                }
                if Instant::now() >= end {
                    return Err(self.err(format!(
                        "MR-JE-C axis '{name}' did not reach {} {} in time (at {:.3})",
                        t.target(),
                        self.je_c.config(t.axis).unit,
                        self.je_c.config(t.axis).units(f.inputs.position)
                    )));
                }
                self.sleep(Duration::from_millis(2));
            }
        }
        Ok(())
    }
}
