//! Bus diagnostics of a running segment, read on the mailbox worker (non-RT) with one frame per
//! SubDevice carried after the cyclic one: per port the link (DL status 0110h) and the ESC
//! error counters (ETG.1000.4 §6.2 / ESC datasheets: invalid frame and RX error counters
//! 0300h–0307h, forwarded RX error counters 0308h–030Bh, ECAT processing unit and PDI error
//! counters 030Ch–030Dh, lost link counters 0310h–0313h), the AL status and code (0130h,
//! 0134h) and the DC system time difference (092Ch); beside them the master's cyclic frame
//! counters and the mailbox messages and Emergencies the worker read from each SubDevice.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;

use crossbeam::queue::ArrayQueue;
use serde::{Deserialize, Serialize};

use super::group::MASTER_MAC;
use super::link::Link;
use super::worker::{MailboxWorker, Shared};
use crate::bus::FrameCounters;
use crate::ethercat::frame::{self, Command, FrameBuilder};
use crate::ethercat::register::{self as reg, AlState};

/// DC system time difference (ETG.1000.4: 092Ch, bit 31 the sign: 1 = local copy smaller).
const DC_SYSTEM_TIME_DIFFERENCE: u16 = 0x092C;
/// The error counter block 0300h–0313h.
const COUNTERS_LEN: usize = 0x14;

/// One port of a SubDevice's ESC.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct PortDiag {
    /// Link detected (DL status).
    pub link: bool,
    /// Invalid frames received (0300h + 2·port).
    pub invalid_frames: u8,
    /// RX errors on the physical layer (0301h + 2·port).
    pub rx_errors: u8,
    /// Frames received marked by an earlier ESC as erroneous (0308h + port).
    pub forwarded_errors: u8,
    /// Times the link was lost (0310h + port).
    pub lost_links: u8,
}

impl PortDiag {
    /// The sum of its error counters.
    pub fn errors(&self) -> u32 {
        [
            self.invalid_frames,
            self.rx_errors,
            self.forwarded_errors,
            self.lost_links,
        ]
        .iter()
        .map(|&n| u32::from(n))
        .sum()
    }
}

/// What one SubDevice shows.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct SubDeviceDiag {
    /// Position in the line (0: next to the master).
    pub position: usize,
    /// Configured station address.
    pub address: u16,
    /// Whether it answered the diagnostics frame (false: the counters below are zero).
    pub answered: bool,
    /// AL state.
    pub al_state: String,
    /// AL status error indication.
    pub al_error: bool,
    /// AL status code.
    pub al_code: u16,
    /// Ports 0–3.
    pub ports: [PortDiag; 4],
    /// ECAT processing unit errors (030Ch).
    pub processing_errors: u8,
    /// PDI errors (030Dh).
    pub pdi_errors: u8,
    /// DC system time difference, ns (signed; 0 where the SubDevice has no DC).
    pub dc_difference_ns: i64,
    /// Mailbox messages the worker read from it since OP.
    pub mailbox_messages: u64,
    /// Of them, CoE Emergencies.
    pub emergencies: u64,
}

/// The segment's diagnostics at one moment.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct SegmentDiag {
    /// Per SubDevice, in line order.
    pub subdevices: Vec<SubDeviceDiag>,
    /// The master's cyclic frames: sent, lost, with a wrong working counter.
    pub frames: u64,
    /// Cyclic frames that did not return.
    pub frames_lost: u64,
    /// Cyclic frames with a wrong working counter.
    pub wkc_errors: u64,
    /// Mailbox notices dropped because the RT loop's queue was full.
    pub notices_dropped: u64,
}

/// What the worker and the host share for diagnostics (never touched by the RT loop except
/// the frame counters, relaxed atomics it stores).
pub(super) struct DiagShared {
    wanted: AtomicBool,
    out: ArrayQueue<SegmentDiag>,
    pub(super) frames: AtomicU64,
    pub(super) lost: AtomicU64,
    pub(super) wkc_errors: AtomicU64,
    /// Per SubDevice: mailbox messages read, and Emergencies among them.
    pub(super) messages: Vec<AtomicU64>,
    pub(super) emergencies: Vec<AtomicU64>,
}

impl DiagShared {
    pub(super) fn new(stations: usize) -> DiagShared {
        DiagShared {
            wanted: AtomicBool::new(false),
            out: ArrayQueue::new(1),
            frames: AtomicU64::new(0),
            lost: AtomicU64::new(0),
            wkc_errors: AtomicU64::new(0),
            messages: (0..stations).map(|_| AtomicU64::new(0)).collect(),
            emergencies: (0..stations).map(|_| AtomicU64::new(0)).collect(),
        }
    }

    /// Mirrors the RT loop's frame counters (relaxed stores, no wait).
    pub(super) fn publish(&self, c: &FrameCounters) {
        self.frames.store(c.frames, Ordering::Relaxed);
        self.lost.store(c.lost, Ordering::Relaxed);
        self.wkc_errors.store(c.wkc_errors, Ordering::Relaxed);
    }
}

/// The host's handle on a running segment's diagnostics: ask, then collect the answer.
#[derive(Clone)]
pub struct BusDiagnostics {
    pub(super) shared: Arc<Shared>,
}

impl std::fmt::Debug for BusDiagnostics {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BusDiagnostics").finish_non_exhaustive()
    }
}

impl BusDiagnostics {
    /// Asks the worker for a reading (a reading not yet collected is discarded).
    pub fn request(&self) {
        let _ = self.shared.diag.out.pop();
        self.shared.diag.wanted.store(true, Ordering::Release);
    }

    /// The reading, once the worker has taken it.
    pub fn take(&self) -> Option<SegmentDiag> {
        self.shared.diag.out.pop()
    }
}

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
