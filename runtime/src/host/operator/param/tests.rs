//! The checks of `param` and `alarms` before anything is sent, and their replies built from
//! the drive's answers.

use super::*;
use crate::host::operator::alarms;
use crate::host::operator::sdo::tests::{shipped, FakeLink};
use crate::host::operator::wire::SdoAnswer;

fn refused(cell: &CellConfig, axis: &str, op: ParamOp, enabled: bool) -> String {
    match plan(cell, axis, &op, enabled) {
        Ok(j) => panic!("{op:?} planned: {j:?}"),
        Err(e) => e.to_string(),
    }
}

/// The drive's answer `outcome` to a transfer on axis `x`.
fn answer(outcome: SdoAnswer) -> SdoReply {
    SdoReply {
        axis: "x".into(),
        index: 0,
        sub: 0,
        name: String::new(),
        data_type: String::new(),
        bits: 32,
        outcome,
    }
}

fn read(value: i64) -> SdoReply {
    answer(SdoAnswer::Read { value })
}

fn set(name: &str, value: i64) -> ParamOp {
    ParamOp::Set {
        name: name.into(),
        value,
    }
}

#[test]
fn nothing_is_planned_for_a_value_name_or_state_the_table_refuses() {
    let cell = shipped("mr-j3-t04.toml");
    let e = refused(&cell, "x", set("PA14", 2), false);
    assert_eq!(
        e,
        "param: PA14 (Rotation direction selection) takes 0..1: 2 is out of it; not written"
    );
    let e = refused(&cell, "x", set("PC02", 100), true);
    assert!(e.contains("not written while the axis is enabled"), "{e}");
    assert!(plan(&cell, "x", &set("PC02", 100), false).is_ok());
    // A `*` parameter acts at the next power-on: written while enabled.
    assert!(plan(&cell, "x", &set("PA14", 1), true).is_ok());
    let e = refused(&cell, "x", set("PA06", 1), false);
    assert!(
        e.contains("PA06 (For manufacturer setting) is not to be changed"),
        "{e}"
    );
    let e = refused(
        &cell,
        "x",
        ParamOp::Get {
            name: "PT45".into(),
        },
        false,
    );
    assert!(
        e.starts_with("param: PT45 is not a parameter of axis 'x'"),
        "{e}"
    );
    assert!(e.contains("PA01, PA03"), "{e}");
    assert!(plan(&cell, "x", &ParamOp::List, true).is_ok());
    let e = refused(&cell, "q", ParamOp::List, false);
    assert!(e.contains("unknown axis 'q'"), "{e}");
}

#[test]
fn models_without_a_table_save_or_history_are_refused_naming_the_manual() {
    // ethercat-cell.toml: y MR-J4-TM, z MR-JET-G-N1.
    let cell = shipped("ethercat-cell.toml");
    for op in [ParamOp::List, ParamOp::Diff, ParamOp::Save, set("PA01", 0)] {
        let e = refused(&cell, "y", op, false);
        assert!(
            e.contains("MR-J4-TM manual's parameter objects (§6.5)"),
            "{e}"
        );
    }
    let e = alarms::plan(&cell, "z", false).unwrap_err();
    assert!(matches!(e, alarms::AlarmsError::NoHistory { .. }), "{e:?}");
    assert!(e.to_string().contains("no alarm history object"), "{e}");
    assert!(plan(&cell, "z", &ParamOp::Save, false).is_ok());
    assert!(alarms::plan(&cell, "x", true).is_ok());
}

