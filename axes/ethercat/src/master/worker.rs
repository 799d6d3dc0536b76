//! The mailbox worker: a non-RT thread that runs every acyclic transfer while the segment is in
//! OP — the SDOs the RT loop posts (mode changes, homing parameters, 607Ch, 603Fh) and the
//! SM1 reads that fetch Emergencies, the host's diagnostics and dictionary walks — through ethercrab, with its frames carried by the RT
//! thread's cyclic exchange ([`super::carrier`]). The RT loop never waits for a mailbox.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

use crossbeam::queue::ArrayQueue;
use ethercrab::{MainDevice, PduRx, PduTx};

use super::carrier::CarriedLink;
use super::dictionary::OdWalk;
use super::dictionary::{dictionary_channels, DictionaryQueue, DictionaryReader};
use super::group::OpGroup;
use super::mailbox::{MailboxIn, NOTICE_QUEUE};
use super::sdo_slot::SdoSlot;
use super::segment::SegmentConfig;
use cellrt_cia402::bus::{MailboxNotice, SdoOutcome, SdoRequest};

/// How long the worker sleeps between looks while transfers come (non-RT; bounds how late a
/// posted request starts).
const BUSY_POLL: Duration = Duration::from_micros(200);
/// How long it sleeps between looks once nothing has come for [`QUIET_AFTER`]: fewer wake-ups
/// beside the RT thread in steady state; a request then starts at most this late.
const IDLE_POLL: Duration = Duration::from_millis(1);
/// Time without work after which the worker polls at [`IDLE_POLL`].
const QUIET_AFTER: Duration = Duration::from_millis(20);
/// The worker's stack: ethercrab's SDO Information futures hold buffers of up to 128 KiB
/// (the OD list), polled on this stack.
const WORKER_STACK: usize = 8 << 20;

/// What the RT thread and the worker share: lock-free, preallocated.
pub(super) struct Shared {
    /// Per axis: its request slot.
    pub(super) sdo: Vec<SdoSlot>,
    /// Per SubDevice: the cyclic frame saw its SM1 full; the worker reads it.
    pub(super) drain: Vec<AtomicBool>,
    /// Notices read from the mailboxes, for the RT loop.
    pub(super) notices: ArrayQueue<MailboxNotice>,
    /// Notices dropped because the queue was full.
    pub(super) dropped: AtomicU64,
    /// Bus diagnostics: the host's requests, the readings and the counters behind them.
    pub(super) diag: Arc<super::diag::DiagShared>,
    /// The host's requests for a dictionary by SDO Information, and the readings.
    pub(super) dictionary: DictionaryQueue,
    /// The host's end of [`Shared::dictionary`].
    pub(super) dictionary_reader: DictionaryReader,
    /// The worker ends.
    stop: AtomicBool,
}

/// ethercrab's side of the segment in OP, moved to the worker.
pub(super) struct Ethercrab {
    pub(super) maindevice: MainDevice<'static>,
    pub(super) group: OpGroup,
    pub(super) tx: PduTx<'static>,
    pub(super) rx: PduRx<'static>,
}

/// The worker: ethercrab, a carried link and what it needs to know of the segment.
pub(super) struct MailboxWorker {
    pub(super) ethercrab: Ethercrab,
    pub(super) link: CarriedLink,
    pub(super) frame: Vec<u8>,
    pub(super) config: SegmentConfig,
    /// Per axis: its SubDevice (position in the line) and slot there.
    pub(super) axes: Vec<(usize, u8)>,
    /// Per SubDevice: its configured station address.
    pub(super) station_addresses: Vec<u16>,
    /// Per SubDevice: its SM1, `None` without a watched mailbox.
    pub(super) sm1: Vec<Option<MailboxIn>>,
    /// Per SubDevice: the axes of its slots (slot 0 = axis A) and whether it is multi-axis.
    pub(super) slots: Vec<(Vec<Option<usize>>, bool)>,
    pub(super) shared: Arc<Shared>,
    /// The dictionary walk in progress.
    pub(super) od_walk: Option<OdWalk>,
}

/// The bus's handle on its worker thread: the shared slots, stopped and joined on drop.
pub(super) struct WorkerHandle {
    pub(super) shared: Arc<Shared>,
    thread: Option<JoinHandle<()>>,
}

impl Shared {
    /// Slots for `axes` axes and `stations` SubDevices.
    pub(super) fn new(axes: usize, stations: usize) -> Shared {
        let (dictionary_reader, dictionary) = dictionary_channels();
        Shared {
            dictionary,
            dictionary_reader,
            sdo: (0..axes).map(|_| SdoSlot::default()).collect(),
            drain: (0..stations).map(|_| AtomicBool::new(false)).collect(),
            notices: ArrayQueue::new(NOTICE_QUEUE),
            dropped: AtomicU64::new(0),
            diag: Arc::new(super::diag::DiagShared::new(stations)),
            stop: AtomicBool::new(false),
        }
    }
}

impl MailboxWorker {
    /// Starts the worker thread.
    pub(super) fn spawn(self) -> std::io::Result<WorkerHandle> {
        let shared = self.shared.clone();
        let thread = std::thread::Builder::new()
            .name("cellrt-mailbox".into())
            .stack_size(WORKER_STACK)
            .spawn(move || self.run())?;
        Ok(WorkerHandle {
            shared,
            thread: Some(thread),
        })
    }

    fn run(mut self) {
        let mut last_work = std::time::Instant::now();
        while !self.shared.stop.load(Ordering::Acquire) {
            let mut worked = false;
            for station in 0..self.shared.drain.len() {
                if self.shared.drain[station].swap(false, Ordering::AcqRel) {
                    self.drain_mailbox(station);
                    worked = true;
                }
            }
            for axis in 0..self.shared.sdo.len() {
                if let Some(request) = self.shared.sdo[axis].claim() {
                    let outcome = self.serve(axis, request);
                    self.shared.sdo[axis].complete(outcome);
                    worked = true;
                }
            }
            worked |= self.diagnose_if_wanted();
            worked |= self.walk_dictionary_if_asked();
            if worked {
                last_work = std::time::Instant::now();
            } else if last_work.elapsed() < QUIET_AFTER {
                std::thread::sleep(BUSY_POLL);
            } else {
                std::thread::sleep(IDLE_POLL);
            }
        }
    }

    /// Runs one request of `axis`.
    fn serve(&mut self, axis: usize, request: SdoRequest) -> SdoOutcome {
        match request {
            SdoRequest::Upload { index, sub } => self
                .sdo_read_value(axis, index, sub)
                .map_or_else(SdoOutcome::Aborted, SdoOutcome::Uploaded),
            SdoRequest::Download { index, sub, data } => self
                .sdo_write(axis, index, sub, data.as_slice())
                .map_or_else(SdoOutcome::Aborted, |()| SdoOutcome::Downloaded),
        }
    }
}

impl Drop for WorkerHandle {
    fn drop(&mut self) {
        self.shared.stop.store(true, Ordering::Release);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}
