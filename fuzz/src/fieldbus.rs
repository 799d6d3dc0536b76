//! Modbus (TCP and RTU), SLMP and CC-Link IE Field Basic decoders, both the drive's (query,
//! request) and the controller's (reply, response) side.

use cellrt_fieldbus::cclink_ief_basic::{CyclicRequest, CyclicResponse};
use cellrt_fieldbus::modbus::{rtu, tcp, Query, Reply};
use cellrt_fieldbus::slmp;

use crate::pieces;

/// The query a reply answers: the first piece decoded as a query PDU, else a 2-register read.
fn first_query(piece: &[u8]) -> Query<'_> {
    Query::decode(piece).unwrap_or(Query::Read {
        address: 0x6041,
        registers: 2,
    })
}

/// Modbus: the first piece is the query; each further piece is read as a TCP stream (every
/// ADU cut from it decoded as query and as reply) and, with its CRC appended, as an RTU frame.
pub fn modbus(data: &[u8]) {
    let mut all = pieces(data);
    let query = first_query(all.next().unwrap_or_default());
    for piece in all {
        let mut stream = piece;
        while let Ok(Some((adu, used))) = tcp::split(stream) {
            let _ = tcp::decode_query(&adu);
            let _ = tcp::decode_reply(adu.transaction, &query, &adu);
            let _ = Reply::decode(&query, adu.pdu);
            stream = &stream[used.max(1).min(stream.len())..];
        }
        let mut frame = piece.to_vec();
        let crc = rtu::crc(&frame);
        frame.extend_from_slice(&crc.to_le_bytes());
        let _ = rtu::decode_query(&frame);
        let _ = rtu::decode_query(piece);
        let slave = frame.first().copied().unwrap_or(1);
        let _ = rtu::decode_reply(slave, &query, &frame);
    }
}

/// SLMP: each piece decoded as a request; a piece that is one answers the next piece's
/// response. Each piece is also a NodeSearch / IPAddressSet request (answered by an emulated
/// drive) and response of either command.
pub fn slmp(data: &[u8]) {
    use cellrt_emulator::mr_je_c::{search, MrJeC};
    use slmp::node_search::{decode_request, decode_response, IP_ADDRESS_SET, NODE_SEARCH};
    // Built when a piece first decodes as a search request (`search::answer` answers nothing
    // else): a drive's dictionary is costly to build for every input.
    let mut drive: Option<MrJeC> = None;
    let mut last: Option<slmp::Request<'_>> = None;
    for piece in pieces(data) {
        let searched = decode_request(piece).is_ok();
        let serial = [
            piece.get(2).copied().unwrap_or(0),
            piece.get(3).copied().unwrap_or(0),
        ];
        let _ = decode_response(piece, serial, NODE_SEARCH);
        let _ = decode_response(piece, serial, IP_ADDRESS_SET);
        if searched {
            let own = std::net::Ipv4Addr::new(192, 168, 3, 10);
            let drive = drive.get_or_insert_with(|| MrJeC::new(Default::default()));
            let _ = search::answer(drive, own, piece, std::time::Duration::ZERO);
        }
        if let Some(request) = &last {
            let _ = slmp::decode_response(request, piece);
        }
        match slmp::decode_request(piece) {
            Ok(request) => last = Some(request),
            Err(e) => {
                let _ = e.answer();
            }
        }
    }
}

/// CC-Link IE Field Basic: each piece as a cyclic request (slave side) and response (master
/// side).
pub fn cclink_ief_basic(data: &[u8]) {
    for piece in pieces(data) {
        if let Ok(request) = CyclicRequest::decode(piece, 0xC0A8_0001) {
            let _ = request.station_of(0xC0A8_0002);
            let _ = request.master_lost_after_ms();
            let _ = (0..=65).filter(|&k| request.transmitting(k)).count();
        }
        let _ = CyclicResponse::decode(piece);
    }
}
