//! Objects linked to servo parameters (MR-JE-C manual §7.3, "Parameter" column): the pair reads
//! the same whichever was written, through the emulator's object access and over Modbus/TCP and
//! SLMP; a parameter takes only what its object can hold. The literal pairs and defaults are
//! the manual's.

use std::time::Duration;

use cellrt_emulator::mr_je_c::{modbus, slmp, MrJeC, MrJeCParams, Refusal};
use cellrt_fieldbus::modbus::tcp;
use cellrt_fieldbus::mr_je_c::links::{Linkage, LINKS};
use cellrt_fieldbus::mr_je_c::parameters::definition;
use cellrt_fieldbus::mr_je_c::{entry, ObjectId, SoftwareVersion, Value};

const T: Duration = Duration::ZERO;

fn id(index: u16, sub: u8) -> ObjectId {
    ObjectId::new(index, sub)
}

fn drive() -> MrJeC {
    MrJeC::new(MrJeCParams::default())
}

fn int(d: &MrJeC, at: ObjectId) -> i64 {
    d.read(at).unwrap().as_i64().unwrap()
}

/// Writes the number `v` to `at` in its dictionary type.
fn put(d: &mut MrJeC, at: ObjectId, v: i64) -> Result<(), Refusal> {
    let ty = entry(at, SoftwareVersion::A4).unwrap().1.ty;
    d.write(at, &Value::from_i64(ty, v).unwrap(), T)
}

/// One object, one parameter (object index, sub, parameter object index), with the object's
/// default (§7.3) and a value in its range to write.
const SAME: [(u16, u8, u16, i64, i64); 23] = [
    (0x2D20, 0, 0x24B4, 50_000, 30_000), // Velocity limit value ↔ PT52
    (0x2D6B, 0, 0x2123, 10_000, 2_500),  // Torque limit value 2 ↔ PC35
    (0x6066, 0, 0x214D, 10, 25),         // Following error time out ↔ PC77
    (0x6067, 0, 0x24C1, 100, 250),       // Position window ↔ PT65
    (0x6068, 0, 0x24C2, 10, 20),         // Position window time ↔ PT66
    (0x606D, 0, 0x24C3, 2_000, 3_000),   // Velocity window ↔ PT67
    (0x606E, 0, 0x24C4, 10, 30),         // Velocity window time ↔ PT68
    (0x606F, 0, 0x24BF, 5_000, 6_000),   // Velocity threshold ↔ PT63
    (0x6070, 0, 0x24C0, 10, 40),         // Velocity threshold time ↔ PT64
    (0x607F, 0, 0x24B3, 2_000_000, 1_000_000), // Max profile velocity ↔ PT51
    (0x6081, 0, 0x24B2, 10_000, 20_000), // Profile velocity ↔ PT50
    (0x6083, 0, 0x2101, 0, 150),         // Profile acceleration ↔ PC01
    (0x6084, 0, 0x2102, 0, 160),         // Profile deceleration ↔ PC02
    (0x6085, 0, 0x2133, 100, 170),       // Quick stop deceleration ↔ PC51
    (0x6087, 0, 0x24B1, 0, 1_000),       // Torque slope ↔ PT49
    (0x6091, 1, 0x2006, 1, 4),           // Gear ratio motor revolutions ↔ PA06
    (0x6091, 2, 0x2007, 1, 3),           // Gear ratio shaft revolutions ↔ PA07
    (0x6098, 0, 0x24AD, 37, -1),         // Homing method ↔ PT45
    (0x6099, 1, 0x2485, 10_000, 5_000),  // Speed during search for switch ↔ PT05
    (0x6099, 2, 0x2486, 1_000, 500),     // Speed during search for zero ↔ PT06
    (0x609A, 0, 0x24BD, 0, 200),         // Homing acceleration ↔ PT61
    (0x60E0, 0, 0x200B, 10_000, 3_000),  // Positive torque limit value ↔ PA11
    (0x60E1, 0, 0x200C, 10_000, 2_000),  // Negative torque limit value ↔ PA12
];

