//! The EtherCAT MainDevice as a [`CyclicBus`]: ethercrab brings the segment up (INIT → PRE-OP, SII,
//! mailboxes, the PDO assignment by SDO, SAFE-OP, OP); in OP the cyclic exchange is cellrt's
//! own frame (one LRW over the process image, preallocated, no heap allocation per cycle; see
//! docs/architecture.md on ethercrab's `tx_rx_dc()`), with the working counter checked every cycle.

use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use super::carrier::CarrierRt;
use super::dc::DcAlignment;
pub use super::group::{MAX_PDI, MAX_SUBDEVICES};
use super::link::Link;
use super::mailbox::MailboxWatch;
use super::process_image::AxisImage;
use super::segment::SegmentConfig;
use super::worker::WorkerHandle;
use crate::frame::DatagramSpan;
use crate::register::AlStatus;
use cellrt_cia402::bus::{
    AcyclicBus, BusError, CyclicBus, FaultInjection, FrameCounters, LinkState, MailboxNotice,
    PostError, SdoData, SdoOutcome, SdoRequest,
};
use cellrt_cia402::cycles::Cycles;

/// An EtherCAT segment in OP as a [`Bus`].
pub struct EthercatBus {
    pub(super) link: Box<dyn Link>,
    /// Carries the mailbox worker's frames after the cyclic one.
    pub(super) carrier: CarrierRt,
    /// The mailbox worker: every acyclic transfer in OP.
    pub(super) worker: WorkerHandle,
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

    /// A handle on the segment's diagnostics for the host (taken before the bus moves to the
    /// RT thread; the readings are made by the mailbox worker).
    pub fn diagnostics(&self) -> super::diag::BusDiagnostics {
        super::diag::BusDiagnostics {
            shared: self.worker.shared.diag.clone(),
        }
    }

    /// A handle on the drives' dictionaries by SDO Information for the host (taken before the
    /// bus moves to the RT thread; the walks are made by the mailbox worker).
    pub fn dictionary_reader(&self) -> super::dictionary::DictionaryReader {
        self.worker.shared.dictionary_reader.clone()
    }

    /// The link (tests and fault injection reach the emulated segment through it).
    pub fn link_mut(&mut self) -> &mut dyn Link {
        self.link.as_mut()
    }
}

/// CiA 301 abort 0504 0000h "SDO protocol timed out": a blocking transfer got no answer.
pub const SDO_TIMED_OUT: u32 = 0x0504_0000;
/// How long a blocking transfer (outside the loop) waits for the mailbox worker.
const BLOCKING_SDO_TIMEOUT: Duration = Duration::from_secs(5);

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

    /// The cyclic frame, then at most one frame of the mailbox worker.
    fn exchange(&mut self, elapsed: Cycles) -> Result<(), BusError> {
        let result = self.cyclic_exchange(elapsed);
        self.carrier.carry(self.link.as_mut());
        result
    }

    fn frame_counters(&self) -> Option<FrameCounters> {
        Some(self.counters)
    }

    fn link_state(&self, axis: usize) -> Option<LinkState> {
        self.al_status(axis).map(LinkState::from)
    }

    /// A notice the mailbox worker has read; each SubDevice whose SM1 the last cyclic frame
    /// saw full is handed to the worker to read (its message comes in a later cycle).
    fn take_mailbox_notice(&mut self) -> Option<MailboxNotice> {
        for (station, full) in self.mailbox.full.iter_mut().enumerate() {
            if std::mem::take(full) {
                self.worker.shared.drain[station].store(true, Ordering::Release);
            }
        }
        self.worker.shared.notices.pop()
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

impl EthercatBus {
    /// Notices dropped because the queue of untaken ones was full (diagnostics).
    pub fn mailbox_notices_dropped(&self) -> u64 {
        self.worker.shared.dropped.load(Ordering::Relaxed)
    }

    /// A transfer outside the loop: posted to the worker, whose frames this thread carries
    /// until the outcome is there (or [`BLOCKING_SDO_TIMEOUT`]: [`SDO_TIMED_OUT`]). It takes
    /// no time on a virtual link clock (that moves with the cyclic exchange only), so the
    /// emulated drives see no cycle missed.
    fn sdo_blocking(&mut self, axis: usize, request: SdoRequest) -> SdoOutcome {
        match self.post_sdo(axis, request) {
            Ok(()) => {}
            Err(PostError::Unsupported) => {
                return SdoOutcome::Aborted(cellrt_cia402::bus::SDO_UNSUPPORTED)
            }
            Err(PostError::Busy) => return SdoOutcome::Aborted(SDO_TIMED_OUT),
        }
        let start = Instant::now();
        loop {
            self.carrier.carry(self.link.as_mut());
            if let Some(outcome) = self.take_sdo(axis) {
                return outcome;
            }
            if start.elapsed() > BLOCKING_SDO_TIMEOUT {
                return SdoOutcome::Aborted(SDO_TIMED_OUT);
            }
            std::thread::sleep(Duration::from_micros(20));
        }
    }
}

impl AcyclicBus for EthercatBus {
    /// Into the axis' slot for the mailbox worker: no frame, no wait.
    fn post_sdo(&mut self, axis: usize, request: SdoRequest) -> Result<(), PostError> {
        self.worker
            .shared
            .sdo
            .get(axis)
            .ok_or(PostError::Unsupported)?
            .post(request)
    }

    fn take_sdo(&mut self, axis: usize) -> Option<SdoOutcome> {
        self.worker.shared.sdo.get(axis)?.take()
    }

    fn sdo_upload(&mut self, axis: usize, index: u16, sub: u8) -> Result<i64, u32> {
        match self.sdo_blocking(axis, SdoRequest::Upload { index, sub }) {
            SdoOutcome::Uploaded(v) => Ok(v),
            SdoOutcome::Aborted(code) => Err(code),
            SdoOutcome::Downloaded => Err(cellrt_cia402::bus::SDO_UNSUPPORTED),
        }
    }

    fn sdo_download(&mut self, axis: usize, index: u16, sub: u8, data: &[u8]) -> Result<(), u32> {
        let data = SdoData::new(data).ok_or(cellrt_cia402::bus::SDO_UNSUPPORTED)?;
        match self.sdo_blocking(axis, SdoRequest::Download { index, sub, data }) {
            SdoOutcome::Downloaded => Ok(()),
            SdoOutcome::Aborted(code) => Err(code),
            SdoOutcome::Uploaded(_) => Err(cellrt_cia402::bus::SDO_UNSUPPORTED),
        }
    }

    fn close(&mut self) -> Result<(), cellrt_cia402::bus::CloseError> {
        self.leave_op()
            .map_err(|e| cellrt_cia402::bus::CloseError(Box::new(e)))
    }
}

impl FaultInjection for EthercatBus {
    /// On the in-process segment: the emulated drive of `axis` raises `code`.
    fn inject_alarm(&mut self, axis: usize, code: u16) -> bool {
        let Some(&AxisImage { station, slot, .. }) = self.axes.get(axis) else {
            return false;
        };
        self.link.inject_alarm(station, usize::from(slot), code)
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
