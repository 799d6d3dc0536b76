//! The MR-JE-C object dictionary table against literal rows of the MR-JE-C manual §7.3.

use cellrt_fieldbus::mr_je_c::{
    entry, object, Access, DataType, Initial, ObjectId, Range, SoftwareVersion, Unit, DICTIONARY,
};

const A4: SoftwareVersion = SoftwareVersion::A4;
const A3: SoftwareVersion = SoftwareVersion::A3;

fn row(index: u16, sub: u8) -> &'static cellrt_fieldbus::mr_je_c::Sub {
    entry(ObjectId::new(index, sub), A4)
        .unwrap_or_else(|| panic!("{index:04X}h:{sub} missing"))
        .1
}

#[test]
fn the_table_is_sorted_and_each_index_appears_once() {
    for w in DICTIONARY.windows(2) {
        assert!(
            w[0].last < w[1].first,
            "{:04X}h / {:04X}h",
            w[0].first,
            w[1].first
        );
    }
    for o in DICTIONARY {
        assert!(o.first <= o.last, "{:04X}h", o.first);
        for w in o.subs.windows(2) {
            assert!(w[0].last < w[1].first, "{:04X}h subs", o.first);
        }
    }
}

#[test]
fn controlword_and_statusword() {
    // 6040h: U16 rw, mappable, default 0000h; 6041h: U16 ro, mappable (§7.3).
    let cw = row(0x6040, 0);
    assert_eq!(
        (cw.ty, cw.access, cw.mappable),
        (DataType::U16, Access::Rw, true)
    );
    assert_eq!(cw.initial, Initial::Value(0));
    let sw = row(0x6041, 0);
    assert_eq!(
        (sw.ty, sw.access, sw.mappable),
        (DataType::U16, Access::Ro, true)
    );
    assert_eq!(object(0x6041, A4).unwrap().name, "Statusword");
    assert!(!object(0x6041, A4).unwrap().continuous);
    assert!(entry(ObjectId::new(0x6041, 1), A4).is_none());
}

#[test]
fn target_position_takes_the_descriptions_setting_range() {
    // 607Ah: I32 rw, pos units; "[Setting range] ... Other than degree unit: -999999 to 999999".
    let t = row(0x607A, 0);
    assert_eq!(
        (t.ty, t.access, t.unit),
        (DataType::I32, Access::Rw, Unit::PosUnits)
    );
    assert_eq!(t.range, Range::Spans(&[(-999_999, 999_999)]));
    assert_eq!(object(0x607A, A4).unwrap().registers(A4), 2);
}

#[test]
fn target_velocity_is_in_hundredths_of_r_per_min() {
    let t = row(0x60FF, 0);
    assert_eq!(
        (t.ty, t.access, t.unit),
        (DataType::I32, Access::Rw, Unit::CentiRpm)
    );
    assert_eq!(t.unit.to_string(), "0.01 r/min");
    assert_eq!(row(0x2B02, 0).unit.to_string(), "r/min");
}

#[test]
fn alarm_history_spans_2a00h_to_2a0fh() {
    for index in [0x2A00, 0x2A07, 0x2A0F] {
        let o = object(index, A4).unwrap();
        assert_eq!(o.first, 0x2A00);
        // 6 registers: sub 0 U8 + U32 + U32 + U16.
        assert_eq!(o.registers(A4), 6);
    }
    assert!(object(0x2A10, A4).is_none());
    assert_eq!(row(0x2A00, 0).initial, Initial::Value(3));
    let no = row(0x2A05, 1);
    assert_eq!(
        (no.ty, no.access, no.name),
        (DataType::U32, Access::Ro, "Alarm No.")
    );
    assert_eq!(row(0x2A0F, 2).unit, Unit::Hour);
    assert_eq!(row(0x2A0F, 3).ty, DataType::U16);
    // Clear (2A40h) and reset (2A46h) are write-only.
    assert_eq!(row(0x2A40, 0).access, Access::Wo);
    assert_eq!(row(0x2A46, 0).access, Access::Wo);
}

