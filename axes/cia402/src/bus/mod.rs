//! Bus backends: the cyclic exchange of PDO images between the master and its drives.
//!
//! A bus offers three seams: [`CyclicBus`], what the RT loop calls every cycle (the images,
//! the exchange, the clock alignment and what the nodes report); [`AcyclicBus`], the acyclic
//! channel used at start-up, mode changes, fault edges and shutdown (SDO, 603Fh, close); and
//! [`FaultInjection`], test faults a bus can raise on itself, which the RT loop never sees
//! (the cell's fault schedule wraps the bus instead). The emulator's `SimBus` runs
//! simulated drives in-process; the EtherCAT master implements the same traits.

mod acyclic;
pub mod dictionary;
mod error;
mod notice;

pub use acyclic::{ImmediateSlot, PostError, SdoData, SdoOutcome, SdoRequest};
pub use dictionary::{DictionaryEntry, DictionarySource, PdoMappable};
pub use error::{BusError, CloseError};
pub use notice::{
    Emergency, LinkState, MailboxNotice, EMERGENCY_SLOT_BYTE, ERROR_REGISTER_GENERIC,
};

use crate::cycles::Cycles;

/// A cyclic process-data exchange with one RxPDO and one TxPDO image per axis: everything
/// the RT loop calls every cycle.
pub trait CyclicBus {
    /// Number of axes on the bus.
    fn axis_count(&self) -> usize;
    /// The RxPDO image (master → drive) of `axis`, written before [`CyclicBus::exchange`].
    fn rx_image_mut(&mut self, axis: usize) -> &mut [u8];
    /// The TxPDO image (drive → master) of `axis`, valid after [`CyclicBus::exchange`].
    fn tx_image(&self, axis: usize) -> &[u8];
    /// One exchange; `elapsed` is the cycle periods since the previous one (1 in steady state).
    fn exchange(&mut self, elapsed: Cycles) -> Result<(), BusError>;
    /// How far to move the RT loop's next deadline, ns (positive: later), so that the cycle
    /// stays aligned to the bus's clock (EtherCAT distributed clocks); 0 where the bus follows
    /// the loop (the in-process simulated drives). Taken once: the next call returns the
    /// correction that has come since.
    fn deadline_correction_ns(&mut self) -> i64 {
        0
    }
    /// Where the last exchange's frame passed the bus clock's cycle against its target place,
    /// ns (EtherCAT DC: its phase in the SYNC0 grid minus the target phase); `None` on a bus
    /// that follows the loop (the in-process simulated drives) or before the first measurement.
    fn dc_phase_error_ns(&self) -> Option<i64> {
        None
    }
    /// Counters of the cyclic frames, on a bus that sends frames (EtherCAT); `None` for the
    /// in-process simulated drives.
    fn frame_counters(&self) -> Option<FrameCounters> {
        None
    }
    /// The communication state of the node that carries `axis`, as the last cyclic exchange
    /// read it; `None` on a bus without one (the in-process simulated drives) or before it
    /// answered.
    fn link_state(&self, axis: usize) -> Option<LinkState> {
        let _ = axis;
        None
    }
    /// The next message a node sent unasked into its mailbox (EtherCAT: a CoE Emergency,
    /// ETG.1000.6 §5.6.2.1), polled by the RT loop every cycle; `None` when there is none. On
    /// EtherCAT a call may do one acyclic round trip (only in a cycle whose frame saw SM1 full).
    fn take_mailbox_notice(&mut self) -> Option<MailboxNotice> {
        None
    }
}

