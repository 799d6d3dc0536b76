//! `param`: an axis' servo parameters by the names its manual gives them, through the objects
//! that carry them (the model's table in `cellrt_cia402::profiles::params`). Every check is made
//! before anything is sent: the name, the manual's setting range, "do not change" parameters,
//! cellrt's rule for parameters that act at once on an enabled axis, and the object's own type
//! and access (`sdo::check`).

use cellrt_cia402::profiles::params::{Effect, Parameter, ParameterFacts, WhileEnabled};
use cellrt_cia402::profiles::DriveModel;

use super::sdo::{self, object_text, SdoError};
use super::sdo_job::{aborted, value, JobPurpose, SdoJob};
use super::targets::{axis_index, TargetError};
use super::wire::{ParamOp, ParamReply, ParamValue, Reply, SdoReply};
use cellrt_config::CellConfig;

/// How the answers of a `param` request become its reply.
#[derive(Debug)]
pub struct ParamPlan {
    axis: String,
    model: DriveModel,
    /// The axis' slot on its amplifier (its objects at the slot's offset, MR-J5W2/W3).
    slot: u8,
    /// The parameter of each step (none for a save).
    rows: Vec<&'static Parameter>,
    kind: Kind,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Read,
    Diff,
    Set,
    Save,
}

/// Why a `param` request is not sent.
#[derive(Debug, thiserror::Error)]
pub enum ParamError {
    /// The request names no axis of the cell.
    #[error("param: {0}")]
    Axis(#[source] TargetError),
    /// The value is outside what the manual allows for the parameter.
    #[error("param: {0}")]
    Value(String),
    /// The parameter acts at once and the axis is enabled.
    #[error(
        "param: {name} ({object}) of axis '{axis}' takes effect at once and is not written \
         while the axis is enabled; power it off first"
    )]
    WhileEnabled {
        /// The parameter.
        name: &'static str,
        /// Its object's name.
        object: &'static str,
        /// The axis.
        axis: String,
    },
    /// The drive has no parameter save.
    #[error("param save: axis '{axis}' ({model}) has no parameter save: {why}")]
    NoSave {
        /// The axis.
        axis: String,
        /// Its drive.
        model: DriveModel,
        /// Why, naming the manual.
        why: &'static str,
    },
    /// The drive's model has no parameter table.
    #[error("param: axis '{axis}' ({model}) has no parameter table: {source_text}")]
    NoTable {
        /// The axis.
        axis: String,
        /// Its drive.
        model: DriveModel,
        /// Where the table would come from.
        source_text: &'static str,
    },
    /// The name is not in the drive's parameter table.
    #[error(
        "param: {name} is not a parameter of axis '{axis}' ({model}; {source_text} lists {names})"
    )]
    Unknown {
        /// The name asked.
        name: String,
        /// The axis.
        axis: String,
        /// Its drive.
        model: DriveModel,
        /// The table's source.
        source_text: &'static str,
        /// The table's names, comma-separated.
        names: String,
    },
    /// An object of the plan does not pass the SDO checks.
    #[error(transparent)]
    Sdo(#[from] SdoError),
}

/// Checks a `param` request on axis `axis` (`enabled`: the axis is in Operation enabled) and
/// plans its transfers; the reason where nothing may be sent.
pub fn plan(
    cell: &CellConfig,
    axis: &str,
    op: &ParamOp,
    enabled: bool,
) -> Result<SdoJob, ParamError> {
    let i = axis_index(cell, axis).map_err(ParamError::Axis)?;
    let a = &cell.axes.on_loop()[i];
    let facts = a.profile.parameters;
    let plan = |rows: Vec<&'static Parameter>, kind| ParamPlan {
        axis: axis.to_string(),
        model: a.drive,
        slot: a.amplifier.as_ref().map_or(0, |s| s.slot),
        rows,
        kind,
    };
    let read = |p: &Parameter| sdo::check(cell, axis, p.object.index, p.object.sub, None);
    match op {
        ParamOp::List | ParamOp::Diff => {
            let rows = table(facts, axis, a.drive)?;
            let steps = rows.iter().map(|p| read(p)).collect::<Result<_, _>>()?;
            let kind = if *op == ParamOp::Diff {
                Kind::Diff
            } else {
                Kind::Read
            };
            Ok(SdoJob::new(steps, plan(rows, kind)))
        }
        ParamOp::Get { name } => {
            let p = lookup(facts, axis, a.drive, name)?;
            Ok(SdoJob::new(vec![read(p)?], plan(vec![p], Kind::Read)))
        }
        ParamOp::Set { name, value } => {
            let p = lookup(facts, axis, a.drive, name)?;
            if let Some(why) = p.refuse(*value) {
                return Err(ParamError::Value(why));
            }
            if enabled && p.while_enabled == WhileEnabled::Refused {
                return Err(ParamError::WhileEnabled {
                    name: p.name,
                    object: p.object.name,
                    axis: axis.to_string(),
                });
            }
            let step = sdo::check(cell, axis, p.object.index, p.object.sub, Some(*value))?;
            Ok(SdoJob::new(vec![step], plan(vec![p], Kind::Set)))
        }
        ParamOp::Save => {
            let s = facts.save.map_err(|why| ParamError::NoSave {
                axis: axis.to_string(),
                model: a.drive,
                why,
            })?;
            let step = sdo::check(
                cell,
                axis,
                s.object.0,
                s.object.1,
                Some(i64::from(s.signature)),
            )?;
            Ok(SdoJob::new(vec![step], plan(Vec::new(), Kind::Save)))
        }
    }
}

