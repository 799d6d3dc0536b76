//! Byte-exact process-data images: a PDO map declared as a table of entries, and the
//! table-driven little-endian codec between images and the typed [`RxPdo`]/[`TxPdo`].
//!
//! Entry layout and sizes follow MR-J5-G-N1 manual §4.3. The cyclic paths hold a
//! [`PdoLayout`] (the map resolved once); `PdoMap`'s own codec methods resolve it per call.

mod layout;
pub mod objects;

pub use layout::{PdoLayout, MAX_LAYOUT_ENTRIES};
pub use objects::{RxPdo, TxPdo};

use crate::shared_slice::SharedSlice;

/// One mapped object (one sub-entry of a 16xxh/1Axxh mapping object).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct PdoEntry {
    /// Object index, e.g. 0x6040; 0 is padding.
    pub index: u16,
    /// Object sub-index.
    pub sub: u8,
    /// Size in bits (a multiple of 8 for every object this crate maps).
    pub bits: u16,
}

impl PdoEntry {
    /// A mapped object.
    pub const fn object(index: u16, sub: u8, bits: u16) -> Self {
        PdoEntry { index, sub, bits }
    }

    /// Padding of `bits` bits (index 0).
    pub const fn padding(bits: u16) -> Self {
        PdoEntry {
            index: 0,
            sub: 0,
            bits,
        }
    }

    /// True for padding.
    pub const fn is_padding(&self) -> bool {
        self.index == 0
    }

    /// The entry a CoE mapping word `index << 16 | sub << 8 | bits` names (index 0: padding).
    pub const fn from_mapping_word(word: u32) -> Self {
        PdoEntry {
            index: (word >> 16) as u16,
            sub: (word >> 8) as u8,
            bits: (word & 0xFF) as u16,
        }
    }

    /// The CoE mapping word `index << 16 | sub << 8 | bits` (e.g. 60400010h), as written to
    /// 16xxh/1Axxh. Sizes above 255 bits do not occur in a mapping entry and are truncated.
    pub const fn mapping_word(&self) -> u32 {
        ((self.index as u32) << 16) | ((self.sub as u32) << 8) | (self.bits as u32 & 0xFF)
    }
}

/// A PDO mapping object (e.g. 1600h) and the entries it maps, in wire order.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct PdoMap {
    /// The mapping object index, e.g. 0x1600 or 0x1A00.
    pub index: u16,
    /// The mapped entries in order; offsets follow from the sizes.
    pub entries: SharedSlice<PdoEntry>,
}

/// A PDO image that does not fit its map.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum PdoError {
    /// The buffer is shorter than the map.
    #[error("PDO map {map:#06X}h needs {expected} bytes, buffer has {actual}")]
    Length {
        /// The mapping object index.
        map: u16,
        /// The map's byte length.
        expected: usize,
        /// The buffer's length.
        actual: usize,
    },
    /// An entry does not start or end on a byte boundary (bit-packed maps are not supported).
    #[error("PDO map {map:#06X}h: entry {index:#06X}h:{sub} is not byte aligned")]
    Unaligned {
        /// The mapping object index.
        map: u16,
        /// The entry's object index.
        index: u16,
        /// The entry's sub-index.
        sub: u8,
    },
    /// An object beside the CiA 402 fields wider than the 32 bits [`TxPdo::extras`] holds.
    #[error("PDO map {map:#06X}h maps {index:04X}h:{sub} with {bits} bits besides the CiA 402 fields; such objects may have at most 32")]
    ExtraTooWide {
        /// The mapping object index.
        map: u16,
        /// The entry's index.
        index: u16,
        /// The entry's sub-index.
        sub: u8,
        /// Its width.
        bits: u16,
    },
    /// More objects beside the CiA 402 fields than [`TxPdo::extras`] holds.
    #[error("PDO map {map:#06X}h has {extras} objects besides the CiA 402 fields, at most {max} are supported")]
    TooManyExtras {
        /// The mapping object index.
        map: u16,
        /// Its objects that no [`TxPdo`] field carries.
        extras: usize,
        /// [`objects::MAX_TX_EXTRAS`].
        max: usize,
    },
    /// More entries than a [`PdoLayout`] holds.
    #[error("PDO map {map:#06X}h has {entries} entries, at most {max} are supported")]
    TooManyEntries {
        /// The mapping object index.
        map: u16,
        /// Its entry count.
        entries: usize,
        /// [`MAX_LAYOUT_ENTRIES`].
        max: usize,
    },
}

impl PdoMap {
    /// Total size of the map in bytes (bits rounded up).
    pub fn byte_len(&self) -> usize {
        let bits: usize = self.entries.iter().map(|e| usize::from(e.bits)).sum();
        bits.div_ceil(8)
    }

    /// Byte offset of object `index:sub` in the image, if it is mapped on a byte boundary.
    pub fn offset_of(&self, index: u16, sub: u8) -> Option<usize> {
        let mut bit = 0usize;
        for e in self.entries.iter() {
            if e.index == index && e.sub == sub && !e.is_padding() {
                return bit.is_multiple_of(8).then_some(bit / 8);
            }
            bit += usize::from(e.bits);
        }
        None
    }

    /// True if the map carries a communication counter (2020h/2021h incremental counter of the
    /// MR-J3-T04, 2D23h/2D24h watchdog counter of the MR-J4-TM), i.e. [`RxPdo::counter`] and
    /// the counter among [`TxPdo::extras`] reach the wire.
    pub fn has_counter(&self) -> bool {
        self.counter_offset().is_some()
    }

