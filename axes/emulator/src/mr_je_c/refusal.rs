//! Why the simulated drive refuses an object access, and the code each transport answers it
//! with (MR-JE-C manual §2.4.5 end codes, §3.6.5 exceptions).

use cellrt_fieldbus::modbus::ExceptionCode;
use cellrt_fieldbus::slmp::EndCode;

/// A refused access, in the order the emulator checks them (index, sub-index, access, size,
/// range; the manual gives no precedence, this one is ours).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum Refusal {
    /// No object at that index.
    #[error("non-existent index")]
    NoIndex,
    /// No such sub-index.
    #[error("non-existent sub-index")]
    NoSubIndex,
    /// A write-only object was read.
    #[error("write-only object")]
    WriteOnly,
    /// A read-only object was written.
    #[error("read-only object")]
    ReadOnly,
    /// More bytes than the object's size.
    #[error("more data than the object's size")]
    TooLarge,
    /// Fewer bytes than the object's size.
    #[error("less data than the object's size")]
    TooSmall,
    /// Block data that does not end on a sub-index.
    #[error("data does not match the object's sizes")]
    SizeDiffers,
    /// Above the range.
    #[error("value above the range")]
    AboveRange,
    /// Below the range.
    #[error("value below the range")]
    BelowRange,
    /// In a gap of the range, or a value the object refuses as a whole.
    #[error("value outside the range")]
    OutOfRange,
    /// A write to the response mapping 1A00h while cyclic communication runs (SSR on).
    #[error("response mapping locked while cyclic communication runs")]
    MappingLocked,
    /// An object that cannot be mapped into the response.
    #[error("object cannot be mapped")]
    NotMappable,
    /// Mapped objects beyond 64 bytes.
    #[error("mapped objects exceed 64 bytes")]
    MappingTooLarge,
    /// Store parameters 1010h is writing the EEPROM (bit 0 = 0, "the parameter cannot be
    /// saved with the command", §7.4.4): another "save", or a parameter write where the
    /// emulator refuses those ([`super::WriteDuringSave::Refuse`]). The manual names no code:
    /// the one for an object "write disabled in the present state" (SLMP CCC9h, §2.4.5) is
    /// ours.
    #[error("the EEPROM is being written (1010h)")]
    Saving,
    /// Modbus registers that split an object, or that chain an object which must be
    /// accessed alone ("continuous read/write impossible", §7.3).
    #[error("registers that do not cover whole objects")]
    Layout,
}

impl Refusal {
    /// The SLMP end code.
    pub const fn end_code(self) -> EndCode {
        match self {
            Self::NoIndex => EndCode::NoIndex,
            Self::NoSubIndex => EndCode::NoSubIndex,
            Self::WriteOnly => EndCode::WriteOnly,
            Self::ReadOnly => EndCode::ReadOnly,
            Self::TooLarge => EndCode::SizeTooLarge,
            Self::TooSmall => EndCode::SizeTooSmall,
            Self::SizeDiffers => EndCode::SizeDiffers,
            Self::AboveRange => EndCode::AboveRange,
            Self::BelowRange => EndCode::BelowRange,
            Self::OutOfRange => EndCode::OutOfRange,
            Self::Layout => EndCode::RequestIncorrect,
            Self::MappingLocked => EndCode::MappedObject,
            Self::Saving => EndCode::ReadOnly,
            Self::NotMappable => EndCode::NotMappable,
            Self::MappingTooLarge => EndCode::MappingTooLarge,
        }
    }

    /// The CiA 301 abort code the drive keeps in 2A60h after a Modbus access it refused
    /// (MR-JE-C manual §7.5.1 table).
    pub const fn abort_code(self) -> u32 {
        match self {
            Self::NoIndex => 0x0602_0000,
            Self::NoSubIndex => 0x0609_0011,
            Self::WriteOnly => 0x0601_0001,
            Self::ReadOnly => 0x0601_0002,
            Self::TooLarge | Self::TooSmall | Self::SizeDiffers => 0x0607_0010,
            Self::AboveRange => 0x0609_0031,
            Self::BelowRange => 0x0609_0032,
            Self::OutOfRange => 0x0609_0030,
            Self::Layout => 0x0601_0000,
            Self::MappingLocked | Self::Saving => 0x0800_0022,
            Self::NotMappable => 0x0604_0041,
            Self::MappingTooLarge => 0x0604_0042,
        }
    }

    /// The Modbus exception: 02h when the register cannot be accessed, 03h for a value the
    /// register cannot take (§3.6.5).
    pub const fn exception(self) -> ExceptionCode {
        match self {
            Self::NoIndex
            | Self::NoSubIndex
            | Self::WriteOnly
            | Self::ReadOnly
            | Self::Layout
            | Self::MappingLocked
            | Self::Saving => ExceptionCode::IllegalDataAddress,
            _ => ExceptionCode::IllegalDataValue,
        }
    }
}
