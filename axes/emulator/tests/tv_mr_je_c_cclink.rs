//! MR-JE-C CC-Link IE Field Network Basic frames (docs/test-vectors.md, mr-je-c.md §13.4): the
//! example request and response byte for byte through both ends of `axes::cclink_ief_basic`,
//! the slave's validation of a request (dropped frames), CSR/SSR at RY/RX bit 63, the
//! master-lost supervision time, and the example response from the simulated drive.

use cellrt_fieldbus::cclink_ief_basic::{
    bit, set_bit, CyclicError, CyclicRequest, CyclicResponse, EndCode, StationData, READY_BIT,
    RESPONSE_SIZE,
};

const REQUEST: &str = "
50 00 00 FF FF 03 00 86 00 00 00 70 0E 00 00 02
00 00 00 24 00 00 00 00 00 00 00 00 00 00 00 00
00 00 00 01 00 00 00 00 00 00 00 00 00 00 00 FA
03 A8 C0 01 00 01 00 32 00 03 00 01 00 01 00 01
00 00 00 01 03 A8 C0 01 00 0F 00 00 00 00 00 00
00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00
00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00
00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00
00 00 00 00 00 00 00 00 00 00 00 00 00 00 80";

const RESPONSE: &str = "
D0 00 00 FF FF 03 00 7A 00 00 00 02 00 00 00 28
00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00
00 00 00 00 00 00 00 00 00 00 00 01 00 00 00 00
00 00 00 01 03 A8 C0 01 00 01 00 01 00 37 04 00
00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00
00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00
00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00
00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00
00 00 80";

/// 192.168.3.250 and 192.168.3.1 as the frames carry them (little-endian u32 of the address).
const MASTER: u32 = 0xC0A8_03FA;
const DRIVE: u32 = 0xC0A8_0301;

fn hex(s: &str) -> Vec<u8> {
    s.split_whitespace()
        .map(|b| u8::from_str_radix(b, 16).unwrap())
        .collect()
}

fn request() -> CyclicRequest {
    let mut station = [StationData::default(); 16];
    station[0].slave_id = DRIVE;
    // RWwn00 = 0001h (6060h = pp), RWwn01 = 000Fh (Controlword), CSR on.
    station[0].words[0] = 0x01;
    station[0].words[2] = 0x0F;
    set_bit(&mut station[0].bits, READY_BIT, true);
    CyclicRequest {
        protocol_version: 2,
        unit_info: 1,
        clock_ms: 0,
        master_id: MASTER,
        group: 1,
        sequence: 1,
        timeout_ms: 50,
        parallel_off_count: 3,
        parameter_no: 1,
        transmission: 1,
        stations: 1,
        station,
    }
}

#[test]
fn the_example_request_byte_for_byte() {
    let want = hex(REQUEST);
    assert_eq!(want.len(), 143);
    let mut buf = [0u8; 1300];
    let n = request().encode(&mut buf).unwrap();
    assert_eq!(&buf[..n], &want[..]);
    let got = CyclicRequest::decode(&want, MASTER).unwrap();
    assert_eq!(got, request());
    assert_eq!(got.station_of(DRIVE), Some(1));
    assert!(got.transmitting(1) && !got.transmitting(2));
    assert!(bit(&got.station[0].bits, READY_BIT), "CSR = RY(n+3)F");
    assert_eq!(got.master_lost_after_ms(), 150);
}

#[test]
fn the_example_response_byte_for_byte() {
    let want = hex(RESPONSE);
    assert_eq!(want.len(), RESPONSE_SIZE);
    let mut station = StationData {
        slave_id: DRIVE,
        ..StationData::default()
    };
    // RWrn00 = 0001h (6061h = pp), RWrn01 = 0437h (Statusword), SSR on.
    station.words[0] = 0x01;
    station.words[2] = 0x37;
    station.words[3] = 0x04;
    set_bit(&mut station.bits, READY_BIT, true);
    let response = CyclicResponse {
        protocol_version: 2,
        end_code: EndCode::Normal,
        vendor_code: 0,
        model_code: 0,
        equipment_version: 0,
        unit_info: 1,
        error_code: 0,
        local_info: 0,
        group: 1,
        sequence: 1,
        station,
    };
    let mut buf = [0u8; RESPONSE_SIZE];
    let n = response.encode(&mut buf).unwrap();
    assert_eq!(&buf[..n], &want[..]);
    assert_eq!(CyclicResponse::decode(&want).unwrap(), response);
    // CB-6: the sequence number is echoed (0x1234 → bytes 57–58 `34 12`).
    let n = CyclicResponse {
        sequence: 0x1234,
        ..response
    }
    .encode(&mut buf)
    .unwrap();
    assert_eq!(&buf[57..59], &[0x34, 0x12]);
    assert_eq!(n, 131);
}

