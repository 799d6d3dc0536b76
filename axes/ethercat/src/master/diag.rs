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

use cellrt_cia402::bus::FrameCounters;

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
    /// The mailbox worker's frames (SDO, mailbox reads, these readings) that did not return:
    /// a wire fault hits them as it hits the cyclic frames.
    #[serde(default)]
    pub mailbox_frames_lost: u64,
    /// Mailbox notices dropped because the RT loop's queue was full.
    pub notices_dropped: u64,
}

/// What the worker and the host share for diagnostics (never touched by the RT loop except
/// the frame counters, relaxed atomics it stores).
pub(super) struct DiagShared {
    pub(super) wanted: AtomicBool,
    pub(super) out: ArrayQueue<SegmentDiag>,
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
    pub(super) shared: Arc<DiagShared>,
}

impl std::fmt::Debug for BusDiagnostics {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BusDiagnostics").finish_non_exhaustive()
    }
}

impl BusDiagnostics {
    /// Asks the worker for a reading (a reading not yet collected is discarded).
    pub fn request(&self) {
        let _ = self.shared.out.pop();
        self.shared.wanted.store(true, Ordering::Release);
    }

    /// The reading, once the worker has taken it.
    pub fn take(&self) -> Option<SegmentDiag> {
        self.shared.out.pop()
    }
}
