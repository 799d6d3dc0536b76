//! Modbus/TCP and Modbus RTU as the MR-JE-C speaks them (MR-JE-C manual §3, §4, §7.1): a drive
//! (server / slave) that answers 03h Read Holding Registers, 08h Diagnostics (echo, sub-function
//! 0000h) and 10h Preset Multiple Registers, with register address = object index and 32-bit
//! values low word first. Both ends use these codecs: the controller's client and the drive
//! emulator. The PDU codec is the `modbus-core` crate's; the framing rules the drive adds
//! (protocol and unit identifiers, strict MBAP length, slave address, CRC) are here.

pub mod client;
mod error;
mod pdu;
pub mod rtu;
pub mod serial;
pub mod tcp;
mod words;

pub use error::ModbusError;
pub use pdu::{ExceptionCode, Query, Reply, MAX_REGISTERS, WRITE};
pub use words::{value_of, words_of, WordOrder};
