//! Modbus/TCP framing as the MR-JE-C applies it (MR-JE-C manual §3.5): the MBAP header's
//! protocol identifier must be 0 and the unit identifier FFh, or the drive discards the query
//! without an answer; ADUs are delimited strictly by the Length field (the manual's own 10h
//! example prints a Length one short: a query must carry the right one).

use super::{ModbusError, Query, Reply};

/// Port the drive listens on.
pub const PORT: u16 = 502;
/// The only unit identifier the drive answers.
pub const UNIT_ID: u8 = 0xFF;
/// MBAP header bytes (transaction, protocol, length, unit).
pub const MBAP_LEN: usize = 7;
/// The largest ADU: the header and a 253-byte PDU.
pub const MAX_ADU: usize = MBAP_LEN + 253;

/// One ADU cut from the stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Adu<'a> {
    /// Transaction identifier (echoed by the drive).
    pub transaction: u16,
    /// Protocol identifier (0 for Modbus).
    pub protocol: u16,
    /// Unit identifier.
    pub unit: u8,
    /// Function code and data.
    pub pdu: &'a [u8],
}

/// Cuts the first ADU from `stream`: `Ok(None)` until all of it has arrived, else the ADU and
/// the bytes it took. A Length that cannot frame an ADU is an error: the stream has lost its
/// framing and the connection must be closed.
pub fn split(stream: &[u8]) -> Result<Option<(Adu<'_>, usize)>, ModbusError> {
    if stream.len() < 6 {
        return Ok(None);
    }
    let length = usize::from(u16::from_be_bytes([stream[4], stream[5]]));
    if length < 2 {
        return Err(ModbusError::Truncated {
            got: length,
            need: 2,
        });
    }
    if 6 + length > MAX_ADU {
        return Err(ModbusError::Oversized {
            got: 6 + length,
            max: MAX_ADU,
        });
    }
    let total = 6 + length;
    if stream.len() < total {
        return Ok(None);
    }
    Ok(Some((
        Adu {
            transaction: u16::from_be_bytes([stream[0], stream[1]]),
            protocol: u16::from_be_bytes([stream[2], stream[3]]),
            unit: stream[6],
            pdu: &stream[MBAP_LEN..total],
        },
        total,
    )))
}

/// The ADU of the PDU `encode` writes after the MBAP header; its length.
fn adu(
    transaction: u16,
    buf: &mut [u8],
    encode: impl FnOnce(&mut [u8]) -> Result<usize, ModbusError>,
) -> Result<usize, ModbusError> {
    if buf.len() < MBAP_LEN {
        return Err(ModbusError::Buffer(buf.len()));
    }
    let pdu_len = encode(&mut buf[MBAP_LEN..])?;
    buf[0..2].copy_from_slice(&transaction.to_be_bytes());
    buf[2..4].fill(0);
    buf[4..6].copy_from_slice(&(pdu_len as u16 + 1).to_be_bytes());
    buf[6] = UNIT_ID;
    Ok(MBAP_LEN + pdu_len)
}

/// Client: the ADU of `query` under `transaction`.
pub fn encode_query(
    transaction: u16,
    query: &Query<'_>,
    buf: &mut [u8],
) -> Result<usize, ModbusError> {
    adu(transaction, buf, |pdu| query.encode(pdu))
}

/// Drive: the query in `adu`, or why it is refused. [`ModbusError::ProtocolId`] and
/// [`ModbusError::UnitId`] are discarded without an answer; the others have an exception
/// ([`ModbusError::exception`]).
pub fn decode_query<'a>(adu: &Adu<'a>) -> Result<Query<'a>, ModbusError> {
    if adu.protocol != 0 {
        return Err(ModbusError::ProtocolId(adu.protocol));
    }
    if adu.unit != UNIT_ID {
        return Err(ModbusError::UnitId(adu.unit));
    }
    Query::decode(adu.pdu)
}

/// Drive: the ADU of `reply` to `transaction`.
pub fn encode_reply(
    transaction: u16,
    reply: &Reply<'_>,
    buf: &mut [u8],
) -> Result<usize, ModbusError> {
    adu(transaction, buf, |pdu| reply.encode(pdu))
}

/// Client: the drive's reply in `adu` to `query` sent under `transaction`.
pub fn decode_reply<'p>(
    transaction: u16,
    query: &Query<'_>,
    adu: &Adu<'p>,
) -> Result<Reply<'p>, ModbusError> {
    if adu.protocol != 0 {
        return Err(ModbusError::ProtocolId(adu.protocol));
    }
    if adu.unit != UNIT_ID {
        return Err(ModbusError::UnitId(adu.unit));
    }
    if adu.transaction != transaction {
        return Err(ModbusError::Mismatch {
            what: "transaction",
            got: adu.transaction,
            expected: transaction,
        });
    }
    Reply::decode(query, adu.pdu)
}
