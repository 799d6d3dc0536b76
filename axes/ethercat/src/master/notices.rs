//! The mailbox worker's side of the mailbox watch: reading what SubDevices sent unasked (CoE
//! Emergencies, ETG.1000.6 §5.6.2.1) and emptying SM1, when the cyclic SM1 status saw it full
//! and before every SDO.

use std::sync::atomic::Ordering;

use super::group::MASTER_MAC;
use super::link::Link;
use super::mailbox::{MAILBOX_READ_ZEROS, MAX_DRAIN, SM_STATUS_FULL};
use super::worker::MailboxWorker;
use crate::emergency::{Emergency, MailboxMessage};
use crate::frame::{self, Command, FrameBuilder};
use crate::register as reg;
use cellrt_cia402::bus::{BusError, MailboxNotice};

impl MailboxWorker {
    /// Reads SubDevice `station`'s SM1 status and, in the same frame, its buffer (which frees
    /// it; ETG.1000.4 §6.7.2): the message if SM1 was full. One acyclic round trip, no heap
    /// allocation. `Ok(false)`: SM1 was empty (or the station has no mailbox).
    pub(super) fn read_mailbox(&mut self, station: usize) -> Result<bool, BusError> {
        let Some(Some(mb)) = self.sm1.get(station).copied() else {
            return Ok(false);
        };
        let adp = u32::from(self.station_addresses[station]);
        let (status, data, len) = {
            let mut b = FrameBuilder::new(&mut self.frame, MASTER_MAC);
            let status = b.push(
                Command::Fprd,
                0,
                (u32::from(reg::sync_manager(1) + 5) << 16) | adp,
                &[0],
            );
            let data = b.push(
                Command::Fprd,
                0,
                (u32::from(mb.start) << 16) | adp,
                &MAILBOX_READ_ZEROS[..usize::from(mb.len)],
            );
            let (Some(status), Some(data)) = (status, data) else {
                return Err(BusError::FrameTooLarge {
                    bytes: usize::from(mb.len) + 1,
                });
            };
            (status, data, b.finish())
        };
        if self.link.round_trip(&mut self.frame, len).is_err() {
            return Err(BusError::FrameLost);
        }
        let full = frame::wkc(&self.frame, &status) == 1
            && self.frame[status.data_offset] & SM_STATUS_FULL != 0;
        if !full || frame::wkc(&self.frame, &data) != 1 {
            return Ok(false);
        }
        let message =
            MailboxMessage::decode(&self.frame[data.data_offset..][..usize::from(mb.len)]);
        let diag = &self.shared.diag;
        diag.messages[station].fetch_add(1, Ordering::Relaxed);
        if matches!(message, MailboxMessage::Emergency(_)) {
            diag.emergencies[station].fetch_add(1, Ordering::Relaxed);
        }
        let first = self.first_axis(station);
        let notice = match message {
            MailboxMessage::Emergency(emergency) => MailboxNotice::Emergency {
                axis: self.emergency_axis(station, &emergency),
                emergency,
            },
            MailboxMessage::Other {
                mailbox_type,
                service,
            } => MailboxNotice::Discarded {
                axis: first,
                mailbox_type,
                service,
            },
            MailboxMessage::Malformed => MailboxNotice::Discarded {
                axis: first,
                mailbox_type: 0,
                service: 0,
            },
        };
        self.push_notice(notice);
        Ok(true)
    }

    /// The axis an Emergency of SubDevice `station` is about: on a multi-axis unit the slot it
    /// names, else (or for a slot no axis uses) the SubDevice's first axis.
    pub(super) fn emergency_axis(&self, station: usize, emergency: &Emergency) -> usize {
        let (slots, multi) = &self.slots[station];
        let slot = if *multi {
            usize::from(emergency.slot())
        } else {
            0
        };
        slots
            .get(slot)
            .copied()
            .flatten()
            .unwrap_or_else(|| self.first_axis(station))
    }

    /// The first axis SubDevice `station` carries (0 if none: a unit with no slot used).
    fn first_axis(&self, station: usize) -> usize {
        self.slots[station]
            .0
            .iter()
            .flatten()
            .copied()
            .next()
            .unwrap_or(0)
    }

    /// Queues a mailbox notice for the executive; a full queue counts it as dropped.
    pub(super) fn push_notice(&mut self, notice: MailboxNotice) {
        if self.shared.notices.push(notice).is_err() {
            self.shared.dropped.fetch_add(1, Ordering::Relaxed);
        }
    }

    /// Empties SubDevice `station`'s SM1 into the notices before an SDO transaction, so that
    /// ethercrab never reads an Emergency (bounded: [`MAX_DRAIN`] messages).
    pub(super) fn drain_mailbox(&mut self, station: usize) {
        for _ in 0..MAX_DRAIN {
            if !matches!(self.read_mailbox(station), Ok(true)) {
                break;
            }
        }
    }
}
