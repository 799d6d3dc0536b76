//! cellrt patch: the SDO Information services beside Get OD List (ETG.1000.6 §5.6.3): Get
//! Object Description (opcodes 3/4), Get Entry Description (opcodes 5/6), the SDO Info Error
//! Request (opcode 7) and the reassembly of a fragmented response. Public as
//! `ethercrab::sdo_info` so that cellrt tests the codecs against hand-built frames (this
//! vendored copy builds without upstream's dev-dependencies, so its own tests do not).

pub use super::headers::SdoInfoOpCode;
use super::{CoeHeader, CoeService};
use crate::{
    error::{Error, MailboxError, PduError},
    mailbox::{MailboxHeader, MailboxType, Priority},

};
use super::CoeAbortCode;
use ethercrab_wire::EtherCrabWireRead;

use super::headers::SdoInfoHeader;

/// Longest object or entry name kept (bytes); a longer name is cut there.
pub const MAX_NAME_LEN: usize = 128;

/// Bytes of a Get Object Description or Get Entry Description response's payload kept: the
/// fixed fields, the optional values and a name of [`MAX_NAME_LEN`].
pub(crate) const DESCRIPTION_BUF: usize = 512;

/// Mailbox header, CoE header and SDO Info header of every SDO Information message.
const HEADERS_LEN: usize = 12;

/// Get Object Description request (ETG.1000.6 §5.6.3.5.1).
#[derive(Debug, Copy, Clone, PartialEq, ethercrab_wire::EtherCrabWireReadWrite)]
#[wire(bytes = 14)]
pub struct ObjectDescriptionRequest {
    #[wire(bytes = 6)]
    pub(crate) header: MailboxHeader,
    #[wire(bytes = 2)]
    pub(crate) coe_header: CoeHeader,
    #[wire(bytes = 4)]
    pub(crate) sdo_info_header: SdoInfoHeader,
    #[wire(bytes = 2)]
    pub(crate) index: u16,
}

impl ObjectDescriptionRequest {
    /// The request for the description of object `index`.
    pub fn new(counter: u8, index: u16) -> Self {
        Self {
            header: request_header(counter, 8),
            coe_header: CoeHeader {
                service: CoeService::SdoInformation,
            },
            sdo_info_header: request_info_header(SdoInfoOpCode::GetObjectDescriptionRequest),
            index,
        }
    }
}

/// Get Entry Description request (ETG.1000.6 §5.6.3.6.1).
#[derive(Debug, Copy, Clone, PartialEq, ethercrab_wire::EtherCrabWireReadWrite)]
#[wire(bytes = 16)]
pub struct EntryDescriptionRequest {
    #[wire(bytes = 6)]
    pub(crate) header: MailboxHeader,
    #[wire(bytes = 2)]
    pub(crate) coe_header: CoeHeader,
    #[wire(bytes = 4)]
    pub(crate) sdo_info_header: SdoInfoHeader,
    #[wire(bytes = 2)]
    pub(crate) index: u16,
    #[wire(bytes = 1)]
    pub(crate) sub_index: u8,
    /// Which optional values the response carries (bits 3–6: unit, default, minimum, maximum).
    #[wire(bytes = 1)]
    pub(crate) value_info: u8,
}

impl EntryDescriptionRequest {
    /// The request for the description of entry `index:sub_index`, without optional values.
    pub fn new(counter: u8, index: u16, sub_index: u8) -> Self {
        Self {
            header: request_header(counter, 10),
            coe_header: CoeHeader {
                service: CoeService::SdoInformation,
            },
            sdo_info_header: request_info_header(SdoInfoOpCode::GetEntryDescriptionRequest),
            index,
            sub_index,
            value_info: 0,
        }
    }
}

fn request_header(counter: u8, length: u16) -> MailboxHeader {
    MailboxHeader {
        length,
        priority: Priority::Lowest,
        mailbox_type: MailboxType::Coe,
        counter,
    }
}

