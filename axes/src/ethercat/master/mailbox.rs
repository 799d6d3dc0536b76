//! The SubDevice→master mailbox (SM1) watched in the cyclic frame and drained before each SDO:
//! CoE Emergencies become [`MailboxNotice`]s of the axis they name (ETG.1000.4 §6.7.2).

use std::collections::VecDeque;

use super::bring_up::OpGroup;
use super::bus::{EthercatBus, MASTER_MAC};
use super::error::{step, EthercatError};
use super::pump::Wire;
use super::segment::SegmentStation;
use crate::bus::{BusError, MailboxNotice};
use crate::ethercat::emergency::{Emergency, MailboxMessage};
use crate::ethercat::frame::{self, Command, DatagramSpan, FrameBuilder};
use crate::ethercat::register as reg;
use ethercrab::MainDevice;

/// SM status (0805h + 8n) bit 3: mailbox full.
pub(super) const SM_STATUS_FULL: u8 = 0x08;
/// Largest SM1 mailbox the master drains itself (bigger ones are left to ethercrab's clearing).
const MAX_MAILBOX_READ: usize = 1024;
/// Zeros to send as the data of a mailbox read (no allocation per read).
static MAILBOX_READ_ZEROS: [u8; MAX_MAILBOX_READ] = [0; MAX_MAILBOX_READ];
/// Mailbox messages drained before an SDO at most (a firmware that refills SM1 faster than
/// this is left to ethercrab's clearing, which discards).
const MAX_DRAIN: usize = 8;
/// Notices held for [`Bus::take_mailbox_notice`] (preallocated; more are dropped and counted).
const NOTICE_QUEUE: usize = 16;

/// A SubDevice's SubDevice→master mailbox (SM1), read back at bring-up.
#[derive(Debug, Clone, Copy)]
pub(super) struct MailboxIn {
    /// Physical start address and length of the buffer.
    start: u16,
    len: u16,
}

/// Per SubDevice with a mailbox: the SM1 watch and drain that read CoE Emergencies in the cyclic
/// frame's cycle and before every SDO, so that ethercrab meets none left over (one that comes
/// during an SDO is [`EthercatBus::emergency_in_sdo`]'s).
#[derive(Debug, Default)]
pub(super) struct MailboxWatch {
    /// Per SubDevice: its SM1, `None` without a mailbox (or one over [`MAX_MAILBOX_READ`]).
    pub(super) sm1: Vec<Option<MailboxIn>>,
    /// Per SubDevice: where the cyclic frame's read of its SM1 status sits.
    pub(super) spans: Vec<Option<DatagramSpan>>,
    /// Per SubDevice: the last cyclic frame saw SM1 full.
    pub(super) full: Vec<bool>,
    /// Per SubDevice: the axes of its slots (slot 0 = axis A) and whether it is multi-axis.
    slots: Vec<(Vec<Option<usize>>, bool)>,
    /// Decoded messages not yet taken.
    pub(super) notices: VecDeque<MailboxNotice>,
    /// Notices dropped because [`NOTICE_QUEUE`] was full.
    dropped: u64,
}

impl MailboxWatch {
    /// Reads back each SubDevice's SM1 at bring-up: a mailbox (control bits 0–1 = 10b),
    /// enabled, that the drain can read in one go is watched.
    pub(super) fn read_back(
        group: &OpGroup,
        maindevice: &MainDevice<'static>,
        wire: &mut Wire<'_>,
        plans: &[SegmentStation],
    ) -> Result<Self, EthercatError> {
        let mut sm1 = Vec::with_capacity(plans.len());
        for position in 0..plans.len() {
            let sd = step("SubDevice lookup", group.subdevice(maindevice, position))?;
            let r = reg::sync_manager(1);
            let read = async {
                let start: u16 = sd.register_read(r).await?;
                let len: u16 = sd.register_read(r + 2).await?;
                let control: u8 = sd.register_read(r + 4).await?;
                let activate: u8 = sd.register_read(r + 6).await?;
                Ok::<_, ethercrab::error::Error>((start, len, control, activate))
            };
            let (start, len, control, activate) = wire.run("SM1 read-back", read)?;
            let mailbox = control & 0x03 == 0x02
                && activate & 1 != 0
                && (8..=MAX_MAILBOX_READ).contains(&usize::from(len));
            sm1.push(mailbox.then_some(MailboxIn { start, len }));
        }
        Ok(MailboxWatch {
            spans: vec![None; sm1.len()],
            full: vec![false; sm1.len()],
            slots: plans
                .iter()
                .map(|p| (p.slots.clone(), p.model.is_multi_axis()))
                .collect(),
            sm1,
            notices: VecDeque::with_capacity(NOTICE_QUEUE),
            dropped: 0,
        })
    }
}

impl EthercatBus {
    /// Notices dropped because the queue of untaken ones was full (diagnostics).
    pub fn mailbox_notices_dropped(&self) -> u64 {
        self.mailbox.dropped
    }

    /// Reads SubDevice `station`'s SM1 status and, in the same frame, its buffer (which frees
    /// it; ETG.1000.4 §6.7.2): the message if SM1 was full. One acyclic round trip, no heap
    /// allocation. `Ok(false)`: SM1 was empty (or the station has no mailbox).
    pub(super) fn read_mailbox(&mut self, station: usize) -> Result<bool, BusError> {
        let Some(Some(mb)) = self.mailbox.sm1.get(station).copied() else {
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
        let (slots, multi) = &self.mailbox.slots[station];
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
        self.mailbox.slots[station]
            .0
            .iter()
            .flatten()
            .copied()
            .next()
            .unwrap_or(0)
    }

    /// Queues a mailbox notice for the executive; a full queue counts it as dropped.
    pub(super) fn push_notice(&mut self, notice: MailboxNotice) {
        if self.mailbox.notices.len() < NOTICE_QUEUE {
            self.mailbox.notices.push_back(notice);
        } else {
            self.mailbox.dropped += 1;
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
        if let Some(f) = self.mailbox.full.get_mut(station) {
            *f = false;
        }
    }
}
