//! The MR-JE-C (MELSERVO-JE, Ethernet / RS-485 interface) as one model: its object dictionary
//! (MR-JE-C manual §7), typed object access shared by the transports (`crate::modbus`,
//! `crate::slmp`); the emulated drive serving them is `cellrt_emulator::mr_je_c`.

pub mod access;
pub mod alarm;
pub mod cell;
pub mod links;
pub mod objects;
pub mod parameters;
pub mod types;
pub mod value;

pub use access::{AccessError, ObjectAccess, OverModbus, TypedObject};
pub use alarm::Alarm;
pub use objects::{entry, object, Object, ObjectId, Sub, DICTIONARY};
pub use types::{
    Access, DataType, Initial, ParseSoftwareVersionError, Range, SoftwareVersion, Unit,
};
pub use value::Value;

/// Controlword bit 6 on at the New set-point edge in jg (6060h = −100) jogs in the reverse
/// (address decreasing) direction. The manual does not say how jg picks the direction (6081h is
/// unsigned, bits 5 and 6 are "operation mode specific", §7.3): a named choice of cellrt's
/// (controller and emulator alike), to check against a real drive.
pub const JOG_REVERSE: u16 = 1 << 6;
