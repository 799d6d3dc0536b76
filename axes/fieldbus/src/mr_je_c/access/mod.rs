//! Typed object access to an MR-JE-C, the same over every transport: `read::<Statusword>()`,
//! `write::<Controlword>(…)`, or by [`ObjectId`] with a dictionary-typed [`Value`]. The layers
//! above do not care whether a cell talks SLMP or Modbus.

mod modbus;
mod slmp;
pub mod typed;

use std::time::Duration;

pub use modbus::OverModbus;
pub use typed::TypedObject;

use super::objects::{entry, Object, ObjectId, Sub};
use super::types::SoftwareVersion;
use super::value::Value;
use crate::modbus::ExceptionCode;
use crate::slmp::EndCode;

/// Why an object access failed, with the transport's own code where the drive refused.
#[derive(Debug, thiserror::Error)]
pub enum AccessError {
    /// Not in the dictionary (of that software version).
    #[error("{0}: no such object on an MR-JE-C with software {1}")]
    Unknown(ObjectId, SoftwareVersion),
    /// A value that does not fit the object's type.
    #[error("{id}: {value} is not a value of the object's type {ty:?}")]
    Type {
        /// The object.
        id: ObjectId,
        /// The value.
        value: Value,
        /// The object's type.
        ty: super::types::DataType,
    },
    /// SLMP: the drive answered with an abnormal end code.
    #[error("{id}: the drive answered {code}")]
    EndCode {
        /// The object.
        id: ObjectId,
        /// End code.
        code: EndCode,
    },
    /// Modbus: the drive answered with an exception.
    #[error("{id}: the drive answered exception {code}")]
    Exception {
        /// The object.
        id: ObjectId,
        /// Exception code.
        code: ExceptionCode,
    },
    /// No reply before the deadline.
    #[error("no reply within {0:?}")]
    Timeout(Duration),
    /// The connection failed, or a frame was refused.
    #[error("{0}")]
    Link(String),
}

/// Object access to one drive.
pub trait ObjectAccess {
    /// The software version whose dictionary types the values.
    fn software(&self) -> SoftwareVersion;

    /// Reads `id`.
    fn read_object(&mut self, id: ObjectId) -> Result<Value, AccessError>;

    /// Writes `value` (of the object's type) to `id`.
    fn write_object(&mut self, id: ObjectId, value: &Value) -> Result<(), AccessError>;

    /// Reads the object `O`.
    fn read<O: TypedObject>(&mut self) -> Result<O::Value, AccessError>
    where
        Self: Sized,
    {
        let v = self.read_object(O::ID)?;
        O::decode(&v).ok_or(AccessError::Type {
            id: O::ID,
            value: v,
            ty: O::TYPE,
        })
    }

    /// Writes the object `O`.
    fn write<O: TypedObject>(&mut self, value: O::Value) -> Result<(), AccessError>
    where
        Self: Sized,
    {
        self.write_object(O::ID, &O::encode(value))
    }
}

/// The dictionary row of `id`, or why there is none.
pub fn lookup(
    id: ObjectId,
    sw: SoftwareVersion,
) -> Result<(&'static Object, &'static Sub), AccessError> {
    entry(id, sw).ok_or(AccessError::Unknown(id, sw))
}

/// Checks that `value` is of `id`'s type.
fn typed(id: ObjectId, sub: &Sub, value: &Value) -> Result<(), AccessError> {
    if value.is(sub.ty) {
        Ok(())
    } else {
        Err(AccessError::Type {
            id,
            value: value.clone(),
            ty: sub.ty,
        })
    }
}
