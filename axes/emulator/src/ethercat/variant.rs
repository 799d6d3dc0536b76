//! How an emulated SubDevice departs from its profile's defaults, to rehearse standard CiA 402
//! drives of other vendors without hardware: a read-only or missing 1C32h:02, no 60F4h, and
//! distributed clocks required, optional or absent (the variations ETG.1020 / ETG.6010 allow
//! and real devices show; the master must bring each of them up or say why not).

use crate::sim::sdo::SdoAbort;

/// 1C32h:02 SM2 cycle time as the SubDevice offers it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CycleTimeObject {
    /// Read and written by SDO (the profile's own behaviour).
    #[default]
    ReadWrite,
    /// Readable with this value, ns; a write is refused with 0601 0002h (ETG.1020 leaves
    /// 1C32h:02's access to the device: some declare it `ro`).
    ReadOnly(u32),
    /// Not in the object dictionary: 0602 0000h.
    Absent,
}

/// The SubDevice's distributed clocks (ESC feature register 0008h bit 2, ETG.1000.4 §6.1.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum EmulatedDc {
    /// DC present; the drive also runs free-run (SM2-synchronous) without SYNC0.
    #[default]
    Optional,
    /// DC present, and PRE-OP → SAFE-OP is refused without SYNC0 active, AL status code 0030h
    /// "invalid DC SYNC configuration" (ETG.1000.6 Table 11).
    Required,
    /// No DC unit in the ESC (feature bit cleared): SYNC0 cannot be configured.
    Absent,
}

/// The departures of one emulated SubDevice from its profile ([`Default`]: none).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SubDeviceVariant {
    /// 1C32h:02.
    pub cycle_time: CycleTimeObject,
    /// 60F4h Following error actual value is in the object dictionary (false: its SDO access
    /// answers 0602 0000h and mapping it answers the profile's not-mappable abort).
    pub following_error_object: bool,
    /// Distributed clocks.
    pub distributed_clocks: EmulatedDc,
    /// How long the firmware takes to answer an SDO request in OP, ns of the segment's clock
    /// (the manuals give no mailbox answer time; 0: at once; bring-up's SDOs are answered at
    /// once). Lets a test show that a slow answer does not hold up the cyclic exchange.
    pub sdo_response_delay_ns: u64,
}

impl Default for SubDeviceVariant {
    fn default() -> Self {
        SubDeviceVariant {
            cycle_time: CycleTimeObject::ReadWrite,
            following_error_object: true,
            distributed_clocks: EmulatedDc::Optional,
            sdo_response_delay_ns: 0,
        }
    }
}

/// 60F4h Following error actual value.
const FOLLOWING_ERROR: u16 = cellrt_cia402::pdo::objects::FOLLOWING_ERROR;

impl SubDeviceVariant {
    /// True if object `index` is not in this SubDevice's dictionary.
    pub fn lacks(&self, index: u16) -> bool {
        index == FOLLOWING_ERROR && !self.following_error_object
    }

    /// The answer to an SDO upload of `index:sub` where the variant decides it: `Some(Ok(bytes))`
    /// for a read-only 1C32h:02, `Some(Err)` for an absent object, `None`: the profile's.
    pub fn upload(&self, index: u16, sub: u8) -> Option<Result<Vec<u8>, SdoAbort>> {
        match (index, sub, self.cycle_time) {
            (0x1C32 | 0x1C33, 2, CycleTimeObject::ReadOnly(ns)) => {
                Some(Ok(ns.to_le_bytes().to_vec()))
            }
            (0x1C32 | 0x1C33, 2, CycleTimeObject::Absent) => Some(Err(SdoAbort::NO_OBJECT)),
            _ if self.lacks(index) => Some(Err(SdoAbort::NO_OBJECT)),
            _ => None,
        }
    }

    /// The refusal of an SDO download of `index:sub` where the variant decides it; `None`:
    /// the profile's behaviour.
    pub fn refuses_download(&self, index: u16, sub: u8) -> Option<SdoAbort> {
        match (index, sub, self.cycle_time) {
            (0x1C32, 2, CycleTimeObject::ReadOnly(_)) => Some(SdoAbort::READ_ONLY),
            (0x1C32, 2, CycleTimeObject::Absent) => Some(SdoAbort::NO_OBJECT),
            _ if self.lacks(index) => Some(SdoAbort::NO_OBJECT),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_departs_in_nothing() {
        let v = SubDeviceVariant::default();
        assert_eq!(v.upload(0x1C32, 2), None);
        assert_eq!(v.refuses_download(0x1C32, 2), None);
        assert_eq!(v.refuses_download(0x60F4, 0), None);
        assert!(!v.lacks(0x60F4));
    }

    #[test]
    fn read_only_cycle_time_reads_its_value_and_refuses_writes_with_0601_0002() {
        let v = SubDeviceVariant {
            cycle_time: CycleTimeObject::ReadOnly(2_000_000),
            following_error_object: false,
            ..SubDeviceVariant::default()
        };
        assert_eq!(
            v.upload(0x1C32, 2),
            Some(Ok(2_000_000u32.to_le_bytes().to_vec()))
        );
        assert_eq!(v.refuses_download(0x1C32, 2), Some(SdoAbort(0x0601_0002)));
        assert_eq!(v.refuses_download(0x60F4, 0), Some(SdoAbort(0x0602_0000)));
        assert_eq!(v.upload(0x60F4, 0), Some(Err(SdoAbort(0x0602_0000))));
        let absent = SubDeviceVariant {
            cycle_time: CycleTimeObject::Absent,
            ..SubDeviceVariant::default()
        };
        assert_eq!(absent.upload(0x1C32, 2), Some(Err(SdoAbort(0x0602_0000))));
        assert_eq!(
            absent.refuses_download(0x1C32, 2),
            Some(SdoAbort(0x0602_0000))
        );
    }
}
