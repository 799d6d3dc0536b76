//! AL state requests outside ethercrab: the clean shutdown's step back to PRE-OP.

use super::bus::EthercatBus;
use super::error::EthercatError;
use super::group::MASTER_MAC;
use crate::ethercat::frame::{Command, FrameBuilder};
use crate::ethercat::register::{self as reg, AlState};

impl EthercatBus {
    /// The clean shutdown's bus part (after the master has sent Shutdown by controlword):
    /// every SubDevice to PRE-OP, so that none raises its leaving-OP alarm.
    pub fn leave_op(&mut self) -> Result<(), EthercatError> {
        self.request_state(AlState::PreOp)
    }

    fn request_state(&mut self, state: AlState) -> Result<(), EthercatError> {
        let mut len = {
            let mut b = FrameBuilder::new(&mut self.frame, MASTER_MAC);
            b.push(
                Command::Bwr,
                0,
                u32::from(reg::AL_CONTROL) << 16,
                &[state as u8, 0],
            );
            b.finish()
        };
        len = self.link.round_trip(&mut self.frame, len)?;
        let _ = len;
        for position in 0..self.stations {
            let adp = (position as u16).wrapping_neg();
            let mut b = FrameBuilder::new(&mut self.frame, MASTER_MAC);
            let span = b
                .push(
                    Command::Aprd,
                    1,
                    (u32::from(reg::AL_STATUS) << 16) | u32::from(adp),
                    &[0; 6],
                )
                .expect("frame buffer holds one datagram");
            let n = b.finish();
            self.link.round_trip(&mut self.frame, n)?;
            let d = &self.frame[span.data_offset..span.data_offset + 6];
            let status = d[0];
            let code = u16::from_le_bytes([d[4], d[5]]);
            if status & 0x0F != state as u8 || status & reg::AL_ERROR_INDICATION != 0 {
                return Err(EthercatError::State {
                    position,
                    state: state.as_str(),
                    status,
                    code,
                });
            }
        }
        Ok(())
    }
}
