//! The EtherCAT MainDevice as a [`CyclicBus`]: ethercrab brings the segment up (INIT → PRE-OP, SII,
//! mailboxes, the PDO assignment by SDO, SAFE-OP, OP); in OP the cyclic exchange is cellrt's
//! own frame (one LRW over the process image, preallocated, no heap allocation per cycle; see
//! docs/architecture.md on ethercrab's `tx_rx_dc()`), with the working counter checked every cycle.

use ethercrab::{MainDevice, PduRx, PduTx};

use super::dc::DcAlignment;
use super::group::OpGroup;
use super::group::MASTER_MAC;
pub use super::group::{MAX_PDI, MAX_SUBDEVICES};
use super::link::Link;
use super::mailbox::{MailboxWatch, SM_STATUS_FULL};
use super::process_image::AxisImage;
use super::segment::SegmentConfig;
use crate::bus::{
    AcyclicBus, BusError, CyclicBus, FaultInjection, FrameCounters, LinkState, MailboxNotice,
    SDO_UNSUPPORTED,
};
use crate::cycles::Cycles;
use crate::ethercat::frame::{self, Command, DatagramSpan, FrameBuilder};
use crate::ethercat::register::{self as reg, AlStatus};

/// An EtherCAT segment in OP as a [`Bus`].
pub struct EthercatBus {
    pub(super) link: Box<dyn Link>,
    pub(super) tx: PduTx<'static>,
    pub(super) rx: PduRx<'static>,
    pub(super) maindevice: MainDevice<'static>,
    pub(super) group: OpGroup,
    pub(super) config: SegmentConfig,
    pub(super) axes: Vec<AxisImage>,
    /// SubDevices on the segment.
    pub(super) stations: usize,
    /// Per SubDevice: its configured station address, where its AL status is read each cycle.
    pub(super) station_addresses: Vec<u16>,
    /// Per SubDevice: where its AL status read sits in the current frame.
    pub(super) al_spans: Vec<Option<DatagramSpan>>,
    /// Per SubDevice: the AL status the last returned frame read (ETG.1000.6 §6.4: 0130h, 0134h).
    pub(super) al: Vec<Option<AlStatus>>,
    pub(super) pdi: Vec<u8>,
    pub(super) frame: Vec<u8>,
    pub(super) expected_wkc: u16,
    pub(super) counters: FrameCounters,
    pub(super) index: u8,
    pub(super) dc: DcAlignment,
    /// The correction the RT loop took since the last exchange, ns.
    pub(super) dc_taken: i64,
    pub(super) mailbox: MailboxWatch,
    /// Optional settings bring-up skipped.
    pub(super) warnings: Vec<super::refusal::BringUpWarning>,
}

impl std::fmt::Debug for EthercatBus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EthercatBus")
            .field("axes", &self.axes.len())
            .field("pdi", &self.pdi.len())
            .field("counters", &self.counters)
            .finish_non_exhaustive()
    }
}

impl EthercatBus {
    /// Counters of the cyclic exchange.
    pub fn counters(&self) -> FrameCounters {
        self.counters
    }

    /// The optional settings bring-up skipped because a SubDevice does not have them or does
    /// not let them be written (the segment came up without them).
    pub fn bring_up_warnings(&self) -> &[super::refusal::BringUpWarning] {
        &self.warnings
    }

    /// The link (tests and fault injection reach the emulated segment through it).
    pub fn link_mut(&mut self) -> &mut dyn Link {
        self.link.as_mut()
    }
}

/// The SDO abort code of an ethercrab error (0800 0000h general error for others).
pub(super) fn abort_code(e: ethercrab::error::Error) -> u32 {
    match e {
        ethercrab::error::Error::Mailbox(ethercrab::error::MailboxError::Aborted {
            code, ..
        }) => u32::from(code),
        _ => 0x0800_0000,
    }
}

impl EthercatBus {
    /// The AL status of the SubDevice that carries `axis`, as the last cyclic frame read it
    /// (ETG.1000.6 §6.4); `None` before it answered.
    pub fn al_status(&self, axis: usize) -> Option<AlStatus> {
        self.axes.get(axis).and_then(|a| self.al[a.station])
    }
}

impl CyclicBus for EthercatBus {
    fn axis_count(&self) -> usize {
        self.axes.len()
    }

    fn rx_image_mut(&mut self, axis: usize) -> &mut [u8] {
        self.axes
            .get_mut(axis)
            .map_or(&mut [], |a| a.rx.as_mut_slice())
    }

