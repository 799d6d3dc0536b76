//! MR-JE-C test vectors (docs/test-vectors.md) byte for byte against the simulated drive:
//! Modbus/TCP MT-*, Modbus RTU MR-*, SLMP SL-*; plus the RTU station rules (station 0 never
//! answers, PN08 selects the interface).

use std::time::Duration;

use cellrt_emulator::mr_je_c::{modbus, rtu, slmp, MrJeC, MrJeCParams};
use cellrt_fieldbus::modbus::tcp;
use cellrt_fieldbus::mr_je_c::{ObjectId, Value};

fn hex(s: &str) -> Vec<u8> {
    s.split_whitespace()
        .map(|b| u8::from_str_radix(b, 16).unwrap())
        .collect()
}

const T: Duration = Duration::ZERO;

fn enabled() -> MrJeC {
    let mut d = MrJeC::new(MrJeCParams::default());
    for w in [6u16, 7, 0xF] {
        d.write(ObjectId::new(0x6040, 0), &Value::U16(w), T)
            .unwrap();
    }
    d
}

fn mt(d: &mut MrJeC, req: &str) -> Option<Vec<u8>> {
    let bytes = hex(req);
    let (adu, used) = tcp::split(&bytes).unwrap().unwrap();
    assert_eq!(used, bytes.len(), "{req}");
    modbus::answer_adu(d, &adu, T)
}

#[test]
fn modbus_tcp_vectors() {
    let mut d = enabled();
    let cases = [
        (
            "MT-2",
            "00 09 00 00 00 06 FF 08 00 00 12 34",
            "00 09 00 00 00 06 FF 08 00 00 12 34",
        ),
        (
            "MT-3c",
            "00 0A 00 00 00 0B FF 10 21 02 00 02 04 01 00 00 00",
            "00 0A 00 00 00 06 FF 10 21 02 00 02",
        ),
        (
            "MT-4",
            "00 0B 00 00 00 06 FF 03 5F FF 00 01",
            "00 0B 00 00 00 03 FF 83 02",
        ),
        (
            "MT-5",
            "00 0C 00 00 00 06 FF 01 00 00 00 01",
            "00 0C 00 00 00 03 FF 81 01",
        ),
        (
            "MT-8",
            "00 01 00 00 00 06 FF 03 60 41 00 01",
            "00 01 00 00 00 05 FF 03 02 04 37",
        ),
        (
            "MT-11",
            "00 04 00 00 00 0B FF 10 60 7A 00 02 04 86 A0 00 01",
            "00 04 00 00 00 06 FF 10 60 7A 00 02",
        ),
        (
            "MT-12",
            "00 05 00 00 00 09 FF 10 60 40 00 01 02 00 0F",
            "00 05 00 00 00 06 FF 10 60 40 00 01",
        ),
        (
            "MT-13",
            "00 06 00 00 00 09 FF 10 2A 46 00 01 02 1E A5",
            "00 06 00 00 00 06 FF 10 2A 46 00 01",
        ),
    ];
    for (id, req, resp) in cases {
        assert_eq!(mt(&mut d, req), Some(hex(resp)), "{id}");
    }
    // MT-3c wrote PC02 low word first; MT-11 wrote 607Ah.
    assert_eq!(d.read(ObjectId::new(0x2102, 0)).unwrap(), Value::U32(0x100));
    assert_eq!(
        d.read(ObjectId::new(0x607A, 0)).unwrap(),
        Value::I32(100_000)
    );
    // MT-6, MT-7: protocol identifier ≠ 0 or unit identifier ≠ FFh: no response.
    assert_eq!(mt(&mut d, "00 07 00 01 00 06 FF 03 60 41 00 01"), None);
    assert_eq!(mt(&mut d, "00 08 00 00 00 06 01 03 60 41 00 01"), None);
    // MT-9: 6061h = −101 reads 009Bh.
    d.write(ObjectId::new(0x6060, 0), &Value::I8(-101), T)
        .unwrap();
    assert_eq!(
        mt(&mut d, "00 02 00 00 00 06 FF 03 60 61 00 01"),
        Some(hex("00 02 00 00 00 05 FF 03 02 00 9B"))
    );
    // MT-14: the whole 1010h record, sub 1 = "save" (sub 0 and subs 2–5 carried).
    let save = "00 07 00 00 00 1D FF 10 10 10 00 0B 16 00 05 61 73 65 76 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00";
    assert_eq!(
        mt(&mut d, save),
        Some(hex("00 07 00 00 00 06 FF 10 10 10 00 0B"))
    );
    // MT-15: 1018h whole, sub 0 = 4 and Vendor ID 2 low word first.
    let id = mt(&mut d, "00 08 00 00 00 06 FF 03 10 18 00 09").unwrap();
    assert_eq!(
        &id[..15],
        &hex("00 08 00 00 00 15 FF 03 12 00 04 00 02 00 00")[..]
    );
}