#[test]
fn a_slave_drops_what_a_conformant_slave_drops() {
    let good = hex(REQUEST);
    let drop = |bytes: &[u8], source: u32| CyclicRequest::decode(bytes, source).unwrap_err();
    // From another address than the master ID.
    assert!(matches!(drop(&good, DRIVE), CyclicError::Source { .. }));
    // One byte short or long, a wrong data length.
    assert!(matches!(
        drop(&good[..142], MASTER),
        CyclicError::Size { .. }
    ));
    let mut long = good.clone();
    long.push(0);
    assert!(matches!(drop(&long, MASTER), CyclicError::Size { .. }));
    for (at, value, what) in [
        (11, 0x71, "command"),
        (15, 3, "protocol version"),
        (19, 0x25, "cyclic info offset"),
        (35, 0x05, "master local unit info"),
        (51, 0, "group No."),
        (51, 65, "group No."),
        (61, 0, "station count"),
    ] {
        let mut bad = good.clone();
        bad[at] = value;
        assert!(CyclicRequest::decode(&bad, MASTER).is_err(), "{what}");
    }
    // A response with an unknown end code or the wrong size.
    let mut resp = hex(RESPONSE);
    resp[13] = 0x12;
    assert!(CyclicResponse::decode(&resp).is_err());
    assert!(CyclicResponse::decode(&resp[..130]).is_err());
}

#[test]
fn the_example_response_from_the_emulator() {
    use cellrt_emulator::mr_je_c::{cyclic::CyclicLink, MrJeC, MrJeCParams};
    use std::time::Duration;
    // The precondition: a request with the transmission bit off connects the master; then
    // Shutdown and Switch On, and the example request (Enable Operation) itself.
    let (mut drive, mut link) = (MrJeC::new(MrJeCParams::default()), CyclicLink::default());
    let mut send = |r: &CyclicRequest| link.answer(&mut drive, r, DRIVE, true, Duration::ZERO);
    send(&CyclicRequest {
        transmission: 0,
        ..request()
    })
    .unwrap();
    for cw in [6u8, 7] {
        let mut r = request();
        r.station[0].words[2] = cw;
        send(&r).unwrap();
    }
    let mut got = [0u8; RESPONSE_SIZE];
    send(&request()).unwrap().encode(&mut got).unwrap();
    // Not asserted (the extract): protocol version (11), vendor/model/equipment (31–40), RWr
    // beyond RWrn01 (63…122).
    for (at, (g, w)) in got.iter().zip(&hex(RESPONSE)).enumerate() {
        if at != 11 && !(31..=40).contains(&at) && !(63..123).contains(&at) {
            assert_eq!(g, w, "byte {at}");
        }
    }
}

mod properties {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn decoders_refuse_garbage_without_panicking(
            bytes in proptest::collection::vec(any::<u8>(), 0..1300),
            source in any::<u32>(),
        ) {
            let _ = CyclicRequest::decode(&bytes, source);
            let _ = CyclicResponse::decode(&bytes);
        }

        #[test]
        fn requests_of_every_station_count_round_trip(
            n in 1usize..=16, sequence in any::<u16>(), fill in any::<u8>(),
        ) {
            let mut r = request();
            r.stations = n;
            r.sequence = sequence;
            for (k, s) in r.station.iter_mut().enumerate().take(n) {
                s.slave_id = DRIVE + k as u32;
                s.words = [fill.wrapping_add(k as u8); 64];
                s.bits = [fill ^ k as u8; 8];
            }
            let mut buf = [0u8; 67 + 76 * 16];
            let len = r.encode(&mut buf).unwrap();
            prop_assert_eq!(len, 67 + 76 * n);
            let back = CyclicRequest::decode(&buf[..len], MASTER).unwrap();
            prop_assert_eq!(back.station_of(DRIVE + n as u32 - 1), Some(n));
            prop_assert_eq!(back, r);
        }
    }
}
