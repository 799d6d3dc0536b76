//! Object access over Modbus/TCP or Modbus RTU (MR-JE-C manual §3.6, §4.8, §7.1): register
//! address = object index, an object read and written whole (a sub-index of a record is read
//! from, or merged into, the whole record), 32-bit values low word first (on RTU, high word
//! first where [Pr. PC72] selects it).

use super::{lookup, typed, AccessError, ObjectAccess};
use crate::modbus::client::{ClientError, Registers, TcpClient};
use crate::modbus::WordOrder;
use crate::mr_je_c::objects::{Object, ObjectId};
use crate::mr_je_c::types::SoftwareVersion;
use crate::mr_je_c::value::Value;

/// A Modbus client (Modbus/TCP, or a station of an RTU line) with the dictionary of the
/// drive's software version.
pub struct OverModbus<C: Registers = TcpClient> {
    /// The client.
    pub client: C,
    /// The drive's software version (lays out 1010h, 1011h, 60E3h).
    pub software: SoftwareVersion,
    /// The order of a 32-bit value's words.
    pub order: WordOrder,
}

impl<C: Registers> OverModbus<C> {
    /// Object access through `client` to a drive with software `software`, 32-bit values low
    /// word first (the drive's initial setting).
    pub fn new(client: C, software: SoftwareVersion) -> OverModbus<C> {
        OverModbus {
            client,
            software,
            order: WordOrder::LowFirst,
        }
    }

    /// The same with 32-bit values in `order` (an RTU drive whose [Pr. PC72] is 1).
    pub fn with_word_order(self, order: WordOrder) -> OverModbus<C> {
        OverModbus { order, ..self }
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

impl<C: Registers> ObjectAccess for OverModbus<C> {
    fn software(&self) -> SoftwareVersion {
        self.software
    }

    fn read_object(&mut self, id: ObjectId) -> Result<Value, AccessError> {
        let (o, sub) = lookup(id, self.software)?;
        let words = self.read_whole(id, o)?;
        let at = place(o, id.sub, self.software);
        Value::from_words(sub.ty, &words[at], self.order)
            .ok_or(AccessError::Link(format!("{id}: short reply")))
    }

    fn write_object(&mut self, id: ObjectId, value: &Value) -> Result<(), AccessError> {
        let (o, sub) = lookup(id, self.software)?;
        typed(id, sub, value)?;
        let mut mine = Vec::with_capacity(2);
        value.push_words(self.order, &mut mine);
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
