//! A csp axis switched to pp at run time and back (issue 19), on each model whose manual lists
//! both: the RT thread follows the drives' mode-switch rules (`cellrt_cia402::mode_switch`;
//! MR-J5-G-N1 manual §7.4, MR-JET-G-N1 manual §7.4): 6060h changes only at standstill with
//! controlword bit 4 low, 607Ah equals 6064h from the cycle before 6060h = 8 so the motor does
//! not jump, and the switch ends when 6061h shows the mode. Judged on the recorded cycles.

#[allow(dead_code)] // the shared support: this test uses the cell rig
mod support;
use support::cell_rig::Rig;

use std::path::Path;

use cellrt_cia402::mode::ModeOfOperation;
use cellrt_config::CellConfig;
use cellrt_runtime::handoff::{AxisRecord, EventKind, EventRecord, ProfileMotion, SwitchableMode};

/// The in-position range of the emulated drives, counts ([Pr. PA10] default 100 pulses).
const IN_POSITION: i32 = 100;
/// Controlword bit 4 (new set-point in pp).
const NEW_SET_POINT: u16 = 1 << 4;

/// 6060h values (CiA 402; MR-J5-G-N1 manual §7.4): csp 8, pp 1.
const CSP: i8 = 8;
const PP: i8 = 1;

/// The motor of the MR-J5 and MR-JET axes: 10 mm/rev at 10000 counts/rev, rated 3000 r/min.
const MOTOR: &str = "motor = { counts_per_rev = 10000, rated_speed = 3000 }";

/// A csp axis of `drive` over `transport`.
fn cell(drive: &str, transport: &str) -> CellConfig {
    cell_of(
        &format!("{drive}-{transport}"),
        drive,
        transport,
        "csp",
        MOTOR,
    )
}

/// A one-axis cell (`tag` names it) of `drive` over `transport` in `mode` with `motor`.
fn cell_of(tag: &str, drive: &str, transport: &str, mode: &str, motor: &str) -> CellConfig {
    let segment = if transport == "ethercat" {
        "[ethercat]\ninterface = \"in-process\""
    } else {
        ""
    };
    let text = format!(
        r#"
[cell]
name = "modesw-{tag}-{}"
cycle_time_us = 1000
[watchdogs]
max_consecutive_overruns = 0
{segment}
[[axes]]
name = "x"
drive = "{drive}"
transport = "{transport}"
mode = "{mode}"
{motor}
unit = "mm"
counts_per_unit = 1000
limits = {{ position = [0.0, 500.0], velocity = 100.0, acceleration = 1000.0, jerk = 10000.0 }}
sim = {{ initial_position = 100.0 }}
"#,
        std::process::id()
    );
    CellConfig::parse(Path::new("mode-switch.toml"), &text).unwrap()
}

/// Sends `motion` to axis 0 and waits for its end and 20 records after; returns (the cycle of
/// its start, or of the refusal, the finished event, every event since).
fn run(rig: &mut Rig, motion: ProfileMotion) -> (u64, EventRecord, Vec<EventRecord>) {
    let (started, finished, events) = rig.profile(motion, 20);
    (started.unwrap_or(finished.cycle), finished, events)
}

/// Checks the recorded switch from `from` to `to` over `span` (the cycles of the switch):
/// 6060h changes once, at standstill, with bit 4 low, and 6061h shows `to` by the end.
fn check_switch(drive: &str, span: &[AxisRecord], from: i8, to: i8) -> usize {
    let first = span
        .iter()
        .position(|r| r.mode == to)
        .unwrap_or_else(|| panic!("{drive}: 6060h never {to}: {span:?}"));
    assert!(
        first > 0,
        "{drive}: the first record of the switch is still {from}"
    );
    assert!(
        span[..first].iter().all(|r| r.mode == from),
        "{drive}: 6060h before the switch"
    );
    assert!(
        span[first..].iter().all(|r| r.mode == to),
        "{drive}: 6060h went back"
    );
    let requested = &span[first];
    assert_eq!(
        requested.velocity_actual, 0,
        "{drive}: requested at standstill"
    );
    assert_eq!(
        requested.controlword & NEW_SET_POINT,
        0,
        "{drive}: bit 4 low while switching"
    );
    assert_eq!(
        span.last().unwrap().mode_display,
        to,
        "{drive}: 6061h at the end"
    );
    first
}

