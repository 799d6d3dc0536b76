//! Object access over SLMP 4020h (MR-JE-C manual §2.4.4): SDO upload and download of one
//! sub-index, values little-endian in their type's size.

use super::{lookup, typed, AccessError, ObjectAccess};
use crate::mr_je_c::objects::ObjectId;
use crate::mr_je_c::types::SoftwareVersion;
use crate::mr_je_c::value::Value;
use crate::slmp::client::{Answer, ClientError, SlmpClient};
use crate::slmp::Command;

fn error(id: ObjectId, e: ClientError) -> AccessError {
    match e {
        ClientError::EndCode(code) => AccessError::EndCode { id, code },
        ClientError::Timeout(t) => AccessError::Timeout(t),
        other => AccessError::Link(other.to_string()),
    }
}

impl ObjectAccess for SlmpClient {
    fn software(&self) -> SoftwareVersion {
        self.software
    }

    fn read_object(&mut self, id: ObjectId) -> Result<Value, AccessError> {
        let (_, sub) = lookup(id, self.software)?;
        let answer = self
            .request(Command::Upload {
                index: id.index,
                sub: id.sub,
            })
            .map_err(|e| error(id, e))?;
        match answer {
            Answer::Data(bytes) => Value::from_le(sub.ty, &bytes).ok_or(AccessError::Link(
                format!("{id}: {} bytes, {} expected", bytes.len(), sub.ty.bytes()),
            )),
            other => Err(AccessError::Link(format!("{id}: unexpected {other:?}"))),
        }
    }

    fn write_object(&mut self, id: ObjectId, value: &Value) -> Result<(), AccessError> {
        let (_, sub) = lookup(id, self.software)?;
        typed(id, sub, value)?;
        self.request(Command::Download {
            index: id.index,
            sub: id.sub,
            data: &value.to_le(),
        })
        .map(|_| ())
        .map_err(|e| error(id, e))
    }
}
