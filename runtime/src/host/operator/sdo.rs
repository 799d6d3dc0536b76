//! `sdo`: an operator's read or write of one object of an axis' drive. Checked against the
//! drive's object dictionary (the ESI's where the axis has one, else the profile's object table)
//! before anything is sent, then carried by the RT thread's acyclic channel (EtherCAT: the
//! mailbox worker) and answered when the RT thread publishes the outcome.

use std::time::{Duration, Instant};

use cellrt_cia402::bus::{SdoData, SdoOutcome, SdoRequest};
use cellrt_cia402::profiles::facts::Range;
use cellrt_cia402::profiles::{Access, DataType};
use cellrt_ethercat::master::abort_meaning;

use super::targets::{axis_index, TargetError};
use super::wire::{SdoAnswer, SdoReply};
use crate::handoff::{UserSdo, UserSdoOutcome};
use crate::host::link::{CellLink, LinkError};
use cellrt_config::{AxisConfig, CellConfig};

/// How long the operator service waits for the drive's answer before it tells the client so;
/// below the client's reply timeout (5 s), above a mailbox round trip with its retries.
pub const SDO_ANSWER_TIMEOUT: Duration = Duration::from_secs(3);

/// An SDO request that passed the checks: what is sent and how its answer is typed.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckedSdo {
    /// Axis index.
    pub axis: usize,
    /// The request to the drive.
    pub request: SdoRequest,
    /// The reply without its outcome (names and type for the client).
    reply: SdoReply,
    data_type: DataType,
}

/// Why an `sdo` request is not sent, or got no usable answer.
#[derive(Debug, thiserror::Error)]
pub enum SdoError {
    /// The request names no axis of the cell.
    #[error("sdo: {0}")]
    Axis(#[source] TargetError),
    /// The axis' dictionary does not list the object.
    #[error(
        "sdo: object {object} is not in the object dictionary of axis '{axis}' ({dictionary})"
    )]
    NotInDictionary {
        /// `index:sub`.
        object: String,
        /// The axis.
        axis: String,
        /// The dictionary looked in (the ESI device or the profile).
        dictionary: String,
    },
    /// The object is not read or written as asked.
    #[error("sdo: {object} of axis '{axis}' ({name}) {refusal}")]
    Object {
        /// `index:sub`.
        object: String,
        /// The axis.
        axis: String,
        /// The object's name in the dictionary.
        name: String,
        /// Why not.
        refusal: ObjectRefusal,
    },
    /// The one request slot is taken.
    #[error("sdo: another sdo request is in flight; try again")]
    InFlight,
    /// The RT thread did not take the request.
    #[error("sdo: {0}")]
    Link(#[source] LinkError),
    /// The drive's answer did not come in time.
    #[error("sdo: no answer for {object} of axis '{axis}' within {timeout:?}")]
    NoAnswer {
        /// `index:sub`.
        object: String,
        /// The axis.
        axis: String,
        /// How long the service waited.
        timeout: Duration,
    },
    /// The axis' bus carries no acyclic transfers.
    #[error("sdo: axis '{axis}' has no acyclic channel to its drive")]
    NoChannel {
        /// The axis.
        axis: String,
    },
    /// A read came back as a download.
    #[error("sdo: the drive answered a read as a write")]
    ReadAnsweredAsWrite,
}

/// Why an object of the dictionary is not read or written as asked.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ObjectRefusal {
    /// A read of a write-only object.
    #[error("is write-only")]
    WriteOnly,
    /// A write of a read-only object.
    #[error("is read-only")]
    ReadOnly,
    /// A write of an object the RT thread writes every cycle.
    #[error("is mapped in the axis' RxPDO (written every cycle); not written by SDO")]
    MappedInRxPdo,
    /// A write of an object of unknown size.
    #[error("has no stated data type; its size is unknown, so it is not written")]
    Untyped,
    /// A value outside the object's data type.
    #[error("takes {data_type}: {value} is out of its range {lo}..{hi}")]
    OutOfTypeRange {
        /// The CiA 301 type name.
        data_type: &'static str,
        /// The value asked.
        value: i64,
        /// The type's least value.
        lo: i64,
        /// The type's greatest value.
        hi: i64,
    },
    /// A value outside the range the dictionary states.
    #[error("takes {lo}..{hi} (stated range): {value} is out of it")]
    OutOfStatedRange {
        /// The value asked.
        value: i64,
        /// The stated least value.
        lo: i64,
        /// The stated greatest value.
        hi: i64,
    },
    /// A type wider than an SDO value carries here.
    #[error("has {bits} bits; not written")]
    TooWide {
        /// The type's size.
        bits: u16,
    },
}