    fn tx_image(&self, axis: usize) -> &[u8] {
        self.axes.get(axis).map_or(&[], |a| a.tx.as_slice())
    }

    fn exchange(&mut self, elapsed: Cycles) -> Result<(), BusError> {
        // The time since the last frame: the cycles passed, moved by the deadline correction the
        // RT loop took (a virtual clock follows it; a real one ignores it).
        let period = u64::from(elapsed.0) * self.config.cycle.as_nanos();
        self.link
            .advance(period.saturating_add_signed(self.dc_taken));
        self.dc_taken = 0;
        if elapsed.0 > 1 {
            self.link.host_stall(u64::from(elapsed.0 - 1));
        }
        for a in &self.axes {
            self.pdi[a.outputs.clone()].copy_from_slice(&a.rx);
        }
        self.index = self.index.wrapping_add(1);
        let (span, dc_span, len) = {
            let mut b = FrameBuilder::new(&mut self.frame, MASTER_MAC);
            let Some(span) = b.push(Command::Lrw, self.index, 0, &self.pdi) else {
                return Err(BusError::FrameTooLarge {
                    bytes: self.pdi.len(),
                });
            };
            let address = (u32::from(reg::DC_SYSTEM_TIME) << 16) | u32::from(self.dc.reference);
            let Some(dc_span) = b.push(Command::Frmw, self.index, address, &[0; 8]) else {
                return Err(BusError::FrameTooLarge {
                    bytes: self.pdi.len() + 8,
                });
            };
            // Each SubDevice's AL status and code (monitoring, ETG.1000.6 §6.4).
            for (slot, &station) in self.al_spans.iter_mut().zip(&self.station_addresses) {
                let address = (u32::from(reg::AL_STATUS) << 16) | u32::from(station);
                *slot = b.push(
                    Command::Fprd,
                    self.index,
                    address,
                    &[0; reg::AL_STATUS_READ_LEN],
                );
                if slot.is_none() {
                    return Err(BusError::FrameTooLarge {
                        bytes: self.pdi.len()
                            + 8
                            + self.station_addresses.len() * reg::AL_STATUS_READ_LEN,
                    });
                }
            }
            // Each mailbox SubDevice's SM1 status: full means a message it sent unasked (an
            // Emergency), read by `take_mailbox_notice` (ETG.1000.4 §6.7.2).
            for ((slot, &station), mb) in self
                .mailbox
                .spans
                .iter_mut()
                .zip(&self.station_addresses)
                .zip(&self.mailbox.sm1)
            {
                *slot = None;
                if mb.is_none() {
                    continue;
                }
                let address = (u32::from(reg::sync_manager(1) + 5) << 16) | u32::from(station);
                *slot = b.push(Command::Fprd, self.index, address, &[0]);
                if slot.is_none() {
                    return Err(BusError::FrameTooLarge {
                        bytes: self.pdi.len() + 8 + self.station_addresses.len() * 8,
                    });
                }
            }
            (span, dc_span, b.finish())
        };
        self.counters.frames += 1;
        if self.link.round_trip(&mut self.frame, len).is_err() {
            self.counters.lost += 1;
            return Err(BusError::FrameLost);
        }
        if frame::wkc(&self.frame, &dc_span) != 0 {
            let at = dc_span.data_offset;
            let mut t = [0u8; 8];
            t.copy_from_slice(&self.frame[at..at + 8]);
            self.dc.observe(u64::from_le_bytes(t));
        }
        for (al, span) in self.al.iter_mut().zip(&self.al_spans) {
            if let Some(span) = span.filter(|s| frame::wkc(&self.frame, s) == 1) {
                let mut b = [0u8; reg::AL_STATUS_READ_LEN];
                b.copy_from_slice(&self.frame[span.data_offset..][..reg::AL_STATUS_READ_LEN]);
                *al = Some(AlStatus::from_bytes(&b));
            }
        }
        for (full, span) in self.mailbox.full.iter_mut().zip(&self.mailbox.spans) {
            if let Some(span) = span.filter(|s| frame::wkc(&self.frame, s) == 1) {
                *full |= self.frame[span.data_offset] & SM_STATUS_FULL != 0;
            }
        }
        let wkc = frame::wkc(&self.frame, &span);
        if wkc != self.expected_wkc {
            self.counters.wkc_errors += 1;
            return Err(BusError::WorkingCounter {
                expected: self.expected_wkc,
                found: wkc,
            });
        }
        let data = &self.frame[span.data_offset..span.data_offset + self.pdi.len()];
        for a in &mut self.axes {
            a.tx.copy_from_slice(&data[a.inputs.clone()]);
        }
        Ok(())
    }

