//! The simulated MR-JE-C's EEPROM (MR-JE-C manual §7.2, §7.4.4, §7.4.5, front matter "EEPROM
//! life") and Status DO 1 (2D11h, §7.5.9): Store parameters 1010h takes its time with bit 0 and
//! S_ERF off while it runs, an unsaved change is lost at power-on and a saved one survives, the
//! EEPROM writes are counted. Through the object access the transports use (`MrJeC::read` /
//! `write`, SLMP frames, Modbus/TCP ADUs), judged on the emulator's clock.

use std::time::Duration;

use cellrt_emulator::mr_je_c::{
    modbus, slmp, EepromWrites, MrJeC, MrJeCParams, Refusal, SaveTime, WriteDuringSave,
};
use cellrt_fieldbus::modbus::tcp;
use cellrt_fieldbus::mr_je_c::{ObjectId, SoftwareVersion, Value};

/// "save" (§7.4.4).
const SAVE: Value = Value::U32(0x6576_6173);
/// [Pr. PC01] STA, linked to 6083h (§7.3).
const PC01: ObjectId = ObjectId::new(0x2101, 0);
/// Point table 001, point data (2801h:1).
const POINT_DATA_1: ObjectId = ObjectId::new(0x2801, 1);

fn id(index: u16, sub: u8) -> ObjectId {
    ObjectId::new(index, sub)
}

fn ms(v: u64) -> Duration {
    Duration::from_millis(v)
}

fn s(v: u64) -> Duration {
    Duration::from_secs(v)
}

fn drive() -> MrJeC {
    MrJeC::new(MrJeCParams::default())
}

fn u32_of(d: &MrJeC, at: ObjectId) -> u32 {
    match d.read(at).unwrap() {
        Value::U32(v) => v,
        other => panic!("{at}: {other:?}"),
    }
}

/// 2D11h Status DO 1.
fn status_do1(d: &MrJeC) -> u16 {
    match d.read(id(0x2D11, 0)).unwrap() {
        Value::U16(v) => v,
        other => panic!("{other:?}"),
    }
}

/// 2D11h bit 1, S_ERF (§7.5.9).
fn s_erf(d: &MrJeC) -> bool {
    status_do1(d) & 0x0002 != 0
}

/// 1010h subs 1, 4, 5 read back (bit 0: 1 can save, 0 saving).
fn store_status(d: &MrJeC) -> [u32; 3] {
    [1, 4, 5].map(|sub| u32_of(d, id(0x1010, sub)))
}

#[test]
fn a_save_clears_bit_0_and_s_erf_for_its_save_time() {
    let mut d = drive();
    // Not writing: bit 0 = 1 (bit 1 = 0, "not saved automatically"), S_ERF on.
    assert_eq!(store_status(&d), [1, 1, 1]);
    assert!(s_erf(&d));
    d.tick(s(1));
    d.write(id(0x1010, 1), &SAVE, s(1)).unwrap();
    assert_eq!(store_status(&d), [0, 0, 0]);
    assert!(!s_erf(&d));
    assert!(d.saving());
    // Sub 1 saves parameters and point tables: 2 s + 8 s = 10 s, the manual's maximum.
    d.tick(s(11) - ms(1));
    assert_eq!(store_status(&d), [0, 0, 0]);
    assert!(!s_erf(&d));
    d.tick(s(11));
    assert_eq!(store_status(&d), [1, 1, 1]);
    assert!(s_erf(&d));
    // Sub 4 (parameters) takes 2 s, sub 5 (point tables) 8 s.
    for (sub, time) in [(4, s(2)), (5, s(8))] {
        let start = s(100 * u64::from(sub));
        d.write(id(0x1010, sub), &SAVE, start).unwrap();
        d.tick(start + time - ms(1));
        assert!(!s_erf(&d), "sub {sub}");
        d.tick(start + time);
        assert!(s_erf(&d), "sub {sub}");
    }
}

#[test]
fn the_save_time_is_a_parameter_of_the_drive() {
    let mut d = MrJeC::new(MrJeCParams {
        eeprom_save_time: SaveTime {
            parameters: ms(300),
            point_tables: ms(700),
        },
        ..Default::default()
    });
    d.write(id(0x1010, 1), &SAVE, ms(0)).unwrap();
    d.tick(ms(999));
    assert!(!s_erf(&d));
    d.tick(ms(1000));
    assert!(s_erf(&d));
}