/// What the dictionary states of one object.
struct ObjectFacts {
    name: String,
    data_type: DataType,
    access: Access,
    range: Range,
}

/// `index:sub` as the manuals print it, e.g. "607Ch:00".
pub fn object_text(index: u16, sub: u8) -> String {
    format!("{index:04X}h:{sub:02X}")
}

/// Checks a read (`value` absent) or write of `index:sub` on axis `axis` against the axis'
/// dictionary; the reason where it must not be sent.
pub fn check(
    cell: &CellConfig,
    axis: &str,
    index: u16,
    sub: u8,
    value: Option<i64>,
) -> Result<CheckedSdo, SdoError> {
    let i = axis_index(cell, axis).map_err(SdoError::Axis)?;
    let a = &cell.axes.on_loop()[i];
    let facts = object_facts(a, index, sub).ok_or_else(|| SdoError::NotInDictionary {
        object: object_text(index, sub),
        axis: axis.to_string(),
        dictionary: dictionary_name(a),
    })?;
    let named = |refusal| SdoError::Object {
        object: object_text(index, sub),
        axis: axis.to_string(),
        name: facts.name.clone(),
        refusal,
    };
    let request = match value {
        None if facts.access == Access::Wo => return Err(named(ObjectRefusal::WriteOnly)),
        None => SdoRequest::Upload { index, sub },
        Some(_) if facts.access == Access::Ro => return Err(named(ObjectRefusal::ReadOnly)),
        Some(_) if a.profile.pdo.rx.maps(index) => return Err(named(ObjectRefusal::MappedInRxPdo)),
        Some(v) => SdoRequest::Download {
            index,
            sub,
            data: encode(v, &facts).map_err(named)?,
        },
    };
    Ok(CheckedSdo {
        axis: i,
        request,
        reply: SdoReply {
            axis: axis.to_string(),
            index,
            sub,
            name: facts.name,
            data_type: facts.data_type.cia301_name().to_string(),
            bits: facts.data_type.bits().unwrap_or(0),
            outcome: SdoAnswer::Written { value: 0 },
        },
        data_type: facts.data_type,
    })
}

/// The dictionary entry of `index:sub`: the ESI's where the axis has one, else the profile's
/// (an object at another slot's offset of a multi-axis unit typed as its axis-A object); an
/// empty profile table lists nothing, and then any object is read untyped.
fn object_facts(a: &AxisConfig, index: u16, sub: u8) -> Option<ObjectFacts> {
    if let Some(esi) = &a.esi {
        let o = esi.object(index, sub)?;
        return Some(ObjectFacts {
            name: o.name.clone(),
            data_type: o.coe_type(),
            access: o.access,
            range: Range::Type,
        });
    }
    let base = a.profile.object_slot(index).map_or(index, |(_, b)| b);
    match a.profile.object(base, sub) {
        Some(o) => Some(ObjectFacts {
            name: o.name.to_string(),
            data_type: o.data_type,
            access: o.access,
            range: o.range,
        }),
        None if a.profile.objects.is_empty() => Some(ObjectFacts {
            name: String::new(),
            data_type: DataType::Unstated,
            access: Access::Unstated,
            range: Range::Type,
        }),
        None => None,
    }
}

fn dictionary_name(a: &AxisConfig) -> String {
    match &a.esi {
        Some(esi) => format!("ESI device {}", esi.name),
        None => a.profile.name.to_string(),
    }
}

/// `v` as the object's bytes, within its type's and the dictionary's stated range.
fn encode(v: i64, facts: &ObjectFacts) -> Result<SdoData, ObjectRefusal> {
    let t = facts.data_type;
    let (Some((lo, hi)), Some(bits)) = (t.value_range(), t.bits()) else {
        return Err(ObjectRefusal::Untyped);
    };
    if !(lo..=hi).contains(&v) {
        return Err(ObjectRefusal::OutOfTypeRange {
            data_type: t.cia301_name(),
            value: v,
            lo,
            hi,
        });
    }
    if facts.range.refuses(v) {
        let (lo, hi) = facts.range.bounds().unwrap_or((lo, hi));
        return Err(ObjectRefusal::OutOfStatedRange { value: v, lo, hi });
    }
    let bytes = v.to_le_bytes();
    let len = usize::from(bits.div_ceil(8));
    SdoData::new(&bytes[..len]).ok_or(ObjectRefusal::TooWide { bits })
}

