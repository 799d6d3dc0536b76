//! [`SimBus`]: the simulated drives in-process, called directly at each exchange.

use crate::sim::drive::SimDrive;
use crate::sim::plant::CycleMapPool;
use cellrt_cia402::bus::{
    AcyclicBus, BusError, CyclicBus, FaultInjection, ImmediateSlot, PostError, SdoOutcome,
    SdoRequest, SDO_UNSUPPORTED,
};
use cellrt_cia402::cycles::Cycles;

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
    /// Per axis: the outcome of its posted acyclic request.
    sdo_slots: Vec<ImmediateSlot>,
}

impl SimBus {
    /// A bus over `drives`, one zeroed rx and tx image each, sized from the profile maps; the
    /// plants of identical axes share one cycle map ([`SimDrive::share_cycle_map`]).
    pub fn new(mut drives: Vec<SimDrive>) -> Self {
        let mut maps = CycleMapPool::default();
        drives.iter_mut().for_each(|d| d.share_cycle_map(&mut maps));
        let rx = drives
            .iter()
            .map(|d| vec![0u8; d.profile().pdo.rx.byte_len()])
            .collect();
        let tx = drives
            .iter()
            .map(|d| vec![0u8; d.profile().pdo.tx.byte_len()])
            .collect();
        let n = drives.len();
        let scratch = drives
            .iter()
            .map(|d| vec![0u8; d.profile().pdo.rx.byte_len()])
            .collect();
        SimBus {
            drives,
            rx,
            tx,
            rx_loss: vec![0; n],
            corrupt: vec![0; n],
            scratch,
            frozen: vec![None; n],
            sdo_slots: vec![ImmediateSlot::default(); n],
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

impl CyclicBus for SimBus {
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
                    .pdo
                    .rx
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

impl AcyclicBus for SimBus {
    /// The in-process drives answer at once; the outcome waits in the axis' slot.
    fn post_sdo(&mut self, axis: usize, request: SdoRequest) -> Result<(), PostError> {
        let Some(d) = self.drives.get_mut(axis) else {
            return Err(PostError::Unsupported);
        };
        self.sdo_slots[axis].post(|| match request {
            SdoRequest::Upload { index, sub } => d
                .sdo_upload(index, sub)
                .map_or_else(|a| SdoOutcome::Aborted(a.0), SdoOutcome::Uploaded),
            SdoRequest::Download { index, sub, data } => d
                .sdo_download(index, sub, data.as_slice())
                .map_or_else(|a| SdoOutcome::Aborted(a.0), |()| SdoOutcome::Downloaded),
        })
    }

    fn take_sdo(&mut self, axis: usize) -> Option<SdoOutcome> {
        self.sdo_slots.get_mut(axis)?.take()
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
}

impl FaultInjection for SimBus {
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
            .is_some_and(|d| d.profile().pdo.rx.has_counter());
        match self.corrupt.get_mut(axis) {
            Some(n) if mapped => {
                *n = cycles;
                true
            }
            _ => false,
        }
    }
}