#[test]
fn modbus_register_layout_rules() {
    let mut d = enabled();
    // 6041h cannot be chained ("continuous" impossible), nor read by half.
    assert_eq!(
        mt(&mut d, "00 01 00 00 00 06 FF 03 60 41 00 02"),
        Some(hex("00 01 00 00 00 03 FF 83 02"))
    );
    assert_eq!(
        mt(&mut d, "00 01 00 00 00 06 FF 03 60 64 00 01"),
        Some(hex("00 01 00 00 00 03 FF 83 02"))
    );
    // MT-1's layout: 2B05h (2 words) + 2B06h + 2B07h, continuous monitors.
    let r = mt(&mut d, "00 01 00 00 00 06 FF 03 2B 05 00 04").unwrap();
    assert_eq!(&r[..9], &hex("00 01 00 00 00 0B FF 03 08")[..]);
    // Write to a read-only register: 02h; out of range: 03h.
    assert_eq!(
        mt(&mut d, "00 02 00 00 00 09 FF 10 60 41 00 01 02 00 00"),
        Some(hex("00 02 00 00 00 03 FF 90 02"))
    );
    assert_eq!(
        mt(&mut d, "00 03 00 00 00 09 FF 10 60 98 00 01 02 00 28"),
        Some(hex("00 03 00 00 00 03 FF 90 03"))
    );
}

#[test]
fn modbus_rtu_vectors_and_station_rules() {
    let mut d = enabled();
    let mr6 = hex("01 03 60 41 00 01 CA 1E");
    // Ethernet is selected ([Pr. PN08] 0000h): RTU is silent.
    assert_eq!(rtu::answer(&mut d, &mr6, T), None);
    d.write(ObjectId::new(0x2588, 0), &Value::U32(0x1000), T)
        .unwrap();
    // Station 0 ([Pr. PC70] initial) never answers.
    assert_eq!(rtu::answer(&mut d, &mr6, T), None);
    d.write(ObjectId::new(0x2146, 0), &Value::U32(1), T)
        .unwrap();
    // MR-6.
    assert_eq!(
        rtu::answer(&mut d, &mr6, T),
        Some(hex("01 03 02 04 37 FB 52"))
    );
    // MR-7 (Controlword 0006h), MR-9 (607Ah = 100000), MR-13 (reset alarm).
    for (id, req, resp) in [
        (
            "MR-7",
            "01 10 60 40 00 01 02 00 06 48 94",
            "01 10 60 40 00 01 1E 1D",
        ),
        (
            "MR-9",
            "01 10 60 7A 00 02 04 86 A0 00 01 34 5C",
            "01 10 60 7A 00 02 7E 11",
        ),
        (
            "MR-13",
            "01 10 2A 46 00 01 02 1E A5 EA EF",
            "01 10 2A 46 00 01 E8 04",
        ),
    ] {
        assert_eq!(rtu::answer(&mut d, &hex(req), T), Some(hex(resp)), "{id}");
    }
    // MR-11: 6061h = −101.
    d.write(ObjectId::new(0x6060, 0), &Value::I8(-101), T)
        .unwrap();
    assert_eq!(
        rtu::answer(&mut d, &hex("01 03 60 61 00 01 CB D4"), T),
        Some(hex("01 03 02 00 9B F9 EF"))
    );
    // Another station's query, and a bad CRC: silence.
    assert_eq!(
        rtu::answer(&mut d, &hex("02 03 2B 05 00 04 5D DF"), T),
        None
    );
    assert_eq!(
        rtu::answer(&mut d, &hex("01 03 60 41 00 01 CA 1F"), T),
        None
    );
    // MR-10: broadcast 2D9Bh = 1: executed, not answered.
    assert_eq!(
        rtu::answer(&mut d, &hex("00 10 2D 9B 00 01 02 00 01 8B 29"), T),
        None
    );
}