#[test]
fn an_endless_save_time_does_not_overflow() {
    let mut d = MrJeC::new(MrJeCParams {
        eeprom_save_time: SaveTime {
            parameters: Duration::MAX,
            point_tables: Duration::MAX,
        },
        ..Default::default()
    });
    d.tick(s(5));
    d.write(id(0x1010, 1), &SAVE, s(5)).unwrap();
    d.tick(s(1_000_000_000));
    assert!(!s_erf(&d));
    // It ends only where the clock does.
    d.tick(Duration::MAX);
    assert!(s_erf(&d));
}

#[test]
fn a_second_save_while_saving_is_refused_over_every_transport() {
    let mut d = drive();
    d.write(id(0x1010, 1), &SAVE, s(0)).unwrap();
    for sub in [1, 4, 5] {
        let r = d.write(id(0x1010, sub), &SAVE, s(1));
        assert_eq!(r, Err(Refusal::Saving), "sub {sub}");
    }
    assert_eq!(Refusal::Saving.end_code() as u16, 0xCCC9);
    assert_eq!(Refusal::Saving.abort_code(), 0x0800_0022);
    // SLMP SL-7 (save all) answered with CCC9h while the first save runs.
    let sl7 = hex("50 00 00 FF FF 03 00 10 00 00 00 20 40 02 00 10 10 01 00 04 00 73 61 76 65");
    let refused = "D0 00 00 FF FF 03 00 0B 00 C9 CC 00 FF FF 03 00 20 40 02 00";
    assert_eq!(slmp::answer_frame(&mut d, &sl7, s(2)), Some(hex(refused)));
    // Modbus/TCP MT-14 (the whole 1010h record, sub 1 = "save"): exception 02h.
    let mt14 = "00 07 00 00 00 1D FF 10 10 10 00 0B 16 00 05 61 73 65 76 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00";
    assert_eq!(
        mt(&mut d, mt14, s(3)),
        Some(hex("00 07 00 00 00 03 FF 90 02"))
    );
    // "0" is no action and stays accepted; after the save, "save" is taken again.
    d.write(id(0x1010, 1), &Value::U32(0), s(4)).unwrap();
    assert_eq!(
        slmp::answer_frame(&mut d, &sl7, s(10)),
        Some(hex("D0 00 00 FF FF 03 00 08 00 00 00 10 10 01 00 04 00"))
    );
    assert_eq!(
        mt(&mut d, mt14, s(20)),
        Some(hex("00 07 00 00 00 06 FF 10 10 10 00 0B"))
    );
    // Other values are an error (§7.4.4 table).
    assert_eq!(
        d.write(id(0x1010, 1), &Value::U32(1), s(30)),
        Err(Refusal::OutOfRange)
    );
}

#[test]
fn subs_2_and_3_take_save_and_store_nothing() {
    let mut d = drive();
    for sub in [2, 3] {
        d.write(id(0x1010, sub), &SAVE, s(0)).unwrap();
        assert_eq!(u32_of(&d, id(0x1010, sub)), 0, "sub {sub}");
        assert!(!d.saving() && s_erf(&d), "sub {sub}");
    }
    assert_eq!(d.eeprom_writes(), EepromWrites::default());
}

#[test]
fn an_unsaved_change_is_lost_at_power_on_and_a_saved_one_survives() {
    let mut d = drive();
    d.write(PC01, &Value::U32(500), s(0)).unwrap();
    d.write(POINT_DATA_1, &Value::I32(123_456), s(0)).unwrap();
    d.power_cycle();
    assert_eq!(d.read(PC01).unwrap(), Value::U32(0));
    assert_eq!(d.read(id(0x6083, 0)).unwrap(), Value::U32(0));
    assert_eq!(d.read(POINT_DATA_1).unwrap(), Value::I32(0));
    // Sub 4 saves the parameters only, sub 5 the point tables only.
    d.write(PC01, &Value::U32(500), s(0)).unwrap();
    d.write(POINT_DATA_1, &Value::I32(123_456), s(0)).unwrap();
    d.write(id(0x1010, 4), &SAVE, s(0)).unwrap();
    d.tick(s(2));
    d.power_cycle();
    assert_eq!(d.read(PC01).unwrap(), Value::U32(500));
    // The linked object is loaded with its parameter (§7.3 6083h ↔ [Pr. PC01]).
    assert_eq!(d.read(id(0x6083, 0)).unwrap(), Value::U32(500));
    assert_eq!(d.read(POINT_DATA_1).unwrap(), Value::I32(0));
    d.write(POINT_DATA_1, &Value::I32(123_456), s(10)).unwrap();
    d.write(id(0x1010, 5), &SAVE, s(10)).unwrap();
    d.tick(s(18));
    d.power_cycle();
    assert_eq!(d.read(POINT_DATA_1).unwrap(), Value::I32(123_456));
    // A linked object written and saved survives through its parameter.
    d.write(id(0x6098, 0), &Value::I8(-1), s(20)).unwrap();
    d.write(id(0x1010, 1), &SAVE, s(20)).unwrap();
    d.tick(s(30));
    d.power_cycle();
    assert_eq!(d.read(id(0x6098, 0)).unwrap(), Value::I8(-1));
    assert_eq!(d.read(id(0x24AD, 0)).unwrap(), Value::U32(0xFFFF_FFFF));
}

