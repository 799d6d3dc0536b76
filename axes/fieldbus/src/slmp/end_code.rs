//! SLMP end codes of the MR-JE-C (MR-JE-C manual §2.4.5).

/// An abnormal end code, with the manual's cause.
#[derive(Debug, Clone, Copy, PartialEq, Eq, strum::FromRepr, strum::EnumIter)]
#[repr(u16)]
pub enum EndCode {
    /// Sub command wrong, or command not prescribed.
    CommandUnknown = 0xC059,
    /// Request message incorrect.
    RequestIncorrect = 0xC05C,
    /// Request data length does not correspond to the number of data points.
    LengthMismatch = 0xC061,
    /// Write to the object mapped to the response message, or a response mapping that may not
    /// be changed now.
    MappedObject = 0xCCC7,
    /// A write-only object was read.
    WriteOnly = 0xCCC8,
    /// Write to a read-only object, or to one write-disabled in the present state.
    ReadOnly = 0xCCC9,
    /// Non-existent index.
    NoIndex = 0xCCCA,
    /// An object that cannot be mapped was written into the response mapping.
    NotMappable = 0xCCCB,
    /// Total size of the mapped objects exceeds 64 bytes.
    MappingTooLarge = 0xCCCC,
    /// Number of data value differs from the prescribed value.
    SizeDiffers = 0xCCD0,
    /// Number of data value greater than prescribed.
    SizeTooLarge = 0xCCD1,
    /// Number of data value smaller than prescribed.
    SizeTooSmall = 0xCCD2,
    /// Non-existent sub-index.
    NoSubIndex = 0xCCD3,
    /// Value outside the parameter range.
    OutOfRange = 0xCCD4,
    /// Value greater than the parameter range.
    AboveRange = 0xCCD5,
    /// Value smaller than the parameter range.
    BelowRange = 0xCCD6,
    /// Write to a parameter object outside the range set by "Parameter block setting".
    ParameterBlock = 0xCCDA,
}

impl EndCode {
    /// The manual's cause, for error messages.
    pub fn cause(self) -> &'static str {
        match self {
            Self::CommandUnknown => "sub command wrong, or command not prescribed",
            Self::RequestIncorrect => "request message incorrect",
            Self::LengthMismatch => "request data length does not match the number of data",
            Self::MappedObject => "object mapped to the response message, or mapping locked",
            Self::WriteOnly => "a write-only object was read",
            Self::ReadOnly => "write to a read-only or write-disabled object",
            Self::NoIndex => "non-existent index",
            Self::NotMappable => "object cannot be mapped",
            Self::MappingTooLarge => "mapped objects exceed 64 bytes",
            Self::SizeDiffers => "number of data differs from the object's size",
            Self::SizeTooLarge => "number of data greater than the object's size",
            Self::SizeTooSmall => "number of data smaller than the object's size",
            Self::NoSubIndex => "non-existent sub-index",
            Self::OutOfRange => "value outside the parameter range",
            Self::AboveRange => "value greater than the parameter range",
            Self::BelowRange => "value smaller than the parameter range",
            Self::ParameterBlock => "parameter outside the writable parameter block",
        }
    }
}

impl std::fmt::Display for EndCode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "end code {:04X}h ({})", *self as u16, self.cause())
    }
}
