//! The segment's fixed sizes and ethercrab's group type in OP: what every part of the master
//! shares, declared once.

use ethercrab::subdevice_group::{HasDc, NoDc, Op};
use ethercrab::{DefaultLock, MainDevice, SubDeviceGroup, SubDevicePdi, SubDeviceRef};

/// SubDevices one segment can hold.
pub const MAX_SUBDEVICES: usize = 16;
/// Bytes of process image one segment can hold.
pub const MAX_PDI: usize = 1024;
/// The source MAC of cellrt's own cyclic frames (ethercrab's MainDevice address, so a
/// segment sees one master).
pub(super) const MASTER_MAC: [u8; 6] = [0x10, 0x10, 0x10, 0x10, 0x10, 0x10];

/// The segment in OP: with distributed clocks (SYNC0 on the SubDevices configured for it), or
/// every SubDevice free-run (SM2-synchronous) where none is (`[axes.ethercat]
/// distributed_clocks = false`).
pub(super) enum OpGroup {
    /// SYNC0 runs on at least one SubDevice.
    Dc(SubDeviceGroup<MAX_SUBDEVICES, MAX_PDI, DefaultLock, Op, HasDc>),
    /// No SubDevice runs SYNC0.
    FreeRun(SubDeviceGroup<MAX_SUBDEVICES, MAX_PDI, DefaultLock, Op, NoDc>),
}

impl OpGroup {
    /// SubDevice `index` of the segment, with its process data.
    pub(super) fn subdevice<'maindevice, 'group>(
        &'group self,
        maindevice: &'maindevice MainDevice<'maindevice>,
        index: usize,
    ) -> Result<
        SubDeviceRef<'maindevice, SubDevicePdi<'group, MAX_PDI, DefaultLock>>,
        ethercrab::error::Error,
    > {
        match self {
            OpGroup::Dc(g) => g.subdevice(maindevice, index),
            OpGroup::FreeRun(g) => g.subdevice(maindevice, index),
        }
    }
}
