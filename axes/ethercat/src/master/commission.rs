//! The segment in PRE-OP for commissioning without a cell (`cellrt bus sdo`, `bus pdos`,
//! `bus states`): ethercrab takes every SubDevice from INIT to PRE-OP (station addresses,
//! mailboxes), then SDO uploads and downloads, the PDO assignment read back (1C12h/1C13h and
//! the mapping objects, ETG.1000.6 §5.6.7.4) and AL state requests per SubDevice. Nothing runs
//! cyclically: the SubDevices stay where the last request left them when the session ends.

use std::time::{Duration, Instant};

use ethercrab::std::ethercat_now;
use ethercrab::{MainDevice, PduRx, PduTx};

use super::al_state::read_al_status;
use super::bring_up::{start_maindevice, PreOpGroup};
use super::error::EthercatError;
use super::group::{MASTER_MAC, MAX_PDI, MAX_SUBDEVICES};
use super::link::{Link, LinkError, Retrying};
use super::pump::pump;
use super::refusal::abort_code;
use crate::frame::{Command, FrameBuilder};
use crate::identity::SubDeviceIdentity;
use crate::register::{self as reg, AlState, AlStatus};

/// Bytes of an Ethernet frame buffer (1514 without FCS, rounded up).
const FRAME_BUF: usize = 1536;
/// The largest object an upload takes (segmented transfers included).
pub const MAX_UPLOAD: usize = 1024;
/// SM2 (outputs) and SM3 (inputs) PDO assignment objects (ETG.1000.6 Table 67).
const PDO_ASSIGNMENT: [u16; 2] = [0x1C12, 0x1C13];
/// Times a raw frame (AL control, AL status) is sent again when its return comes late.
const RETRIES: usize = 3;
/// How often an AL state request's outcome is read while the SubDevice changes state.
const AL_POLL: Duration = Duration::from_millis(2);

/// A SubDevice of the segment in PRE-OP.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FoundSubDevice {
    /// Position in the line (0 = next to the master).
    pub position: usize,
    /// Its name from the SII.
    pub name: String,
    /// 1018h as ethercrab read it.
    pub identity: SubDeviceIdentity,
}

/// An SDO transfer that did not complete.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SdoFailure {
    /// The SubDevice aborted it with this code (ETG.1000.6 Table 41).
    #[error("aborted with {code:#010x} ({})", super::refusal::abort_meaning(*code))]
    Abort {
        /// The abort code.
        code: u32,
    },
    /// No SubDevice at that position.
    #[error("no SubDevice at position {position} ({count} on the line)")]
    NoSubDevice {
        /// The position asked for.
        position: usize,
        /// SubDevices found.
        count: usize,
    },
}

/// One mapping object of a PDO assignment and its entries (mapping words, ETG.1000.6
/// §5.6.7.4.7: index << 16 | sub << 8 | bits).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AssignedPdo {
    /// The mapping object (1600h…, 1A00h…).
    pub index: u16,
    /// Its entries' mapping words, in order.
    pub entries: Vec<u32>,
}

/// The PDOs a SubDevice has assigned to SM2 (RxPDO, outputs) and SM3 (TxPDO, inputs).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PdoAssignment {
    /// 1C12h's mapping objects.
    pub rx: Vec<AssignedPdo>,
    /// 1C13h's mapping objects.
    pub tx: Vec<AssignedPdo>,
}

/// The segment in PRE-OP, owned by one commissioning command.
pub struct Commissioning {
    link: Box<dyn Link>,
    tx: PduTx<'static>,
    rx: PduRx<'static>,
    maindevice: MainDevice<'static>,
    group: PreOpGroup,
    frame: Vec<u8>,
}

impl Commissioning {
    /// Takes every SubDevice on `link` to PRE-OP (ethercrab's INIT → PRE-OP: addresses, SII,
    /// mailboxes).
    pub fn open(mut link: Box<dyn Link>) -> Result<Commissioning, EthercatError> {
        let (mut tx, mut rx, maindevice) = start_maindevice()?;
        let mut frame = vec![0u8; FRAME_BUF];
        let group = super::error::step(
            "bring-up to PRE-OP",
            pump(
                maindevice.init_single_group::<MAX_SUBDEVICES, MAX_PDI>(ethercat_now),
                &mut tx,
                &mut rx,
                link.as_mut(),
                &mut frame,
            ),
        )?;
        Ok(Commissioning {
            link,
            tx,
            rx,
            maindevice,
            group,
            frame,
        })
    }

    /// The SubDevices, by position.
    pub fn subdevices(&self) -> Vec<FoundSubDevice> {
        self.group
            .iter(&self.maindevice)
            .enumerate()
            .map(|(position, sd)| {
                let id = sd.identity();
                FoundSubDevice {
                    position,
                    name: sd.name().to_string(),
                    identity: SubDeviceIdentity {
                        vendor_id: id.vendor_id,
                        product_code: id.product_id,
                        revision: id.revision,
                        serial: id.serial,
                    },
                }
            })
            .collect()
    }

