//! The cyclic frame of the segment in OP: one LRW over the process image, the reference
//! clock's system time, each SubDevice's AL status and SM1 status; built in a preallocated
//! buffer, the working counter checked (ETG.1000.4 §5.4, ETG.1000.6 §6.4).

use super::bus::EthercatBus;
use super::group::MASTER_MAC;
use super::mailbox::SM_STATUS_FULL;
use crate::frame::{self, Command, FrameBuilder};
use crate::register::{self as reg, AlStatus};
use cellrt_cia402::bus::BusError;
use cellrt_cia402::cycles::Cycles;

impl EthercatBus {
    /// Sends the cyclic frame and takes in what it returns; `elapsed` cycles since the last.
    pub(super) fn cyclic_exchange(&mut self, elapsed: Cycles) -> Result<(), BusError> {
        // The counters so far, for the host's diagnostics (relaxed atomic stores).
        self.worker.shared.diag.publish(&self.counters);
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
}
