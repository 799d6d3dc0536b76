//! A [`PdoMap`] resolved once into fixed byte offsets, widths and typed fields, so encoding and
//! decoding a cycle's image is a straight run of fixed-width little-endian reads and writes
//! (no per-cycle walk of the entry table, no object lookups, no allocation).

use super::objects::{RxField, TxField, MAX_TX_EXTRAS};
use super::{PdoError, PdoMap, RxPdo, TxPdo};

/// Most entries a layout holds (a CoE mapping object has at most 254; the maps in the
/// specs hold under 16).
pub const MAX_LAYOUT_ENTRIES: usize = 32;

/// One entry of the image at its byte offset.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
struct Slot {
    offset: u16,
    bytes: u8,
    bits: u16,
    /// The RxPDO field this entry carries (`None`: padding or an object the view lacks).
    rx: Option<RxField>,
    /// The TxPDO field this entry carries.
    tx: Option<TxField>,
    /// An object (not padding) that no [`TxPdo`] field carries: in a TxPDO, one of
    /// [`TxPdo::extras`], found by `index:sub`.
    extra: bool,
    index: u16,
    sub: u8,
}

/// A PDO map with its entries resolved to offsets and fields; build once, use every cycle.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PdoLayout {
    map: PdoMap,
    /// Why the map cannot be laid out; every encode and decode then returns it.
    invalid: Option<PdoError>,
    byte_len: usize,
    len: usize,
    /// Why this map cannot be a TxPDO image even if it can be laid out (more objects beside
    /// the CiA 402 fields than [`TxPdo::extras`] holds, or one wider than 32 bits): found once
    /// here, not by a walk of the entries every cycle.
    invalid_tx: Option<PdoError>,
    slots: [Slot; MAX_LAYOUT_ENTRIES],
}

impl PdoLayout {
    /// Resolves `map`. A map that cannot be laid out (an entry not byte aligned, more than
    /// [`MAX_LAYOUT_ENTRIES`] entries) gives a layout whose every encode and decode returns
    /// that error (see [`PdoLayout::error`]).
    pub fn new(map: &PdoMap) -> Self {
        let mut layout = PdoLayout {
            map: map.clone(),
            invalid: None,
            byte_len: map.byte_len(),
            len: 0,
            invalid_tx: None,
            slots: [Slot::default(); MAX_LAYOUT_ENTRIES],
        };
        if let Err(e) = map.check_len(map.byte_len()) {
            layout.invalid = Some(e);
            return layout;
        }
        if map.entries.len() > MAX_LAYOUT_ENTRIES {
            layout.invalid = Some(PdoError::TooManyEntries {
                map: map.index,
                entries: map.entries.len(),
                max: MAX_LAYOUT_ENTRIES,
            });
            return layout;
        }
        for ((offset, e), slot) in map.layout().zip(layout.slots.iter_mut()) {
            let padding = e.is_padding();
            let tx = if padding {
                None
            } else {
                TxField::of(e.index, e.sub)
            };
            let extra = !padding && tx.is_none();
            *slot = Slot {
                offset: offset as u16,
                bytes: (e.bits / 8) as u8,
                bits: e.bits,
                rx: if padding {
                    None
                } else {
                    RxField::of(e.index, e.sub)
                },
                tx,
                extra,
                index: e.index,
                sub: e.sub,
            };
        }
        layout.len = map.entries.len();
        layout.invalid_tx = layout.tx_error();
        layout
    }

    /// Why the laid-out map cannot be a TxPDO image, if it cannot.
    fn tx_error(&self) -> Option<PdoError> {
        let extras = self.slots().iter().filter(|s| s.extra).count();
        if extras > MAX_TX_EXTRAS {
            return Some(PdoError::TooManyExtras {
                map: self.map.index,
                extras,
                max: MAX_TX_EXTRAS,
            });
        }
        let s = self.slots().iter().find(|s| s.extra && s.bits > 32)?;
        Some(PdoError::ExtraTooWide {
            map: self.map.index,
            index: s.index,
            sub: s.sub,
            bits: s.bits,
        })
    }

    /// Why this map cannot be laid out, if it cannot.
    pub fn error(&self) -> Option<PdoError> {
        self.invalid
    }

    /// The map this layout was built from.
    pub fn map(&self) -> &PdoMap {
        &self.map
    }