#[test]
fn a_power_cycle_during_a_save_keeps_what_the_eeprom_held() {
    let mut d = drive();
    d.write(PC01, &Value::U32(500), s(0)).unwrap();
    d.write(id(0x1010, 4), &SAVE, s(0)).unwrap();
    d.tick(s(2) - ms(1));
    d.power_cycle();
    assert_eq!(d.read(PC01).unwrap(), Value::U32(0));
    assert!(!d.saving() && s_erf(&d));
    // The EEPROM was being written: the write is counted.
    assert_eq!(d.eeprom_writes().parameters, 1);
}

#[test]
fn a_write_during_a_save_goes_to_the_ram_and_the_save_keeps_its_start_values() {
    let mut d = drive();
    d.write(PC01, &Value::U32(500), s(0)).unwrap();
    d.write(id(0x1010, 4), &SAVE, s(0)).unwrap();
    d.write(PC01, &Value::U32(700), s(1)).unwrap();
    d.write(id(0x6084, 0), &Value::U32(800), s(1)).unwrap();
    assert_eq!(d.read(PC01).unwrap(), Value::U32(700));
    d.tick(s(2));
    d.power_cycle();
    assert_eq!(d.read(PC01).unwrap(), Value::U32(500));
    assert_eq!(d.read(id(0x6084, 0)).unwrap(), Value::U32(0));
    // A parameter set by commissioning while a save runs stays set when the save ends.
    d.write(id(0x1010, 4), &SAVE, s(10)).unwrap();
    d.commission(id(0x2597, 0), &Value::U32(10), s(11)).unwrap();
    d.tick(s(12));
    d.power_cycle();
    assert_eq!(d.read(id(0x2597, 0)).unwrap(), Value::U32(10));
}

#[test]
fn writes_during_a_save_can_be_refused_instead() {
    let mut d = MrJeC::new(MrJeCParams {
        write_during_save: WriteDuringSave::Refuse,
        ..Default::default()
    });
    d.write(id(0x1010, 1), &SAVE, s(0)).unwrap();
    for (at, v) in [
        (PC01, Value::U32(1)),
        (id(0x6083, 0), Value::U32(1)),
        (id(0x6065, 0), Value::U32(1)),
        (POINT_DATA_1, Value::I32(1)),
    ] {
        assert_eq!(d.write(at, &v, s(1)), Err(Refusal::Saving), "{at}");
    }
    // Objects not kept in the EEPROM stay writable.
    d.write(id(0x6040, 0), &Value::U16(6), s(1)).unwrap();
    d.write(id(0x607A, 0), &Value::I32(5), s(1)).unwrap();
    d.tick(s(10));
    d.write(PC01, &Value::U32(1), s(10)).unwrap();
}