#[test]
fn parameter_objects() {
    // PN02 → 2582h, PC02 → 2102h: U32 rw, continuous access possible.
    for index in [0x2582, 0x2102, 0x2001, 0x25B0] {
        let o = object(index, A4).unwrap();
        assert!(o.continuous, "{index:04X}h");
        assert_eq!(o.registers(A4), 2);
        assert_eq!(row(index, 0).access, Access::Rw);
    }
    assert_eq!(object(0x2582, A4).unwrap().name, "PN01 to PN48");
    // Between the blocks: nothing (PA32 is 2020h, PB01 2081h).
    assert!(object(0x2021, A4).is_none());
    assert!(object(0x25B1, A4).is_none());
}

#[test]
fn records_count_their_registers_and_depend_on_the_software_version() {
    // "No. of points": 1010h 11, 1018h 9, 2801h 15, 2C12h 9, 607Bh 5, 60E3h 1 + entries.
    let regs = |index| object(index, A4).unwrap().registers(A4);
    assert_eq!(regs(0x1010), 11);
    assert_eq!(regs(0x1018), 9);
    assert_eq!(regs(0x2801), 15);
    assert_eq!(regs(0x2C12), 9);
    assert_eq!(regs(0x607B), 5);
    assert_eq!(regs(0x1008), 16);
    assert_eq!(regs(0x60E3), 41);
    assert_eq!(object(0x60E3, A3).unwrap().registers(A3), 40);
    assert_eq!(row(0x6502, 0).initial.value(A4), Some(0x000B_002D));
    assert_eq!(row(0x6502, 0).initial.value(A3), Some(0x0000_002D));
    // Point tables and 2D60h need A4.
    assert!(object(0x2801, A3).is_none());
    assert!(object(0x2D60, A3).is_none());
    assert!(entry(ObjectId::new(0x1010, 5), A3).is_none());
}

#[test]
fn fixed_and_automatic_objects() {
    assert_eq!(row(0x605A, 0).initial, Initial::Value(2));
    assert_eq!(row(0x605A, 0).range, Range::Fixed);
    assert_eq!(row(0x1000, 0).initial, Initial::Value(0x0002_0192));
    assert_eq!(row(0x6098, 0).initial, Initial::Value(37));
    assert_eq!(row(0x6098, 0).range, Range::Spans(&[(-43, 39)]));
    assert_eq!(row(0x607B, 1).range, Range::Automatic);
    assert_eq!(row(0x1A00, 1).initial, Initial::Value(0x6061_0008));
    assert_eq!(row(0x1A00, 32).ty, DataType::U32);
}

#[test]
fn object_ids_parse() {
    assert_eq!(
        "6041".parse::<ObjectId>().unwrap(),
        ObjectId::new(0x6041, 0)
    );
    assert_eq!(
        "1018h:2".parse::<ObjectId>().unwrap(),
        ObjectId::new(0x1018, 2)
    );
    assert_eq!(
        "0x607A".parse::<ObjectId>().unwrap(),
        ObjectId::new(0x607A, 0)
    );
    assert!("60411".parse::<ObjectId>().is_err());
    assert!("6041:x".parse::<ObjectId>().is_err());
    assert_eq!(ObjectId::new(0x1018, 2).to_string(), "1018h:2");
}

/// The dictionary speaks the drives' one vocabulary (`cellrt_cia402::profiles::facts`) but
/// uses only what §7.3 states: integers and strings, ro/rw/wo, nothing unstated.
#[test]
fn the_dictionary_states_every_type_and_access() {
    let core: DataType = cellrt_cia402::profiles::facts::DataType::U16;
    assert_eq!(core.registers(), 1);
    for o in DICTIONARY {
        for s in o.subs {
            assert!(
                !matches!(s.ty, DataType::Bool | DataType::Unstated),
                "{:04X}h:{} type {:?}",
                o.first,
                s.first,
                s.ty
            );
            assert_ne!(s.access, Access::Unstated, "{:04X}h:{}", o.first, s.first);
            assert!(s.ty.bytes() > 0 && s.ty.registers() * 2 >= s.ty.bytes());
        }
    }
}
