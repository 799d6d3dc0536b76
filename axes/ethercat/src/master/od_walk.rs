//! The mailbox worker's walk through a SubDevice's dictionary by SDO Information: Get OD List
//! (all objects), then per object Get Object Description and per sub-index Get Entry
//! Description (ETG.1000.6 §5.6.3.3–§5.6.3.6). One exchange per pass of the worker's loop, so
//! that the RT loop's SDOs and the SM1 drains are not held up behind a long walk.

use ethercrab::error::{Error, MailboxError};
use ethercrab::{EntryDescription, ObjectAccess, ObjectCode, ObjectDescriptionListQuery};

use super::dictionary::{DictionaryReading, NoSdoInformation, OdWalk};
use super::refusal::abort_code;
use super::worker::MailboxWorker;
use cellrt_cia402::bus::dictionary::{access_of, data_type_name};
use cellrt_cia402::bus::{DictionaryEntry, PdoMappable};

/// What one step of a walk came to.
enum Step {
    Continue,
    Done(Result<Vec<DictionaryEntry>, NoSdoInformation>),
}

/// An ethercrab error as the walk reports it, `object` naming what was read.
fn failed(object: String, e: &Error) -> NoSdoInformation {
    NoSdoInformation::Failed {
        object,
        reason: e.to_string(),
    }
}

/// True for the drive's SDO Info Error Request (the entry is absent, not the walk broken).
fn refused(e: &Error) -> bool {
    matches!(e, Error::Mailbox(MailboxError::SdoInfoAborted { .. }))
}

/// The listing's entry of an Entry Description; `object_name` where the entry has none.
fn entry_of(e: &EntryDescription, object_name: &str) -> DictionaryEntry {
    let name = String::from_utf8_lossy(&e.name).trim().to_string();
    DictionaryEntry {
        index: e.index,
        sub: e.sub_index,
        name: if name.is_empty() {
            object_name.to_string()
        } else {
            name
        },
        data_type: data_type_name(e.data_type, e.bit_length),
        bits: Some(e.bit_length),
        access: access_of(e.access.readable(), e.access.writable()),
        write_restriction: write_restriction(e.access),
        pdo: PdoMappable::from_bits(
            e.access.contains(ObjectAccess::RXPDO_MAPPABLE),
            e.access.contains(ObjectAccess::TXPDO_MAPPABLE),
        ),
    }
}

/// The states a writable entry is written in where OP is not among them, as an ESI's
/// `WriteRestrictions` names them ("PreOP", "PreOP, SafeOP").
fn write_restriction(access: ObjectAccess) -> Option<String> {
    if !access.writable() || access.contains(ObjectAccess::WRITE_OP) {
        return None;
    }
    let states: Vec<&str> = [
        (ObjectAccess::WRITE_PREOP, "PreOP"),
        (ObjectAccess::WRITE_SAFEOP, "SafeOP"),
    ]
    .iter()
    .filter(|(bit, _)| access.contains(*bit))
    .map(|&(_, name)| name)
    .collect();
    Some(states.join(", "))
}

impl MailboxWorker {
    /// Takes a request from the host if none is being walked, else walks one step further;
    /// true if it did either.
    pub(super) fn walk_dictionary_if_asked(&mut self) -> bool {
        if self.od_walk.is_none() {
            let Ok(axis) = self.shared.dictionary.requests.try_recv() else {
                return false;
            };
            match self.start_walk(axis) {
                Ok(walk) => self.od_walk = Some(walk),
                Err(e) => self.reply_dictionary(axis, Err(e)),
            }
            return true;
        }
        let Some(mut walk) = self.od_walk.take() else {
            return false;
        };
        match self.walk_step(&mut walk) {
            Step::Continue => self.od_walk = Some(walk),
            Step::Done(entries) => self.reply_dictionary(walk.axis, entries),
        }
        true
    }

    fn reply_dictionary(
        &self,
        axis: usize,
        entries: Result<Vec<DictionaryEntry>, NoSdoInformation>,
    ) {
        let _ = self
            .shared
            .dictionary
            .replies
            .try_send(DictionaryReading { axis, entries });
    }

    /// A walk of `axis`' SubDevice if its SII offers SDO Information.
    fn start_walk(&mut self, axis: usize) -> Result<OdWalk, NoSdoInformation> {
        let &(station, _) = self
            .axes
            .get(axis)
            .ok_or(NoSdoInformation::UnknownAxis(axis))?;
        let crab = &self.ethercrab;
        let offered = crab
            .group
            .subdevice(&crab.maindevice, station)
            .is_ok_and(|sd| sd.supports_sdo_info());
        if !offered {
            return Err(NoSdoInformation::NotOffered);
        }
        Ok(OdWalk {
            axis,
            station,
            objects: None,
            object: None,
            entries: Vec::new(),
        })
    }

    /// One exchange of `walk`: the OD list, an object's description or an entry's.
    fn walk_step(&mut self, walk: &mut OdWalk) -> Step {
        let (axis, station) = (walk.axis, walk.station);
        let Some(objects) = walk.objects.as_mut() else {
            let list = self.sdo_transfer(axis, station, async |sd| {
                // Out of the 128 KiB list only the indices are kept, on the heap.
                Ok(sd
                    .sdo_info_object_description_list(ObjectDescriptionListQuery::All)
                    .await?
                    .map(|l| {
                        l.iter()
                            .copied()
                            .collect::<std::collections::VecDeque<u16>>()
                    }))
            });
            return match list {
                Ok(Some(mut l)) => {
                    l.make_contiguous().sort_unstable();
                    walk.objects = Some(l);
                    Step::Continue
                }
                Ok(None) => Step::Done(Err(NoSdoInformation::NoMailbox)),
                Err(e) if refused(&e) => Step::Done(Err(NoSdoInformation::Refused {
                    code: abort_code(e),
                })),
                Err(e) => Step::Done(Err(failed("the OD list".into(), &e))),
            };
        };
        if let Some((index, name, subs)) = walk.object.as_mut() {
            let Some(sub) = subs.next() else {
                walk.object = None;
                return Step::Continue;
            };
            let index = *index;
            let entry = self.sdo_transfer(axis, station, async |sd| {
                sd.sdo_info_entry_description(index, sub).await
            });
            return match entry {
                Ok(Some(e)) => {
                    walk.entries.push(entry_of(&e, name));
                    Step::Continue
                }
                // An absent sub-index of a RECORD.
                Err(e) if refused(&e) => Step::Continue,
                Ok(None) => Step::Done(Err(NoSdoInformation::NoMailbox)),
                Err(e) => Step::Done(Err(failed(format!("entry {index:04X}h:{sub:02X}"), &e))),
            };
        }
        let Some(index) = objects.pop_front() else {
            return Step::Done(Ok(std::mem::take(&mut walk.entries)));
        };
        let object = self.sdo_transfer(axis, station, async |sd| {
            sd.sdo_info_object_description(index).await
        });
        match object {
            Ok(Some(o)) => {
                let last = match o.object_code {
                    ObjectCode::Var => 0,
                    _ => o.max_sub_index,
                };
                let name = String::from_utf8_lossy(&o.name).trim().to_string();
                walk.object = Some((index, name, 0..=last));
                Step::Continue
            }
            // Listed but not described: left out.
            Err(e) if refused(&e) => Step::Continue,
            Ok(None) => Step::Done(Err(NoSdoInformation::NoMailbox)),
            Err(e) => Step::Done(Err(failed(format!("object {index:04X}h"), &e))),
        }
    }
}
