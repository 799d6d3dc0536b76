//! Bus backends: the cyclic exchange of PDO images between the master and its drives.
//!
//! [`SimBus`] runs [`SimDrive`]s in-process; EtherCAT backends implement the same [`Bus`] trait.

use crate::cycles::Cycles;
use crate::ethercat::emergency::Emergency;
use crate::ethercat::register::AlStatus;
use crate::pdo::PdoError;
use crate::sim::drive::SimDrive;

/// A cyclic process-data exchange with one RxPDO and one TxPDO image per axis.
pub trait Bus {
    /// Number of axes on the bus.
    fn axis_count(&self) -> usize;
    /// The RxPDO image (master → drive) of `axis`, written before [`Bus::exchange`].
    fn rx_image_mut(&mut self, axis: usize) -> &mut [u8];
    /// The TxPDO image (drive → master) of `axis`, valid after [`Bus::exchange`].
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
    /// Fault injection: makes `axis`' drive raise alarm `code`. Returns false where the bus
    /// cannot inject (real drives).
    fn inject_alarm(&mut self, axis: usize, code: u16) -> bool {
        let _ = (axis, code);
        false
    }
    /// Fault injection: `axis`' RxPDO is not delivered for the next `cycles` exchanges (lost
    /// frames; the drive's communication checks count them). False where unsupported.
    fn inject_rx_loss(&mut self, axis: usize, cycles: u32) -> bool {
        let _ = (axis, cycles);
        false
    }
    /// Fault injection: the communication counter `axis`' drive receives is corrupted for the
    /// next `cycles` exchanges (on [`SimBus`]: frozen at its first value, like stale frames the
    /// NIC resends, mr-j3-t04.md TV-IC-3). False where unsupported or the map has no counter.
    fn inject_counter_corruption(&mut self, axis: usize, cycles: u32) -> bool {
        let _ = (axis, cycles);
        false
    }
    /// Fault injection (EtherCAT): `axis`' SubDevice does not answer for the next `cycles`
    /// exchanges. False where unsupported.
    fn inject_subdevice_stall(&mut self, axis: usize, cycles: u32) -> bool {
        let _ = (axis, cycles);
        false
    }
    /// Fault injection (EtherCAT, emulated segment): the next `cycles` cyclic frames return
    /// `delay_ns` late; at or beyond the frame timeout they are lost at the master. False
    /// where unsupported.
    fn inject_frame_delay(&mut self, delay_ns: u64, cycles: u32) -> bool {
        let _ = (delay_ns, cycles);
        false
    }
    /// Fault injection (EtherCAT, emulated segment): bit errors on the link in front of
    /// `axis`' SubDevice for the next `cycles` frames (CRC errors: the SubDevices from there
    /// on do not process them, the master loses them). False where unsupported.
    fn inject_frame_corruption(&mut self, axis: usize, cycles: u32) -> bool {
        let _ = (axis, cycles);
        false
    }
    /// Fault injection (EtherCAT, emulated segment): the cyclic LRW datagram of the next
    /// `cycles` frames is removed (working counter 0 at the master). False where unsupported.
    fn inject_datagram_drop(&mut self, cycles: u32) -> bool {
        let _ = cycles;
        false
    }
    /// Fault injection (EtherCAT, emulated segment): the link in front of `axis`' SubDevice
    /// is down for the next `cycles` frames. False where unsupported.
    fn inject_link_loss(&mut self, axis: usize, cycles: u32) -> bool {
        let _ = (axis, cycles);
        false
    }
    /// Acyclic read (an SDO upload on a real bus) of `index:sub` of `axis`; called at start-up
    /// and after a homing (607Ch), not every cycle. `Err(abort code)` as for
    /// [`Bus::sdo_download`].
    fn sdo_upload(&mut self, axis: usize, index: u16, sub: u8) -> Result<i64, u32> {
        let _ = (axis, index, sub);
        Err(SDO_UNSUPPORTED)
    }

