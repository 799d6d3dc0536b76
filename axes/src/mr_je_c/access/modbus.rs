//! Object access over Modbus/TCP (MR-JE-C manual §3.6, §7.1): register address = object
//! index, an object read and written whole (a sub-index of a record is read from, or merged
//! into, the whole record), 32-bit values low word first.

use super::{lookup, typed, AccessError, ObjectAccess};
use crate::modbus::client::{ClientError, TcpClient};
use crate::modbus::WordOrder;
use crate::mr_je_c::objects::{Object, ObjectId};
use crate::mr_je_c::types::SoftwareVersion;
use crate::mr_je_c::value::Value;

/// A Modbus/TCP client with the dictionary of the drive's software version.
pub struct OverModbus {
    /// The client.
    pub client: TcpClient,
    /// The drive's software version (lays out 1010h, 1011h, 60E3h).
    pub software: SoftwareVersion,
}

impl OverModbus {
    /// Object access through `client` to a drive with software `software`.
    pub fn new(client: TcpClient, software: SoftwareVersion) -> OverModbus {
        OverModbus { client, software }
    }

    fn read_whole(&mut self, id: ObjectId, o: &Object) -> Result<Vec<u16>, AccessError> {
        let mut words = vec![0u16; o.registers(self.software)];
        self.client
            .read_registers(id.index, &mut words)
            .map_err(|e| error(id, e))?;
        Ok(words)
    }
}

/// Where the sub-index `sub` lies in the object's registers.
fn place(o: &Object, sub: u8, sw: SoftwareVersion) -> std::ops::Range<usize> {
    let mut at = 0;
    for (k, row) in o.each_sub(sw) {
        let n = row.ty.registers();
        if k == sub {
            return at..at + n;
        }
        at += n;
    }
    at..at
}

fn error(id: ObjectId, e: ClientError) -> AccessError {
    match e {
        ClientError::Exception { code, .. } => AccessError::Exception { id, code },
        ClientError::Timeout(t) => AccessError::Timeout(t),
        other => AccessError::Link(other.to_string()),
    }
}

impl ObjectAccess for OverModbus {
    fn software(&self) -> SoftwareVersion {
        self.software
    }

    fn read_object(&mut self, id: ObjectId) -> Result<Value, AccessError> {
        let (o, sub) = lookup(id, self.software)?;
        let words = self.read_whole(id, o)?;
        let at = place(o, id.sub, self.software);
        Value::from_words(sub.ty, &words[at], WordOrder::LowFirst)
            .ok_or(AccessError::Link(format!("{id}: short reply")))
    }

    fn write_object(&mut self, id: ObjectId, value: &Value) -> Result<(), AccessError> {
        let (o, sub) = lookup(id, self.software)?;
        typed(id, sub, value)?;
        let mut mine = Vec::with_capacity(2);
        value.push_words(WordOrder::LowFirst, &mut mine);
        let words = if o.is_record() {
            let mut words = self.read_whole(id, o)?;
            words[place(o, id.sub, self.software)].copy_from_slice(&mine);
            words
        } else {
            mine
        };
        self.client
            .write_registers(id.index, &words)
            .map_err(|e| error(id, e))
    }
}
