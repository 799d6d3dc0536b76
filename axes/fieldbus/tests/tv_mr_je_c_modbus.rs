//! MR-JE-C Modbus test vectors (docs/test-vectors.md, MR-JE-C MT-* and MR-*), byte for byte,
//! through both ends of the codec: the controller's query encoding and reply decoding, and
//! the drive's query decoding and reply encoding (MR-JE-C manual §3.5, §3.6, §4.7, §4.8).

use cellrt_fieldbus::modbus::{
    rtu, tcp, value_of, words_of, ExceptionCode, ModbusError, Query, Reply, WordOrder,
};

fn hex(s: &str) -> Vec<u8> {
    s.split_whitespace()
        .map(|b| u8::from_str_radix(b, 16).unwrap())
        .collect()
}

/// The client encodes `query` to `request`; the drive decodes `request` back to `query`,
/// encodes `reply` to `response`; the client decodes `response` back to `reply`.
fn tcp_vector(id: &str, query: Query<'_>, request: &str, reply: Reply<'_>, response: &str) {
    let (request, response) = (hex(request), hex(response));
    let t = u16::from_be_bytes([request[0], request[1]]);
    let mut buf = [0u8; tcp::MAX_ADU];
    let n = tcp::encode_query(t, &query, &mut buf).unwrap();
    assert_eq!(&buf[..n], &request[..], "{id}: request");
    let (adu, used) = tcp::split(&request).unwrap().unwrap();
    assert_eq!(used, request.len(), "{id}");
    assert_eq!(tcp::decode_query(&adu).unwrap(), query, "{id}: drive side");
    let n = tcp::encode_reply(t, &reply, &mut buf).unwrap();
    assert_eq!(&buf[..n], &response[..], "{id}: response");
    let (adu, _) = tcp::split(&response).unwrap().unwrap();
    assert_eq!(tcp::decode_reply(t, &query, &adu).unwrap(), reply, "{id}");
}

fn rtu_vector(
    id: &str,
    slave: u8,
    query: Query<'_>,
    request: &str,
    reply: Reply<'_>,
    response: &str,
) {
    let (request, response) = (hex(request), hex(response));
    let mut buf = [0u8; rtu::MAX_FRAME];
    let n = rtu::encode_query(slave, &query, &mut buf).unwrap();
    assert_eq!(&buf[..n], &request[..], "{id}: request");
    assert_eq!(rtu::decode_query(&request).unwrap(), (slave, query), "{id}");
    let n = rtu::encode_reply(slave, &reply, &mut buf).unwrap();
    assert_eq!(&buf[..n], &response[..], "{id}: response");
    assert_eq!(
        rtu::decode_reply(slave, &query, &response).unwrap(),
        reply,
        "{id}"
    );
}