fn request_info_header(op_code: SdoInfoOpCode) -> SdoInfoHeader {
    SdoInfoHeader {
        op_code,
        incomplete: false,
        fragments_left: 0,
    }
}

/// What kind of object an index holds (ETG.1000.6 Table 44, CiA 301 §7.4.3).
#[derive(Debug, Copy, Clone, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ObjectCode {
    /// A single value (sub-index 0 only).
    Var,
    /// Sub-indices 1.. of one data type, sub-index 0 their count.
    Array,
    /// Sub-indices of their own types, sub-index 0 the highest.
    Record,
    /// Another code (DOMAIN, DEFTYPE, …).
    Other(u8),
}

impl From<u8> for ObjectCode {
    fn from(code: u8) -> Self {
        match code {
            7 => Self::Var,
            8 => Self::Array,
            9 => Self::Record,
            other => Self::Other(other),
        }
    }
}

/// An object's description (Get Object Description response, ETG.1000.6 §5.6.3.5.2).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ObjectDescription {
    /// Object index.
    pub index: u16,
    /// Data type index (CiA 301 §7.4.7, e.g. 0007h UNSIGNED32).
    pub data_type: u16,
    /// Highest sub-index.
    pub max_sub_index: u8,
    /// VAR, ARRAY or RECORD.
    pub object_code: ObjectCode,
    /// The name's bytes (cut at [`MAX_NAME_LEN`]).
    pub name: heapless::Vec<u8, MAX_NAME_LEN>,
}

bitflags::bitflags! {
    /// An entry's object access word (ETG.1000.6 §5.6.3.6.2).
    #[derive(Debug, Copy, Clone, PartialEq, Eq)]
    pub struct ObjectAccess: u16 {
        /// Readable in PRE-OP.
        const READ_PREOP = 1 << 0;
        /// Readable in SAFE-OP.
        const READ_SAFEOP = 1 << 1;
        /// Readable in OP.
        const READ_OP = 1 << 2;
        /// Writable in PRE-OP.
        const WRITE_PREOP = 1 << 3;
        /// Writable in SAFE-OP.
        const WRITE_SAFEOP = 1 << 4;
        /// Writable in OP.
        const WRITE_OP = 1 << 5;
        /// Mappable in an RxPDO.
        const RXPDO_MAPPABLE = 1 << 6;
        /// Mappable in a TxPDO.
        const TXPDO_MAPPABLE = 1 << 7;
        /// Stored for a device replacement (backup).
        const BACKUP = 1 << 8;
        /// A startup setting.
        const SETTINGS = 1 << 9;
    }
}

impl ObjectAccess {
    /// Readable in some state.
    pub fn readable(self) -> bool {
        self.intersects(Self::READ_PREOP | Self::READ_SAFEOP | Self::READ_OP)
    }

    /// Writable in some state.
    pub fn writable(self) -> bool {
        self.intersects(Self::WRITE_PREOP | Self::WRITE_SAFEOP | Self::WRITE_OP)
    }
}

/// An entry's description (Get Entry Description response, ETG.1000.6 §5.6.3.6.2).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EntryDescription {
    /// Object index.
    pub index: u16,
    /// Sub-index.
    pub sub_index: u8,
    /// Data type index (CiA 301 §7.4.7).
    pub data_type: u16,
    /// Size of a value in bits.
    pub bit_length: u16,
    /// Access per state and mappability.
    pub access: ObjectAccess,
    /// The name's bytes (cut at [`MAX_NAME_LEN`]).
    pub name: heapless::Vec<u8, MAX_NAME_LEN>,
}

fn name_of(bytes: &[u8]) -> heapless::Vec<u8, MAX_NAME_LEN> {
    let bytes = &bytes[..bytes.len().min(MAX_NAME_LEN)];
    // Some servers end the name with a NUL.
    let end = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
    heapless::Vec::from_slice(&bytes[..end]).unwrap_or_default()
}

