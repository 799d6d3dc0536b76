//! MR-JE-C SLMP test vectors SL-1 … SL-11 (docs/test-vectors.md), byte for byte through both
//! ends of `cellrt_fieldbus::slmp` (MR-JE-C manual §2.4.2–§2.4.5). The bytes the manual does not fix (the
//! response's "Number of data value", the error information) are asserted on the drive side as
//! our design and not relied on by the client.

use cellrt_fieldbus::slmp::{
    decode_request, decode_response, encode_request, encode_response, Command, EndCode, Reply,
    Request, Response, Route, SlmpError, Subheader, MAX_FRAME,
};

fn hex(s: &str) -> Vec<u8> {
    s.split_whitespace()
        .map(|b| u8::from_str_radix(b, 16).unwrap())
        .collect()
}

fn e3(command: Command<'_>) -> Request<'_> {
    Request {
        subheader: Subheader::E3,
        route: Route::default(),
        monitoring_timer: 0,
        command,
    }
}

/// Client encodes `request` to `req`; the drive decodes it back and encodes `reply` to `resp`;
/// the client decodes `resp` to `reply`.
fn vector(id: &str, request: Request<'_>, req: &str, reply: Reply<'_>, resp: &str) {
    let (req, resp) = (hex(req), hex(resp));
    let mut buf = [0u8; MAX_FRAME];
    let n = encode_request(&request, &mut buf).unwrap();
    assert_eq!(&buf[..n], &req[..], "{id}: request");
    assert_eq!(decode_request(&req).unwrap(), request, "{id}: drive side");
    let response = Response {
        subheader: request.subheader,
        route: request.route,
        reply,
    };
    let n = encode_response(&response, &mut buf).unwrap();
    assert_eq!(&buf[..n], &resp[..], "{id}: response");
    assert_eq!(decode_response(&request, &resp).unwrap(), response, "{id}");
}

/// The drive refuses `req` with `code`, answering `resp`.
fn refused(id: &str, req: &str, code: EndCode, resp: &str) {
    let e = decode_request(&hex(req)).unwrap_err();
    let answer = e.answer().unwrap_or_else(|| panic!("{id}: {e}"));
    assert!(
        matches!(answer.reply, Reply::Error { code: c, .. } if c == code),
        "{id}: {e}"
    );
    let mut buf = [0u8; MAX_FRAME];
    let n = encode_response(&answer, &mut buf).unwrap();
    assert_eq!(&buf[..n], &hex(resp)[..], "{id}");
}

#[test]
fn object_access_vectors() {
    vector(
        "SL-1",
        e3(Command::Upload {
            index: 0x6041,
            sub: 0,
        }),
        "50 00 00 FF FF 03 00 0C 00 00 00 20 40 01 00 41 60 00 00 00 00",
        Reply::Upload {
            index: 0x6041,
            sub: 0,
            data: &[0x37, 0x04],
        },
        "D0 00 00 FF FF 03 00 0A 00 00 00 41 60 00 00 02 00 37 04",
    );
    vector(
        "SL-2",
        e3(Command::Download {
            index: 0x6040,
            sub: 0,
            data: &[0x0F, 0x00],
        }),
        "50 00 00 FF FF 03 00 0E 00 00 00 20 40 02 00 40 60 00 00 02 00 0F 00",
        Reply::Download {
            index: 0x6040,
            sub: 0,
            count: 2,
        },
        "D0 00 00 FF FF 03 00 08 00 00 00 40 60 00 00 02 00",
    );
    vector(
        "SL-3",
        Request {
            subheader: Subheader::E4 {
                serial: [0x34, 0x12],
            },
            route: Route::default(),
            monitoring_timer: 0x0010,
            command: Command::Upload {
                index: 0x6064,
                sub: 0,
            },
        },
        "54 00 34 12 00 00 00 FF FF 03 00 0C 00 10 00 20 40 01 00 64 60 00 00 00 00",
        Reply::Upload {
            index: 0x6064,
            sub: 0,
            data: &100_000u32.to_le_bytes(),
        },
        "D4 00 34 12 00 00 00 FF FF 03 00 0C 00 00 00 64 60 00 00 04 00 A0 86 01 00",
    );
    for (id, index, value, req, resp) in [
        (
            "SL-7",
            0x1010,
            *b"save",
            "50 00 00 FF FF 03 00 10 00 00 00 20 40 02 00 10 10 01 00 04 00 73 61 76 65",
            "D0 00 00 FF FF 03 00 08 00 00 00 10 10 01 00 04 00",
        ),
        (
            "SL-8",
            0x1011,
            *b"load",
            "50 00 00 FF FF 03 00 10 00 00 00 20 40 02 00 11 10 01 00 04 00 6C 6F 61 64",
            "D0 00 00 FF FF 03 00 08 00 00 00 11 10 01 00 04 00",
        ),
    ] {
        vector(
            id,
            e3(Command::Download {
                index,
                sub: 1,
                data: &value,
            }),
            req,
            Reply::Download {
                index,
                sub: 1,
                count: 4,
            },
            resp,
        );
    }
    vector(
        "SL-9",
        e3(Command::Download {
            index: 0x1A00,
            sub: 0,
            data: &[0],
        }),
        "50 00 00 FF FF 03 00 0D 00 00 00 20 40 02 00 00 1A 00 00 01 00 00",
        Reply::Download {
            index: 0x1A00,
            sub: 0,
            count: 1,
        },
        "D0 00 00 FF FF 03 00 08 00 00 00 00 1A 00 00 01 00",
    );
    let map_statusword = 0x6041_0010u32.to_le_bytes();
    vector(
        "SL-10",
        e3(Command::Download {
            index: 0x1A00,
            sub: 1,
            data: &map_statusword,
        }),
        "50 00 00 FF FF 03 00 10 00 00 00 20 40 02 00 00 1A 01 00 04 00 10 00 41 60",
        Reply::Download {
            index: 0x1A00,
            sub: 1,
            count: 4,
        },
        "D0 00 00 FF FF 03 00 08 00 00 00 00 1A 01 00 04 00",
    );
}

#[test]
fn abnormal_responses() {
    // SL-6: an unknown sub command is refused by the codec itself.
    refused(
        "SL-6",
        "50 00 00 FF FF 03 00 0C 00 00 00 20 40 03 00 41 60 00 00 00 00",
        EndCode::CommandUnknown,
        "D0 00 00 FF FF 03 00 0B 00 59 C0 00 FF FF 03 00 20 40 03 00",
    );
    // SL-4, SL-5, SL-11: refusals of the object dictionary, in the same error format.
    for (id, command, code, resp) in [
        (
            "SL-4",
            (0x4020u16, 1u16),
            EndCode::NoIndex,
            "D0 00 00 FF FF 03 00 0B 00 CA CC 00 FF FF 03 00 20 40 01 00",
        ),
        (
            "SL-5",
            (0x4020, 2),
            EndCode::ReadOnly,
            "D0 00 00 FF FF 03 00 0B 00 C9 CC 00 FF FF 03 00 20 40 02 00",
        ),
        (
            "SL-11",
            (0x4020, 2),
            EndCode::MappedObject,
            "D0 00 00 FF FF 03 00 0B 00 C7 CC 00 FF FF 03 00 20 40 02 00",
        ),
    ] {
        let e = SlmpError::Refused {
            code,
            subheader: Subheader::E3,
            route: Route::default(),
            command: command.0,
            sub: command.1,
        };
        let mut buf = [0u8; MAX_FRAME];
        let n = encode_response(&e.answer().unwrap(), &mut buf).unwrap();
        assert_eq!(&buf[..n], &hex(resp)[..], "{id}");
        // The client reads the end code; the error information is not relied on.
        let request = e3(Command::Upload {
            index: 0x5FFF,
            sub: 0,
        });
        match decode_response(&request, &hex(resp)).unwrap().reply {
            Reply::Error { code: c, .. } => assert_eq!(c, code, "{id}"),
            other => panic!("{id}: {other:?}"),
        }
    }
    // A request data length that does not match the frame: C061h.
    refused(
        "length",
        "50 00 00 FF FF 03 00 0D 00 00 00 20 40 01 00 41 60 00 00 00 00",
        EndCode::LengthMismatch,
        "D0 00 00 FF FF 03 00 0B 00 61 C0 00 FF FF 03 00 20 40 01 00",
    );
    // ASCII frames and garbage are not answered.
    let e = decode_request(b"500000FF03FF00").unwrap_err();
    assert!(matches!(e, SlmpError::Subheader(_)), "{e}");
    assert!(e.answer().is_none());
}

#[test]
fn the_client_checks_that_the_response_answers_its_request() {
    let request = Request {
        subheader: Subheader::E4 {
            serial: [0x34, 0x12],
        },
        route: Route::default(),
        monitoring_timer: 0,
        command: Command::Upload {
            index: 0x6064,
            sub: 0,
        },
    };
    // Another serial number, another index, a wrong length.
    for resp in [
        "D4 00 35 12 00 00 00 FF FF 03 00 0C 00 00 00 64 60 00 00 04 00 A0 86 01 00",
        "D4 00 34 12 00 00 00 FF FF 03 00 0C 00 00 00 65 60 00 00 04 00 A0 86 01 00",
        "D4 00 34 12 00 00 00 FF FF 03 00 0D 00 00 00 64 60 00 00 04 00 A0 86 01 00",
    ] {
        assert!(
            matches!(
                decode_response(&request, &hex(resp)),
                Err(SlmpError::Mismatch { .. })
            ),
            "{resp}"
        );
    }
    // An unknown end code is an error, not a guess.
    let e = decode_response(
        &request,
        &hex("D4 00 34 12 00 00 00 FF FF 03 00 0B 00 34 12 00 FF FF 03 00 20 40 01 00"),
    )
    .unwrap_err();
    assert_eq!(e, SlmpError::UnknownEndCode(0x1234));
}

#[test]
fn model_code_read_0101h() {
    let request = e3(Command::ModelRead);
    let mut buf = [0u8; MAX_FRAME];
    let n = encode_request(&request, &mut buf).unwrap();
    assert_eq!(
        &buf[..n],
        &hex("50 00 00 FF FF 03 00 06 00 00 00 01 01 00 00")[..]
    );
    assert_eq!(decode_request(&buf[..n]).unwrap(), request);
    // The response format is not in the manual: 16 ASCII characters and a 2-byte code.
    let response = Response {
        subheader: Subheader::E3,
        route: Route::default(),
        reply: Reply::Model {
            name: *b"MR-JE-10C       ",
            code: 0x0123,
        },
    };
    let n = encode_response(&response, &mut buf).unwrap();
    assert_eq!(n, 9 + 2 + 18, "3E header, length, end code, name and code");
    assert_eq!(decode_response(&request, &buf[..n]).unwrap(), response);
}

mod properties {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn decoders_refuse_garbage_without_panicking(
            bytes in proptest::collection::vec(any::<u8>(), 0..64),
            e4 in any::<bool>(),
        ) {
            let mut frame = if e4 { vec![0x54, 0x00] } else { vec![0x50, 0x00] };
            frame.extend_from_slice(&bytes);
            let _ = decode_request(&frame);
            let _ = decode_request(&bytes);
            frame[0] = if e4 { 0xD4 } else { 0xD0 };
            let request = e3(Command::Upload { index: 0x6041, sub: 0 });
            let _ = decode_response(&request, &frame);
            let _ = decode_response(&request, &bytes);
        }

        #[test]
        fn downloads_round_trip(
            index in any::<u16>(), sub in any::<u8>(), timer in any::<u16>(),
            data in proptest::collection::vec(any::<u8>(), 1..64),
            serial in any::<[u8; 2]>(), network in any::<u8>(), station in any::<u8>(),
            block in any::<bool>(),
        ) {
            let command = if block {
                Command::BlockDownload { index, sub, data: &data }
            } else {
                Command::Download { index, sub, data: &data }
            };
            let request = Request {
                subheader: Subheader::E4 { serial },
                route: Route { network, station },
                monitoring_timer: timer,
                command,
            };
            let mut buf = [0u8; MAX_FRAME];
            let n = encode_request(&request, &mut buf).unwrap();
            prop_assert_eq!(decode_request(&buf[..n]).unwrap(), request);
        }
    }
}
