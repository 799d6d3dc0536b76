//! The simulated drive's side of Modbus (MR-JE-C manual §3.6, §4.8, §7.1): register address =
//! object index; an object is read and written whole; consecutive addresses advance by one
//! object; objects without "continuous read/write" must be the whole request; a request of
//! several objects succeeds if one of them does (the unreadable ones read 0, §3.6.5).
//! Sub-indexes a record write cannot change (read-only, e.g. "Number of entries") are carried
//! and ignored, as are sub-indexes written with the value they held before the request. Every
//! access leaves its trace in the diagnostic objects (§7.5.1–§7.5.2): 2A60h the abort code of
//! the object that failed (0 when none did), 2A64h the last object accessed with success (index
//! in the upper word, its last sub-index in the lower: 2C12h reads 2C120004h), 2A65h how many
//! objects the request accessed with success.

use std::time::Duration;

use super::{MrJeC, Refusal};
use cellrt_fieldbus::modbus::{Query, Reply, WordOrder};
use cellrt_fieldbus::mr_je_c::objects::{object, Object, ObjectId};
use cellrt_fieldbus::mr_je_c::value::Value;

/// The drive's reply to `query` at `now`; `out` holds the bytes a read reply points into.
pub fn answer<'b>(
    drive: &mut MrJeC,
    query: &Query<'_>,
    order: WordOrder,
    now: Duration,
    out: &'b mut Vec<u8>,
) -> Reply<'b> {
    let refused = |function, r: Refusal| Reply::Exception {
        function,
        code: r.exception(),
    };
    match *query {
        Query::Echo(v) => Reply::Echo(v),
        Query::Read { address, registers } => {
            let mut words = Vec::new();
            match walk(
                drive,
                address,
                usize::from(registers),
                |drive, o, index, _| read_object(drive, o, index, order, &mut words),
            ) {
                Ok(()) => {
                    out.clear();
                    out.extend(words.iter().flat_map(|w| w.to_be_bytes()));
                    // Registers of objects that could not be read after a served one read 0.
                    out.resize(2 * usize::from(registers), 0);
                    Reply::Read(out)
                }
                Err(r) => refused(query.function(), r),
            }
        }
        Query::Write { address, data } => {
            let words: Vec<u16> = data
                .chunks_exact(2)
                .map(|p| u16::from_be_bytes([p[0], p[1]]))
                .collect();
            let mut at = 0;
            match walk(drive, address, words.len(), |drive, o, index, room| {
                let n = write_object(drive, o, index, &words[at..at + room], order, now)?;
                at += n;
                Ok(n)
            }) {
                Ok(()) => Reply::Written {
                    address,
                    registers: words.len() as u16,
                },
                Err(r) => refused(query.function(), r),
            }
        }
    }
}

/// Visits the objects from `address` on until `registers` are covered; `visit` gets the room
/// left and returns the registers it took. Fails only if no object was served.
fn walk(
    drive: &mut MrJeC,
    address: u16,
    registers: usize,
    mut visit: impl FnMut(&mut MrJeC, &'static Object, u16, usize) -> Result<usize, Refusal>,
) -> Result<(), Refusal> {
    let sw = drive.params().software;
    let (mut index, mut done, mut served) = (address, 0, 0u16);
    let mut last = None;
    let mut failed = None;
    while done < registers {
        let result = object(index, sw).ok_or(Refusal::NoIndex).and_then(|o| {
            let whole = o.registers(sw);
            let alone = index == address && whole == registers;
            if whole > registers - done || !(o.continuous || alone) {
                Err(Refusal::Layout)
            } else {
                let last_sub = o.each_sub(sw).map(|(sub, _)| sub).last().unwrap_or(0);
                visit(drive, o, index, registers - done).map(|n| (n, last_sub))
            }
        });
        match result {
            Ok((n, last_sub)) => {
                done += n;
                served += 1;
                last = Some((index, last_sub));
            }
            Err(r) => {
                failed = Some(r);
                break;
            }
        }
        index = index.wrapping_add(1);
    }
    drive.note_modbus_access(failed.map_or(0, Refusal::abort_code), last, served);
    match failed {
        Some(r) if served == 0 => Err(r),
        _ => Ok(()),
    }
}

fn read_object(
    drive: &mut MrJeC,
    o: &Object,
    index: u16,
    order: WordOrder,
    words: &mut Vec<u16>,
) -> Result<usize, Refusal> {
    let sw = drive.params().software;
    let start = words.len();
    for (sub, _) in o.each_sub(sw) {
        match drive.read(ObjectId::new(index, sub)) {
            Ok(v) => v.push_words(order, words),
            Err(r) => {
                words.truncate(start);
                return Err(r);
            }
        }
    }
    Ok(words.len() - start)
}

fn write_object(
    drive: &mut MrJeC,
    o: &Object,
    index: u16,
    words: &[u16],
    order: WordOrder,
    now: Duration,
) -> Result<usize, Refusal> {
    let sw = drive.params().software;
    // "The value it holds" is the one before the request: a sub-index written first may
    // change how another reads (1010h:1 "save" turns subs 4 and 5 to 0 while it runs).
    let held: Vec<Option<Value>> = o
        .each_sub(sw)
        .map(|(sub, _)| drive.read(ObjectId::new(index, sub)).ok())
        .collect();
    let mut at = 0;
    for ((sub, row), held) in o.each_sub(sw).zip(held) {
        let n = row.ty.registers();
        let id = ObjectId::new(index, sub);
        let value = Value::from_words(row.ty, &words[at..at + n], order).ok_or(Refusal::Layout)?;
        at += n;
        let unchanged = held.is_some_and(|v| v == value);
        if o.is_record() && (!row.access.writable() || unchanged) {
            continue;
        }
        drive.write(id, &value, now)?;
    }
    Ok(at)
}

/// The reply ADU to one Modbus/TCP ADU at `now`; none where the drive discards the query
/// (protocol identifier not 0, unit identifier not FFh, §3.5) or Ethernet is not selected.
pub fn answer_adu(
    drive: &mut MrJeC,
    adu: &cellrt_fieldbus::modbus::tcp::Adu<'_>,
    now: Duration,
) -> Option<Vec<u8>> {
    use cellrt_fieldbus::modbus::tcp;
    if !drive.serves(super::Transport::ModbusTcp) {
        return None;
    }
    let mut out = [0u8; tcp::MAX_ADU];
    let n = match tcp::decode_query(adu) {
        Ok(query) => {
            drive.received(super::Transport::ModbusTcp, now);
            let mut data = Vec::new();
            let reply = answer(drive, &query, WordOrder::LowFirst, now, &mut data);
            tcp::encode_reply(adu.transaction, &reply, &mut out).ok()?
        }
        Err(e) => {
            let function = adu.pdu.first().copied().unwrap_or(0);
            let reply = e.exception(function)?;
            if matches!(
                e,
                cellrt_fieldbus::modbus::ModbusError::ProtocolId(_)
                    | cellrt_fieldbus::modbus::ModbusError::UnitId(_)
            ) {
                return None;
            }
            drive.received(super::Transport::ModbusTcp, now);
            tcp::encode_reply(adu.transaction, &reply, &mut out).ok()?
        }
    };
    Some(out[..n].to_vec())
}
