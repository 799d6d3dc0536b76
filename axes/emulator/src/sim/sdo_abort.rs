//! The CiA 301 SDO abort codes the simulated drives answer with.

use std::fmt;

/// A CiA 301 SDO abort code.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct SdoAbort(pub u32);

impl SdoAbort {
    /// 0601 0000h Unsupported access to an object (MR-J3-T04's answer to a mapped 6060h).
    pub const UNSUPPORTED_ACCESS: SdoAbort = SdoAbort(0x0601_0000);
    /// 0601 0001h Attempt to read a write-only object.
    pub const WRITE_ONLY: SdoAbort = SdoAbort(0x0601_0001);
    /// 0601 0002h Attempt to write a read-only object.
    pub const READ_ONLY: SdoAbort = SdoAbort(0x0601_0002);
    /// 0601 0006h Object mapped to an RxPDO: written cyclically, not by SDO.
    pub const MAPPED_TO_RXPDO: SdoAbort = SdoAbort(0x0601_0006);
    /// 0602 0000h Object does not exist in the object dictionary.
    pub const NO_OBJECT: SdoAbort = SdoAbort(0x0602_0000);
    /// 0607 0012h Data type does not match, length of service parameter too high.
    pub const TOO_LONG: SdoAbort = SdoAbort(0x0607_0012);
    /// 0607 0013h Data type does not match, length of service parameter too low.
    pub const TOO_SHORT: SdoAbort = SdoAbort(0x0607_0013);
    /// 0609 0011h Sub-index does not exist.
    pub const NO_SUBINDEX: SdoAbort = SdoAbort(0x0609_0011);
    /// 0609 0030h Value range of parameter exceeded.
    pub const VALUE_RANGE: SdoAbort = SdoAbort(0x0609_0030);
    /// 0800 0020h Data cannot be transferred or stored: the simulator's answer to a wrong
    /// store/restore signature, whose abort code MR-JET-G-N1 manual leaves unstated.
    pub const CANNOT_STORE: SdoAbort = SdoAbort(0x0800_0020);
}

impl fmt::Display for SdoAbort {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "SDO abort {:04X} {:04X}h", self.0 >> 16, self.0 & 0xFFFF)
    }
}

impl std::error::Error for SdoAbort {}
