//! FSoE safety process data of the simulated drive and STO (`sim::fsoe`).

use super::SimDrive;
use crate::sim::fsoe::FsoeSlave;
use cellrt_cia402::fsoe::{ConnectionParams, FsoeError, FsoeFrame, SafetyStatus};

impl SimDrive {
    /// The FSoE connection parameter set from the master (MR-JET-G-N1 manual §9.3 item 4; see
    /// [`FsoeSlave::connect`]). A slave address other than [Pr. PSC07] raises the profile's
    /// AL.584.1 and returns [`FsoeError::AddressMismatch`]. Without FSoE on this drive:
    /// [`FsoeError::NotSupported`].
    pub fn fsoe_connect(&mut self, params: &ConnectionParams) -> Result<(), FsoeError> {
        let model = self.profile.model;
        let f = self
            .fsoe
            .as_mut()
            .ok_or(FsoeError::NotSupported { model })?;
        let r = f.connect(params);
        if let Err(FsoeError::AddressMismatch { alarm, .. }) = r {
            self.raise(alarm);
            self.tx = self.make_tx();
        }
        r
    }

    /// One safety PDO exchange: the master's frame `rx` (1608h, 11 bytes) in, the slave's
    /// frame (1A08h) into `tx`. Call it once per bus cycle next to [`SimDrive::cycle`]; a cycle
    /// without it counts against the FSoE watchdog. Bad sizes return an error and change
    /// nothing. Allocation-free.
    pub fn fsoe_exchange(&mut self, rx: &[u8], tx: &mut [u8]) -> Result<(), FsoeError> {
        let model = self.profile.model;
        let speed = self.plant.velocity();
        let f = self
            .fsoe
            .as_mut()
            .ok_or(FsoeError::NotSupported { model })?;
        let layout = self
            .profile
            .fsoe
            .map(|x| x.frame)
            .ok_or(FsoeError::NotSupported { model })?;
        if tx.len() != usize::from(layout.len) {
            return Err(FsoeError::FrameLength {
                expected: usize::from(layout.len),
                actual: tx.len(),
            });
        }
        let frame = FsoeFrame::decode(&layout, rx)?;
        f.frame(&frame, speed).encode(&layout, tx)
    }

    /// The FSoE status the slave reports now (`None` without FSoE).
    pub fn fsoe_status(&self) -> Option<SafetyStatus> {
        let speed = self.plant.velocity();
        self.fsoe.as_ref().map(|f| f.status(speed))
    }

    /// The FSoE slave, if configured.
    pub fn fsoe(&self) -> Option<&FsoeSlave> {
        self.fsoe.as_ref()
    }

    /// STO is in effect (FSoE): the drive cannot be switched on and gives no torque.
    pub fn safe_torque_off(&self) -> bool {
        self.fsoe.as_ref().is_some_and(FsoeSlave::sto)
    }
}
