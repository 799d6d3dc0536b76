//! SDO transfers in OP, on the mailbox worker: the object's station and offset index on a
//! multi-axis unit, its data type, and the transfer with SM1 drained first and a met
//! Emergency handed on.

use ethercrab::{DefaultLock, SubDevicePdi, SubDeviceRef};

use super::group::MAX_PDI;
use super::pump::pump;
use super::refusal::abort_code;
use super::worker::MailboxWorker;
use crate::emergency::Emergency;
use cellrt_cia402::bus::{MailboxNotice, SDO_UNSUPPORTED};
use cellrt_cia402::profiles::{DataType, DriveProfile};

impl MailboxWorker {
    /// The SubDevice of `axis` and the index of its axis-A object `index` there (on a
    /// multi-axis unit at the axis' offset index, MR-J5-G-N1 manual §2.2, §3.1, §4.3, §4.4).
    pub(super) fn station_object(&self, axis: usize, index: u16) -> Option<(usize, u16)> {
        let &(station, slot) = self.axes.get(axis)?;
        let p = &self.config.drives.get(axis)?.profile;
        Some((station, p.axis_object(index, slot).unwrap_or(index)))
    }

    /// Writes `data` (1, 2 or 4 bytes) to `index:sub` of `axis`. `Err(abort code)`.
    pub(super) fn sdo_write(
        &mut self,
        axis: usize,
        index: u16,
        sub: u8,
        data: &[u8],
    ) -> Result<(), u32> {
        let (station, index) = self.station_object(axis, index).ok_or(SDO_UNSUPPORTED)?;
        self.sdo_transfer(axis, station, async |sd| {
            expedited_download(sd, index, sub, data).await
        })
        .map_err(abort_code)
    }

    pub(super) fn sdo_read_value(&mut self, axis: usize, index: u16, sub: u8) -> Result<i64, u32> {
        let d = self.config.drives.get(axis).ok_or(SDO_UNSUPPORTED)?;
        // The type of an object given at another axis' offset index is its axis-A object's.
        let base = d.profile.object_slot(index).map_or(index, |(_, b)| b);
        let data_type = object_type(&d.profile, base, sub);
        if matches!(data_type, DataType::VisibleString { .. }) {
            // A string is not a number (no EtherCAT profile has one).
            return Err(SDO_UNSUPPORTED);
        }
        let (station, index) = self.station_object(axis, index).ok_or(SDO_UNSUPPORTED)?;
        self.sdo_transfer(axis, station, async |sd| {
            Ok(match data_type {
                DataType::I8 => i64::from(sd.sdo_read::<i8>(index, sub).await?),
                DataType::U8 | DataType::Bool => i64::from(sd.sdo_read::<u8>(index, sub).await?),
                DataType::I16 => i64::from(sd.sdo_read::<i16>(index, sub).await?),
                DataType::U16 => i64::from(sd.sdo_read::<u16>(index, sub).await?),
                DataType::U32 => i64::from(sd.sdo_read::<u32>(index, sub).await?),
                DataType::I32 | DataType::Unstated | DataType::VisibleString { .. } => {
                    i64::from(sd.sdo_read::<i32>(index, sub).await?)
                }
            })
        })
        .map_err(abort_code)
    }

    /// One SDO (or SDO Information) transfer with SubDevice `station` for `axis`: SM1
    /// emptied first (so ethercrab meets no Emergency left there), repeated once where an
    /// Emergency came in its response's place.
    pub(super) fn sdo_transfer<T>(
        &mut self,
        axis: usize,
        station: usize,
        transfer: impl AsyncFn(
            &SubDeviceRef<'_, SubDevicePdi<'_, MAX_PDI, DefaultLock>>,
        ) -> Result<T, ethercrab::error::Error>,
    ) -> Result<T, ethercrab::error::Error> {
        let mut emergency_met = false;
        loop {
            self.drain_mailbox(station);
            let crab = &mut self.ethercrab;
            let sd = crab.group.subdevice(&crab.maindevice, station)?;
            let result = pump(
                transfer(&sd),
                &mut crab.tx,
                &mut crab.rx,
                &mut self.link,
                &mut self.frame,
            );
            if !self.emergency_in_sdo(axis, &result, &mut emergency_met) {
                return result;
            }
        }
    }

    /// An SDO of `axis` that met a CoE Emergency where its response should be (the drive
    /// raised an alarm after the request; patched ethercrab returns it as an error): the
    /// Emergency becomes a notice of the axis it names and the SDO is repeated once. True:
    /// repeat it.
    fn emergency_in_sdo<T>(
        &mut self,
        axis: usize,
        result: &Result<T, ethercrab::error::Error>,
        met: &mut bool,
    ) -> bool {
        let Err(ethercrab::error::Error::Mailbox(ethercrab::error::MailboxError::Emergency {
            error_code,
            error_register,
            data,
        })) = *result
        else {
            return false;
        };
        let emergency = Emergency {
            error_code,
            error_register,
            data,
        };
        let axis = self.axes.get(axis).map_or(axis, |&(station, _)| {
            self.emergency_axis(station, &emergency)
        });
        self.push_notice(MailboxNotice::Emergency { axis, emergency });
        let repeat = !*met;
        *met = true;
        repeat
    }
}

/// An expedited SDO download of `data` (1, 2 or 4 bytes, little-endian) to `index:sub`: the
/// one way the master writes an object (in OP, in a start-up list, by `cellrt bus sdo`).
pub(super) async fn expedited_download<S: std::ops::Deref<Target = ethercrab::SubDevice>>(
    sd: &SubDeviceRef<'_, S>,
    index: u16,
    sub: u8,
    data: &[u8],
) -> Result<(), ethercrab::error::Error> {
    match *data {
        [a] => sd.sdo_write(index, sub, [a]).await,
        [a, b] => sd.sdo_write(index, sub, [a, b]).await,
        [a, b, c, d] => sd.sdo_write(index, sub, [a, b, c, d]).await,
        _ => Err(ethercrab::error::Error::Internal),
    }
}

/// The data type of `index:sub`: the communication objects by CiA 301 / ETG.1000.6, the
/// mapped objects by their mapping size, the rest from the profile (INTEGER32 where unknown).
pub fn object_type(profile: &DriveProfile, index: u16, sub: u8) -> DataType {
    let mapped_bits = profile
        .pdo
        .rx
        .entries
        .iter()
        .chain(profile.pdo.tx.entries.iter())
        .find(|e| !e.is_padding() && e.index == index && e.sub == sub)
        .map(|e| e.bits);
    match (index, sub) {
        (cellrt_cia402::pdo::objects::ERROR_CODE, 0) => DataType::U16,
        (0x1018 | 0x1C12 | 0x1C13 | 0x1600..=0x17FF | 0x1A00..=0x1BFF, 0) => DataType::U8,
        (0x1C12 | 0x1C13, _) => DataType::U16,
        (0x1000 | 0x1018 | 0x1600..=0x17FF | 0x1A00..=0x1BFF, _) => DataType::U32,
        _ => match (profile.object(index, sub), mapped_bits) {
            (Some(o), _) if o.data_type != DataType::Unstated => o.data_type,
            (_, Some(8)) => DataType::I8,
            (_, Some(16)) => DataType::I16,
            _ => DataType::I32,
        },
    }
}
