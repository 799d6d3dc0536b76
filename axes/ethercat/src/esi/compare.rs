//! A live drive's object dictionary (read through SDO Information) against its ESI: the
//! entries the ESI describes that the drive lacks, those whose size, access or PDO
//! mappability differ, and the drive's entries the ESI leaves out (a note, not a fault: an ESI
//! need not list every object).

use serde::Serialize;

use super::device::EsiDevice;
use cellrt_cia402::bus::dictionary::{DictionaryEntry, PdoMappable};
use cellrt_cia402::profiles::Access;

/// One entry, `index:sub`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
pub struct EntryId {
    /// Object index.
    pub index: u16,
    /// Sub-index.
    pub sub: u8,
}

impl std::fmt::Display for EntryId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:04X}h:{:02}", self.index, self.sub)
    }
}

/// An entry both describe, with a fact they disagree on.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct EntryMismatch {
    /// The entry.
    pub entry: EntryId,
    /// What differs, e.g. "access: ESI rw, drive ro".
    pub what: String,
}

/// The outcome of [`compare`].
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct DictionaryComparison {
    /// Entries the ESI describes that the drive does not list.
    pub missing_on_drive: Vec<EntryId>,
    /// Entries both describe, differently.
    pub mismatches: Vec<EntryMismatch>,
    /// Entries the drive lists that the ESI leaves out.
    pub not_in_esi: Vec<EntryId>,
    /// Entries both describe alike.
    pub agreeing: usize,
}

impl DictionaryComparison {
    /// True if the drive has every entry the ESI describes, as the ESI describes it.
    pub fn conforms(&self) -> bool {
        self.missing_on_drive.is_empty() && self.mismatches.is_empty()
    }
}

fn access_text(a: Access) -> &'static str {
    match a {
        Access::Ro => "ro",
        Access::Rw => "rw",
        Access::Wo => "wo",
        Access::Unstated => "unstated",
    }
}

/// `live` (the drive's entries) against the dictionary of `esi`. Facts one side leaves
/// unstated are not compared.
pub fn compare(esi: &EsiDevice, live: &[DictionaryEntry]) -> DictionaryComparison {
    let mut out = DictionaryComparison::default();
    for o in &esi.objects {
        let id = EntryId {
            index: o.index,
            sub: o.sub,
        };
        let Some(d) = live.iter().find(|d| d.index == o.index && d.sub == o.sub) else {
            out.missing_on_drive.push(id);
            continue;
        };
        let mut differs = Vec::new();
        if let Some(bits) = d.bits.filter(|&b| b != o.bits && o.bits != 0) {
            differs.push(format!("bit length: ESI {}, drive {bits}", o.bits));
        }
        if o.access != Access::Unstated && d.access != Access::Unstated && o.access != d.access {
            differs.push(format!(
                "access: ESI {}, drive {}",
                access_text(o.access),
                access_text(d.access)
            ));
        }
        let esi_pdo = PdoMappable::from_bits(o.pdo.rx, o.pdo.tx);
        if d.pdo != PdoMappable::Unstated && d.pdo != esi_pdo {
            differs.push(format!(
                "PDO mapping: ESI {}, drive {}",
                esi_pdo.as_str(),
                d.pdo.as_str()
            ));
        }
        if differs.is_empty() {
            out.agreeing += 1;
        } else {
            out.mismatches.push(EntryMismatch {
                entry: id,
                what: differs.join("; "),
            });
        }
    }
    out.not_in_esi = live
        .iter()
        .filter(|d| esi.object(d.index, d.sub).is_none())
        .map(|d| EntryId {
            index: d.index,
            sub: d.sub,
        })
        .collect();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn esi() -> EsiDevice {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/esi/mr-j4-tm.xml");
        super::super::load(&path).unwrap().remove(0)
    }

    /// The drive's list as SDO Information would give it: every ESI entry as described.
    fn live_of(d: &EsiDevice) -> Vec<DictionaryEntry> {
        d.objects
            .iter()
            .map(|o| DictionaryEntry {
                index: o.index,
                sub: o.sub,
                name: o.name.clone(),
                data_type: o.data_type.clone(),
                bits: Some(o.bits),
                access: o.access,
                write_restriction: None,
                pdo: PdoMappable::from_bits(o.pdo.rx, o.pdo.tx),
            })
            .collect()
    }

    #[test]
    fn a_drive_as_its_esi_describes_it_conforms() {
        let d = esi();
        let mut live = live_of(&d);
        live.push(DictionaryEntry {
            index: 0x1000,
            sub: 0,
            name: "Device type".into(),
            data_type: "UNSIGNED32".into(),
            bits: Some(32),
            access: Access::Ro,
            write_restriction: None,
            pdo: PdoMappable::No,
        });
        let c = compare(&d, &live);
        assert!(c.conforms(), "{c:?}");
        assert_eq!(c.agreeing, d.objects.len());
        // 1000h is not in this ESI's dictionary: a note, not a fault.
        assert!(d.object(0x1000, 0).is_none());
        assert_eq!(
            c.not_in_esi,
            [EntryId {
                index: 0x1000,
                sub: 0
            }]
        );
    }

    #[test]
    fn a_missing_entry_and_each_differing_fact_are_named() {
        let d = esi();
        let mut live = live_of(&d);
        // 6041h Statusword: ro and TxPDO-mappable in the ESI (MR-J4-TM §5.1).
        let sw = live.iter_mut().find(|e| e.index == 0x6041).unwrap();
        sw.access = Access::Rw;
        sw.pdo = PdoMappable::No;
        sw.bits = Some(32);
        live.retain(|e| e.index != 0x6040);
        let c = compare(&d, &live);
        assert!(!c.conforms());
        assert_eq!(
            c.missing_on_drive,
            [EntryId {
                index: 0x6040,
                sub: 0
            }]
        );
        assert_eq!(c.mismatches.len(), 1);
        assert_eq!(
            c.mismatches[0].what,
            "bit length: ESI 16, drive 32; access: ESI ro, drive rw; PDO mapping: ESI TxPDO, drive -"
        );
        assert_eq!(c.mismatches[0].entry.to_string(), "6041h:00");
    }
}