    /// Runs `transfer` with the SubDevice at `position`.
    fn transfer<T>(
        &mut self,
        position: usize,
        transfer: impl AsyncFnOnce(
            &ethercrab::SubDeviceRef<'_, &ethercrab::SubDevice>,
        ) -> Result<T, ethercrab::error::Error>,
    ) -> Result<T, SdoFailure> {
        let count = self.group.len();
        let sd = self
            .group
            .subdevice(&self.maindevice, position)
            .map_err(|_| SdoFailure::NoSubDevice { position, count })?;
        pump(
            transfer(&sd),
            &mut self.tx,
            &mut self.rx,
            self.link.as_mut(),
            &mut self.frame,
        )
        .map_err(|e| SdoFailure::Abort {
            code: abort_code(e),
        })
    }

    /// Uploads `index:sub` of the SubDevice at `position`: its bytes as sent (expedited,
    /// normal or segmented, at most [`MAX_UPLOAD`]).
    pub fn upload(&mut self, position: usize, index: u16, sub: u8) -> Result<Vec<u8>, SdoFailure> {
        self.transfer(position, async |sd| {
            sd.sdo_read::<heapless::Vec<u8, MAX_UPLOAD>>(index, sub)
                .await
        })
        .map(|v| v.to_vec())
    }

    /// Downloads `data` (1, 2 or 4 bytes: expedited) to `index:sub` of the SubDevice at
    /// `position`.
    pub fn download(
        &mut self,
        position: usize,
        index: u16,
        sub: u8,
        data: &[u8],
    ) -> Result<(), SdoFailure> {
        self.transfer(position, async |sd| {
            super::sdo::expedited_download(sd, index, sub, data).await
        })
    }

    /// The data type and name of `index:sub` by SDO Information (Get Entry Description), where
    /// the SubDevice offers it and the type is a basic one.
    pub fn entry_type(
        &mut self,
        position: usize,
        index: u16,
        sub: u8,
    ) -> Option<(cellrt_cia402::profiles::DataType, String)> {
        let entry = self
            .transfer(position, async |sd| {
                sd.sdo_info_entry_description(index, sub).await
            })
            .ok()??;
        let data_type = cellrt_cia402::profiles::DataType::from_cia301_index(
            entry.data_type,
            entry.bit_length,
        )?;
        Some((data_type, String::from_utf8_lossy(&entry.name).into_owned()))
    }

    /// The unsigned value of `index:sub` (1, 2 or 4 bytes, little-endian).
    fn upload_unsigned(&mut self, position: usize, index: u16, sub: u8) -> Result<u32, SdoFailure> {
        let bytes = self.upload(position, index, sub)?;
        let mut le = [0u8; 4];
        for (k, b) in bytes.iter().take(4).enumerate() {
            le[k] = *b;
        }
        Ok(u32::from_le_bytes(le))
    }

    /// The PDO assignment of the SubDevice at `position`: 1C12h and 1C13h, and each assigned
    /// mapping object's entries.
    pub fn pdo_assignment(&mut self, position: usize) -> Result<PdoAssignment, SdoFailure> {
        let mut sides = [Vec::new(), Vec::new()];
        for (side, assignment) in sides.iter_mut().zip(PDO_ASSIGNMENT) {
            let count = self.upload_unsigned(position, assignment, 0)?;
            for k in 1..=count.min(254) as u8 {
                let index = self.upload_unsigned(position, assignment, k)? as u16;
                let entries = self.upload_unsigned(position, index, 0)?;
                let entries = (1..=entries.min(254) as u8)
                    .map(|e| self.upload_unsigned(position, index, e))
                    .collect::<Result<Vec<u32>, SdoFailure>>()?;
                side.push(AssignedPdo { index, entries });
            }
        }
        let [rx, tx] = sides;
        Ok(PdoAssignment { rx, tx })
    }

    /// The AL status and code of the SubDevice at `position`.
    pub fn al_status(&mut self, position: usize) -> Result<AlStatus, LinkError> {
        read_al_status(
            &mut Retrying::new(self.link.as_mut(), RETRIES),
            &mut self.frame,
            position,
        )
    }

    /// Requests `state` from the SubDevice at `position` (AL control, auto-increment addressed)
    /// and waits up to `timeout` for it to get there or refuse (AL status error bit); returns
    /// the AL status it ends in. The SubDevice is not configured further: a request for SAFE-OP
    /// or OP may be refused, and the status code says why. An indicated error is acknowledged
    /// with the request.
    pub fn request_state(
        &mut self,
        position: usize,
        state: AlState,
        timeout: Duration,
    ) -> Result<AlStatus, LinkError> {
        let adp = (position as u16).wrapping_neg();
        // An indicated error is acknowledged with the request (ETG.1000.6 §6.4.1.4).
        let ack = if self.al_status(position)?.error {
            reg::AL_ERROR_INDICATION
        } else {
            0
        };
        let len = {
            let mut b = FrameBuilder::new(&mut self.frame, MASTER_MAC);
            b.push(
                Command::Apwr,
                1,
                (u32::from(reg::AL_CONTROL) << 16) | u32::from(adp),
                &[state as u8 | ack, 0],
            );
            b.finish()
        };
        Retrying::new(self.link.as_mut(), RETRIES).round_trip(&mut self.frame, len)?;
        let deadline = Instant::now() + timeout;
        loop {
            let s = self.al_status(position)?;
            if s.state == Some(state) || s.error || Instant::now() >= deadline {
                return Ok(s);
            }
            std::thread::sleep(AL_POLL);
        }
    }

    /// SubDevices on the line.
    pub fn len(&self) -> usize {
        self.group.len()
    }

    /// True when no SubDevice answered.
    pub fn is_empty(&self) -> bool {
        self.group.len() == 0
    }
}
