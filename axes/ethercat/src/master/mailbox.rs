//! The SubDevice→master mailbox (SM1) watched in the cyclic frame and drained before each SDO:
//! CoE Emergencies become [`MailboxNotice`]s of the axis they name (ETG.1000.4 §6.7.2).

use super::error::{step, EthercatError};
use super::group::OpGroup;
use super::pump::Wire;
use super::segment::SegmentStation;
use crate::frame::DatagramSpan;
use crate::register as reg;
use ethercrab::MainDevice;

/// SM status (0805h + 8n) bit 3: mailbox full.
pub(super) const SM_STATUS_FULL: u8 = 0x08;
/// Largest SM1 mailbox the master drains itself (bigger ones are left to ethercrab's clearing).
const MAX_MAILBOX_READ: usize = 1024;
/// Zeros to send as the data of a mailbox read (no allocation per read).
pub(super) static MAILBOX_READ_ZEROS: [u8; MAX_MAILBOX_READ] = [0; MAX_MAILBOX_READ];
/// Mailbox messages drained before an SDO at most (a firmware that refills SM1 faster than
/// this is left to ethercrab's clearing, which discards).
pub(super) const MAX_DRAIN: usize = 8;
/// Notices held for [`CyclicBus::take_mailbox_notice`] (preallocated; more are dropped and
/// counted).
///
/// [`CyclicBus::take_mailbox_notice`]: cellrt_cia402::bus::CyclicBus::take_mailbox_notice
pub(super) const NOTICE_QUEUE: usize = 16;

/// A SubDevice's SubDevice→master mailbox (SM1), read back at bring-up.
#[derive(Debug, Clone, Copy)]
pub(super) struct MailboxIn {
    /// Physical start address and length of the buffer.
    pub(super) start: u16,
    pub(super) len: u16,
}

/// Per SubDevice with a mailbox: the SM1 watch in the cyclic frame; the mailbox worker reads
/// CoE Emergencies when it sees SM1 full and before every SDO, so that ethercrab meets none
/// left over (one that comes during an SDO is `MailboxWorker::emergency_in_sdo`'s).
#[derive(Debug, Default)]
pub(super) struct MailboxWatch {
    /// Per SubDevice: its SM1, `None` without a mailbox (or one over [`MAX_MAILBOX_READ`]).
    pub(super) sm1: Vec<Option<MailboxIn>>,
    /// Per SubDevice: where the cyclic frame's read of its SM1 status sits.
    pub(super) spans: Vec<Option<DatagramSpan>>,
    /// Per SubDevice: the last cyclic frame saw SM1 full.
    pub(super) full: Vec<bool>,
    /// Per SubDevice: the axes of its slots (slot 0 = axis A) and whether it is multi-axis.
    pub(super) slots: Vec<(Vec<Option<usize>>, bool)>,
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
        })
    }
}