#[test]
fn eeprom_writes_are_counted_by_region() {
    let mut d = drive();
    assert_eq!(d.eeprom_writes(), EepromWrites::default());
    // Object writes change the RAM only (§7.4.4).
    d.write(PC01, &Value::U32(500), s(0)).unwrap();
    d.write(POINT_DATA_1, &Value::I32(1), s(0)).unwrap();
    assert_eq!(d.eeprom_writes(), EepromWrites::default());
    d.write(id(0x1010, 1), &SAVE, s(0)).unwrap();
    d.tick(s(10));
    d.write(id(0x1010, 4), &SAVE, s(10)).unwrap();
    d.tick(s(12));
    d.write(id(0x1010, 5), &SAVE, s(12)).unwrap();
    d.tick(s(20));
    let counted = EepromWrites {
        parameters: 2,
        point_tables: 2,
    };
    assert_eq!(d.eeprom_writes(), counted);
    // A parameter set by commissioning goes to the EEPROM at once and survives.
    d.commission(id(0x2597, 0), &Value::U32(10), s(20)).unwrap();
    assert_eq!(d.eeprom_writes().parameters, 3);
    d.power_cycle();
    assert_eq!(d.read(id(0x2597, 0)).unwrap(), Value::U32(10));
    assert_eq!(d.read(PC01).unwrap(), Value::U32(500));
    // 1011h:1 "load": the factory values are written at the next power-on.
    d.write(id(0x1011, 1), &Value::U32(0x6461_6F6C), s(20))
        .unwrap();
    d.power_cycle();
    let restored = EepromWrites {
        parameters: 4,
        point_tables: 3,
    };
    assert_eq!(d.eeprom_writes(), restored);
    assert_eq!(d.read(id(0x2597, 0)).unwrap(), Value::U32(3600));
    d.power_cycle();
    assert_eq!(
        d.eeprom_writes(),
        restored,
        "the count survives power cycles"
    );
    assert_eq!(d.read(PC01).unwrap(), Value::U32(0));
}

#[test]
fn a3_saves_the_parameters_only() {
    let mut d = MrJeC::new(MrJeCParams {
        software: SoftwareVersion::A3,
        ..Default::default()
    });
    assert_eq!(d.read(id(0x1010, 0)).unwrap(), Value::I8(1));
    d.write(PC01, &Value::U32(500), s(0)).unwrap();
    d.write(id(0x1010, 1), &SAVE, s(0)).unwrap();
    d.tick(s(2) - ms(1));
    assert!(!s_erf(&d));
    d.tick(s(2));
    assert!(s_erf(&d));
    assert_eq!(
        d.eeprom_writes(),
        EepromWrites {
            parameters: 1,
            point_tables: 0
        }
    );
    d.power_cycle();
    assert_eq!(d.read(PC01).unwrap(), Value::U32(500));
}

#[test]
fn status_do_1_gives_s_mbr_s_tl1_and_s_bwng() {
    let mut d = drive();
    // S_BWNG (bit 15) is on after power-on until 3 s (the manual: 2.5 s to 3.5 s), S_ERF
    // (bit 1) on; S_MBR (bit 3) off at servo-off.
    assert_eq!(status_do1(&d), 0x8002);
    d.tick(s(3) - ms(1));
    assert_eq!(status_do1(&d), 0x8002);
    d.tick(s(3));
    assert_eq!(status_do1(&d), 0x0002);
    for w in [6u16, 7, 0xF] {
        d.write(id(0x6040, 0), &Value::U16(w), s(3)).unwrap();
    }
    assert_eq!(status_do1(&d), 0x000A);
    // C_TL1 (2D01h bit 8) → S_TL1 (2D11h bit 8).
    d.write(id(0x2D01, 0), &Value::U16(0x0100), s(3)).unwrap();
    assert_eq!(status_do1(&d), 0x010A);
    d.write(id(0x2D01, 0), &Value::U16(0), s(3)).unwrap();
    // An alarm turns S_MBR off.
    d.raise(cellrt_fieldbus::mr_je_c::Alarm::MODBUS_RTU_TIMEOUT);
    assert_eq!(status_do1(&d), 0x0002);
    // After a power cycle S_BWNG is on again for 3 s of the emulator's clock.
    d.tick(s(60));
    d.power_cycle();
    assert_eq!(status_do1(&d), 0x8002);
    d.tick(s(63));
    assert_eq!(status_do1(&d), 0x0002);
}

fn hex(s: &str) -> Vec<u8> {
    s.split_whitespace()
        .map(|b| u8::from_str_radix(b, 16).unwrap())
        .collect()
}

fn mt(d: &mut MrJeC, req: &str, now: Duration) -> Option<Vec<u8>> {
    let bytes = hex(req);
    let (adu, used) = tcp::split(&bytes).unwrap().unwrap();
    assert_eq!(used, bytes.len(), "{req}");
    modbus::answer_adu(d, &adu, now)
}