#[test]
fn diff_keeps_the_parameters_off_their_initial_value_and_a_refused_read_shows_its_code() {
    let cell = shipped("mr-j3-t04.toml");
    let mut job = plan(&cell, "x", &ParamOp::Diff, false).unwrap();
    for p in MR_J3_T04_TABLE {
        let v = match p.name {
            "PA14" => 1,
            _ => p.object.default.unwrap(),
        };
        job.answered(read(v));
    }
    match job.finish() {
        Reply::Param(r) => {
            let names: Vec<&str> = r.parameters.iter().map(|p| p.name.as_str()).collect();
            assert_eq!(names, ["PA14"]);
            assert_eq!(r.parameters[0].shown, "1");
            assert_eq!(r.parameters[0].default, "0");
        }
        other => panic!("{other:?}"),
    }
    let mut job = plan(
        &cell,
        "x",
        &ParamOp::Get {
            name: "PB03".into(),
        },
        false,
    )
    .unwrap();
    job.answered(answer(SdoAnswer::Aborted {
        code: 0x0601_0000,
        meaning: "unsupported access".into(),
    }));
    match job.finish() {
        Reply::Param(r) => {
            assert_eq!(r.parameters[0].value, None);
            assert!(r.parameters[0].shown.contains("0x06010000"), "{r:?}");
        }
        other => panic!("{other:?}"),
    }
    let mut job = plan(&cell, "x", &set("PB03", 5), false).unwrap();
    job.answered(answer(SdoAnswer::Aborted {
        code: 0x0800_0020,
        meaning: "data cannot be stored".into(),
    }));
    match job.finish() {
        Reply::Rejected { reason } => assert!(
            reason.starts_with(
                "param: PB03 of axis 'x': refused by the drive: abort code 0x08000020"
            ),
            "{reason}"
        ),
        other => panic!("{other:?}"),
    }
}

#[test]
fn the_history_lists_the_recorded_alarms_newest_first_by_their_manual_names() {
    let cell = shipped("mr-j3-t04.toml");
    let mut job = alarms::plan(&cell, "x", false).unwrap();
    // 2030h: AL.36 at 2 h; 2031h: AL.52; 2032h empty, so 2032h–2035h are not read further
    // (MR-J3-T04 manual §8.9).
    let no = |value| SdoReply {
        sub: 1,
        ..read(value)
    };
    for (number, hours) in [(0x36, 2), (0x52, 1)] {
        job.answered(no(number));
        job.answered(read(hours));
        job.answered(read(0));
    }
    job.answered(no(0));
    let mut sdo = crate::host::operator::sdo::SdoInFlight::default();
    let mut link = FakeLink::default();
    assert!(
        matches!(job.start_next(&mut sdo, &mut link), Ok(false)),
        "nothing left"
    );
    match job.finish() {
        Reply::Alarms(r) => {
            let got: Vec<(u8, &str, u32)> = r
                .entries
                .iter()
                .map(|e| (e.entry, e.name.as_str(), e.hours))
                .collect();
            assert_eq!(
                got,
                [
                    (0, "AL.36 Receive error 2", 2),
                    (1, "AL.52 Error excessive", 1)
                ]
            );
        }
        other => panic!("{other:?}"),
    }
}

const MR_J3_T04_TABLE: &[cellrt_cia402::profiles::params::Parameter] =
    cellrt_cia402::profiles::params::MR_J3_T04.table;

#[test]
fn a_parameter_of_axis_b_of_a_multi_axis_unit_names_its_own_object() {
    // ethercat-multiaxis.toml: y is axis B of an MR-J5W2-G-N1 (MR-J5-G-N1 manual §1.5: its
    // manufacturer objects at +1000h, PC43 at 3D6Dh:02).
    let cell = shipped("ethercat-multiaxis.toml");
    let mut job = plan(
        &cell,
        "y",
        &ParamOp::Get {
            name: "PC43".into(),
        },
        false,
    )
    .unwrap();
    job.answered(read(4_000));
    match job.finish() {
        Reply::Param(r) => assert_eq!(
            (r.parameters[0].object.as_str(), r.parameters[0].value),
            ("3D6Dh:02", Some(4_000))
        ),
        other => panic!("{other:?}"),
    }
}

#[test]
fn writes_to_a_drive_are_the_requests_a_running_program_refuses() {
    use crate::host::operator::wire::Request;
    let param = |op| Request::Param {
        axis: "x".into(),
        op,
    };
    assert!(param(set("PA14", 1)).writes_to_a_drive());
    assert!(param(ParamOp::Save).writes_to_a_drive());
    assert!(!param(ParamOp::List).writes_to_a_drive());
    assert!(!param(ParamOp::Diff).writes_to_a_drive());
    let alarms = |clear| Request::Alarms {
        axis: "x".into(),
        clear,
    };
    assert!(alarms(true).writes_to_a_drive());
    assert!(!alarms(false).writes_to_a_drive());
}
