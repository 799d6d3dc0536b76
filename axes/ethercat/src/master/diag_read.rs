//! The mailbox worker's reading of the diagnostics ([`super::diag`]): one frame of FPRDs per
//! SubDevice — DL status, AL status and code, the error counter block, the DC system time
//! difference — carried after the cyclic frame.

use std::sync::atomic::Ordering;

use super::diag::{PortDiag, SegmentDiag, SubDeviceDiag};
use super::group::MASTER_MAC;
use super::link::Link;
use super::worker::MailboxWorker;
use crate::frame::{self, Command, FrameBuilder};
use crate::register::{self as reg, AlState};

/// DC system time difference (ETG.1000.4: 092Ch, bit 31 the sign: 1 = local copy smaller).
const DC_SYSTEM_TIME_DIFFERENCE: u16 = 0x092C;
/// The error counter block 0300h–0313h.
const COUNTERS_LEN: usize = 0x14;

impl MailboxWorker {
    /// Takes a reading when the host asked for one.
    pub(super) fn diagnose_if_wanted(&mut self) -> bool {
        if !self.shared.diag.wanted.swap(false, Ordering::AcqRel) {
            return false;
        }
        let subdevices = (0..self.station_addresses.len())
            .map(|s| self.read_subdevice(s))
            .collect();
        let d = &self.shared.diag;
        let reading = SegmentDiag {
            subdevices,
            frames: d.frames.load(Ordering::Relaxed),
            frames_lost: d.lost.load(Ordering::Relaxed),
            wkc_errors: d.wkc_errors.load(Ordering::Relaxed),
            mailbox_frames_lost: self.link.frames_lost(),
            notices_dropped: self.shared.dropped.load(Ordering::Relaxed),
        };
        let _ = self.shared.diag.out.force_push(reading);
        true
    }

    /// One frame of FPRDs to SubDevice `station`: DL status, AL status and code, the error
    /// counters and the DC system time difference.
    fn read_subdevice(&mut self, station: usize) -> SubDeviceDiag {
        let address = self.station_addresses[station];
        let d = &self.shared.diag;
        let mut out = SubDeviceDiag {
            position: station,
            address,
            answered: false,
            al_state: "no answer".into(),
            al_error: false,
            al_code: 0,
            ports: [PortDiag::default(); 4],
            processing_errors: 0,
            pdi_errors: 0,
            dc_difference_ns: 0,
            mailbox_messages: d.messages[station].load(Ordering::Relaxed),
            emergencies: d.emergencies[station].load(Ordering::Relaxed),
        };
        let adp = u32::from(address);
        let at = |register: u16| (u32::from(register) << 16) | adp;
        let (spans, len) = {
            let mut b = FrameBuilder::new(&mut self.frame, MASTER_MAC);
            let spans = [
                b.push(Command::Fprd, 0, at(reg::DL_STATUS), &[0; 2]),
                b.push(
                    Command::Fprd,
                    0,
                    at(reg::AL_STATUS),
                    &[0; reg::AL_STATUS_READ_LEN],
                ),
                b.push(
                    Command::Fprd,
                    0,
                    at(reg::RX_ERROR_COUNTER),
                    &[0; COUNTERS_LEN],
                ),
                b.push(Command::Fprd, 0, at(DC_SYSTEM_TIME_DIFFERENCE), &[0; 4]),
            ];
            (spans, b.finish())
        };
        let [Some(dl), Some(al), Some(counters), Some(dc)] = spans else {
            return out;
        };
        if self.link.round_trip(&mut self.frame, len).is_err() {
            return out;
        }
        let f = &self.frame;
        let answered = |s: &frame::DatagramSpan| frame::wkc(f, s) == 1;
        if answered(&counters) {
            out.answered = true;
            let c = &f[counters.data_offset..][..COUNTERS_LEN];
            for (p, port) in out.ports.iter_mut().enumerate() {
                port.invalid_frames = c[2 * p];
                port.rx_errors = c[2 * p + 1];
                port.forwarded_errors = c[8 + p];
                port.lost_links = c[0x10 + p];
            }
            out.processing_errors = c[0x0C];
            out.pdi_errors = c[0x0D];
        }
        if answered(&dl) {
            let s = u16::from_le_bytes([f[dl.data_offset], f[dl.data_offset + 1]]);
            // DL status bits 4–7: link on ports 0–3.
            for (p, port) in out.ports.iter_mut().enumerate() {
                port.link = s & (reg::DL_LINK_PORT0 << p) != 0;
            }
        }
        if answered(&al) {
            let b = &f[al.data_offset..][..reg::AL_STATUS_READ_LEN];
            out.al_state = AlState::from_bits(b[0] & 0x0F)
                .map_or_else(|| format!("{:#04x}", b[0] & 0x0F), |s| s.as_str().into());
            out.al_error = b[0] & reg::AL_ERROR_INDICATION != 0;
            out.al_code = u16::from_le_bytes([b[4], b[5]]);
        }
        if answered(&dc) {
            let raw = u32::from_le_bytes(f[dc.data_offset..][..4].try_into().expect("4 bytes"));
            let magnitude = i64::from(raw & 0x7FFF_FFFF);
            out.dc_difference_ns = if raw & 0x8000_0000 != 0 {
                -magnitude
            } else {
                magnitude
            };
        }
        out
    }
}