fn table(
    facts: &'static ParameterFacts,
    axis: &str,
    model: DriveModel,
) -> Result<Vec<&'static Parameter>, ParamError> {
    if facts.table.is_empty() {
        return Err(ParamError::NoTable {
            axis: axis.to_string(),
            model,
            source_text: facts.table_source,
        });
    }
    Ok(facts.table.iter().collect())
}

fn lookup(
    facts: &'static ParameterFacts,
    axis: &str,
    model: DriveModel,
    name: &str,
) -> Result<&'static Parameter, ParamError> {
    let rows = table(facts, axis, model)?;
    facts.parameter(name).ok_or_else(|| {
        let names: Vec<&str> = rows.iter().map(|p| p.name).collect();
        ParamError::Unknown {
            name: name.to_string(),
            axis: axis.to_string(),
            model,
            source_text: facts.table_source,
            names: names.join(", "),
        }
    })
}

impl JobPurpose for ParamPlan {
    /// The reply from the drive's answers, one per step in order.
    fn finish(self: Box<Self>, answers: &[SdoReply]) -> Reply {
        let refused = answers.iter().find_map(aborted);
        match (self.kind, refused) {
            (Kind::Set | Kind::Save, Some(why)) => {
                let what = self.rows.first().map_or("save", |p| p.name);
                return Reply::Rejected {
                    reason: format!("param: {what} of axis '{}': {why}", self.axis),
                };
            }
            (Kind::Save, None) => {
                return Reply::Param(ParamReply {
                    axis: self.axis,
                    model: self.model.to_string(),
                    parameters: Vec::new(),
                    note: Some(save_note(self.model)),
                })
            }
            _ => {}
        }
        let mut values: Vec<ParamValue> = self
            .rows
            .iter()
            .zip(answers)
            .map(|(p, r)| param_value(p, r, self.object_index(p)))
            .collect();
        if self.kind == Kind::Diff {
            values.retain(|v| {
                let p = self.rows.iter().find(|p| p.name == v.name);
                v.value.is_some() && v.value != p.and_then(|p| p.object.default)
            });
        }
        let note = match (self.kind, self.rows.first()) {
            (Kind::Set, Some(p)) if p.effect() == Effect::AfterPowerCycle => Some(format!(
                "{} takes effect after a power cycle; save it first (cellrt param save) or it is lost",
                p.name
            )),
            _ => None,
        };
        Reply::Param(ParamReply {
            axis: self.axis,
            model: self.model.to_string(),
            parameters: values,
            note,
        })
    }
}

impl ParamPlan {
    /// The index of `p`'s object on this axis (axis A's index at the slot's offset).
    fn object_index(&self, p: &Parameter) -> u16 {
        let profile = cellrt_cia402::profiles::profile(self.model);
        profile
            .axis_object(p.object.index, self.slot)
            .unwrap_or(p.object.index)
    }
}

fn save_note(model: DriveModel) -> String {
    let p = cellrt_cia402::profiles::profile(model).parameters;
    match p.save {
        Ok(s) => format!(
            "saved: {} written {:08X}h ({})",
            object_text(s.object.0, s.object.1),
            s.signature,
            s.source
        ),
        Err(_) => "saved".into(),
    }
}

/// `p` as the drive answered it, its object at `index`.
fn param_value(p: &Parameter, r: &SdoReply, index: u16) -> ParamValue {
    let v = value(r);
    ParamValue {
        name: p.name.to_string(),
        symbol: p.symbol.to_string(),
        title: p.object.name.to_string(),
        object: object_text(index, p.object.sub),
        value: v,
        shown: match v {
            Some(v) => p.format(v),
            None => aborted(r).unwrap_or_default(),
        },
        default: p.object.default.map_or_else(String::new, |d| p.format(d)),
        setting: p.setting.text(p.display),
        units: p.object.unit.to_string(),
        effect: p.effect().as_str().to_string(),
    }
}

#[cfg(test)]
mod tests;
