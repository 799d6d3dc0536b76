//! Acyclic transfers the RT loop asks for while it runs (an SDO on EtherCAT): posted into a
//! preallocated slot per axis and completed in a later cycle, so that the loop never waits for
//! a mailbox round trip (ETG.1000.6 §5.6.2: an SDO takes several frames and the drive's answer
//! time).

/// The data of an SDO download: 1, 2 or 4 bytes, little-endian (CiA 301 expedited transfer).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SdoData {
    bytes: [u8; 4],
    len: u8,
}

impl SdoData {
    /// The bytes of `data` if it is 1, 2 or 4 bytes long.
    pub fn new(data: &[u8]) -> Option<SdoData> {
        if !matches!(data.len(), 1 | 2 | 4) {
            return None;
        }
        let mut bytes = [0; 4];
        bytes[..data.len()].copy_from_slice(data);
        Some(SdoData {
            bytes,
            len: data.len() as u8,
        })
    }

    /// A 4-byte value.
    pub fn from_u32(v: u32) -> SdoData {
        SdoData {
            bytes: v.to_le_bytes(),
            len: 4,
        }
    }

    /// The bytes to write.
    pub fn as_slice(&self) -> &[u8] {
        &self.bytes[..usize::from(self.len)]
    }
}

/// What the RT loop asks of an axis' drive acyclically.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SdoRequest {
    /// Read `index:sub` (typed by the drive's profile).
    Upload {
        /// Object index.
        index: u16,
        /// Sub-index.
        sub: u8,
    },
    /// Write `data` to `index:sub`.
    Download {
        /// Object index.
        index: u16,
        /// Sub-index.
        sub: u8,
        /// The value.
        data: SdoData,
    },
}

impl SdoRequest {
    /// The request in 64 bits, for a slot of atomics: data (0–31), index (32–47), sub (48–55),
    /// data length (56–58), download (63).
    pub fn to_bits(self) -> u64 {
        match self {
            SdoRequest::Upload { index, sub } => u64::from(index) << 32 | u64::from(sub) << 48,
            SdoRequest::Download { index, sub, data } => {
                let bytes = data.as_slice();
                let mut raw = [0u8; 4];
                raw[..bytes.len()].copy_from_slice(bytes);
                u64::from(u32::from_le_bytes(raw))
                    | u64::from(index) << 32
                    | u64::from(sub) << 48
                    | (bytes.len() as u64) << 56
                    | 1 << 63
            }
        }
    }

    /// Inverse of [`SdoRequest::to_bits`].
    pub fn from_bits(v: u64) -> SdoRequest {
        let index = (v >> 32) as u16;
        let sub = (v >> 48) as u8;
        if v >> 63 == 0 {
            return SdoRequest::Upload { index, sub };
        }
        let len = ((v >> 56) & 0x7) as usize;
        let raw = (v as u32).to_le_bytes();
        let data = SdoData::new(&raw[..len.min(4)]).unwrap_or(SdoData::from_u32(v as u32));
        SdoRequest::Download { index, sub, data }
    }
}

/// How a posted request ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SdoOutcome {
    /// The upload's value.
    Uploaded(i64),
    /// The download was taken.
    Downloaded,
    /// The drive (or the bus) refused it: the CiA 301 abort code.
    Aborted(u32),
}

impl SdoOutcome {
    /// The outcome as a kind (0 uploaded, 1 downloaded, 2 aborted) and a value (the upload's
    /// value or the abort code), for a slot of atomics.
    pub fn to_parts(self) -> (u8, u64) {
        match self {
            SdoOutcome::Uploaded(v) => (0, v as u64),
            SdoOutcome::Downloaded => (1, 0),
            SdoOutcome::Aborted(code) => (2, u64::from(code)),
        }
    }

    /// Inverse of [`SdoOutcome::to_parts`]; `None` for another kind.
    pub fn from_parts(kind: u8, value: u64) -> Option<SdoOutcome> {
        Some(match kind {
            0 => SdoOutcome::Uploaded(value as i64),
            1 => SdoOutcome::Downloaded,
            2 => SdoOutcome::Aborted(value as u32),
            _ => return None,
        })
    }
}

/// Why a request could not be posted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum PostError {
    /// The axis has a request in flight or an outcome not yet taken (one per axis, as a drive
    /// serves one mailbox request at a time).
    #[error("the axis has an acyclic request in flight")]
    Busy,
    /// The bus has no acyclic channel to this axis.
    #[error("no acyclic channel to the axis")]
    Unsupported,
}

/// One axis' slot on a bus whose transfers complete at once (the in-process simulated drives):
/// the outcome waits there until the RT loop takes it in a later call.
#[derive(Debug, Clone, Copy, Default)]
pub struct ImmediateSlot(Option<SdoOutcome>);

impl ImmediateSlot {
    /// Runs `transfer` now and keeps its outcome; `Busy` while an outcome is not yet taken.
    pub fn post(&mut self, transfer: impl FnOnce() -> SdoOutcome) -> Result<(), PostError> {
        if self.0.is_some() {
            return Err(PostError::Busy);
        }
        self.0 = Some(transfer());
        Ok(())
    }

    /// The outcome, once.
    pub fn take(&mut self) -> Option<SdoOutcome> {
        self.0.take()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sdo_data_holds_one_two_or_four_bytes() {
        assert_eq!(SdoData::new(&[8]).unwrap().as_slice(), &[8]);
        assert_eq!(
            SdoData::new(&[1, 2, 3, 4]).unwrap().as_slice(),
            &[1, 2, 3, 4]
        );
        assert!(SdoData::new(&[]).is_none());
        assert!(SdoData::new(&[1, 2, 3]).is_none());
        assert!(SdoData::new(&[0; 8]).is_none());
    }

    #[test]
    fn requests_survive_packing() {
        for r in [
            SdoRequest::Upload {
                index: 0x607C,
                sub: 0,
            },
            SdoRequest::Download {
                index: 0x6060,
                sub: 0,
                data: SdoData::new(&[6]).unwrap(),
            },
            SdoRequest::Download {
                index: 0x2D01,
                sub: 0xFF,
                data: SdoData::new(&[0xFF, 0xFE]).unwrap(),
            },
            SdoRequest::Download {
                index: 0xFFFF,
                sub: 3,
                data: SdoData::new(&[1, 2, 3, 0x80]).unwrap(),
            },
        ] {
            assert_eq!(SdoRequest::from_bits(r.to_bits()), r);
        }
    }

    #[test]
    fn outcomes_survive_packing() {
        for o in [
            SdoOutcome::Uploaded(-2),
            SdoOutcome::Uploaded(i64::from(u32::MAX)),
            SdoOutcome::Downloaded,
            SdoOutcome::Aborted(0x0602_0000),
        ] {
            let (kind, value) = o.to_parts();
            assert_eq!(SdoOutcome::from_parts(kind, value), Some(o));
        }
        assert_eq!(SdoOutcome::from_parts(3, 0), None);
    }

    #[test]
    fn an_immediate_slot_holds_one_outcome_until_taken() {
        let mut slot = ImmediateSlot::default();
        slot.post(|| SdoOutcome::Downloaded).unwrap();
        assert_eq!(slot.post(|| SdoOutcome::Aborted(1)), Err(PostError::Busy));
        assert_eq!(slot.take(), Some(SdoOutcome::Downloaded));
        assert_eq!(slot.take(), None);
        slot.post(|| SdoOutcome::Uploaded(-3)).unwrap();
        assert_eq!(slot.take(), Some(SdoOutcome::Uploaded(-3)));
    }
}
