//! Variable PDO mapping: a model's profile running a mapping other than its default maps, and
//! the checks a mapping must pass against the model's [`PdoRules`] (entry count, byte length,
//! mappable objects). One definition used by configuration (`[axes.pdo]`), the simulated drive
//! and the EtherCAT SubDevice emulator's CoE server.

use super::{DriveProfile, PdoRules};
use crate::pdo::{PdoEntry, PdoMap};

/// The direction of a PDO.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, strum::IntoStaticStr)]
pub enum PdoDirection {
    /// RxPDO, master → drive (16xxh).
    #[strum(serialize = "RxPDO")]
    Rx,
    /// TxPDO, drive → master (1Axxh).
    #[strum(serialize = "TxPDO")]
    Tx,
}

impl PdoDirection {
    /// "RxPDO" or "TxPDO".
    pub fn name(self) -> &'static str {
        self.into()
    }
}

/// Why a mapping does not fit the model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum MappingError {
    /// More entries than a mapping object holds.
    #[error("{direction} of {model} maps {entries} entries, the drive takes at most {max}", direction = .direction.name())]
    TooManyEntries {
        /// The PDO.
        direction: PdoDirection,
        /// The model name.
        model: &'static str,
        /// Entries given.
        entries: usize,
        /// [`PdoRules::max_entries`].
        max: u8,
    },
    /// An object the model cannot map into this PDO.
    #[error("{model} cannot map object {index:04X}h:{sub:02X} into the {direction}", direction = .direction.name())]
    NotMappable {
        /// The PDO.
        direction: PdoDirection,
        /// The model name.
        model: &'static str,
        /// Object index.
        index: u16,
        /// Sub-index.
        sub: u8,
    },
    /// Padding whose length is not 0, 8, 16, 24 or 32 bits, or an object not a whole number of bytes.
    #[error("{direction} entry {index:04X}h:{sub:02X} of {bits} bits is not byte aligned", direction = .direction.name())]
    Unaligned {
        /// The PDO.
        direction: PdoDirection,
        /// Object index (0 for padding).
        index: u16,
        /// Sub-index.
        sub: u8,
        /// Length in bits.
        bits: u16,
    },
    /// The mapping is longer than the PDO allows.
    #[error("{direction} of {model} would be {bytes} bytes, the drive takes at most {max}", direction = .direction.name())]
    TooLong {
        /// The PDO.
        direction: PdoDirection,
        /// The model name.
        model: &'static str,
        /// The mapping's length.
        bytes: usize,
        /// The limit.
        max: u16,
    },
}

impl MappingError {
    /// The PDO the error is about.
    pub fn direction(&self) -> PdoDirection {
        match *self {
            MappingError::TooManyEntries { direction, .. }
            | MappingError::NotMappable { direction, .. }
            | MappingError::Unaligned { direction, .. }
            | MappingError::TooLong { direction, .. } => direction,
        }
    }

    /// The SDO abort code the model answers this with.
    pub fn abort_code(&self, rules: &PdoRules) -> u32 {
        match self {
            MappingError::TooManyEntries { .. } => 0x0609_0011,
            MappingError::NotMappable { .. } | MappingError::Unaligned { .. } => {
                rules.not_mappable_abort
            }
            MappingError::TooLong { .. } => rules.too_long_abort,
        }
    }
}

impl DriveProfile {
    /// True if `index:sub` may be mapped into the `direction` PDO: the model's default map
    /// carries it, the manual's list names it, or the object table marks it mappable.
    pub fn mappable(&self, direction: PdoDirection, index: u16, sub: u8) -> bool {
        let (default, listed, kind) = match direction {
            PdoDirection::Rx => (
                &base_of(self).pdo.rx,
                self.pdo.rules.rx_mappable,
                super::Pdo::Rx,
            ),
            PdoDirection::Tx => (
                &base_of(self).pdo.tx,
                self.pdo.rules.tx_mappable,
                super::Pdo::Tx,
            ),
        };
        default
            .entries
            .iter()
            .any(|e| e.index == index && e.sub == sub)
            || (sub == 0 && listed.contains(&index))
            || self.object(index, sub).is_some_and(|o| o.pdo == kind)
    }

    /// Checks one mapping entry (padding: 0, 8, 16, 24 or 32 bits; objects: mappable, whole bytes).
    pub fn check_mapping_entry(
        &self,
        direction: PdoDirection,
        entry: PdoEntry,
    ) -> Result<(), MappingError> {
        if entry.is_padding() {
            if entry.bits > 32 || !entry.bits.is_multiple_of(8) {
                return Err(MappingError::Unaligned {
                    direction,
                    index: 0,
                    sub: entry.sub,
                    bits: entry.bits,
                });
            }
            return Ok(());
        }
        if !self.mappable(direction, entry.index, entry.sub) {
            return Err(MappingError::NotMappable {
                direction,
                model: self.model.as_str(),
                index: entry.index,
                sub: entry.sub,
            });
        }
        if entry.bits == 0 || !entry.bits.is_multiple_of(8) {
            return Err(MappingError::Unaligned {
                direction,
                index: entry.index,
                sub: entry.sub,
                bits: entry.bits,
            });
        }
        Ok(())
    }