/// `raw` as the object's type holds it (the master types by the profile, which an ESI axis
/// may not list).
fn typed(raw: i64, t: DataType) -> i64 {
    match t {
        DataType::Bool | DataType::U8 => i64::from(raw as u8),
        DataType::I8 => i64::from(raw as i8),
        DataType::I16 => i64::from(raw as i16),
        DataType::U16 => i64::from(raw as u16),
        DataType::I32 => i64::from(raw as i32),
        DataType::U32 => i64::from(raw as u32),
        DataType::VisibleString { .. } | DataType::Unstated => raw,
    }
}

/// The operator service's one SDO request in flight.
#[derive(Debug)]
pub struct SdoInFlight {
    last_seq: u16,
    current: Option<(u16, CheckedSdo, Instant)>,
    timeout: Duration,
}

impl Default for SdoInFlight {
    fn default() -> Self {
        SdoInFlight::with_timeout(SDO_ANSWER_TIMEOUT)
    }
}

impl SdoInFlight {
    /// Waits `timeout` for each answer ([`SDO_ANSWER_TIMEOUT`] by default).
    pub fn with_timeout(timeout: Duration) -> Self {
        SdoInFlight {
            last_seq: 0,
            current: None,
            timeout,
        }
    }

    /// True while a request waits for its answer.
    pub fn busy(&self) -> bool {
        self.current.is_some()
    }

    /// Hands `checked` to the RT thread.
    pub fn start(&mut self, link: &mut dyn CellLink, checked: CheckedSdo) -> Result<(), SdoError> {
        if self.busy() {
            return Err(SdoError::InFlight);
        }
        let seq = self.last_seq.wrapping_add(1).max(1);
        link.sdo(UserSdo {
            seq,
            axis: checked.axis as u16,
            request: checked.request,
        })
        .map_err(SdoError::Link)?;
        self.last_seq = seq;
        self.current = Some((seq, checked, Instant::now() + self.timeout));
        Ok(())
    }

    /// The answer of the request in flight once the RT thread published it, or the refusal
    /// after the timeout: `Ok` the drive's answer, `Err` a reason.
    pub fn poll(&mut self, link: &mut dyn CellLink) -> Option<Result<SdoReply, SdoError>> {
        let (seq, checked, deadline) = self.current.as_ref()?;
        let outcome = match link.sdo_outcome(*seq) {
            Some(o) => o,
            None if Instant::now() < *deadline => return None,
            None => {
                let r = &checked.reply;
                let e = SdoError::NoAnswer {
                    object: object_text(r.index, r.sub),
                    axis: r.axis.clone(),
                    timeout: self.timeout,
                };
                self.current = None;
                return Some(Err(e));
            }
        };
        let (_, checked, _) = self.current.take()?;
        Some(answer(checked, outcome))
    }
}

fn answer(checked: CheckedSdo, outcome: UserSdoOutcome) -> Result<SdoReply, SdoError> {
    let mut reply = checked.reply;
    reply.outcome = match (outcome, checked.request) {
        (UserSdoOutcome::Unsupported, _) => return Err(SdoError::NoChannel { axis: reply.axis }),
        (UserSdoOutcome::Done(SdoOutcome::Uploaded(v)), _) => SdoAnswer::Read {
            value: typed(v, checked.data_type),
        },
        (UserSdoOutcome::Done(SdoOutcome::Aborted(code)), _) => SdoAnswer::Aborted {
            code,
            meaning: abort_meaning(code).to_string(),
        },
        (UserSdoOutcome::Done(SdoOutcome::Downloaded), SdoRequest::Download { data, .. }) => {
            let mut raw = [0u8; 8];
            raw[..data.as_slice().len()].copy_from_slice(data.as_slice());
            SdoAnswer::Written {
                value: typed(i64::from_le_bytes(raw), checked.data_type),
            }
        }
        (UserSdoOutcome::Done(SdoOutcome::Downloaded), SdoRequest::Upload { .. }) => {
            return Err(SdoError::ReadAnsweredAsWrite)
        }
    };
    Ok(reply)
}

#[cfg(test)]
pub(super) mod tests;
