//! Bus backends: the cyclic exchange of PDO images between the master and its drives.
//!
//! [`SimBus`] runs [`SimDrive`]s in-process; EtherCAT backends implement the same [`Bus`] trait.

use crate::cycles::Cycles;
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
    /// Fault injection: makes `axis`' drive raise alarm `code`. Returns false where the bus
    /// cannot inject (real drives).
    fn inject_alarm(&mut self, axis: usize, code: u16) -> bool {
        let _ = (axis, code);
        false
    }
}

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
}

/// In-process bus of simulated drives, with images preallocated at construction.
#[derive(Debug, Clone)]
pub struct SimBus {
    drives: Vec<SimDrive>,
    rx: Vec<Vec<u8>>,
    tx: Vec<Vec<u8>>,
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
        SimBus { drives, rx, tx }
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

    fn exchange(&mut self, elapsed: Cycles) -> Result<(), BusError> {
        let mut first = Ok(());
        let images = self.rx.iter().zip(self.tx.iter_mut());
        for (axis, (drive, (rx, tx))) in self.drives.iter_mut().zip(images).enumerate() {
            if let Err(source) = drive.cycle(rx, tx, elapsed) {
                if first.is_ok() {
                    first = Err(BusError::Pdo { axis, source });
                }
            }
        }
        first
    }
}
