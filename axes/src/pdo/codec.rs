//! The table-driven little-endian walk over a [`PdoMap`]'s entries.

use super::{PdoEntry, PdoError, PdoMap};

/// Writes every entry's value (from `value`, truncated to the entry size) little-endian.
pub(super) fn encode(
    map: &PdoMap,
    buf: &mut [u8],
    value: impl Fn(&PdoEntry) -> u64,
) -> Result<(), PdoError> {
    let len = buf.len();
    let mut off = 0usize;
    for e in map.entries {
        let n = byte_size(map, e)?;
        let v = if e.is_padding() { 0 } else { value(e) };
        let bytes = v.to_le_bytes();
        let dst = buf.get_mut(off..off + n).ok_or_else(|| short(map, len))?;
        for (i, d) in dst.iter_mut().enumerate() {
            *d = bytes.get(i).copied().unwrap_or(0);
        }
        off += n;
    }
    Ok(())
}

/// Reads every entry little-endian (zero-extended to 64 bits) and hands it to `sink`.
pub(super) fn decode(
    map: &PdoMap,
    buf: &[u8],
    mut sink: impl FnMut(&PdoEntry, u64),
) -> Result<(), PdoError> {
    let mut off = 0usize;
    for e in map.entries {
        let n = byte_size(map, e)?;
        let src = buf.get(off..off + n).ok_or_else(|| short(map, buf.len()))?;
        if !e.is_padding() {
            let mut raw = [0u8; 8];
            for (r, s) in raw.iter_mut().zip(src) {
                *r = *s;
            }
            sink(e, u64::from_le_bytes(raw));
        }
        off += n;
    }
    Ok(())
}

fn byte_size(map: &PdoMap, e: &PdoEntry) -> Result<usize, PdoError> {
    if !e.bits.is_multiple_of(8) {
        return Err(PdoError::Unaligned {
            map: map.index,
            index: e.index,
            sub: e.sub,
        });
    }
    Ok(usize::from(e.bits / 8))
}

fn short(map: &PdoMap, actual: usize) -> PdoError {
    PdoError::Length {
        map: map.index,
        expected: map.byte_len(),
        actual,
    }
}