    fn frame_counters(&self) -> Option<FrameCounters> {
        Some(self.counters)
    }

    fn link_state(&self, axis: usize) -> Option<LinkState> {
        self.al_status(axis).map(LinkState::from)
    }

    /// A notice already read (before an SDO), else one acyclic read of the first SubDevice
    /// whose SM1 the last cyclic frame saw full. A lost read frame is tried again next cycle.
    fn take_mailbox_notice(&mut self) -> Option<MailboxNotice> {
        if let Some(n) = self.mailbox.notices.pop_front() {
            return Some(n);
        }
        let station = self.mailbox.full.iter().position(|&f| f)?;
        if self.read_mailbox(station).is_ok() {
            self.mailbox.full[station] = false;
        }
        self.mailbox.notices.pop_front()
    }

    fn deadline_correction_ns(&mut self) -> i64 {
        let c = std::mem::take(&mut self.dc.pending);
        self.dc_taken += c;
        c
    }

    /// The cyclic frame's phase error in the SYNC0 cycle; `None` before the first frame has
    /// passed the reference clock.
    fn dc_phase_error_ns(&self) -> Option<i64> {
        self.dc.locked.then_some(self.dc.error)
    }
}

impl AcyclicBus for EthercatBus {
    fn sdo_upload(&mut self, axis: usize, index: u16, sub: u8) -> Result<i64, u32> {
        self.sdo_read_value(axis, index, sub)
    }

    fn sdo_download(&mut self, axis: usize, index: u16, sub: u8, data: &[u8]) -> Result<(), u32> {
        let (station, index) = self.station_object(axis, index).ok_or(SDO_UNSUPPORTED)?;
        self.sdo_transfer(axis, station, async |sd| match *data {
            [a] => sd.sdo_write(index, sub, a).await,
            [a, b] => sd.sdo_write(index, sub, u16::from_le_bytes([a, b])).await,
            [a, b, c, d] => {
                sd.sdo_write(index, sub, u32::from_le_bytes([a, b, c, d]))
                    .await
            }
            _ => Err(ethercrab::error::Error::Internal),
        })
    }

    fn close(&mut self) -> Result<(), String> {
        self.leave_op().map_err(|e| e.to_string())
    }

    fn read_error_code(&mut self, axis: usize) -> Option<u16> {
        self.sdo_read_value(axis, crate::pdo::objects::ERROR_CODE, 0)
            .ok()
            .map(|v| v as u16)
    }
}

impl FaultInjection for EthercatBus {
    /// On the in-process segment: the emulated drive of `axis` raises `code`.
    fn inject_alarm(&mut self, axis: usize, code: u16) -> bool {
        let Some(&AxisImage { station, slot, .. }) = self.axes.get(axis) else {
            return false;
        };
        match self
            .link
            .segment_mut()
            .and_then(|s| s.station_mut(station))
            .and_then(|st| st.drive_at_mut(usize::from(slot)))
        {
            Some(d) => {
                d.inject_alarm(code);
                true
            }
            None => false,
        }
    }

    /// The next `cycles` cyclic frames are lost on the wire: every SubDevice misses them (one
    /// frame carries the whole segment's process data), not only `axis`'.
    fn inject_rx_loss(&mut self, axis: usize, cycles: u32) -> bool {
        axis < self.axes.len() && self.link.drop_frames(cycles)
    }

    /// The SubDevice of `axis` (with every axis of its unit) stops answering.
    fn inject_subdevice_stall(&mut self, axis: usize, cycles: u32) -> bool {
        self.axes
            .get(axis)
            .is_some_and(|a| self.link.stall_subdevice(a.station, cycles))
    }

    fn inject_frame_delay(&mut self, delay_ns: u64, cycles: u32) -> bool {
        self.link.delay_frames(delay_ns, cycles)
    }

    fn inject_frame_corruption(&mut self, axis: usize, cycles: u32) -> bool {
        self.axes
            .get(axis)
            .is_some_and(|a| self.link.corrupt_frames(a.station, cycles))
    }

    fn inject_datagram_drop(&mut self, cycles: u32) -> bool {
        self.link.drop_datagrams(cycles)
    }

    fn inject_link_loss(&mut self, axis: usize, cycles: u32) -> bool {
        self.axes
            .get(axis)
            .is_some_and(|a| self.link.lose_link(a.station, cycles))
    }
}