    /// Acyclic write (an SDO download on a real bus) of `data` to `index:sub` of `axis`; called
    /// at a homing start (6098h), not every cycle. `Err(abort code)`, [`SDO_UNSUPPORTED`] where
    /// the bus has no acyclic channel.
    fn sdo_download(&mut self, axis: usize, index: u16, sub: u8, data: &[u8]) -> Result<(), u32> {
        let _ = (axis, index, sub, data);
        Err(SDO_UNSUPPORTED)
    }
    /// The bus part of the clean shutdown, after the loop's last exchange (EtherCAT: every
    /// SubDevice to PRE-OP). `Err` names what did not complete.
    fn close(&mut self) -> Result<(), String> {
        Ok(())
    }
    /// 603Fh Error code of `axis` by acyclic read (an SDO upload on a real bus), for maps that
    /// do not carry it. Called once per fault edge, not every cycle. `None` where unsupported.
    fn read_error_code(&mut self, axis: usize) -> Option<u16> {
        let _ = axis;
        None
    }
    /// Counters of the cyclic frames, on a bus that sends frames (EtherCAT); `None` for the
    /// in-process simulated drives.
    fn frame_counters(&self) -> Option<FrameCounters> {
        None
    }
    /// The AL status of the SubDevice that carries `axis`, as the last cyclic frame read it;
    /// `None` on a bus without one (the in-process simulated drives) or before it answered.
    fn al_status(&self, axis: usize) -> Option<AlStatus> {
        let _ = axis;
        None
    }
    /// The next message a SubDevice sent unasked into its mailbox (EtherCAT: a CoE Emergency,
    /// ETG.1000.6 §5.6.2.1), polled by the RT loop every cycle; `None` when there is none. On
    /// EtherCAT a call may do one acyclic round trip (only in a cycle whose frame saw SM1 full).
    fn take_mailbox_notice(&mut self) -> Option<MailboxNotice> {
        None
    }
}

/// A mailbox message a SubDevice sent unasked, by axis (see [`Bus::take_mailbox_notice`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MailboxNotice {
    /// A CoE Emergency of `axis` (on a multi-axis unit the slot it names, else its first axis).
    Emergency {
        /// The axis.
        axis: usize,
        /// What the drive sent.
        emergency: Emergency,
    },
    /// Something else that was not asked for (not CoE, or another CoE service), discarded.
    Discarded {
        /// The first axis of the SubDevice.
        axis: usize,
        /// Mailbox type (ETG.1000.4 Table 29; 0 if malformed).
        mailbox_type: u8,
        /// CoE service (0 if not CoE).
        service: u16,
    },
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

/// The abort code [`Bus::sdo_download`] returns where there is no acyclic channel (CiA 301
/// 0601 0000h, unsupported access to an object).
pub const SDO_UNSUPPORTED: u32 = 0x0601_0000;

/// A failed exchange, naming the axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum BusError {
    /// An axis's image did not fit its PDO map.
    #[error("axis {axis}: {source}")]
    Pdo {
        /// The axis index.
        axis: usize,
        /// The codec error.
        source: PdoError,
    },
    /// The cyclic frame did not return (EtherCAT).
    #[error("cyclic frame lost")]
    FrameLost,
    /// The cyclic frame returned with a wrong working counter (EtherCAT): a SubDevice did not
    /// exchange its process data.
    #[error("working counter {found}, expected {expected}")]
    WorkingCounter {
        /// The sum every SubDevice exchanging adds.
        expected: u16,
        /// The counter returned.
        found: u16,
    },
    /// The process image does not fit one frame.
    #[error("process image of {bytes} bytes does not fit one frame")]
    FrameTooLarge {
        /// Its size.
        bytes: usize,
    },
}

/// In-process bus of simulated drives, with images preallocated at construction.
#[derive(Debug, Clone)]
pub struct SimBus {
    drives: Vec<SimDrive>,
    rx: Vec<Vec<u8>>,
    tx: Vec<Vec<u8>>,
    /// Per axis: exchanges left without RxPDO delivery.
    rx_loss: Vec<u32>,
    /// Per axis: exchanges left with a corrupted counter.
    corrupt: Vec<u32>,
    /// Per axis: scratch image for the corrupted delivery (preallocated).
    scratch: Vec<Vec<u8>>,
    /// Per axis: the counter value frozen at the start of a corruption.
    frozen: Vec<Option<u8>>,
}

impl SimBus {
    /// A bus over `drives`, one zeroed rx and tx image each, sized from the profile maps.
    pub fn new(drives: Vec<SimDrive>) -> Self {
        let rx = drives
            .iter()
            .map(|d| vec![0u8; d.profile().rx_pdo.byte_len()])
            .collect();
        let tx = drives
            .iter()
            .map(|d| vec![0u8; d.profile().tx_pdo.byte_len()])
            .collect();
        let n = drives.len();
        let scratch = drives
            .iter()
            .map(|d| vec![0u8; d.profile().rx_pdo.byte_len()])
            .collect();
        SimBus {
            drives,
            rx,
            tx,
            rx_loss: vec![0; n],
            corrupt: vec![0; n],
            scratch,
            frozen: vec![None; n],
        }
    }

    /// The AL state of the station(s) leaves OP: every drive's [`SimDrive::leave_op`] (one ESM
    /// per station; multi-axis units re-initialise every axis). Returns how many raised an alarm.
    pub fn leave_op(&mut self) -> usize {
        self.drives
            .iter_mut()
            .filter_map(SimDrive::leave_op)
            .count()
    }

