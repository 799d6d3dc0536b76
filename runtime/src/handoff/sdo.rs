//! An operator's SDO request to one axis' drive and its outcome, as they cross the hand-off:
//! one request slot (two atomics) the host fills and the RT thread empties, and one outcome the
//! RT thread publishes with the request's sequence number, so that neither side locks or
//! allocates.

use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};

use cellrt_cia402::bus::{SdoOutcome, SdoRequest};

/// An operator's SDO request: `seq` (never 0) names it in its outcome.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UserSdo {
    /// Sequence number of the request (1.., wrapping past 0).
    pub seq: u16,
    /// Axis index.
    pub axis: u16,
    /// The upload or download.
    pub request: SdoRequest,
}

/// How an operator's SDO request ended, as the RT thread publishes it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UserSdoOutcome {
    /// The drive (or the bus) answered.
    Done(SdoOutcome),
    /// The axis has no acyclic channel (or no such axis runs).
    Unsupported,
}

/// The outcome kind of [`UserSdoOutcome::Unsupported`] (the others are
/// [`SdoOutcome::to_parts`]'s).
const KIND_UNSUPPORTED: u8 = 0xFF;

/// The request slot: the header (0 = empty; seq 16–31, axis 0–15) and the request
/// ([`SdoRequest::to_bits`]). Filled only while empty (by one host thread); the RT thread reads
/// the request before it empties the header.
#[derive(Debug, Default)]
pub(super) struct SdoRequestSlot {
    header: AtomicU32,
    request: AtomicU64,
}

/// The latest outcome: `header` (seq 16–31, kind 0–7; seq 0 = none yet) stored after `value`.
#[derive(Debug, Default)]
pub(super) struct SdoOutcomeSlot {
    header: AtomicU32,
    value: AtomicU64,
}

/// Why the host could not leave a request.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum SdoSlotBusy {
    /// The RT thread has not taken the previous request yet.
    #[error("the previous SDO request has not been taken by the RT thread yet")]
    Untaken,
}

impl UserSdo {
    /// The request as a header (seq 16–31, never 0; axis 0–15) and a word, as the slot and
    /// the external planner's link carry it.
    pub fn to_wire(&self) -> (u32, u64) {
        (
            u32::from(self.seq.max(1)) << 16 | u32::from(self.axis),
            self.request.to_bits(),
        )
    }

    /// The request of a header and word ([`UserSdo::to_wire`]); none for header 0.
    pub fn from_wire(header: u32, word: u64) -> Option<UserSdo> {
        (header != 0).then(|| UserSdo {
            seq: (header >> 16) as u16,
            axis: header as u16,
            request: SdoRequest::from_bits(word),
        })
    }
}

impl UserSdoOutcome {
    /// The outcome of request `seq` as a header (seq 16–31, kind 0–7) and a word.
    pub fn to_wire(self, seq: u16) -> (u32, u64) {
        let (kind, value) = match self {
            UserSdoOutcome::Done(o) => o.to_parts(),
            UserSdoOutcome::Unsupported => (KIND_UNSUPPORTED, 0),
        };
        (u32::from(seq) << 16 | u32::from(kind), value)
    }

    /// The outcome a header and word carry, if it answers request `seq`.
    pub fn from_wire(header: u32, word: u64, seq: u16) -> Option<UserSdoOutcome> {
        if (header >> 16) as u16 != seq {
            return None;
        }
        Some(
            SdoOutcome::from_parts(header as u8, word)
                .map_or(UserSdoOutcome::Unsupported, UserSdoOutcome::Done),
        )
    }
}

impl SdoRequestSlot {
    /// Host side: leaves `sdo` for the RT thread; refused while the previous one is untaken.
    pub(super) fn put(&self, sdo: UserSdo) -> Result<(), SdoSlotBusy> {
        if self.header.load(Ordering::Acquire) != 0 {
            return Err(SdoSlotBusy::Untaken);
        }
        let (header, word) = sdo.to_wire();
        self.request.store(word, Ordering::Relaxed);
        self.header.store(header, Ordering::Release);
        Ok(())
    }

    /// RT side: takes the request, if any (the slot is empty afterwards).
    pub(super) fn take(&self) -> Option<UserSdo> {
        let h = self.header.load(Ordering::Acquire);
        let sdo = UserSdo::from_wire(h, self.request.load(Ordering::Relaxed))?;
        self.header.store(0, Ordering::Release);
        Some(sdo)
    }
}

impl SdoOutcomeSlot {
    /// RT side: publishes the outcome of request `seq`.
    pub(super) fn publish(&self, seq: u16, outcome: UserSdoOutcome) {
        let (header, value) = outcome.to_wire(seq);
        self.value.store(value, Ordering::Relaxed);
        self.header.store(header, Ordering::Release);
    }

    /// Host side: the outcome of request `seq`, once published.
    pub(super) fn get(&self, seq: u16) -> Option<UserSdoOutcome> {
        let h = self.header.load(Ordering::Acquire);
        UserSdoOutcome::from_wire(h, self.value.load(Ordering::Relaxed), seq)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cellrt_cia402::bus::SdoData;

    #[test]
    fn a_request_crosses_the_slot_once_and_only_while_it_is_empty() {
        let slot = SdoRequestSlot::default();
        assert_eq!(slot.take(), None);
        let write = UserSdo {
            seq: 0xFFFF,
            axis: 255,
            request: SdoRequest::Download {
                index: 0x6085,
                sub: 0,
                data: SdoData::new(&[0xFA, 0, 0, 0x80]).unwrap(),
            },
        };
        slot.put(write).unwrap();
        let read = UserSdo {
            seq: 2,
            axis: 1,
            request: SdoRequest::Upload {
                index: 0x1C32,
                sub: 2,
            },
        };
        assert_eq!(slot.put(read), Err(SdoSlotBusy::Untaken));
        assert_eq!(slot.take(), Some(write));
        assert_eq!(slot.take(), None);
        slot.put(read).unwrap();
        assert_eq!(slot.take(), Some(read));
        let byte = UserSdo {
            seq: 3,
            axis: 0,
            request: SdoRequest::Download {
                index: 0x6098,
                sub: 0,
                data: SdoData::new(&[0xDF]).unwrap(),
            },
        };
        slot.put(byte).unwrap();
        assert_eq!(slot.take(), Some(byte));
    }

    #[test]
    fn an_outcome_is_seen_only_under_its_own_sequence_number() {
        let slot = SdoOutcomeSlot::default();
        assert_eq!(slot.get(1), None);
        for outcome in [
            UserSdoOutcome::Done(SdoOutcome::Uploaded(-5)),
            UserSdoOutcome::Done(SdoOutcome::Downloaded),
            UserSdoOutcome::Done(SdoOutcome::Aborted(0x0601_0002)),
            UserSdoOutcome::Unsupported,
        ] {
            slot.publish(7, outcome);
            assert_eq!(slot.get(7), Some(outcome));
            assert_eq!(slot.get(8), None);
        }
    }
}