#[test]
fn slmp_vectors() {
    let mut d = enabled();
    for (id, req, resp) in [
        (
            "SL-1",
            "50 00 00 FF FF 03 00 0C 00 00 00 20 40 01 00 41 60 00 00 00 00",
            "D0 00 00 FF FF 03 00 0A 00 00 00 41 60 00 00 02 00 37 04",
        ),
        (
            "SL-2",
            "50 00 00 FF FF 03 00 0E 00 00 00 20 40 02 00 40 60 00 00 02 00 0F 00",
            "D0 00 00 FF FF 03 00 08 00 00 00 40 60 00 00 02 00",
        ),
        (
            "SL-4",
            "50 00 00 FF FF 03 00 0C 00 00 00 20 40 01 00 FF 5F 00 00 00 00",
            "D0 00 00 FF FF 03 00 0B 00 CA CC 00 FF FF 03 00 20 40 01 00",
        ),
        (
            "SL-5",
            "50 00 00 FF FF 03 00 0E 00 00 00 20 40 02 00 41 60 00 00 02 00 00 00",
            "D0 00 00 FF FF 03 00 0B 00 C9 CC 00 FF FF 03 00 20 40 02 00",
        ),
        (
            "SL-6",
            "50 00 00 FF FF 03 00 0C 00 00 00 20 40 03 00 41 60 00 00 00 00",
            "D0 00 00 FF FF 03 00 0B 00 59 C0 00 FF FF 03 00 20 40 03 00",
        ),
        (
            "SL-7",
            "50 00 00 FF FF 03 00 10 00 00 00 20 40 02 00 10 10 01 00 04 00 73 61 76 65",
            "D0 00 00 FF FF 03 00 08 00 00 00 10 10 01 00 04 00",
        ),
        (
            "SL-8",
            "50 00 00 FF FF 03 00 10 00 00 00 20 40 02 00 11 10 01 00 04 00 6C 6F 61 64",
            "D0 00 00 FF FF 03 00 08 00 00 00 11 10 01 00 04 00",
        ),
        (
            "SL-9",
            "50 00 00 FF FF 03 00 0D 00 00 00 20 40 02 00 00 1A 00 00 01 00 00",
            "D0 00 00 FF FF 03 00 08 00 00 00 00 1A 00 00 01 00",
        ),
    ] {
        assert_eq!(
            slmp::answer_frame(&mut d, &hex(req), T),
            Some(hex(resp)),
            "{id}"
        );
    }
}

#[test]
fn slmp_block_access_and_model_read() {
    let mut d = enabled();
    // Block upload of 1018h from sub 1: Vendor ID 2, Product Code 1003h, revision, serial.
    let r = slmp::answer_frame(
        &mut d,
        &hex("50 00 00 FF FF 03 00 0C 00 00 00 20 40 05 00 18 10 01 00 00 00"),
        T,
    )
    .unwrap();
    assert_eq!(&r[15..17], &[16, 0]);
    assert_eq!(&r[17..25], &hex("02 00 00 00 03 10 00 00")[..]);
    // Block download of 607Dh:1–2 (min, max).
    let r = slmp::answer_frame(&mut d, &hex("50 00 00 FF FF 03 00 14 00 00 00 20 40 06 00 7D 60 01 00 08 00 9C FF FF FF 64 00 00 00"), T).unwrap();
    assert_eq!(&r[9..11], &[0, 0]);
    assert_eq!(d.read(ObjectId::new(0x607D, 1)).unwrap(), Value::I32(-100));
    assert_eq!(d.read(ObjectId::new(0x607D, 2)).unwrap(), Value::I32(100));
    // One byte past the last sub-index: CCD1h.
    let r = slmp::answer_frame(&mut d, &hex("50 00 00 FF FF 03 00 15 00 00 00 20 40 06 00 7D 60 01 00 09 00 00 00 00 00 00 00 00 00 00"), T).unwrap();
    assert_eq!(&r[9..11], &[0xD1, 0xCC]);
    // 0101h: the model name, space padded to 16 characters.
    let r = slmp::answer_frame(
        &mut d,
        &hex("50 00 00 FF FF 03 00 06 00 00 00 01 01 00 00"),
        T,
    )
    .unwrap();
    assert_eq!(&r[11..27], b"MR-JE-20C       ");
}

mod never_panics {
    use super::*;
    use cellrt_fieldbus::modbus::{Query, WordOrder};
    use cellrt_fieldbus::slmp::{Command, Request, Route, Subheader};
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn any_bytes_on_any_transport(bytes in proptest::collection::vec(any::<u8>(), 0..600)) {
            let mut d = enabled();
            let _ = slmp::answer_frame(&mut d, &bytes, T);
            let _ = rtu::answer(&mut d, &bytes, T);
            if let Ok(Some((adu, _))) = tcp::split(&bytes) {
                let _ = modbus::answer_adu(&mut d, &adu, T);
            }
        }

        #[test]
        fn any_register_range(address in any::<u16>(), registers in 1u16..=122, fill in any::<u8>()) {
            let mut d = enabled();
            let mut out = Vec::new();
            let read = Query::Read { address, registers };
            let _ = modbus::answer(&mut d, &read, WordOrder::LowFirst, T, &mut out);
            let data = vec![fill; 2 * usize::from(registers)];
            let write = Query::Write { address, data: &data };
            let _ = modbus::answer(&mut d, &write, WordOrder::LowFirst, T, &mut out);
        }

