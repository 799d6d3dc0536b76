use super::*;
use crate::profiles::{profile, DataType, DriveModel};

/// (name, object, default, envelope) of a row.
fn row(model: DriveModel, name: &str) -> (u16, u8, Option<i64>, Option<(i64, i64)>) {
    let p = profile(model).parameters.parameter(name).unwrap();
    (
        p.object.index,
        p.object.sub,
        p.object.default,
        p.object.range.bounds(),
    )
}

#[test]
fn mr_j3_t04_rows_are_the_manuals() {
    use DriveModel::MrJ3T04 as M;
    // MR-J3-T04 manual §5.1 and §8.10.1 (PA = 2300h, PB = 2301h, PC = 2302h, PO = 2309h).
    assert_eq!(
        row(M, "PA19"),
        (0x2300, 19, Some(0x000E), Some((0, 0xFFFF)))
    );
    assert_eq!(row(M, "PB03"), (0x2301, 3, Some(0), Some((0, 20_000))));
    assert_eq!(row(M, "PC02"), (0x2302, 2, Some(0), Some((0, 50_000))));
    assert_eq!(
        row(M, "pd04"),
        (0x2303, 4, Some(0x0021_212B), Some((0, 0x003F_3F3F)))
    );
    assert_eq!(row(M, "PO03"), (0x2309, 3, Some(0), Some((0, 0x0203))));
    let f = profile(M).parameters;
    let pa14 = f.parameter("PA14").unwrap();
    assert_eq!(
        (pa14.symbol, pa14.effect()),
        ("*POL", Effect::AfterPowerCycle)
    );
    assert_eq!(f.parameter("PC02").unwrap().effect(), Effect::Immediately);
    assert_eq!(pa14.object.data_type, DataType::I32);
    assert_eq!(f.by_object(0x2309, 2).unwrap().name, "PO02");
    assert!(
        f.parameter("PA02").is_none(),
        "not in this manual (MR-J3-A manual)"
    );
    let save = f.save.unwrap();
    assert_eq!((save.object, save.signature), ((0x1010, 1), 0x6576_6173));
    let h = f.alarm_history.unwrap();
    assert_eq!((h.first, h.entries, h.clear), (0x2030, 6, (0x2040, 0x1EA5)));
    // The profile serves them.
    let o = profile(M).object(0x2035, 3).unwrap();
    assert_eq!(o.name, "Alarm detail");
    assert_eq!(
        profile(M).object(0x2300, 14).unwrap().name,
        "Rotation direction selection"
    );
}

#[test]
fn settings_follow_the_manuals_digits_and_ranges() {
    let f = &MR_J3_T04;
    let po03 = f.parameter("PO03").unwrap();
    assert_eq!(po03.refuse(0x0200), None, "free-run recommendation");
    assert_eq!(po03.refuse(0x0003), None);
    let e = po03.refuse(0x0100).unwrap();
    assert_eq!(
        e,
        "PO03 (Communication protection switch) takes hex digit 0: 0/1/2/3, digit 1: 0, \
         digit 2: 0/2: 0100h is out of it; not written"
    );
    assert!(po03.refuse(0x1_0000).is_some());
    assert!(po03.refuse(-1).is_some());
    let pb03 = f.parameter("PB03").unwrap();
    assert_eq!(pb03.refuse(20_000), None);
    assert_eq!(
        pb03.refuse(20_001).unwrap(),
        "PB03 (Position command acceleration/deceleration time constant) takes 0..20000: \
         20001 is out of it; not written"
    );
    let pd01 = f.parameter("PD01").unwrap();
    assert_eq!(pd01.refuse(0x0C00), None);
    assert!(pd01.refuse(0x0100).is_some());
    let pa01 = f.parameter("PA01").unwrap();
    assert!(pa01.refuse(0).unwrap().contains("is not to be changed"));
    assert_eq!(pa01.object.range, crate::profiles::facts::Range::Type);
    assert_eq!(f.parameter("PA19").unwrap().format(0x100B), "100Bh");
    assert_eq!(pb03.format(250), "250");
}

#[test]
fn the_write_inhibit_table_is_pa19s() {
    let w = MR_J3_T04.write_inhibit.unwrap();
    assert_eq!(
        w.access(0x000E),
        (&[0x2300, 0x2301, 0x2302, 0x2303, 0x2309][..], false)
    );
    assert_eq!(w.access(0x100B), (&[0x2300][..], true));
    assert_eq!(w.access(0x0000), (&[0x2300][..], false));
}

#[test]
fn mr_jet_and_mr_j5_carry_torque_limit_2_and_refuse_what_their_manuals_lack() {
    for m in [DriveModel::MrJetGN1, DriveModel::MrJ5GN1] {
        // MR-JET-G-N1 / MR-J5-G-N1 manuals §9.1: 2D6Dh:02 default 10000, 0-10000.
        assert_eq!(row(m, "PC43"), (0x2D6D, 2, Some(10_000), Some((0, 10_000))));
        assert_eq!(row(m, "PC42"), (0x2D6D, 1, Some(0), Some((0, 1))));
        let f = profile(m).parameters;
        assert!(f
            .alarm_history
            .unwrap_err()
            .contains("no alarm history object"));
        assert_eq!(f.save.unwrap().readback, SaveReadback::IdleBit);
        assert_eq!(profile(m).object(0x2D6D, 2).unwrap().default, Some(10_000));
    }
    let j4 = profile(DriveModel::MrJ4TM).parameters;
    assert!(j4.table.is_empty());
    assert!(j4.save.unwrap_err().contains("MR-J4-TM manual"));
}

#[test]
fn every_row_has_a_source_a_type_and_a_default_inside_its_setting() {
    for m in DriveModel::ALL {
        for p in profile(*m).parameters.table {
            assert!(!p.object.source.is_empty(), "{}", p.name);
            assert!(p.object.data_type.bits().is_some(), "{}", p.name);
            let d = p.object.default.unwrap();
            assert!(
                p.setting == Setting::DoNotChange || p.setting.allows(d),
                "{} default {d}",
                p.name
            );
        }
    }
}
