//! The segment's fixed sizes and ethercrab's group type in OP: what every part of the master
//! shares, declared once.

use ethercrab::subdevice_group::{HasDc, Op};
use ethercrab::{DefaultLock, SubDeviceGroup};

/// SubDevices one segment can hold.
pub const MAX_SUBDEVICES: usize = 16;
/// Bytes of process image one segment can hold.
pub const MAX_PDI: usize = 1024;
/// The source MAC of cellrt's own cyclic frames (ethercrab's MainDevice address, so a
/// segment sees one master).
pub(super) const MASTER_MAC: [u8; 6] = [0x10, 0x10, 0x10, 0x10, 0x10, 0x10];

/// The segment in OP with distributed clocks.
pub(super) type OpGroup = SubDeviceGroup<MAX_SUBDEVICES, MAX_PDI, DefaultLock, Op, HasDc>;
