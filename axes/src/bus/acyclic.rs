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
