//! AL state requests and reads outside ethercrab: the clean shutdown's step back to PRE-OP, and
//! the AL status of one SubDevice by its position (bring-up diagnosis, bus scan).

use super::bus::EthercatBus;
use super::error::EthercatError;
use super::group::MASTER_MAC;
use super::link::{Link, LinkError};
use crate::frame::{Command, FrameBuilder};
use crate::register::{self as reg, AlState, AlStatus, AL_STATUS_READ_LEN};

impl EthercatBus {
    /// The clean shutdown's bus part (after the master has sent Shutdown by controlword):
    /// every SubDevice to PRE-OP, so that none raises its leaving-OP alarm.
    pub fn leave_op(&mut self) -> Result<(), EthercatError> {
        self.request_state(AlState::PreOp)
    }

    fn request_state(&mut self, state: AlState) -> Result<(), EthercatError> {
        let len = {
            let mut b = FrameBuilder::new(&mut self.frame, MASTER_MAC);
            b.push(
                Command::Bwr,
                0,
                u32::from(reg::AL_CONTROL) << 16,
                &[state as u8, 0],
            );
            b.finish()
        };
        self.link.round_trip(&mut self.frame, len)?;
        for position in 0..self.stations {
            let s = read_al_status(self.link.as_mut(), &mut self.frame, position)?;
            if s.state != Some(state) || s.error {
                return Err(EthercatError::State {
                    position,
                    state: state.as_str(),
                    status: s.encode() as u8,
                    code: s.code,
                });
            }
        }
        Ok(())
    }
}

/// Reads `len` bytes at register `ado` of the SubDevice at `position` in the line
/// (auto-increment addressing: works in any state, before addresses are set). `None`: no
/// SubDevice answered (working counter 0).
pub(super) fn read_registers<const N: usize>(
    link: &mut dyn Link,
    frame: &mut [u8],
    position: usize,
    ado: u16,
) -> Result<Option<[u8; N]>, LinkError> {
    let adp = (position as u16).wrapping_neg();
    let mut b = FrameBuilder::new(frame, MASTER_MAC);
    let span = b
        .push(
            Command::Aprd,
            1,
            (u32::from(ado) << 16) | u32::from(adp),
            &[0; N],
        )
        .expect("frame buffer holds one datagram");
    let n = b.finish();
    link.round_trip(frame, n)?;
    if crate::frame::wkc(frame, &span) == 0 {
        return Ok(None);
    }
    let mut out = [0u8; N];
    out.copy_from_slice(&frame[span.data_offset..span.data_offset + N]);
    Ok(Some(out))
}

/// The AL status (0130h) and code (0134h) of the SubDevice at `position` (ETG.1000.6 §6.4);
/// all zero (no state) where none answered.
pub(super) fn read_al_status(
    link: &mut dyn Link,
    frame: &mut [u8],
    position: usize,
) -> Result<AlStatus, LinkError> {
    let b = read_registers::<AL_STATUS_READ_LEN>(link, frame, position, reg::AL_STATUS)?;
    Ok(AlStatus::from_bytes(&b.unwrap_or_default()))
}