    /// Byte offset of the communication counter in the image, if mapped.
    pub fn counter_offset(&self) -> Option<usize> {
        objects::COUNTER_OBJECTS
            .iter()
            .find_map(|&i| self.offset_of(i, 0))
    }

    /// True if object `index` (any sub) is mapped.
    pub fn maps(&self, index: u16) -> bool {
        index != 0 && self.entries.iter().any(|e| e.index == index)
    }

    /// Iterates `(byte offset, entry)` over the entries, for tools and tests.
    pub fn layout(&self) -> impl Iterator<Item = (usize, PdoEntry)> + '_ {
        self.entries.iter().scan(0usize, |bit, e| {
            let off = *bit / 8;
            *bit += usize::from(e.bits);
            Some((off, *e))
        })
    }

    /// Checks that an image of `len` bytes can hold this map and that every entry is byte aligned.
    pub fn check_len(&self, len: usize) -> Result<(), PdoError> {
        if let Some(e) = self.entries.iter().find(|e| !e.bits.is_multiple_of(8)) {
            return Err(PdoError::Unaligned {
                map: self.index,
                index: e.index,
                sub: e.sub,
            });
        }
        let expected = self.byte_len();
        if len < expected {
            return Err(PdoError::Length {
                map: self.index,
                expected,
                actual: len,
            });
        }
        Ok(())
    }

    /// Writes `pdo` into the first [`PdoMap::byte_len`] bytes of `buf` (trailing bytes untouched).
    ///
    /// Padding and objects `RxPdo` does not carry are written as zero.
    pub fn encode_rx(&self, pdo: &RxPdo, buf: &mut [u8]) -> Result<(), PdoError> {
        PdoLayout::new(self).encode_rx(pdo, buf)
    }

    /// Reads an [`RxPdo`] from `buf`; objects it does not carry are ignored, absent ones stay default.
    pub fn decode_rx(&self, buf: &[u8]) -> Result<RxPdo, PdoError> {
        PdoLayout::new(self).decode_rx(buf)
    }

    /// Writes `pdo` into the first [`PdoMap::byte_len`] bytes of `buf` (trailing bytes untouched).
    ///
    /// Padding and objects `TxPdo` does not carry are written as zero.
    pub fn encode_tx(&self, pdo: &TxPdo, buf: &mut [u8]) -> Result<(), PdoError> {
        PdoLayout::new(self).encode_tx(pdo, buf)
    }

    /// Reads a [`TxPdo`] from `buf`; objects it does not carry are ignored, absent ones stay default.
    pub fn decode_tx(&self, buf: &[u8]) -> Result<TxPdo, PdoError> {
        PdoLayout::new(self).decode_tx(buf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::controlword::Controlword;
    use crate::profiles::{profile, DriveModel};
    use proptest::prelude::*;

    /// The MR-J5-G-N1 default RxPDO 1600h (24 bytes).
    fn rx_1600() -> PdoMap {
        profile(DriveModel::MrJ5GN1).pdo.rx.clone()
    }

    /// The MR-J5-G-N1 default TxPDO 1A00h (24 bytes).
    fn tx_1a00() -> PdoMap {
        profile(DriveModel::MrJ5GN1).pdo.tx.clone()
    }

    const ODD: PdoMap = PdoMap {
        index: 0x1601,
        entries: SharedSlice::Static(&[
            PdoEntry::object(0x6040, 0, 16),
            PdoEntry::object(0x2000, 0, 3),
        ]),
    };

    #[test]
    fn unaligned_entries_are_rejected() {
        let mut buf = [0u8; 8];
        let e = ODD.encode_rx(&RxPdo::default(), &mut buf).unwrap_err();
        assert_eq!(
            e,
            PdoError::Unaligned {
                map: 0x1601,
                index: 0x2000,
                sub: 0
            }
        );
        assert_eq!(buf, [0u8; 8], "nothing written");
        assert!(ODD.decode_tx(&buf).is_err());
    }

    #[test]
    fn longer_buffers_keep_their_tail() {
        let mut buf = [0xAAu8; 30];
        rx_1600().encode_rx(&RxPdo::default(), &mut buf).unwrap();
        assert_eq!(&buf[24..], &[0xAA; 6]);
    }

    proptest! {
        #[test]
        fn decoding_random_bytes_never_panics(bytes in prop::collection::vec(any::<u8>(), 0..40)) {
            let rx = rx_1600().decode_rx(&bytes);
            let tx = tx_1a00().decode_tx(&bytes);
            prop_assert_eq!(rx.is_ok(), bytes.len() >= 24);
            prop_assert_eq!(tx.is_ok(), bytes.len() >= 24);
        }

        #[test]
        fn rx_round_trip(mode: i8, cw: u16, pos: i32, vel: i32, lim: u32, tq: i16) {
            let pdo = RxPdo {
                mode,
                controlword: Controlword(cw),
                target_position: pos,
                target_velocity: vel,
                velocity_limit: lim,
                target_torque: tq,
                ..RxPdo::default()
            };
            let mut buf = [0u8; 24];
            rx_1600().encode_rx(&pdo, &mut buf).unwrap();
            prop_assert_eq!(rx_1600().decode_rx(&buf).unwrap(), pdo);
        }
    }
}
