//! The planner's side of the MR-JE-C axes: a program's power, reset and move steps command
//! them through their threads' queues and wait for their feedback. In a move that mixes
//! streamed and MR-JE-C axes, the drives get their set-points just before the streamed motion
//! is handed to the RT thread (so they start within one link period of it), and the step ends
//! when every axis is done.

use std::time::{Duration, Instant};

use cellrt_fieldbus::mr_je_c::cell::AxisCommand;

use super::{Planner, ProgramError, POWER_TIMEOUT};
use crate::host::je_c::jobs::{JobCounts, JobError, JobOutcome};
use crate::host::je_c::stopped_text;
use crate::host::program::{DriveMove, TorqueTarget};
use cellrt_config::AxisRef;

/// Slack on top of a move's own duration before it counts as stuck.
const MOVE_SLACK: Duration = Duration::from_secs(5);
/// How long an MR-JE-C torque ramp (or its halt) may take beyond its own time: bounds a drive
/// that stops answering.
const TORQUE_RAMP_TIMEOUT: Duration = Duration::from_secs(10);
/// How long an MR-JE-C homing may take: method 37 moves nothing, so this only bounds a drive
/// that never answers with Homing attained or Homing error.
const JE_C_HOME_TIMEOUT: Duration = Duration::from_secs(10);

impl Planner<'_> {
    /// Powers the MR-JE-C axes of `links` on or off and waits until each is (or is not) in
    /// Operation enabled.
    pub(super) fn je_c_power(&mut self, links: &[usize], on: bool) -> Result<(), ProgramError> {
        let c = if on {
            AxisCommand::PowerOn
        } else {
            AxisCommand::PowerOff
        };
        links
            .iter()
            .try_for_each(|&k| self.je_c.command(k, c))
            .map_err(|e| self.err(e))?;
        let end = Instant::now() + POWER_TIMEOUT;
        loop {
            let pending = links.iter().copied().find(|&k| {
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
                return Err(self.err(JobError::Stopped {
                    axis: name.clone(),
                    stopped: stopped_text(s),
                }));
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
        let acceleration = c.acceleration;
        let jog = c
            .jog_command(velocity, acceleration)
            .map_err(|e| self.err(e))?;
        let before = self.je_c.job_counts(axis);
        self.je_c.command(axis, jog).map_err(|e| self.err(e))?;
        self.sleep(Duration::from_secs_f64(seconds));
        self.je_c
            .command(axis, AxisCommand::Halt)
            .map_err(|e| self.err(e))?;
        let stop = Duration::from_secs_f64(2.0 * velocity.abs() / acceleration);
        // The velocity job ends with the halt, then the halt at standstill.
        self.je_c_wait_jobs(&[(axis, before, 2)], stop + MOVE_SLACK, "jog")
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
        let before: Vec<JobCounts> = commands
            .iter()
            .map(|(k, _)| self.je_c.job_counts(*k))
            .collect();
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
        let ramps: Vec<_> = commands
            .iter()
            .zip(&before)
            .map(|(&(k, _), &b)| (k, b, 1))
            .collect();
        self.je_c_wait_jobs(&ramps, limit, "torque ramp")?;
        self.sleep(Duration::from_secs_f64(seconds));
        for (k, _) in &commands {
            self.je_c
                .command(*k, AxisCommand::Halt)
                .map_err(|e| self.err(e))?;
        }
        let halts: Vec<_> = commands
            .iter()
            .zip(&before)
            .map(|(&(k, _), &b)| (k, b, 2))
            .collect();
        self.je_c_wait_jobs(&halts, limit, "halt of the torque")
    }

    /// Homes an MR-JE-C axis in its drive's hm and waits for Homing attained (the job done) or
    /// Homing error (failed), at most [`JE_C_HOME_TIMEOUT`].
    pub(super) fn je_c_home(&mut self, axis: usize) -> Result<(), ProgramError> {
        let before = self.je_c.job_counts(axis);
        self.je_c
            .command(axis, AxisCommand::Home)
            .map_err(|e| self.err(e))?;
        self.je_c_wait_jobs(&[(axis, before, 1)], JE_C_HOME_TIMEOUT, "homing")
    }

    /// Waits until every axis of `waits` (axis, counts before, jobs started) has done its jobs;
    /// fails when one fails, an axis is stopped, or `limit` has passed, naming `what`. The one
    /// wait of every MR-JE-C step (move, jog, torque, homing).
    fn je_c_wait_jobs(
        &mut self,
        waits: &[(usize, JobCounts, u32)],
        limit: Duration,
        what: &'static str,
    ) -> Result<(), ProgramError> {
        let end = Instant::now() + limit;
        for &(axis, before, jobs) in waits {
            loop {
                let outcome = self.je_c.job_outcome(axis, before, jobs);
                if outcome == JobOutcome::Done || self.aborted() {
                    break;
                }
                if let Some(e) = self.je_c.job_error(axis, outcome, what) {
                    return Err(self.err(e));
                }
                if Instant::now() >= end {
                    let f = self.je_c.feedback(axis);
                    let c = self.je_c.config(axis);
                    return Err(self.err(format!(
                        "MR-JE-C axis '{}': the {what} did not end within {limit:?} (at {:.3} {}, statusword {:04X}h)",
                        c.name,
                        c.units(f.inputs.position),
                        c.unit,
                        f.inputs.statusword
                    )));
                }
                self.sleep(Duration::from_millis(2));
            }
        }
        Ok(())
    }

    /// Sends each MR-JE-C axis of a move its set-point; the job counts before, to wait on.
    pub(super) fn je_c_start(
        &mut self,
        targets: &[DriveMove],
    ) -> Result<Vec<JobCounts>, ProgramError> {
        let before: Vec<JobCounts> = targets
            .iter()
            .map(|t| self.je_c.job_counts(t.axis))
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

    /// Waits until each MR-JE-C axis of a move reports it done; fails on a stop, a refusal or
    /// after the move's time with slack.
    pub(super) fn je_c_wait(
        &mut self,
        targets: &[DriveMove],
        before: &[JobCounts],
    ) -> Result<(), ProgramError> {
        let longest = targets
            .iter()
            .map(|t| {
                let c = self.je_c.config(t.axis);
                let from = c.units(self.je_c.feedback(t.axis).inputs.position);
                (t.target() - from).abs() / t.velocity + 2.0 * t.velocity / t.acceleration
            })
            .fold(0.0, f64::max);
        let limit = Duration::from_secs_f64(2.0 * longest) + MOVE_SLACK;
        let waits: Vec<_> = targets
            .iter()
            .zip(before)
            .map(|(t, &b)| (t.axis, b, 1))
            .collect();
        self.je_c_wait_jobs(&waits, limit, "move")
    }
}
