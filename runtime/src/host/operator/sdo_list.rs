//! `sdo_list`: an axis' object dictionary on a running cell. On an EtherCAT drive that offers
//! SDO Information the mailbox worker reads it from the drive (ETG.1000.6 §5.6.3); elsewhere —
//! a simulated drive, an MR-JE-C over Modbus/SLMP, a SubDevice without SDO Information or one
//! that refuses it — the list is the drive profile's own table (the ESI's where the axis has
//! one), and the reply says which and why. The service thread never waits for the walk: the
//! request starts it, a later pass answers the client.

use std::time::{Duration, Instant};

use cellrt_cia402::bus::{DictionaryEntry, DictionarySource, PdoMappable};
use cellrt_config::{AxisConfig, AxisRef, CellConfig};
use cellrt_fieldbus::mr_je_c::objects::DICTIONARY as JE_C_DICTIONARY;
use cellrt_fieldbus::mr_je_c::SoftwareVersion;
use serde::{Deserialize, Serialize};

use super::targets::{axis_ref, TargetError};
use crate::host::link::CellLink;

/// How long a walk may take: one SDO Information exchange per entry, each a few mailbox
/// frames carried one per cycle (below the client's 30 s for requests of many transfers).
pub const WALK_TIMEOUT: Duration = Duration::from_secs(25);

/// The answer to `sdo_list`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct SdoListReply {
    /// Axis name.
    pub axis: String,
    /// Where the list came from.
    pub source: DictionarySource,
    /// Why the list is not the drive's own (set when `source` is the profile).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fallback: Option<String>,
    /// The dictionary the profile list is (e.g. "Mitsubishi MR-J4-TM"), or the drive's.
    pub dictionary: String,
    /// The entries, in index and sub-index order.
    pub entries: Vec<DictionaryEntry>,
}

/// Why an `sdo_list` request gets no list.
#[derive(Debug, thiserror::Error)]
pub enum SdoListError {
    /// The request names no axis of the cell.
    #[error("sdo list: {0}")]
    Axis(#[from] TargetError),
    /// Another client's list is being read.
    #[error("sdo list: a dictionary is being read for another request; try again")]
    InProgress,
    /// The mailbox worker did not finish in time.
    #[error("sdo list: axis '{axis}': the drive's dictionary was not read within {} s", .timeout.as_secs())]
    NoReading {
        /// The axis.
        axis: String,
        /// How long the service waited.
        timeout: Duration,
    },
}

/// The walk in progress: the axis, its slot on the bus and when it started.
#[derive(Debug)]
struct Walk {
    axis: String,
    slot: usize,
    started: Instant,
}

/// The `sdo_list` request being answered.
#[derive(Debug, Default)]
pub struct ListInFlight {
    walk: Option<Walk>,
}

/// What a request leads to at once.
#[derive(Debug)]
pub enum ListStart {
    /// The answer (no walk needed).
    Answered(Box<SdoListReply>),
    /// The mailbox worker walks the drive's dictionary; [`ListInFlight::poll`] answers.
    Walking,
}

impl ListInFlight {
    /// Answers from the profile where the drive cannot be asked, else starts the walk.
    pub fn start(
        &mut self,
        link: &dyn CellLink,
        cell: &CellConfig,
        axis: &str,
    ) -> Result<ListStart, SdoListError> {
        let at = axis_ref(cell, axis)?;
        let slot = match at {
            AxisRef::Link(k) => {
                let why = "MR-JE-C is driven over Modbus/SLMP: no CoE SDO Information";
                return Ok(ListStart::Answered(Box::new(je_c_reply(cell, k, why))));
            }
            AxisRef::Loop(i) => i,
        };
        let a = &cell.axes.on_loop()[slot];
        let Some(reader) = link.dictionary_reader() else {
            let why = match cell.ethercat {
                None => "a simulated drive: no EtherCAT SDO Information",
                Some(_) => "the operator service runs outside the controller: its EtherCAT master is not reachable for SDO Information",
            };
            return Ok(ListStart::Answered(Box::new(profile_reply(a, why))));
        };
        if self.walk.is_some() || !reader.request(slot) {
            return Err(SdoListError::InProgress);
        }
        self.walk = Some(Walk {
            axis: axis.to_string(),
            slot,
            started: Instant::now(),
        });
        Ok(ListStart::Walking)
    }