    /// Image size in bytes.
    pub fn byte_len(&self) -> usize {
        self.byte_len
    }

    /// Checks that an image of `len` bytes fits this (valid) map.
    pub fn check_len(&self, len: usize) -> Result<(), PdoError> {
        if let Some(e) = self.invalid {
            return Err(e);
        }
        if len < self.byte_len {
            return Err(PdoError::Length {
                map: self.map.index,
                expected: self.byte_len,
                actual: len,
            });
        }
        Ok(())
    }

    /// [`PdoLayout::check_len`], and that the image's objects beside the CiA 402 fields fit
    /// [`TxPdo::extras`].
    fn check_tx(&self, len: usize) -> Result<(), PdoError> {
        self.check_len(len)?;
        self.invalid_tx.map_or(Ok(()), Err)
    }

    fn slots(&self) -> &[Slot] {
        &self.slots[..self.len]
    }

    /// Writes `pdo` into the first [`PdoLayout::byte_len`] bytes of `buf`; padding and objects
    /// `RxPdo` does not carry are written as zero.
    pub fn encode_rx(&self, pdo: &RxPdo, buf: &mut [u8]) -> Result<(), PdoError> {
        self.check_len(buf.len())?;
        for s in self.slots() {
            write_le(buf, s, s.rx.map_or(0, |f| pdo.get(f)));
        }
        Ok(())
    }

    /// Reads an [`RxPdo`] from `buf`; absent objects stay default.
    pub fn decode_rx(&self, buf: &[u8]) -> Result<RxPdo, PdoError> {
        self.check_len(buf.len())?;
        let mut pdo = RxPdo::default();
        for s in self.slots() {
            if let Some(f) = s.rx {
                pdo.set(f, s.bits, read_le(buf, s));
            }
        }
        Ok(pdo)
    }

    /// Writes `pdo` into the first [`PdoLayout::byte_len`] bytes of `buf`; padding and objects
    /// `TxPdo` does not carry (neither a field nor one of its extras) are written as zero.
    pub fn encode_tx(&self, pdo: &TxPdo, buf: &mut [u8]) -> Result<(), PdoError> {
        self.check_tx(buf.len())?;
        for s in self.slots() {
            let v = match s.tx {
                Some(f) => pdo.get(f),
                None if s.extra => pdo.extras.get(s.index, s.sub).unwrap_or(0),
                None => 0,
            };
            write_le(buf, s, v);
        }
        Ok(())
    }

    /// Reads a [`TxPdo`] from `buf`: the CiA 402 fields, and every other object into
    /// [`TxPdo::extras`]; absent fields stay default.
    pub fn decode_tx(&self, buf: &[u8]) -> Result<TxPdo, PdoError> {
        let mut pdo = TxPdo::default();
        self.decode_tx_into(buf, &mut pdo)?;
        Ok(pdo)
    }

    /// [`PdoLayout::decode_tx`] into `pdo` in place (the RT loop's per-axis feedback, not a
    /// copy of it); `pdo` is untouched when the image is refused.
    pub fn decode_tx_into(&self, buf: &[u8], pdo: &mut TxPdo) -> Result<(), PdoError> {
        self.check_tx(buf.len())?;
        *pdo = TxPdo::default();
        for s in self.slots() {
            if let Some(f) = s.tx {
                pdo.set(f, s.bits, read_le(buf, s));
            } else if s.extra {
                // Fits: check_tx counted the extras against the table's size.
                let _ = pdo.extras.set(s.index, s.sub, read_le(buf, s));
            }
        }
        Ok(())
    }
}

/// Writes the low `s.bytes` bytes of `v` little-endian at `s.offset` (bounds checked by the caller).
#[inline]
fn write_le(buf: &mut [u8], s: &Slot, v: u64) {
    let o = usize::from(s.offset);
    let b = v.to_le_bytes();
    match s.bytes {
        1 => buf[o] = b[0],
        2 => buf[o..o + 2].copy_from_slice(&b[..2]),
        4 => buf[o..o + 4].copy_from_slice(&b[..4]),
        n => {
            let n = usize::from(n);
            for (i, d) in buf[o..o + n].iter_mut().enumerate() {
                *d = b.get(i).copied().unwrap_or(0);
            }
        }
    }
}

