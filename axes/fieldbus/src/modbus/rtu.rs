//! Modbus RTU framing as the MR-JE-C applies it (MR-JE-C manual §4.5–§4.8): slave address,
//! PDU, CRC-16/MODBUS low byte first. Address 0 is a broadcast, taken only with 10h and never
//! answered; a frame with a wrong CRC is not answered either.

use super::pdu::WRITE;
use super::{ModbusError, Query, Reply};

/// The broadcast address.
pub const BROADCAST: u8 = 0;
/// The largest RTU frame: address, 253-byte PDU, CRC.
pub const MAX_FRAME: usize = 256;

/// CRC-16/MODBUS of `bytes` (sent low byte first). `modbus-core` returns it byte-swapped, ready
/// for a big-endian write.
pub fn crc(bytes: &[u8]) -> u16 {
    modbus_core::rtu::crc16(bytes).swap_bytes()
}

fn seal(len: usize, buf: &mut [u8]) -> Result<usize, ModbusError> {
    if buf.len() < len + 2 {
        return Err(ModbusError::Buffer(buf.len()));
    }
    let c = crc(&buf[..len]);
    buf[len..len + 2].copy_from_slice(&c.to_le_bytes());
    Ok(len + 2)
}

/// Checks the CRC of a whole frame; its address and PDU.
pub fn open(frame: &[u8]) -> Result<(u8, &[u8]), ModbusError> {
    if frame.len() < 4 {
        return Err(ModbusError::Truncated {
            got: frame.len(),
            need: 4,
        });
    }
    if frame.len() > MAX_FRAME {
        return Err(ModbusError::Oversized {
            got: frame.len(),
            max: MAX_FRAME,
        });
    }
    let (body, tail) = frame.split_at(frame.len() - 2);
    let got = u16::from_le_bytes([tail[0], tail[1]]);
    let expected = crc(body);
    if got != expected {
        return Err(ModbusError::Crc { got, expected });
    }
    Ok((body[0], &body[1..]))
}

/// Master: the frame of `query` to `slave` (0: broadcast, 10h only).
pub fn encode_query(slave: u8, query: &Query<'_>, buf: &mut [u8]) -> Result<usize, ModbusError> {
    if slave == BROADCAST && query.function() != WRITE {
        return Err(ModbusError::Malformed {
            function: query.function(),
            why: "only 10h may be broadcast",
        });
    }
    if buf.is_empty() {
        return Err(ModbusError::Buffer(0));
    }
    buf[0] = slave;
    let n = query.encode(&mut buf[1..])?;
    seal(1 + n, buf)
}

/// Slave: the query in `frame` with its address, or why it is refused (a CRC error is never
/// answered, nor is anything sent to the broadcast address).
pub fn decode_query(frame: &[u8]) -> Result<(u8, Query<'_>), ModbusError> {
    let (slave, pdu) = open(frame)?;
    let query = Query::decode(pdu)?;
    if slave == BROADCAST && query.function() != WRITE {
        return Err(ModbusError::Malformed {
            function: query.function(),
            why: "only 10h may be broadcast",
        });
    }
    Ok((slave, query))
}

/// Slave: the frame of `reply` from `slave`.
pub fn encode_reply(slave: u8, reply: &Reply<'_>, buf: &mut [u8]) -> Result<usize, ModbusError> {
    if buf.is_empty() {
        return Err(ModbusError::Buffer(0));
    }
    buf[0] = slave;
    let n = reply.encode(&mut buf[1..])?;
    seal(1 + n, buf)
}

/// Master: the reply in `frame` from `slave` to `query`.
pub fn decode_reply<'p>(
    slave: u8,
    query: &Query<'_>,
    frame: &'p [u8],
) -> Result<Reply<'p>, ModbusError> {
    let (from, pdu) = open(frame)?;
    if from != slave {
        return Err(ModbusError::Mismatch {
            what: "slave",
            got: u16::from(from),
            expected: u16::from(slave),
        });
    }
    Reply::decode(query, pdu)
}