    /// Every drive back to OP ([`SimDrive::enter_op`]).
    pub fn enter_op(&mut self) {
        self.drives.iter_mut().for_each(SimDrive::enter_op);
    }

    /// The drive of `axis`.
    ///
    /// # Panics
    /// If `axis >= axis_count()` (a wiring bug, not bad input); see [`SimBus::get_drive`].
    pub fn drive(&self, axis: usize) -> &SimDrive {
        &self.drives[axis]
    }

    /// The drive of `axis`, mutably (fault injection). Panics like [`SimBus::drive`].
    pub fn drive_mut(&mut self, axis: usize) -> &mut SimDrive {
        &mut self.drives[axis]
    }

    /// The drive of `axis`, or `None` if there is no such axis.
    pub fn get_drive(&self, axis: usize) -> Option<&SimDrive> {
        self.drives.get(axis)
    }
}

impl Bus for SimBus {
    fn axis_count(&self) -> usize {
        self.drives.len()
    }

    /// An empty slice for a nonexistent axis (encoding into it then fails with the map named).
    fn rx_image_mut(&mut self, axis: usize) -> &mut [u8] {
        self.rx.get_mut(axis).map_or(&mut [], |v| v.as_mut_slice())
    }

    /// An empty slice for a nonexistent axis.
    fn tx_image(&self, axis: usize) -> &[u8] {
        self.tx.get(axis).map_or(&[], |v| v.as_slice())
    }

    /// Runs every drive's cycle; all drives run even if one fails, the first error is returned.
    fn inject_alarm(&mut self, axis: usize, code: u16) -> bool {
        match self.drives.get_mut(axis) {
            Some(d) => {
                d.inject_alarm(code);
                true
            }
            None => false,
        }
    }

    fn inject_rx_loss(&mut self, axis: usize, cycles: u32) -> bool {
        match self.rx_loss.get_mut(axis) {
            Some(n) => {
                *n = cycles;
                true
            }
            None => false,
        }
    }

    fn inject_counter_corruption(&mut self, axis: usize, cycles: u32) -> bool {
        let mapped = self
            .drives
            .get(axis)
            .is_some_and(|d| d.profile().rx_pdo.has_counter());
        match self.corrupt.get_mut(axis) {
            Some(n) if mapped => {
                *n = cycles;
                true
            }
            _ => false,
        }
    }

    fn read_error_code(&mut self, axis: usize) -> Option<u16> {
        self.get_drive(axis).map(|d| d.tx_pdo().error_code)
    }

    fn sdo_upload(&mut self, axis: usize, index: u16, sub: u8) -> Result<i64, u32> {
        match self.drives.get(axis) {
            Some(d) => d.sdo_upload(index, sub).map_err(|a| a.0),
            None => Err(SDO_UNSUPPORTED),
        }
    }

    fn sdo_download(&mut self, axis: usize, index: u16, sub: u8, data: &[u8]) -> Result<(), u32> {
        match self.drives.get_mut(axis) {
            Some(d) => d.sdo_download(index, sub, data).map_err(|a| a.0),
            None => Err(SDO_UNSUPPORTED),
        }
    }

    fn exchange(&mut self, elapsed: Cycles) -> Result<(), BusError> {
        let mut first = Ok(());
        let images = self.rx.iter().zip(self.tx.iter_mut());
        let inject = self
            .rx_loss
            .iter_mut()
            .zip(self.corrupt.iter_mut())
            .zip(self.scratch.iter_mut().zip(self.frozen.iter_mut()));
        for (axis, ((drive, (rx, tx)), ((loss, corrupt), (scratch, frozen)))) in
            self.drives.iter_mut().zip(images).zip(inject).enumerate()
        {
            let result = if *loss > 0 {
                *loss -= 1;
                drive.cycle_lost(tx, elapsed)
            } else if *corrupt > 0 {
                *corrupt -= 1;
                let n = scratch.len().min(rx.len());
                scratch[..n].copy_from_slice(&rx[..n]);
                if let Some(b) = drive
                    .profile()
                    .rx_pdo
                    .counter_offset()
                    .and_then(|o| scratch.get_mut(o))
                {
                    *b = *frozen.get_or_insert(*b);
                }
                drive.cycle(&scratch[..n], tx, elapsed)
            } else {
                *frozen = None;
                drive.cycle(rx, tx, elapsed)
            };
            if let Err(source) = result {
                if first.is_ok() {
                    first = Err(BusError::Pdo { axis, source });
                }
            }
        }
        first
    }
}
