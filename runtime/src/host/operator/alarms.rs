//! `alarms`: an axis' alarm history (MR-J3-T04 manual §8.9: 2030h newest … 2035h, each with
//! its number, hours of operation and detail) read entry by entry, or cleared (1EA5h to 2040h);
//! refused, naming the manual, where the model has none.

use cellrt_cia402::profiles::params::history_sub;
use cellrt_cia402::profiles::{DriveModel, SharedProfile};

use super::sdo::{self, SdoError};
use super::sdo_job::{aborted, value, JobPurpose, SdoJob};
use super::targets::{axis_index, TargetError};
use super::wire::{AlarmEntry, AlarmsReply, Reply, SdoReply};
use cellrt_config::CellConfig;

/// The sub-indices read of each history entry, in order.
const SUBS: [u8; 3] = [history_sub::NUMBER, history_sub::TIME, history_sub::DETAIL];

/// How the answers of an `alarms` request become its reply.
#[derive(Debug)]
pub struct AlarmsPlan {
    axis: String,
    profile: SharedProfile,
    clear: bool,
}

/// Why an `alarms` request is not sent.
#[derive(Debug, thiserror::Error)]
pub enum AlarmsError {
    /// The request names no axis of the cell.
    #[error("alarms: {0}")]
    Axis(#[source] TargetError),
    /// The drive's model has no alarm history objects.
    #[error("alarms: axis '{axis}' ({model}) has no alarm history: {why}")]
    NoHistory {
        /// The axis.
        axis: String,
        /// Its drive.
        model: DriveModel,
        /// Why, naming the manual.
        why: &'static str,
    },
    /// An object of the history does not pass the SDO checks.
    #[error(transparent)]
    Sdo(#[from] SdoError),
}

/// Checks an `alarms` request and plans its transfers.
pub fn plan(cell: &CellConfig, axis: &str, clear: bool) -> Result<SdoJob, AlarmsError> {
    let i = axis_index(cell, axis).map_err(AlarmsError::Axis)?;
    let a = &cell.axes.on_loop()[i];
    let h = a
        .profile
        .parameters
        .alarm_history
        .map_err(|why| AlarmsError::NoHistory {
            axis: axis.to_string(),
            model: a.drive,
            why,
        })?;
    let steps = if clear {
        vec![sdo::check(
            cell,
            axis,
            h.clear.0,
            0,
            Some(i64::from(h.clear.1)),
        )?]
    } else {
        let objects = (0..u16::from(h.entries)).flat_map(|n| SUBS.map(|s| (h.first + n, s)));
        objects
            .map(|(index, sub)| sdo::check(cell, axis, index, sub, None))
            .collect::<Result<_, _>>()?
    };
    let plan = AlarmsPlan {
        axis: axis.to_string(),
        profile: a.profile.clone(),
        clear,
    };
    Ok(SdoJob::new(steps, plan))
}

impl JobPurpose for AlarmsPlan {
    /// True if `r` reads an empty entry's Alarm No.: the history fills from its newest entry,
    /// so the older entries are empty too and are not read [inferred: the manual does not
    /// say, a history is written newest first and cleared as a whole].
    fn ends_at(&self, r: &SdoReply) -> bool {
        !self.clear && r.sub == history_sub::NUMBER && value(r) == Some(0)
    }

    /// The reply from the drive's answers (three per entry up to the first empty one, or the
    /// clear's one).
    fn finish(self: Box<Self>, answers: &[SdoReply]) -> Reply {
        if let Some(why) = answers.iter().find_map(aborted) {
            return Reply::Rejected {
                reason: format!("alarms: axis '{}': {why}", self.axis),
            };
        }
        let entries = answers
            .chunks(SUBS.len())
            .enumerate()
            .filter(|_| !self.clear)
            .filter_map(|(n, r)| {
                let number = value(r.first()?)? as u16;
                let text = self.profile.alarm_text(number);
                (number != 0).then(|| AlarmEntry {
                    entry: n as u8,
                    number,
                    name: text.name().unwrap_or_else(|| format!("{number:04X}h")),
                    cause: text.cause().map(str::to_string),
                    remedy: text.remedy().map(str::to_string),
                    hours: r.get(1).and_then(value).unwrap_or(0) as u32,
                    detail: r.get(2).and_then(value).unwrap_or(0) as u16,
                })
            })
            .collect();
        Reply::Alarms(AlarmsReply {
            axis: self.axis,
            model: self.profile.model.to_string(),
            entries,
            cleared: self.clear,
        })
    }
}