        #[test]
        fn any_slmp_object_access(
            index in any::<u16>(),
            sub in any::<u8>(),
            data in proptest::collection::vec(any::<u8>(), 0..80),
        ) {
            let mut d = enabled();
            let mut out = Vec::new();
            for command in [
                Command::Upload { index, sub },
                Command::BlockUpload { index, sub },
                Command::Download { index, sub, data: &data },
                Command::BlockDownload { index, sub, data: &data },
            ] {
                let r = Request {
                    subheader: Subheader::E3,
                    route: Route::default(),
                    monitoring_timer: 0,
                    command,
                };
                let _ = slmp::answer(&mut d, &r, T, &mut out);
            }
        }
    }
}

/// The Modbus diagnostic objects (MR-JE-C manual §7.5.1–§7.5.4): OV-12, 2A64h after reading
/// 2C12h has 2C12h in its upper word (the lower, 0004h, is the record's last element); a read
/// of 2B0Dh–2B10h, where 2B10h does not exist, succeeds for the first three objects (2A65h =
/// 3, 2A60h = 0602 0000h, OV-13's rule); a refused read leaves 2A65h = 0 and its abort code;
/// a good one clears 2A60h.
#[test]
fn modbus_accesses_leave_their_trace_in_2a60h_to_2a65h() {
    use cellrt_fieldbus::modbus::{Query, Reply, WordOrder};
    let mut d = enabled();
    let read = |d: &mut MrJeC, address: u16, registers: u16| {
        let mut out = Vec::new();
        let q = Query::Read { address, registers };
        !matches!(
            modbus::answer(d, &q, WordOrder::LowFirst, T, &mut out),
            Reply::Exception { .. }
        )
    };
    let int = |d: &MrJeC, index: u16| d.read(ObjectId::new(index, 0)).unwrap().as_i64().unwrap();
    // OV-12: 2C12h is 0 + 4 × U32 = 9 registers.
    assert!(read(&mut d, 0x2C12, 9));
    assert_eq!(int(&d, 0x2A64) as u32 >> 16, 0x2C12);
    assert_eq!(int(&d, 0x2A64) as u32, 0x2C12_0004);
    assert_eq!((int(&d, 0x2A60), int(&d, 0x2A65)), (0, 1));
    // 2B0Dh (2 registers), 2B0Eh, 2B0Fh, then 2B10h is missing: partial success.
    assert!(read(&mut d, 0x2B0D, 5));
    assert_eq!(int(&d, 0x2A65), 3);
    assert_eq!(int(&d, 0x2A60), 0x0602_0000);
    assert_eq!(int(&d, 0x2A64) as u32 >> 16, 0x2B0F);
    // Refused as a whole: the abort code, nothing accessed, the last success kept.
    assert!(!read(&mut d, 0x5FFF, 1));
    assert_eq!((int(&d, 0x2A60), int(&d, 0x2A65)), (0x0602_0000, 0));
    assert_eq!(int(&d, 0x2A64) as u32 >> 16, 0x2B0F);
    assert!(read(&mut d, 0x6041, 1));
    assert_eq!((int(&d, 0x2A60), int(&d, 0x2A65)), (0, 1));
}

/// 2A68h counts RS-485 frames with a CRC or length error, on every drive of the line, and is
/// cleared by 1EA5h only.
#[test]
fn rtu_frame_errors_count_in_2a68h() {
    let mut d = enabled();
    d.write(ObjectId::new(0x2588, 0), &Value::U32(0x1000), T)
        .unwrap();
    d.write(ObjectId::new(0x2146, 0), &Value::U32(1), T)
        .unwrap();
    let count = |d: &MrJeC| d.read(ObjectId::new(0x2A68, 0)).unwrap().as_i64().unwrap();
    // MR-6 with its CRC's last byte wrong, and a 3-byte frame: no answer, two counts.
    assert_eq!(
        rtu::answer(&mut d, &hex("01 03 60 41 00 01 CA 1F"), T),
        None
    );
    assert_eq!(rtu::answer(&mut d, &hex("01 03 60"), T), None);
    assert_eq!(count(&d), 2);
    // A good frame to another station is not an error.
    assert_eq!(
        rtu::answer(&mut d, &hex("02 03 2B 05 00 04 5D DF"), T),
        None
    );
    assert_eq!(count(&d), 2);
    assert!(d
        .write(ObjectId::new(0x2A68, 0), &Value::U16(5), T)
        .is_err());
    d.write(ObjectId::new(0x2A68, 0), &Value::U16(0x1EA5), T)
        .unwrap();
    assert_eq!(count(&d), 0);
}
