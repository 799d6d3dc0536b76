//! One axis' acyclic request slot between the RT thread and the mailbox worker: the request and
//! its outcome packed in atomics, handed over by the slot's state (release/acquire), so that
//! neither side locks or allocates.

use std::sync::atomic::{AtomicU64, AtomicU8, Ordering};

use cellrt_cia402::bus::{PostError, SdoOutcome, SdoRequest};

const FREE: u8 = 0;
const POSTED: u8 = 1;
const BUSY: u8 = 2;
const DONE: u8 = 3;

/// The slot: free → posted (RT) → busy (worker) → done (worker) → free (RT takes it).
#[derive(Debug, Default)]
pub(super) struct SdoSlot {
    state: AtomicU8,
    request: AtomicU64,
    outcome_kind: AtomicU8,
    outcome: AtomicU64,
}

impl SdoSlot {
    /// RT side: posts `request` if the slot is free.
    pub(super) fn post(&self, request: SdoRequest) -> Result<(), PostError> {
        if self.state.load(Ordering::Acquire) != FREE {
            return Err(PostError::Busy);
        }
        self.request.store(request.to_bits(), Ordering::Relaxed);
        self.state.store(POSTED, Ordering::Release);
        Ok(())
    }

    /// RT side: the outcome once done; the slot is free again.
    pub(super) fn take(&self) -> Option<SdoOutcome> {
        if self.state.load(Ordering::Acquire) != DONE {
            return None;
        }
        let v = self.outcome.load(Ordering::Relaxed);
        let outcome = SdoOutcome::from_parts(self.outcome_kind.load(Ordering::Relaxed), v);
        self.state.store(FREE, Ordering::Release);
        outcome
    }

    /// Worker side: the posted request, if any; the slot is busy until [`SdoSlot::complete`].
    pub(super) fn claim(&self) -> Option<SdoRequest> {
        self.state
            .compare_exchange(POSTED, BUSY, Ordering::Acquire, Ordering::Relaxed)
            .ok()?;
        Some(SdoRequest::from_bits(self.request.load(Ordering::Relaxed)))
    }

    /// Worker side: the claimed request ended with `outcome`.
    pub(super) fn complete(&self, outcome: SdoOutcome) {
        let (kind, v) = outcome.to_parts();
        self.outcome.store(v, Ordering::Relaxed);
        self.outcome_kind.store(kind, Ordering::Relaxed);
        self.state.store(DONE, Ordering::Release);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