/// Acyclic access to the drives (SDO on a real bus) and the bus's shutdown. While the loop
/// runs it posts requests ([`AcyclicBus::post_sdo`]) and takes their outcomes in later cycles
/// ([`AcyclicBus::take_sdo`]); the blocking calls are for before the loop starts and after it
/// ends.
pub trait AcyclicBus {
    /// Posts `request` for `axis`; its outcome comes from [`AcyclicBus::take_sdo`] in a later
    /// call. Never blocks: the transfer runs off the RT thread (EtherCAT: the mailbox worker,
    /// whose frames the cyclic exchange carries). One request per axis at a time.
    fn post_sdo(&mut self, axis: usize, request: SdoRequest) -> Result<(), PostError> {
        let _ = (axis, request);
        Err(PostError::Unsupported)
    }
    /// The outcome of `axis`' posted request once it has completed (taken once); `None` while
    /// it is in flight or when none was posted.
    fn take_sdo(&mut self, axis: usize) -> Option<SdoOutcome> {
        let _ = axis;
        None
    }
    /// Acyclic read (an SDO upload on a real bus) of `index:sub` of `axis`, blocking: before
    /// the loop starts (607Ch). `Err(abort code)` as for [`AcyclicBus::sdo_download`].
    fn sdo_upload(&mut self, axis: usize, index: u16, sub: u8) -> Result<i64, u32> {
        let _ = (axis, index, sub);
        Err(SDO_UNSUPPORTED)
    }
    /// Acyclic write (an SDO download on a real bus) of `data` to `index:sub` of `axis`,
    /// blocking: outside the loop. `Err(abort code)`, [`SDO_UNSUPPORTED`] where the bus has no
    /// acyclic channel.
    fn sdo_download(&mut self, axis: usize, index: u16, sub: u8, data: &[u8]) -> Result<(), u32> {
        let _ = (axis, index, sub, data);
        Err(SDO_UNSUPPORTED)
    }
    /// The bus part of the clean shutdown, after the loop's last exchange (EtherCAT: every
    /// SubDevice to PRE-OP). `Err` names what did not complete.
    fn close(&mut self) -> Result<(), CloseError> {
        Ok(())
    }
}

/// Faults a bus raises on itself for tests and the cell's `[[inject]]` schedule; each takes
/// effect from the next exchange. Every method returns false where the bus cannot inject the
/// fault (real drives, or a fault of another kind of bus).
pub trait FaultInjection {
    /// `axis`' drive raises alarm `code` (603Fh).
    fn inject_alarm(&mut self, axis: usize, code: u16) -> bool {
        let _ = (axis, code);
        false
    }
    /// `axis`' RxPDO is not delivered for the next `cycles` exchanges (lost frames; the
    /// drive's communication checks count them).
    fn inject_rx_loss(&mut self, axis: usize, cycles: u32) -> bool {
        let _ = (axis, cycles);
        false
    }
    /// The communication counter `axis`' drive receives is corrupted for the next `cycles`
    /// exchanges (on the emulator's `SimBus`: frozen at its first value, like stale frames the NIC resends,
    /// test vector TV-IC-3 in `docs/test-vectors.md`). False also where the map has no counter.
    fn inject_counter_corruption(&mut self, axis: usize, cycles: u32) -> bool {
        let _ = (axis, cycles);
        false
    }
    /// EtherCAT: `axis`' SubDevice does not answer for the next `cycles` exchanges.
    fn inject_subdevice_stall(&mut self, axis: usize, cycles: u32) -> bool {
        let _ = (axis, cycles);
        false
    }
    /// EtherCAT, emulated segment: the next `cycles` cyclic frames return `delay_ns` late; at
    /// or beyond the frame timeout they are lost at the master.
    fn inject_frame_delay(&mut self, delay_ns: u64, cycles: u32) -> bool {
        let _ = (delay_ns, cycles);
        false
    }
    /// EtherCAT, emulated segment: bit errors on the link in front of `axis`' SubDevice for
    /// the next `cycles` frames (CRC errors: the SubDevices from there on do not process
    /// them, the master loses them).
    fn inject_frame_corruption(&mut self, axis: usize, cycles: u32) -> bool {
        let _ = (axis, cycles);
        false
    }
    /// EtherCAT, emulated segment: the cyclic LRW datagram of the next `cycles` frames is
    /// removed (working counter 0 at the master).
    fn inject_datagram_drop(&mut self, cycles: u32) -> bool {
        let _ = cycles;
        false
    }
    /// EtherCAT, emulated segment: the link in front of `axis`' SubDevice is down for the
    /// next `cycles` frames.
    fn inject_link_loss(&mut self, axis: usize, cycles: u32) -> bool {
        let _ = (axis, cycles);
        false
    }
}

/// Counters of a bus's cyclic frames: what the summary and `cellrt bench ethercat` report
/// as lost frames and working-counter errors.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct FrameCounters {
    /// Cyclic frames sent.
    pub frames: u64,
    /// Frames that did not return.
    pub lost: u64,
    /// Frames that returned with a wrong working counter.
    pub wkc_errors: u64,
}

/// The abort code [`AcyclicBus::sdo_download`] returns where there is no acyclic channel
/// (CiA 301 0601 0000h, unsupported access to an object).
pub const SDO_UNSUPPORTED: u32 = 0x0601_0000;