#[test]
fn modbus_tcp_vectors() {
    let read = Query::Read {
        address: 0x2B05,
        registers: 4,
    };
    tcp_vector(
        "MT-1",
        read,
        "12 34 00 00 00 06 FF 03 2B 05 00 04",
        Reply::Read(&hex("56 78 12 34 10 00 20 00")),
        "12 34 00 00 00 0B FF 03 08 56 78 12 34 10 00 20 00",
    );
    tcp_vector(
        "MT-2",
        Query::Echo(0x1234),
        "12 34 00 00 00 06 FF 08 00 00 12 34",
        Reply::Echo(0x1234),
        "12 34 00 00 00 06 FF 08 00 00 12 34",
    );
    let pc02 = hex("01 00 00 00");
    let write_pc02 = Query::Write {
        address: 0x2102,
        data: &pc02,
    };
    let written = Reply::Written {
        address: 0x2102,
        registers: 2,
    };
    tcp_vector(
        "MT-3c",
        write_pc02,
        "12 34 00 00 00 0B FF 10 21 02 00 02 04 01 00 00 00",
        written,
        "12 34 00 00 00 06 FF 10 21 02 00 02",
    );
    tcp_vector(
        "MT-4",
        read,
        "12 34 00 00 00 06 FF 03 2B 05 00 04",
        Reply::Exception {
            function: 0x03,
            code: ExceptionCode::IllegalDataAddress,
        },
        "12 34 00 00 00 03 FF 83 02",
    );
    tcp_vector(
        "MT-8",
        Query::Read {
            address: 0x6041,
            registers: 1,
        },
        "00 01 00 00 00 06 FF 03 60 41 00 01",
        Reply::Read(&hex("04 37")),
        "00 01 00 00 00 05 FF 03 02 04 37",
    );
    tcp_vector(
        "MT-9",
        Query::Read {
            address: 0x6061,
            registers: 1,
        },
        "00 02 00 00 00 06 FF 03 60 61 00 01",
        Reply::Read(&hex("00 9B")),
        "00 02 00 00 00 05 FF 03 02 00 9B",
    );
    tcp_vector(
        "MT-10",
        Query::Read {
            address: 0x6064,
            registers: 2,
        },
        "00 03 00 00 00 06 FF 03 60 64 00 02",
        Reply::Read(&hex("86 A0 00 01")),
        "00 03 00 00 00 07 FF 03 04 86 A0 00 01",
    );
    let target = hex("86 A0 00 01");
    tcp_vector(
        "MT-11",
        Query::Write {
            address: 0x607A,
            data: &target,
        },
        "00 04 00 00 00 0B FF 10 60 7A 00 02 04 86 A0 00 01",
        Reply::Written {
            address: 0x607A,
            registers: 2,
        },
        "00 04 00 00 00 06 FF 10 60 7A 00 02",
    );
    let cw = hex("00 0F");
    tcp_vector(
        "MT-12",
        Query::Write {
            address: 0x6040,
            data: &cw,
        },
        "00 05 00 00 00 09 FF 10 60 40 00 01 02 00 0F",
        Reply::Written {
            address: 0x6040,
            registers: 1,
        },
        "00 05 00 00 00 06 FF 10 60 40 00 01",
    );
    let reset = hex("1E A5");
    tcp_vector(
        "MT-13",
        Query::Write {
            address: 0x2A46,
            data: &reset,
        },
        "00 06 00 00 00 09 FF 10 2A 46 00 01 02 1E A5",
        Reply::Written {
            address: 0x2A46,
            registers: 1,
        },
        "00 06 00 00 00 06 FF 10 2A 46 00 01",
    );
    let save = hex("00 05 61 73 65 76 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00");
    tcp_vector(
        "MT-14",
        Query::Write {
            address: 0x1010,
            data: &save,
        },
        "00 07 00 00 00 1D FF 10 10 10 00 0B 16 00 05 61 73 65 76 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00",
        Reply::Written {
            address: 0x1010,
            registers: 11,
        },
        "00 07 00 00 00 06 FF 10 10 10 00 0B",
    );
    // MT-15: the whole 1018h record, 9 registers (sub0 = 4, sub1 = 2 low word first, …).
    let identity = hex("00 04 00 02 00 00 00 00 00 00 00 00 00 00 00 00 00 00");
    tcp_vector(
        "MT-15",
        Query::Read {
            address: 0x1018,
            registers: 9,
        },
        "00 08 00 00 00 06 FF 03 10 18 00 09",
        Reply::Read(&identity),
        "00 08 00 00 00 15 FF 03 12 00 04 00 02 00 00 00 00 00 00 00 00 00 00 00 00 00 00",
    );
}

#[test]
fn the_drive_refuses_and_discards_as_the_manual_says() {
    // MT-5: an unsupported function gets exception 01h with function + 80h.
    let unsupported = hex("12 34 00 00 00 06 FF 01 00 00 00 01");
    let (adu, _) = tcp::split(&unsupported).unwrap().unwrap();
    let e = tcp::decode_query(&adu).unwrap_err();
    assert_eq!(e, ModbusError::Function(0x01));
    let mut buf = [0u8; tcp::MAX_ADU];
    let n = tcp::encode_reply(0x1234, &e.exception(0x01).unwrap(), &mut buf).unwrap();
    assert_eq!(&buf[..n], &hex("12 34 00 00 00 03 FF 81 01")[..]);
    // MT-6 / MT-7: a protocol identifier other than 0 or a unit other than FFh: no answer.
    for (frame, want) in [
        (
            "12 34 00 01 00 06 FF 03 60 41 00 01",
            ModbusError::ProtocolId(1),
        ),
        (
            "12 34 00 00 00 06 01 03 60 41 00 01",
            ModbusError::UnitId(1),
        ),
    ] {
        let bytes = hex(frame);
        let (adu, _) = tcp::split(&bytes).unwrap().unwrap();
        let e = tcp::decode_query(&adu).unwrap_err();
        assert_eq!(e, want);
        assert_eq!(
            e.exception(0x03),
            None,
            "{frame}: discarded without an answer"
        );
    }
    // MT-3 as printed (Length 000Ah): framed strictly by Length, the ADU has Byte Count 4 and
    // three data bytes: malformed, exception 03h; the trailing byte waits for the next ADU.
    let printed = hex("12 34 00 00 00 0A FF 10 21 02 00 02 04 01 00 00 00");
    let (adu, used) = tcp::split(&printed).unwrap().unwrap();
    assert_eq!(used, printed.len() - 1);
    let e = tcp::decode_query(&adu).unwrap_err();
    assert!(
        matches!(
            e,
            ModbusError::Truncated { .. } | ModbusError::Malformed { .. }
        ),
        "{e}"
    );
    // No. of Registers = 0: exception 03h.
    let zero = hex("12 34 00 00 00 06 FF 03 60 41 00 00");
    let (adu, _) = tcp::split(&zero).unwrap().unwrap();
    let e = tcp::decode_query(&adu).unwrap_err();
    assert_eq!(
        e.exception(0x03),
        Some(Reply::Exception {
            function: 0x03,
            code: ExceptionCode::IllegalDataValue
        })
    );
    // A partial ADU waits for more bytes.
    assert_eq!(tcp::split(&hex("12 34 00 00 00 06 FF 03")).unwrap(), None);
}

