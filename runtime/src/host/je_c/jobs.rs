//! Waiting for an MR-JE-C axis' jobs: a command to its link thread starts one or more jobs
//! (a move, a jog and its halt, a torque ramp, a homing), and the axis' feedback counts the
//! jobs done and failed. One judgement of that feedback serves the program's steps (which
//! block until the jobs are over) and the operator's tracked commands (which poll).

use cellrt_fieldbus::mr_je_c::cell::{Stopped, HOMING_ERROR};

use super::{stopped_text, JecAxes};

/// An axis' jobs done and failed at one moment: what a wait for its next jobs counts from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct JobCounts {
    /// Jobs the axis finished.
    pub done: u32,
    /// Jobs the drive refused or cut short.
    pub failed: u32,
}

/// What an axis' feedback says of the jobs a command started.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JobOutcome {
    /// Not all of them done yet.
    Pending,
    /// All of them done.
    Done,
    /// The axis was stopped by its watchdog or an alarm.
    Stopped(Stopped),
    /// The drive refused a job or cut it short.
    Refused {
        /// The statusword when it was seen.
        statusword: u16,
    },
}

impl JecAxes {
    /// Axis `k`'s job counts now.
    pub fn job_counts(&self, k: usize) -> JobCounts {
        let f = self.feedback(k);
        JobCounts {
            done: f.done,
            failed: f.failed,
        }
    }

    /// Where axis `k` stands with `jobs` jobs started after `before` was counted.
    pub fn job_outcome(&self, k: usize, before: JobCounts, jobs: u32) -> JobOutcome {
        let f = self.feedback(k);
        if f.done >= before.done + jobs {
            JobOutcome::Done
        } else if let Some(s) = f.stopped {
            JobOutcome::Stopped(s)
        } else if f.failed > before.failed {
            JobOutcome::Refused {
                statusword: f.inputs.statusword,
            }
        } else {
            JobOutcome::Pending
        }
    }

    /// Why axis `k`'s `what` (a move, a homing …) did not end as it should, for a step or a
    /// command that waited for it; `None` while it is pending or done.
    pub fn job_error(&self, k: usize, outcome: JobOutcome, what: &'static str) -> Option<JobError> {
        let axis = self.config(k).name.clone();
        match outcome {
            JobOutcome::Pending | JobOutcome::Done => None,
            JobOutcome::Stopped(s) => Some(JobError::Stopped {
                axis,
                stopped: stopped_text(s),
            }),
            JobOutcome::Refused { statusword } => Some(JobError::Refused {
                axis,
                what,
                statusword,
                homing_error: what == "homing" && statusword & HOMING_ERROR != 0,
            }),
        }
    }
}

/// Why an MR-JE-C axis' job did not end as it should.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum JobError {
    /// The axis was stopped by its watchdog or an alarm.
    #[error("MR-JE-C axis '{axis}': {stopped}")]
    Stopped {
        /// The axis.
        axis: String,
        /// Why it was stopped ([`stopped_text`]).
        stopped: String,
    },
    /// The drive refused the job or cut it short.
    #[error("MR-JE-C axis '{axis}': the {what} was refused or cut short (statusword {statusword:04X}h{})", if *homing_error { ", Homing error" } else { "" })]
    Refused {
        /// The axis.
        axis: String,
        /// The job ("move", "homing" …).
        what: &'static str,
        /// The statusword when it was seen.
        statusword: u16,
        /// Statusword bit 13 in hm: Homing error.
        homing_error: bool,
    },
}