fn u16_at(data: &[u8], at: usize) -> Result<u16, Error> {
    data.get(at..at + 2)
        .map(|b| u16::from_le_bytes([b[0], b[1]]))
        .ok_or(Error::Pdu(PduError::Decode))
}

impl ObjectDescription {
    /// Decodes the service data of a Get Object Description response (after the SDO Info
    /// header): index, data type, max sub-index, object code, name.
    pub fn parse(data: &[u8]) -> Result<Self, Error> {
        let (&max_sub_index, &code) = data
            .get(4)
            .zip(data.get(5))
            .ok_or(Error::Pdu(PduError::Decode))?;
        Ok(Self {
            index: u16_at(data, 0)?,
            data_type: u16_at(data, 2)?,
            max_sub_index,
            object_code: ObjectCode::from(code),
            name: name_of(&data[6..]),
        })
    }
}

impl EntryDescription {
    /// Decodes the service data of a Get Entry Description response (after the SDO Info
    /// header): index, sub-index, value info, data type, bit length, object access, the
    /// optional values (refused: they are never asked for, their sizes are not decoded), name.
    pub fn parse(data: &[u8]) -> Result<Self, Error> {
        let (&sub_index, &value_info) = data
            .get(2)
            .zip(data.get(3))
            .ok_or(Error::Pdu(PduError::Decode))?;
        let access = u16_at(data, 8)?;
        if value_info & 0x78 != 0 {
            return Err(Error::Pdu(PduError::Decode));
        }
        Ok(Self {
            index: u16_at(data, 0)?,
            sub_index,
            data_type: u16_at(data, 4)?,
            bit_length: u16_at(data, 6)?,
            access: ObjectAccess::from_bits_retain(access),
            name: name_of(&data[10..]),
        })
    }
}

/// What one mailbox message of an SDO Information response contributed.
#[derive(Debug, Copy, Clone, PartialEq, Eq)]
pub enum Fragment {
    /// Its data was appended; more fragments follow.
    More,
    /// Its data was appended; it was the last.
    Last,
    /// Not a fragment of the awaited response (another service or opcode): skipped.
    Other,
}

/// Appends the service data of one SDO Information mailbox message `message` to `buf` if it
/// is a fragment of the `expected` response; `skip_first` bytes of the first fragment's data
/// are dropped (the list type word of a Get OD List response). An SDO Info Error Request is
/// `MailboxError::SdoInfoAborted` with its abort code.
pub fn take_fragment<const N: usize>(
    message: &[u8],
    expected: SdoInfoOpCode,
    skip_first: usize,
    buf: &mut heapless::Vec<u8, N>,
    first: bool,
) -> Result<Fragment, Error> {
    let mailbox = MailboxHeader::unpack_from_slice(message)?;
    let coe = CoeHeader::unpack_from_slice(message.get(6..).ok_or(Error::Pdu(PduError::Decode))?);
    if mailbox.mailbox_type != MailboxType::Coe
        || !matches!(coe, Ok(CoeHeader { service: CoeService::SdoInformation }))
    {
        return Ok(Fragment::Other);
    }
    let Ok(info) = SdoInfoHeader::unpack_from_slice(&message[8..]) else {
        return Ok(Fragment::Other);
    };
    let end = (usize::from(mailbox.length) + 6).min(message.len());
    let data = message
        .get(HEADERS_LEN..end)
        .ok_or(Error::Pdu(PduError::Decode))?;
    if info.op_code == SdoInfoOpCode::SdoInfoErrorRequest {
        let code = CoeAbortCode::unpack_from_slice(data)?;
        return Err(Error::Mailbox(MailboxError::SdoInfoAborted { code }));
    }
    if info.op_code != expected {
        return Ok(Fragment::Other);
    }
    let data = if first {
        data.get(skip_first..).ok_or(Error::Pdu(PduError::Decode))?
    } else {
        data
    };
    buf.extend_from_slice(data)
        .map_err(|_| Error::Pdu(PduError::TooLong))?;
    Ok(if info.incomplete {
        Fragment::More
    } else {
        Fragment::Last
    })
}