#[test]
fn modbus_rtu_vectors() {
    rtu_vector(
        "MR-1",
        2,
        Query::Read {
            address: 0x2B05,
            registers: 4,
        },
        "02 03 2B 05 00 04 5D DF",
        Reply::Read(&hex("56 78 12 34 10 00 20 00")),
        "02 03 08 56 78 12 34 10 00 20 00 48 34",
    );
    rtu_vector(
        "MR-2",
        3,
        Query::Echo(0x1234),
        "03 08 00 00 12 34 EC 9E",
        Reply::Echo(0x1234),
        "03 08 00 00 12 34 EC 9E",
    );
    let pc02 = hex("01 00 00 00");
    rtu_vector(
        "MR-3",
        2,
        Query::Write {
            address: 0x2102,
            data: &pc02,
        },
        "02 10 21 02 00 02 04 01 00 00 00 E8 9F",
        Reply::Written {
            address: 0x2102,
            registers: 2,
        },
        "02 10 21 02 00 02 EA 07",
    );
    let status = Query::Read {
        address: 0x6041,
        registers: 1,
    };
    rtu_vector(
        "MR-6",
        1,
        status,
        "01 03 60 41 00 01 CA 1E",
        Reply::Read(&hex("04 37")),
        "01 03 02 04 37 FB 52",
    );
    for (cw, frame) in [
        ("00 06", "01 10 60 40 00 01 02 00 06 48 94"),
        ("00 07", "01 10 60 40 00 01 02 00 07 89 54"),
        ("00 0F", "01 10 60 40 00 01 02 00 0F 88 92"),
    ] {
        let data = hex(cw);
        rtu_vector(
            "MR-7",
            1,
            Query::Write {
                address: 0x6040,
                data: &data,
            },
            frame,
            Reply::Written {
                address: 0x6040,
                registers: 1,
            },
            "01 10 60 40 00 01 1E 1D",
        );
    }
    rtu_vector(
        "MR-8",
        1,
        Query::Read {
            address: 0x6064,
            registers: 2,
        },
        "01 03 60 64 00 02 9B D4",
        Reply::Read(&hex("86 A0 00 01")),
        "01 03 04 86 A0 00 01 12 99",
    );
    let target = hex("86 A0 00 01");
    rtu_vector(
        "MR-9",
        1,
        Query::Write {
            address: 0x607A,
            data: &target,
        },
        "01 10 60 7A 00 02 04 86 A0 00 01 34 5C",
        Reply::Written {
            address: 0x607A,
            registers: 2,
        },
        "01 10 60 7A 00 02 7E 11",
    );
    rtu_vector(
        "MR-11",
        1,
        Query::Read {
            address: 0x6061,
            registers: 1,
        },
        "01 03 60 61 00 01 CB D4",
        Reply::Read(&hex("00 9B")),
        "01 03 02 00 9B F9 EF",
    );
    let reset = hex("1E A5");
    rtu_vector(
        "MR-13",
        1,
        Query::Write {
            address: 0x2A46,
            data: &reset,
        },
        "01 10 2A 46 00 01 02 1E A5 EA EF",
        Reply::Written {
            address: 0x2A46,
            registers: 1,
        },
        "01 10 2A 46 00 01 E8 04",
    );
}