    /// Checks a whole mapping against the model's rules.
    pub fn check_mapping(
        &self,
        direction: PdoDirection,
        entries: &[PdoEntry],
    ) -> Result<(), MappingError> {
        let rules = &self.pdo.rules;
        if entries.len() > usize::from(rules.max_entries) {
            return Err(MappingError::TooManyEntries {
                direction,
                model: self.model.as_str(),
                entries: entries.len(),
                max: rules.max_entries,
            });
        }
        for e in entries {
            self.check_mapping_entry(direction, *e)?;
        }
        let bytes = entries.iter().map(|e| usize::from(e.bits)).sum::<usize>() / 8;
        let max = match direction {
            PdoDirection::Rx => rules.max_rx_bytes,
            PdoDirection::Tx => rules.max_tx_bytes,
        };
        if bytes > usize::from(max) {
            return Err(MappingError::TooLong {
                direction,
                model: self.model.as_str(),
                bytes,
                max,
            });
        }
        Ok(())
    }

    /// This model's profile running `rx` and `tx` in its default mapping objects instead of
    /// the default entries (checked against [`PdoRules`]): an owned profile, built off the RT
    /// path by whoever remaps (the configuration, the simulated drive's CoE server).
    pub fn with_pdo_maps(
        &self,
        rx: &[PdoEntry],
        tx: &[PdoEntry],
    ) -> Result<DriveProfile, MappingError> {
        self.check_mapping(PdoDirection::Rx, rx)?;
        self.check_mapping(PdoDirection::Tx, tx)?;
        let remap = |map: &PdoMap, entries: &[PdoEntry]| PdoMap {
            index: map.index,
            entries: if map.entries == entries {
                map.entries.clone()
            } else {
                entries.into()
            },
        };
        Ok(DriveProfile {
            pdo: super::PdoFacts {
                rx: remap(&self.pdo.rx, rx),
                tx: remap(&self.pdo.tx, tx),
                ..self.pdo.clone()
            },
            ..self.clone()
        })
    }

    /// This profile presenting `vendor_id` / `product_code` in 1018h where given (the cell
    /// config's `[axes.ethercat]` identity: what the emulator presents and the master
    /// expects), the profile's own values elsewhere.
    pub fn with_identity(&self, vendor_id: Option<u32>, product_code: Option<u32>) -> DriveProfile {
        let identity = super::Identity {
            vendor_id: vendor_id.or(self.identity.vendor_id),
            product_code: product_code.or(self.identity.product_code),
            revision: self.identity.revision,
            source: if vendor_id.is_some() || product_code.is_some() {
                "cell config [axes.ethercat]"
            } else {
                self.identity.source
            },
            ..self.identity
        };
        DriveProfile {
            identity,
            ..self.clone()
        }
    }

    /// True if this profile runs its model's default maps.
    pub fn default_mapping(&self) -> bool {
        let base = base_of(self);
        self.pdo.rx == base.pdo.rx && self.pdo.tx == base.pdo.tx
    }
}

/// The model's own (default-mapped) profile.
fn base_of(p: &DriveProfile) -> &'static DriveProfile {
    super::profile(p.model)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profiles::{profile, DriveModel};

    #[test]
    fn a_remapped_profile_owns_its_maps_and_the_default_is_the_same_profile() {
        let p = profile(DriveModel::MrJ5GN1);
        let same = p
            .with_pdo_maps(&p.pdo.rx.entries, &p.pdo.tx.entries)
            .unwrap();
        assert_eq!(*p, same);
        let rx = &p.pdo.rx.entries[..3];
        let a = p.with_pdo_maps(rx, &p.pdo.tx.entries).unwrap();
        let b = p.with_pdo_maps(rx, &p.pdo.tx.entries).unwrap();
        assert_eq!(a, b);
        assert_eq!(a.pdo.rx.entries, rx);
        assert_eq!(a.pdo.rx.index, p.pdo.rx.index);
        assert!(!a.default_mapping() && p.default_mapping());
    }

    #[test]
    fn mappings_are_checked_against_the_models_rules() {
        let j3 = profile(DriveModel::MrJ3T04);
        // MR-J3-T04 TV-PDO-1 (docs/test-vectors.md): 6041h cannot go into the RxPDO (0604 0041h) ...
        let e = j3
            .check_mapping(PdoDirection::Rx, &[PdoEntry::object(0x6041, 0, 16)])
            .unwrap_err();
        assert_eq!(e.abort_code(&j3.pdo.rules), 0x0604_0041);
        assert!(e.to_string().contains("6041h:00"), "{e}");
        // ... and 32 bytes exceed its 30 (0604 0042h).
        let long = [PdoEntry::object(0x607A, 0, 32); 8];
        let e = j3.check_mapping(PdoDirection::Rx, &long).unwrap_err();
        assert_eq!(e.abort_code(&j3.pdo.rules), 0x0604_0042);
        // Padding of 8 bits is allowed, of 12 bits not.
        j3.check_mapping(
            PdoDirection::Rx,
            &[PdoEntry::padding(8), PdoEntry::object(0x60FF, 0, 32)],
        )
        .unwrap();
        assert!(j3
            .check_mapping(PdoDirection::Rx, &[PdoEntry::padding(12)])
            .is_err());
        // The MR-J5 answers what it cannot map with 0604 0043h (its only listed code).
        let j5 = profile(DriveModel::MrJ5GN1);
        let e = j5
            .check_mapping(PdoDirection::Tx, &[PdoEntry::object(0x6040, 0, 16)])
            .unwrap_err();
        assert_eq!(e.abort_code(&j5.pdo.rules), 0x0604_0043);
        assert!(j5.mappable(PdoDirection::Rx, 0x6040, 0));
    }
}
