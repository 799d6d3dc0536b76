//! One axis' acyclic request slot between the RT thread and the mailbox worker: the request and
//! its outcome packed in atomics, handed over by the slot's state (release/acquire), so that
//! neither side locks or allocates.

use std::sync::atomic::{AtomicU64, AtomicU8, Ordering};

use crate::bus::{PostError, SdoData, SdoOutcome, SdoRequest};

const FREE: u8 = 0;
const POSTED: u8 = 1;
const BUSY: u8 = 2;
const DONE: u8 = 3;

const OUTCOME_UPLOADED: u8 = 0;
const OUTCOME_DOWNLOADED: u8 = 1;
const OUTCOME_ABORTED: u8 = 2;

/// The slot: free → posted (RT) → busy (worker) → done (worker) → free (RT takes it).
#[derive(Debug, Default)]
pub(super) struct SdoSlot {
    state: AtomicU8,
    request: AtomicU64,
    outcome_kind: AtomicU8,
    outcome: AtomicU64,
}

/// A request in 64 bits: data (0–31), index (32–47), sub (48–55), data length (56–58),
/// download (63).
fn pack(r: SdoRequest) -> u64 {
    match r {
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

fn unpack(v: u64) -> SdoRequest {
    let index = (v >> 32) as u16;
    let sub = (v >> 48) as u8;
    if v >> 63 == 0 {
        return SdoRequest::Upload { index, sub };
    }
    let len = ((v >> 56) & 0x7) as usize;
    let raw = (v as u32).to_le_bytes();
    let data = SdoData::new(&raw[..len]).unwrap_or(SdoData::from_u32(v as u32));
    SdoRequest::Download { index, sub, data }
}

impl SdoSlot {
    /// RT side: posts `request` if the slot is free.
    pub(super) fn post(&self, request: SdoRequest) -> Result<(), PostError> {
        if self.state.load(Ordering::Acquire) != FREE {
            return Err(PostError::Busy);
        }
        self.request.store(pack(request), Ordering::Relaxed);
        self.state.store(POSTED, Ordering::Release);
        Ok(())
    }

    /// RT side: the outcome once done; the slot is free again.
    pub(super) fn take(&self) -> Option<SdoOutcome> {
        if self.state.load(Ordering::Acquire) != DONE {
            return None;
        }
        let v = self.outcome.load(Ordering::Relaxed);
        let outcome = match self.outcome_kind.load(Ordering::Relaxed) {
            OUTCOME_UPLOADED => SdoOutcome::Uploaded(v as i64),
            OUTCOME_DOWNLOADED => SdoOutcome::Downloaded,
            _ => SdoOutcome::Aborted(v as u32),
        };
        self.state.store(FREE, Ordering::Release);
        Some(outcome)
    }

    /// Worker side: the posted request, if any; the slot is busy until [`SdoSlot::complete`].
    pub(super) fn claim(&self) -> Option<SdoRequest> {
        self.state
            .compare_exchange(POSTED, BUSY, Ordering::Acquire, Ordering::Relaxed)
            .ok()?;
        Some(unpack(self.request.load(Ordering::Relaxed)))
    }

    /// Worker side: the claimed request ended with `outcome`.
    pub(super) fn complete(&self, outcome: SdoOutcome) {
        let (kind, v) = match outcome {
            SdoOutcome::Uploaded(v) => (OUTCOME_UPLOADED, v as u64),
            SdoOutcome::Downloaded => (OUTCOME_DOWNLOADED, 0),
            SdoOutcome::Aborted(code) => (OUTCOME_ABORTED, u64::from(code)),
        };
        self.outcome.store(v, Ordering::Relaxed);
        self.outcome_kind.store(kind, Ordering::Relaxed);
        self.state.store(DONE, Ordering::Release);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
            assert_eq!(unpack(pack(r)), r);
        }
    }

    #[test]
    fn a_slot_takes_one_request_and_hands_back_its_outcome_once() {
        let slot = SdoSlot::default();
        assert_eq!(slot.claim(), None);
        let r = SdoRequest::Upload {
            index: 0x603F,
            sub: 0,
        };
        slot.post(r).unwrap();
        assert_eq!(slot.post(r), Err(PostError::Busy));
        assert_eq!(slot.take(), None, "not done yet");
        assert_eq!(slot.claim(), Some(r));
        assert_eq!(slot.claim(), None, "claimed once");
        assert_eq!(slot.take(), None);
        slot.complete(SdoOutcome::Uploaded(-2));
        assert_eq!(slot.take(), Some(SdoOutcome::Uploaded(-2)));
        assert_eq!(slot.take(), None);
        slot.post(r).unwrap();
        slot.claim().unwrap();
        slot.complete(SdoOutcome::Aborted(0x0602_0000));
        assert_eq!(slot.take(), Some(SdoOutcome::Aborted(0x0602_0000)));
    }
}