#[test]
fn rtu_exceptions_broadcast_and_crc() {
    let mut buf = [0u8; rtu::MAX_FRAME];
    // MR-4 / MR-5: exception frames from slave 02h.
    for (function, code, frame) in [
        (0x03, ExceptionCode::IllegalDataAddress, "02 83 02 30 F1"),
        (0x01, ExceptionCode::IllegalFunction, "02 81 01 71 90"),
    ] {
        let n = rtu::encode_reply(2, &Reply::Exception { function, code }, &mut buf).unwrap();
        assert_eq!(&buf[..n], &hex(frame)[..]);
    }
    // MR-10: broadcast of 2D9Bh = 1 (10h only; never answered).
    let one = hex("00 01");
    let forced_stop = Query::Write {
        address: 0x2D9B,
        data: &one,
    };
    let n = rtu::encode_query(rtu::BROADCAST, &forced_stop, &mut buf).unwrap();
    assert_eq!(&buf[..n], &hex("00 10 2D 9B 00 01 02 00 01 8B 29")[..]);
    assert_eq!(
        rtu::decode_query(&buf[..n]).unwrap(),
        (rtu::BROADCAST, forced_stop)
    );
    let read = Query::Read {
        address: 0x6041,
        registers: 1,
    };
    assert!(
        rtu::encode_query(rtu::BROADCAST, &read, &mut buf).is_err(),
        "03h broadcast"
    );
    // MR-12: diagnostics sub-function 0001h is refused with function 88h.
    let (_, e) = (
        0,
        rtu::decode_query(&hex("01 08 00 01 12 34 BC BC")).unwrap_err(),
    );
    match e.exception(0x08) {
        Some(Reply::Exception { function, .. }) => assert_eq!(function | 0x80, 0x88),
        other => panic!("{other:?}"),
    }
    // A CRC error is not answered.
    let e = rtu::decode_query(&hex("01 03 60 41 00 01 CA 1F")).unwrap_err();
    assert!(matches!(e, ModbusError::Crc { .. }), "{e}");
    assert_eq!(e.exception(0x03), None);
}

#[test]
fn the_crc_is_crc_16_modbus() {
    // The catalogue check value of CRC-16/MODBUS.
    assert_eq!(rtu::crc(b"123456789"), 0x4B37);
}

#[test]
fn word_order_of_32_bit_values() {
    // §3.6.2 / MR-14: 12345678h is `56 78 12 34` low word first, `12 34 56 78` with PC72 = 1.
    assert_eq!(
        words_of(0x1234_5678, 2, WordOrder::LowFirst),
        [0x5678, 0x1234]
    );
    assert_eq!(
        words_of(0x1234_5678, 2, WordOrder::HighFirst),
        [0x1234, 0x5678]
    );
    assert_eq!(value_of(&[0x86A0, 0x0001], WordOrder::LowFirst), 100_000);
    assert_eq!(value_of(&[0x0001, 0x86A0], WordOrder::HighFirst), 100_000);
    assert_eq!(value_of(&[0x0437], WordOrder::LowFirst), 0x0437);
}

mod properties {
    use super::*;
    use proptest::prelude::*;

    /// A query to build: 0 = read, 1 = echo, 2 = write of `n` registers from `bytes`.
    fn build(kind: u8, address: u16, n: u16, bytes: &[u8]) -> Query<'_> {
        match kind {
            0 => Query::Read {
                address,
                registers: n,
            },
            1 => Query::Echo(address ^ n),
            _ => Query::Write {
                address,
                data: &bytes[..2 * usize::from(n)],
            },
        }
    }

    proptest! {
        #[test]
        fn every_query_round_trips_over_tcp_and_rtu(
            bytes in proptest::collection::vec(any::<u8>(), 244),
            kind in 0u8..3,
            address in any::<u16>(),
            n in 1u16..=122,
            t in any::<u16>(),
            slave in 1u8..=247,
        ) {
            let query = build(kind, address, n, &bytes);
            let mut buf = [0u8; tcp::MAX_ADU];
            let len = tcp::encode_query(t, &query, &mut buf).unwrap();
            let (adu, used) = tcp::split(&buf[..len]).unwrap().unwrap();
            prop_assert_eq!(used, len);
            prop_assert_eq!(tcp::decode_query(&adu).unwrap(), query);
            let len = rtu::encode_query(slave, &query, &mut buf).unwrap();
            prop_assert_eq!(rtu::decode_query(&buf[..len]).unwrap(), (slave, query));
        }

        #[test]
        fn decoders_refuse_garbage_without_panicking(
            bytes in proptest::collection::vec(any::<u8>(), 0..300),
        ) {
            if let Ok(Some((adu, used))) = tcp::split(&bytes) {
                prop_assert!(used <= bytes.len());
                let _ = tcp::decode_query(&adu);
                for q in [Query::Read { address: 0x6041, registers: 2 }, Query::Echo(7)] {
                    let _ = tcp::decode_reply(adu.transaction, &q, &adu);
                }
            }
            let _ = rtu::decode_query(&bytes);
            let _ = rtu::decode_reply(1, &Query::Read { address: 0x6064, registers: 2 }, &bytes);
        }

        #[test]
        fn a_frame_with_a_flipped_bit_fails_its_crc(
            address in any::<u16>(), registers in 1u16..=122, bit in 0usize..48,
        ) {
            let mut buf = [0u8; rtu::MAX_FRAME];
            let n = rtu::encode_query(1, &Query::Read { address, registers }, &mut buf).unwrap();
            buf[bit / 8] ^= 1 << (bit % 8);
            prop_assert!(rtu::decode_query(&buf[..n]).is_err());
        }
    }
}
