//! An operator request that takes one or more SDO transfers (`sdo`, `param`, `alarms`): the
//! checked transfers in order, the drive's answers as they come, and the reply built from
//! them once the last one is answered. The transfers go one at a time through [`SdoInFlight`].

use std::collections::VecDeque;

use super::sdo::{CheckedSdo, SdoError, SdoInFlight};
use super::wire::{Reply, SdoAnswer, SdoReply};
use crate::host::link::CellLink;

/// What a job's answers become (the requests built on SDO jobs say it themselves).
pub trait JobPurpose: std::fmt::Debug {
    /// Whether `reply` makes the steps left moot.
    fn ends_at(&self, reply: &SdoReply) -> bool {
        let _ = reply;
        false
    }

    /// The reply to the client, from every answer in order.
    fn finish(self: Box<Self>, answers: &[SdoReply]) -> Reply;
}

/// One `sdo` read or write: its answer.
#[derive(Debug)]
pub struct SingleSdo;

impl JobPurpose for SingleSdo {
    fn finish(self: Box<Self>, answers: &[SdoReply]) -> Reply {
        match answers.first() {
            Some(r) => Reply::Sdo(r.clone()),
            None => Reply::Rejected {
                reason: "sdo: no answer".into(),
            },
        }
    }
}

/// A request's SDO transfers and the answers so far.
#[derive(Debug)]
pub struct SdoJob {
    steps: VecDeque<CheckedSdo>,
    answers: Vec<SdoReply>,
    purpose: Box<dyn JobPurpose>,
}

impl SdoJob {
    /// `steps` in order, answered as `purpose` says.
    pub fn new(steps: Vec<CheckedSdo>, purpose: impl JobPurpose + 'static) -> SdoJob {
        SdoJob {
            steps: steps.into(),
            answers: Vec::new(),
            purpose: Box::new(purpose),
        }
    }

    /// Hands the next step to the RT thread; `Ok(false)` when none is left.
    pub fn start_next(
        &mut self,
        sdo: &mut SdoInFlight,
        link: &mut dyn CellLink,
    ) -> Result<bool, SdoError> {
        match self.steps.pop_front() {
            Some(step) => sdo.start(link, step).map(|()| true),
            None => Ok(false),
        }
    }

    /// Takes the answer of the step in flight; the steps left are dropped where the answer
    /// makes them moot (an empty alarm history entry: the older ones are empty too).
    pub fn answered(&mut self, reply: SdoReply) {
        if self.purpose.ends_at(&reply) {
            self.steps.clear();
        }
        self.answers.push(reply);
    }

    /// The reply to the client, from every answer.
    pub fn finish(self) -> Reply {
        self.purpose.finish(&self.answers)
    }
}

/// The drive's refusal of `r` as text ("abort code 0x06010000 (…)"), if it refused.
pub fn aborted(r: &SdoReply) -> Option<String> {
    match &r.outcome {
        SdoAnswer::Aborted { code, meaning } => Some(format!(
            "refused by the drive: abort code 0x{code:08X} ({meaning})"
        )),
        _ => None,
    }
}

/// The value of an answered read or write.
pub fn value(r: &SdoReply) -> Option<i64> {
    match r.outcome {
        SdoAnswer::Read { value } | SdoAnswer::Written { value } => Some(value),
        SdoAnswer::Aborted { .. } => None,
    }
}