#[test]
fn one_parameter_links_start_alike_and_read_the_same_whichever_is_written() {
    for (index, sub, param, default, v) in SAME {
        let (object, param) = (id(index, sub), id(param, 0));
        let mut d = drive();
        assert_eq!(int(&d, object), default, "{object} default");
        assert_eq!(int(&d, param) as u32, default as u32, "{param} default");
        put(&mut d, object, v).unwrap();
        assert_eq!(int(&d, param) as u32, v as u32, "{object} → {param}");
        let mut d = drive();
        put(&mut d, param, i64::from(v as u32)).unwrap();
        assert_eq!(int(&d, object), v, "{param} → {object}");
    }
}

#[test]
fn the_manuals_parameter_initial_values_are_the_objects_defaults() {
    // §5.1 prints the PC parameters' initial values; §7.3 the objects' defaults.
    for (param, initial, object, default) in [
        (0x2101, 0, id(0x6083, 0), 0),               // PC01 STA
        (0x2102, 0, id(0x6084, 0), 0),               // PC02 STB
        (0x2123, 10_000, id(0x2D6B, 0), 10_000),     // PC35 TL2 "1000.0 %"
        (0x2133, 100, id(0x6085, 0), 100),           // PC51 RSBR
        (0x214B, 0x0000, id(0x6065, 0), 12_582_912), // PC75 FEWL (low word of 6065h)
        (0x214C, 0x00C0, id(0x6065, 0), 12_582_912), // PC76 FEWH (high word)
        (0x214D, 10, id(0x6066, 0), 10),             // PC77 FEWF
    ] {
        assert_eq!(definition(param).unwrap().initial, initial, "{param:04X}h");
        let d = drive();
        assert_eq!(int(&d, id(param, 0)), i64::from(initial), "{param:04X}h");
        assert_eq!(int(&d, object), default, "{object}");
    }
}

#[test]
fn split_links_hold_the_low_and_high_word() {
    let mut d = drive();
    // 6065h ↔ PC75 (bits 0–15), PC76 (bits 16–31).
    put(&mut d, id(0x6065, 0), 0x0001_2345).unwrap();
    assert_eq!(int(&d, id(0x214B, 0)), 0x2345);
    assert_eq!(int(&d, id(0x214C, 0)), 0x0001);
    put(&mut d, id(0x214C, 0), 0x00C0).unwrap();
    assert_eq!(int(&d, id(0x6065, 0)), 0x00C0_2345);
    // 607Dh:1 ↔ PT17/PT18, 607Dh:2 ↔ PT15/PT16; negative limits in two's complement.
    put(&mut d, id(0x607D, 1), -1000).unwrap();
    assert_eq!(int(&d, id(0x2491, 0)), 0xFC18);
    assert_eq!(int(&d, id(0x2492, 0)), 0xFFFF);
    put(&mut d, id(0x248F, 0), 0x86A0).unwrap();
    put(&mut d, id(0x2490, 0), 0x0001).unwrap();
    assert_eq!(int(&d, id(0x607D, 2)), 100_000);
    // A word holds 0000h–FFFFh.
    assert_eq!(
        put(&mut d, id(0x214B, 0), 0x1_0000),
        Err(Refusal::AboveRange)
    );
    assert_eq!(int(&d, id(0x6065, 0)), 0x00C0_2345);
}

#[test]
fn a_parameter_takes_only_what_its_object_can_hold() {
    let mut d = drive();
    // PT45 ↔ 6098h (−43 to 39), PC35 ↔ 2D6Bh (0 to 10000), PT65 ↔ 6067h (0–65534, FFFFFFFFh).
    for (param, v, refusal) in [
        (0x24AD, 40, Refusal::AboveRange),
        (0x24AD, i64::from(-44i32 as u32), Refusal::BelowRange),
        (0x2123, 10_001, Refusal::AboveRange),
        (0x24C1, 65_535, Refusal::OutOfRange),
    ] {
        assert_eq!(put(&mut d, id(param, 0), v), Err(refusal), "{param:04X}h");
    }
    assert_eq!(int(&d, id(0x6098, 0)), 37);
    assert_eq!(int(&d, id(0x2D6B, 0)), 10_000);
    assert_eq!(int(&d, id(0x6067, 0)), 100);
    put(&mut d, id(0x24C1, 0), 0xFFFF_FFFF).unwrap();
    assert_eq!(int(&d, id(0x6067, 0)), 0xFFFF_FFFF);
    // A parameter whose link is not described keeps its own value: PT69 ↔ 605Ah/605Dh.
    put(&mut d, id(0x24C5, 0), 0x1234).unwrap();
    assert_eq!(int(&d, id(0x605A, 0)), 2);
    assert_eq!(int(&d, id(0x605D, 0)), 1);
}