    /// The list once walked (the profile's where the drive had no SDO Information), or the
    /// timeout; `None` while the walk goes on (or none does).
    pub fn poll(
        &mut self,
        link: &dyn CellLink,
        cell: &CellConfig,
    ) -> Option<Result<SdoListReply, SdoListError>> {
        let walk = self.walk.as_ref()?;
        let a = &cell.axes.on_loop()[walk.slot];
        let reading = link
            .dictionary_reader()
            .and_then(|r| r.take())
            .filter(|r| r.axis == walk.slot);
        let walk = match reading {
            Some(reading) => {
                let walk = self.walk.take()?;
                return Some(Ok(match reading.entries {
                    Ok(entries) => SdoListReply {
                        axis: walk.axis,
                        source: DictionarySource::SdoInformation,
                        fallback: None,
                        dictionary: dictionary_name(a),
                        entries,
                    },
                    Err(why) => profile_reply(a, &why.to_string()),
                }));
            }
            None if walk.started.elapsed() < WALK_TIMEOUT => return None,
            None => self.walk.take()?,
        };
        Some(Err(SdoListError::NoReading {
            axis: walk.axis,
            timeout: WALK_TIMEOUT,
        }))
    }
}

fn dictionary_name(a: &AxisConfig) -> String {
    match &a.esi {
        Some(esi) => format!("ESI device {}", esi.name),
        None => a.profile.name.to_string(),
    }
}

/// The list of the axis' ESI, else its profile's table; `why` the drive was not asked.
fn profile_reply(a: &AxisConfig, why: &str) -> SdoListReply {
    let mut entries: Vec<DictionaryEntry> = match &a.esi {
        Some(esi) => esi
            .objects
            .iter()
            .map(|o| {
                let t = o.coe_type();
                DictionaryEntry {
                    index: o.index,
                    sub: o.sub,
                    name: o.name.clone(),
                    data_type: t.cia301_name().to_string(),
                    bits: Some(o.bits),
                    access: o.access,
                    write_restriction: o.write_restriction.clone(),
                    pdo: PdoMappable::from_bits(o.pdo.rx, o.pdo.tx),
                }
            })
            .collect(),
        None => a
            .profile
            .all_objects()
            .map(DictionaryEntry::from_profile)
            .collect(),
    };
    sorted(&mut entries);
    SdoListReply {
        axis: a.name.clone(),
        source: DictionarySource::Profile,
        fallback: Some(why.to_string()),
        dictionary: dictionary_name(a),
        entries,
    }
}

/// The MR-JE-C dictionary table (MR-JE-C manual §7.3) of link axis `k`, software A4.
fn je_c_reply(cell: &CellConfig, k: usize, why: &str) -> SdoListReply {
    let sw = SoftwareVersion::default();
    let mut entries = Vec::new();
    for o in JE_C_DICTIONARY.iter().filter(|o| o.since <= sw) {
        for index in o.first..=o.last {
            for (sub, s) in o.each_sub(sw) {
                entries.push(DictionaryEntry {
                    index,
                    sub,
                    name: if s.name.is_empty() { o.name } else { s.name }.to_string(),
                    data_type: s.ty.cia301_name().to_string(),
                    bits: s.ty.bits(),
                    access: s.access,
                    write_restriction: None,
                    pdo: PdoMappable::from_bits(false, s.mappable),
                });
            }
        }
    }
    sorted(&mut entries);
    SdoListReply {
        axis: cell.axes.on_link()[k].name.clone(),
        source: DictionarySource::Profile,
        fallback: Some(why.to_string()),
        dictionary: "Mitsubishi MR-JE-C".to_string(),
        entries,
    }
}

/// In index and sub-index order, each entry once.
fn sorted(entries: &mut Vec<DictionaryEntry>) {
    entries.sort_by_key(|e| (e.index, e.sub));
    entries.dedup_by_key(|e| (e.index, e.sub));
}
