//! The simulated drive's side of Modbus RTU frames (MR-JE-C manual §4.5–§4.9): answers only
//! its own station number, never as station 0 (the factory setting of [Pr. PC70]), executes
//! broadcasts (address 0, 10h only) without answering unless 2D98h disables them (2D9Bh is
//! executed even then), takes 32-bit words in the order of [Pr. PC72], and is silent while
//! [Pr. PN08] selects Ethernet. A frame with a CRC or length error counts in 2A68h.
//!
//! On a line whose character format (bit rate, parity, stop bits) differs from the drive's
//! [Pr. PC71]/[Pr. PF45], the drive's UART receives every frame with parity or framing errors:
//! it counts one error per frame in 2A68h (hardware errors, §7.5.4) and never answers. One
//! count per frame, not per character, is our choice (the manual does not say how it counts).

use std::time::Duration;

use super::{modbus, MrJeC, Transport};
use cellrt_fieldbus::modbus::rtu::{decode_query, encode_reply, BROADCAST, MAX_FRAME};
use cellrt_fieldbus::modbus::serial::LineSettings;
use cellrt_fieldbus::modbus::{Query, WordOrder};
use cellrt_fieldbus::mr_je_c::objects::ObjectId;

/// The reply frame to the RTU frame `frame` that came at `now` on a line of character format
/// `line`, if the drive answers: a drive set to another format only counts the frame as
/// garbled.
pub fn answer_on_line(
    drive: &mut MrJeC,
    frame: &[u8],
    now: Duration,
    line: &LineSettings,
) -> Option<Vec<u8>> {
    if drive.serves(Transport::ModbusRtu) && drive.rtu_line().as_ref() != Some(line) {
        drive.count_rtu_error();
        return None;
    }
    answer(drive, frame, now)
}

/// The reply frame to the RTU frame `frame` at `now`, if the drive answers.
pub fn answer(drive: &mut MrJeC, frame: &[u8], now: Duration) -> Option<Vec<u8>> {
    if !drive.serves(Transport::ModbusRtu) {
        return None;
    }
    if cellrt_fieldbus::modbus::rtu::open(frame).is_err() {
        // A CRC or frame length error: every drive on the line counts it, none answers.
        drive.count_rtu_error();
        return None;
    }
    let (slave, query) = decode_query(frame).ok()?;
    let station = drive.station();
    let broadcast = slave == BROADCAST;
    if !broadcast && (station == 0 || slave != station) {
        return None;
    }
    drive.received(Transport::ModbusRtu, now);
    if broadcast && broadcasts_disabled(drive) && !is_forced_stop(&query) {
        return None;
    }
    let high_first = drive.read(ObjectId::new(0x2148, 0)).ok()?.as_i64()? & 0xF == 1;
    let order = if high_first {
        WordOrder::HighFirst
    } else {
        WordOrder::LowFirst
    };
    let mut data = Vec::new();
    let reply = modbus::answer(drive, &query, order, now, &mut data);
    if broadcast {
        return None;
    }
    let mut out = [0u8; MAX_FRAME];
    let n = encode_reply(station, &reply, &mut out).ok()?;
    Some(out[..n].to_vec())
}

fn broadcasts_disabled(drive: &MrJeC) -> bool {
    drive
        .read(ObjectId::new(0x2D98, 0))
        .ok()
        .and_then(|v| v.as_i64())
        == Some(1)
}

fn is_forced_stop(query: &Query<'_>) -> bool {
    matches!(
        query,
        Query::Write {
            address: 0x2D9B,
            ..
        }
    )
}