#[test]
fn a_csp_axis_switches_to_pp_moves_by_its_drive_and_switches_back_without_a_jump() {
    for (drive, transport) in [
        ("mr-j5-g-n1", "sim"),
        ("mr-jet-g-n1", "sim"),
        ("mr-j5w2-g-n1", "sim"),
        // 6060h/6061h over the emulated EtherCAT segment; 6081h–6084h by CoE SDO.
        ("mr-j5-g-n1", "ethercat"),
    ] {
        let tag = format!("{drive} over {transport}");
        let mut rig = Rig::start(cell(drive, transport));
        let s = 1000.0;

        // csp → pp.
        let (started, finished, events) =
            run(&mut rig, ProfileMotion::SwitchMode(SwitchableMode::Pp));
        assert_eq!(finished.value, 0, "{tag}: switched: {events:?}");
        let switched = events
            .iter()
            .find(|e| e.kind == EventKind::ModeSwitched)
            .unwrap_or_else(|| panic!("{tag}: no mode_switched event: {events:?}"));
        assert_eq!(switched.value, i64::from(PP), "{tag}");
        check_switch(&tag, &rig.span(started, finished.cycle), CSP, PP);
        assert_eq!(
            rig.handoff.status().live[0]
                .mode
                .load(std::sync::atomic::Ordering::Acquire),
            PP,
            "{tag}: the status names the mode"
        );

        // The drive positions the axis by its own profile.
        let start = rig.records.last().unwrap().position_actual;
        let target = start + (20.0 * s) as i32;
        // 50 mm/s, 500 mm/s² both ways.
        let pp_move = ProfileMotion::Move {
            target,
            velocity: 50.0 * s,
            acceleration: 500.0 * s,
            deceleration: 500.0 * s,
            immediate: true,
        };
        let (move_started, moved, _) = run(&mut rig, pp_move);
        assert_eq!(moved.value, 0, "{tag}: pp move done");
        let (v, a) = rig.peaks(&rig.span(move_started, moved.cycle));
        assert!((45.0..=50.0 * 1.02).contains(&v), "{tag}: peak {v} mm/s");
        assert!(a <= 500.0 * 1.1, "{tag}: peak {a} mm/s²");
        let at = rig.records.last().unwrap().position_actual;
        assert!(
            (at - target).abs() <= IN_POSITION,
            "{tag}: {at} vs {target}"
        );

        // Asking for pp again is refused (it runs in pp), and nothing changes.
        let (_, again, _) = run(&mut rig, ProfileMotion::SwitchMode(SwitchableMode::Pp));
        assert_eq!(again.value, 1, "{tag}: refused");

        // pp → csp: 607Ah follows 6064h from before 6060h = 8, so the drive takes over where
        // the motor stands.
        let (started, finished, events) =
            run(&mut rig, ProfileMotion::SwitchMode(SwitchableMode::Csp));
        assert_eq!(finished.value, 0, "{tag}: back: {events:?}");
        let back = rig.span(started, finished.cycle);
        let first = check_switch(&tag, &back, PP, CSP);
        for r in &back[first - 1..] {
            assert!(
                (r.target_position - r.position_actual).abs() <= IN_POSITION,
                "{tag}: 607Ah {} vs 6064h {} in cycle {}",
                r.target_position,
                r.position_actual,
                r.cycle
            );
        }
        // Back in csp, the axis holds where it stood (the streamed setpoint took over there).
        let after = rig.span(finished.cycle, u64::MAX);
        assert!(after.len() >= 20, "{tag}");
        for r in &after {
            assert_eq!(r.mode, CSP, "{tag}");
            assert!(
                (r.position_actual - at).abs() <= IN_POSITION,
                "{tag}: moved to {} after the switch (stood at {at})",
                r.position_actual
            );
            assert!(
                (r.setpoint - f64::from(at)).abs() <= f64::from(IN_POSITION),
                "{tag}: setpoint {} after the switch",
                r.setpoint
            );
        }
        // A pp move of a csp axis is refused.
        let (_, refused, _) = run(&mut rig, pp_move);
        assert_eq!(refused.value, 1, "{tag}: no pp move in csp");
        rig.stop();
    }
}

#[test]
fn a_switch_is_refused_where_the_axis_cannot_switch() {
    // A pv axis (not csp), and a csp axis of a model without pp (MR-J4-TM in its default
    // cyclic mode group, MR-J4-TM manual §5.4.1): refused, 6060h untouched.
    let pv = cell_of("pv", "mr-j5-g-n1", "sim", "pv", MOTOR);
    let j4 = cell_of(
        "j4",
        "mr-j4-tm",
        "sim",
        "csp",
        "motor = { rated_speed = 3000 }",
    );
    for (what, cell, mode) in [
        ("pv axis", pv, ModeOfOperation::ProfileVelocity),
        ("MR-J4-TM csp axis", j4, ModeOfOperation::CyclicSyncPosition),
    ] {
        assert!(
            cellrt_config::profile_axis::pp_switch(&cell.axes.on_loop()[0]).is_err(),
            "{what}"
        );
        let mut rig = Rig::start(cell);
        let (_, finished, events) = run(&mut rig, ProfileMotion::SwitchMode(SwitchableMode::Pp));
        assert_eq!(finished.value, 1, "{what}: refused");
        assert!(
            events.iter().all(|e| e.kind != EventKind::ModeSwitched),
            "{what}"
        );
        assert!(
            rig.records.iter().all(|r| r.mode == mode.as_i8()),
            "{what}: 6060h stayed {}",
            mode.as_str()
        );
        rig.stop();
    }
}