#[test]
fn the_link_holds_over_modbus_and_slmp() {
    let mut d = drive();
    // Modbus/TCP 10h: [Pr. PC01] (2101h) = 500, low word first; 03h of 6083h reads it.
    let w = hex("00 01 00 00 00 0B FF 10 21 01 00 02 04 01 F4 00 00");
    assert_eq!(
        mt(&mut d, &w),
        Some(hex("00 01 00 00 00 06 FF 10 21 01 00 02"))
    );
    let r = hex("00 02 00 00 00 06 FF 03 60 83 00 02");
    assert_eq!(
        mt(&mut d, &r),
        Some(hex("00 02 00 00 00 07 FF 03 04 01 F4 00 00"))
    );
    // SLMP 4020h/0002h: 6098h = 35 (23h); 4020h/0001h of [Pr. PT45] (24ADh) reads 23h.
    let w = hex("50 00 00 FF FF 03 00 0D 00 00 00 20 40 02 00 98 60 00 00 01 00 23");
    assert_eq!(
        slmp::answer_frame(&mut d, &w, T),
        Some(hex("D0 00 00 FF FF 03 00 08 00 00 00 98 60 00 00 01 00"))
    );
    let r = hex("50 00 00 FF FF 03 00 0C 00 00 00 20 40 01 00 AD 24 00 00 00 00");
    assert_eq!(
        slmp::answer_frame(&mut d, &r, T),
        Some(hex(
            "D0 00 00 FF FF 03 00 0C 00 00 00 AD 24 00 00 04 00 23 00 00 00"
        ))
    );
}

#[test]
fn the_table_is_the_manuals_parameter_column() {
    // Every object the §7.3 list links, and the parameters it names.
    let listed: Vec<(ObjectId, Vec<u16>)> = LINKS
        .iter()
        .map(|l| {
            let params = match l.linkage {
                Linkage::Same(p) => vec![p.index()],
                Linkage::Words { low, high } => vec![low.index(), high.index()],
                Linkage::Undescribed(ps) => ps.iter().map(|p| p.index()).collect(),
            };
            (l.object, params)
        })
        .collect();
    let mut manual: Vec<(ObjectId, Vec<u16>)> = SAME
        .iter()
        .map(|&(index, sub, param, _, _)| (id(index, sub), vec![param]))
        .collect();
    manual.extend([
        (id(0x605A, 0), vec![0x24C5]),         // PT69
        (id(0x605D, 0), vec![0x24C5]),         // PT69
        (id(0x6065, 0), vec![0x214B, 0x214C]), // PC75, PC76
        (id(0x607D, 1), vec![0x2491, 0x2492]), // PT17, PT18
        (id(0x607D, 2), vec![0x248F, 0x2490]), // PT15, PT16
        (id(0x607E, 0), vec![0x200E, 0x211D]), // PA14, PC29
        (id(0x6092, 2), vec![0x2481]),         // PT01
        (id(0x60F2, 0), vec![0x2483]),         // PT03
    ]);
    manual.sort();
    assert_eq!(listed, manual);
    for (object, _) in &manual {
        assert!(entry(*object, SoftwareVersion::A4).is_some(), "{object}");
    }
}

fn hex(s: &str) -> Vec<u8> {
    s.split_whitespace()
        .map(|b| u8::from_str_radix(b, 16).unwrap())
        .collect()
}

fn mt(d: &mut MrJeC, bytes: &[u8]) -> Option<Vec<u8>> {
    let (adu, used) = tcp::split(bytes).unwrap().unwrap();
    assert_eq!(used, bytes.len());
    modbus::answer_adu(d, &adu, T)
}
