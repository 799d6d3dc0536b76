//! The MR-JE-C (MELSERVO-JE, Ethernet / RS-485 interface) as one model: its object dictionary
//! (MR-JE-C manual §7), typed object access shared by the transports (`axes::modbus`,
//! `axes::slmp`), and a simulated drive serving them.

pub mod access;
pub mod alarm;
pub mod cell;
pub mod emulator;
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