/// Reads `s.bytes` bytes little-endian at `s.offset`, zero-extended.
#[inline]
fn read_le(buf: &[u8], s: &Slot) -> u64 {
    let o = usize::from(s.offset);
    match s.bytes {
        1 => u64::from(buf[o]),
        2 => u64::from(u16::from_le_bytes([buf[o], buf[o + 1]])),
        4 => u64::from(u32::from_le_bytes([
            buf[o],
            buf[o + 1],
            buf[o + 2],
            buf[o + 3],
        ])),
        n => {
            let mut raw = [0u8; 8];
            for (r, b) in raw.iter_mut().zip(&buf[o..o + usize::from(n)]) {
                *r = *b;
            }
            u64::from_le_bytes(raw)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pdo::PdoEntry;
    use crate::shared_slice::SharedSlice;

    const MANY: [PdoEntry; MAX_LAYOUT_ENTRIES + 1] = [PdoEntry::padding(8); MAX_LAYOUT_ENTRIES + 1];

    #[test]
    fn a_map_too_long_for_the_layout_is_refused_at_every_use() {
        let map = PdoMap {
            index: 0x1602,
            entries: SharedSlice::Static(&MANY),
        };
        let layout = PdoLayout::new(&map);
        let e = PdoError::TooManyEntries {
            map: 0x1602,
            entries: MAX_LAYOUT_ENTRIES + 1,
            max: MAX_LAYOUT_ENTRIES,
        };
        assert_eq!(layout.error(), Some(e));
        let mut buf = [0x55u8; 64];
        assert_eq!(layout.encode_rx(&RxPdo::default(), &mut buf), Err(e));
        assert_eq!(buf, [0x55u8; 64], "nothing written");
        assert_eq!(layout.decode_tx(&buf), Err(e));
        assert!(e.to_string().contains("1602h"), "{e}");
    }

    /// An extra object wider than 32 bits is refused naming it; a 32-bit one round-trips.
    #[test]
    fn an_extra_object_wider_than_32_bits_is_refused() {
        const WIDE: PdoMap = PdoMap {
            index: 0x1A07,
            entries: SharedSlice::Static(&[
                PdoEntry::object(0x6041, 0, 16),
                PdoEntry::object(0x2B10, 1, 64),
            ]),
        };
        let e = PdoLayout::new(&WIDE).decode_tx(&[0u8; 10]).unwrap_err();
        assert_eq!(
            e,
            PdoError::ExtraTooWide {
                map: 0x1A07,
                index: 0x2B10,
                sub: 1,
                bits: 64
            }
        );
        assert!(e.to_string().contains("2B10h:1 with 64 bits"), "{e}");
        const WORD: PdoMap = PdoMap {
            index: 0x1A07,
            entries: SharedSlice::Static(&[
                PdoEntry::object(0x6041, 0, 16),
                PdoEntry::object(0x2B10, 1, 32),
            ]),
        };
        let layout = PdoLayout::new(&WORD);
        let tx = layout
            .decode_tx(&[0x37, 0x12, 0x78, 0x56, 0x34, 0xF2])
            .unwrap();
        assert_eq!(tx.extras.get(0x2B10, 1), Some(0xF234_5678));
    }

    #[test]
    fn fields_land_at_the_mapped_offsets_with_their_widths() {
        const MAP: PdoMap = PdoMap {
            index: 0x1A05,
            entries: SharedSlice::Static(&[
                PdoEntry::object(0x6041, 0, 16),
                PdoEntry::padding(8),
                PdoEntry::object(0x6061, 0, 8),
                PdoEntry::object(0x6064, 0, 32),
                PdoEntry::object(0x2D24, 0, 8),
            ]),
        };
        let layout = PdoLayout::new(&MAP);
        let tx = TxPdo {
            statusword: crate::statusword::Statusword(0x1237),
            mode_display: -3,
            position_actual: -2,
            ..TxPdo::default()
        };
        let mut tx = tx;
        tx.extras.set(0x2D24, 0, 0xA5).unwrap();
        let mut buf = [0xEEu8; 10];
        layout.encode_tx(&tx, &mut buf).unwrap();
        assert_eq!(
            buf,
            [0x37, 0x12, 0, 0xFD, 0xFE, 0xFF, 0xFF, 0xFF, 0xA5, 0xEE]
        );
        assert_eq!(layout.decode_tx(&buf), Ok(tx));
        assert!(layout.decode_tx(&buf[..8]).is_err(), "short image");
    }
}
