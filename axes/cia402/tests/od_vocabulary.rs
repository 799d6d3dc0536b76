//! The EtherCAT models' dictionaries speak the one object-dictionary vocabulary the MR-JE-C's
//! does (`Range`, `Unit` of `profiles::facts`): units and ranges are values, not text.

use cellrt_cia402::profiles::facts::{Range, Unit};
use cellrt_cia402::profiles::{profile, DriveModel};

fn entry(model: DriveModel, index: u16, sub: u8) -> cellrt_cia402::profiles::OdEntry {
    *profile(model)
        .object(index, sub)
        .unwrap_or_else(|| panic!("{model:?} lists {index:04X}h:{sub}"))
}

#[test]
fn units_are_the_shared_unit_values() {
    // 6077h in 0.1 % of rated torque (CiA 402; the MR-J5 and MR-JET manuals leave it unstated).
    let t = entry(DriveModel::MrJ5GN1, 0x6077, 0);
    assert_eq!(t.unit, Unit::TenthPercentRated);
    assert_eq!(t.unit.to_string(), "0.1 % rated");
    assert!(
        t.source.contains("unit: CiA 402 [background]"),
        "{}",
        t.source
    );
    // MR-J5 manual §6: 606Ch's unit is not stated.
    assert_eq!(entry(DriveModel::MrJ5GN1, 0x606C, 0).unit, Unit::Unstated);
    assert_eq!(
        entry(DriveModel::GenericCia402, 0x607A, 0).unit,
        Unit::PosUnits
    );
}

#[test]
fn ranges_are_the_shared_range_values() {
    // ETG.1020 1C32h:02 over the cycles cellrt runs: 125 000 … 8 000 000 ns.
    let c = entry(DriveModel::GenericCia402, 0x1C32, 2);
    assert_eq!(c.range, Range::Spans(&[(125_000, 8_000_000)]));
    assert_eq!(c.unit, Unit::Nanosecond);
    assert!(c.range.refuses(124_999));
    assert!(!c.range.refuses(125_000));
    assert!(!c.range.refuses(8_000_000));
    assert!(c.range.refuses(8_000_001));
    assert_eq!(c.range.bounds(), Some((125_000, 8_000_000)));
    // No range stated: any value of the type.
    let p = entry(DriveModel::GenericCia402, 0x6064, 0);
    assert_eq!(p.range, Range::Type);
    assert!(!p.range.refuses(i64::from(i32::MIN)));
    assert_eq!(p.range.bounds(), None);
}

#[test]
fn a_range_of_several_spans_refuses_the_gap_between_them() {
    let r = Range::Spans(&[(0, 3), (10, 12)]);
    assert!(!r.refuses(3));
    assert!(r.refuses(4), "between the spans");
    assert!(!r.refuses(10));
    assert_eq!(r.bounds(), Some((0, 12)));
    assert!(Range::Between(0, 255).refuses(256));
}
