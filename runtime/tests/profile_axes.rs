//! Profile axes (pp/pv/tq) of an in-process cell: the RT executive turns a drive-side motion
//! from the hand-off into the drive's objects and controlword bits and follows the statusword,
//! on each model that lists the mode (MR-J4-TM with PA01 `___2`, MR-JET-G-N1, MR-J5-G-N1; pp
//! also on the MR-J5W2/W3-G-N1).
//! Judged on the recorded cycles (the emulated clock), not on wall-clock time: the recorded
//! speeds and accelerations within the commanded profile, the final position within the
//! in-position range (100 pulses, [Pr. PA10]'s default), the handshake bits in their cycles.

#[allow(dead_code)] // the shared support: this test uses the cell rig
mod support;
use support::cell_rig::Rig;

use std::path::Path;

use cellrt_config::CellConfig;
use cellrt_runtime::handoff::{
    AxisRecord, CellCommand, CellState, EventKind, EventRecord, ProfileMotion,
};

/// The in-position range of the emulated drives, counts ([Pr. PA10] default 100 pulses).
const IN_POSITION: i32 = 100;

/// (drive, extra axis keys, counts per mm): a 10 mm/rev axis on each, the MR-J4-TM with its
/// 22-bit encoder (4194304 counts/rev), the others at 10000 counts/rev; the rated speed 3000
/// r/min (500 mm/s) on all.
const MODELS: [(&str, &str, f64); 3] = [
    ("mr-j4-tm", "mode_group = \"profile\"", 419_430.4),
    (
        "mr-jet-g-n1",
        "motor = { counts_per_rev = 10000, rated_speed = 3000 }",
        1000.0,
    ),
    (
        "mr-j5-g-n1",
        "motor = { counts_per_rev = 10000, rated_speed = 3000 }",
        1000.0,
    ),
];

/// The models that list pp only (the MR-J5 multi-axis units: no pv/tq, MR-J5-G-N1 manual §1.2).
const PP_ONLY_MODELS: [(&str, &str, f64); 2] = [
    (
        "mr-j5w2-g-n1",
        "motor = { counts_per_rev = 10000, rated_speed = 3000 }",
        1000.0,
    ),
    (
        "mr-j5w3-g-n1",
        "motor = { counts_per_rev = 10000, rated_speed = 3000 }",
        1000.0,
    ),
];

fn cell(tag: &str, drive: &str, extra: &str, counts_per_mm: f64, mode: &str) -> CellConfig {
    let motor = if drive == "mr-j4-tm" {
        "motor = { rated_speed = 3000 }"
    } else {
        ""
    };
    let text = format!(
        r#"
[cell]
name = "prof-{tag}-{drive}-{}"
cycle_time_us = 1000
[watchdogs]
max_consecutive_overruns = 0
[[axes]]
name = "x"
drive = "{drive}"
mode = "{mode}"
{extra}
{motor}
unit = "mm"
counts_per_unit = {counts_per_mm}
limits = {{ position = [0.0, 500.0], velocity = 100.0, acceleration = 1000.0, jerk = 10000.0 }}
sim = {{ initial_position = 100.0 }}
"#,
        std::process::id()
    );
    CellConfig::parse(Path::new("profile.toml"), &text).unwrap()
}

/// Sends `motion` and waits for its end and the record of that cycle; returns (the cycle of
/// the `profile_started` event, the finished event).
fn run(rig: &mut Rig, motion: ProfileMotion) -> (u64, EventRecord) {
    let (started, finished, _) = rig.profile(motion, 1);
    (started.unwrap_or(0), finished)
}

/// The most cycles an overrun of the loaded test machine skipped within `span`: a condition
/// met in skipped cycles is seen that much later.
fn max_gap(span: &[AxisRecord]) -> u64 {
    span.windows(2)
        .map(|w| w[1].cycle - w[0].cycle - 1)
        .max()
        .unwrap_or(0)
}

const NEW_SET_POINT: u16 = 1 << 4;
const TARGET_REACHED: u16 = 1 << 10;
const SET_POINT_ACKNOWLEDGE: u16 = 1 << 12;
const HALT: u16 = 1 << 8;

#[test]
fn pp_moves_within_its_profile_with_the_set_point_handshake() {
    for (drive, extra, s) in MODELS.into_iter().chain(PP_ONLY_MODELS) {
        let mut rig = Rig::start(cell("pp", drive, extra, s, "pp"));
        let start = rig.records.last().unwrap().position_actual;
        let target = start + (30.0 * s) as i32;
        let (started, finished) = run(
            &mut rig,
            ProfileMotion::Move {
                target,
                velocity: 50.0 * s,
                acceleration: 500.0 * s,
                deceleration: 250.0 * s,
                immediate: true,
            },
        );
        assert_eq!(finished.value, 0, "{drive}: done");
        let span = rig.span(started, finished.cycle);
        // Bit 4 goes up in the starting cycle (the objects are in the RxPDO, or written by SDO
        // first), the drive acknowledges in the next record and bit 4 drops in that cycle.
        let up = span
            .iter()
            .position(|r| r.controlword & NEW_SET_POINT != 0)
            .unwrap_or_else(|| panic!("{drive}: no set-point"));
        assert_eq!(
            span[up + 1].statusword & SET_POINT_ACKNOWLEDGE,
            SET_POINT_ACKNOWLEDGE,
            "{drive}: bit 12 in the next cycle"
        );
        assert_eq!(span[up + 1].controlword & NEW_SET_POINT, 0, "{drive}");
        assert_eq!(span[up].target_position, target, "{drive}: 607Ah");
        let last = span.last().unwrap();
        assert_eq!(
            last.statusword & (TARGET_REACHED | SET_POINT_ACKNOWLEDGE),
            TARGET_REACHED,
            "{drive}: finished on bit 10 with bit 12 = 0"
        );
        assert!(
            (last.position_actual - target).abs() <= IN_POSITION,
            "{drive}: {} vs {target}",
            last.position_actual
        );
        let (v, a) = rig.peaks(&span);
        assert!((45.0..=50.0 * 1.02).contains(&v), "{drive}: peak {v} mm/s");
        assert!(a <= 500.0 * 1.1, "{drive}: peak {a} mm/s²");
        // 30 mm at 50 mm/s with 0.1 s / 0.2 s ramps: 0.75 s, plus the settling into 6067h.
        let cycles = finished.cycle - span[up].cycle;
        let late = max_gap(&span);
        assert!(
            (740..=900 + late).contains(&cycles),
            "{drive}: {cycles} cycles"
        );
        rig.stop();
    }
}

#[test]
fn pv_ramps_to_its_velocity_and_a_stop_halts_it() {
    for (drive, extra, s) in MODELS {
        let mut rig = Rig::start(cell("pv", drive, extra, s, "pv"));
        let (started, finished) = run(
            &mut rig,
            ProfileMotion::Jog {
                velocity: -40.0 * s,
                acceleration: 400.0 * s,
                deceleration: 800.0 * s,
            },
        );
        assert_eq!(finished.value, 0, "{drive}");
        let span = rig.span(started, finished.cycle);
        let (v, a) = rig.peaks(&span);
        assert!(v <= 40.0 * 1.02, "{drive}: {v}");
        assert!(a <= 400.0 * 1.1, "{drive}: {a}");
        // 40 mm/s at 400 mm/s²: 100 cycles from the first 60FFh (after the SDO-written
        // 6083h/6084h where the RxPDO lacks them); bit 10 once 606Ch is within 606Dh.
        let first = span.iter().find(|r| r.target_velocity != 0).unwrap().cycle;
        let cycles = finished.cycle - first;
        assert!(
            (80..=130 + max_gap(&span)).contains(&cycles),
            "{drive}: {cycles}"
        );
        assert!(span.last().unwrap().statusword & TARGET_REACHED != 0);
        // At speed, a cell stop halts the drive (605Dh: 6084h here) and the cell is idle once
        // it stands.
        rig.wait(
            |r| {
                r.records
                    .last()
                    .is_some_and(|a| a.cycle >= finished.cycle + 100)
            },
            "at speed",
        );
        let seen = rig.events.len();
        rig.handoff.send_command(CellCommand::Stop).unwrap();
        rig.wait(
            |r| {
                r.events[seen..]
                    .iter()
                    .any(|e| e.kind == EventKind::StopFinished)
            },
            "stop finished",
        );
        let stop = rig.events[seen..]
            .iter()
            .find(|e| e.kind == EventKind::StopStarted)
            .unwrap()
            .cycle;
        let end = rig.events[seen..]
            .iter()
            .find(|e| e.kind == EventKind::StopFinished)
            .unwrap()
            .cycle;
        rig.wait(
            |r| r.records.last().is_some_and(|a| a.cycle >= end),
            "records",
        );
        let halt = rig.span(stop, end);
        assert!(
            halt.iter().skip(1).all(|r| r.controlword & HALT != 0),
            "{drive}"
        );
        let (_, a) = rig.peaks(&halt);
        assert!(a <= 800.0 * 1.1, "{drive}: halt deceleration {a}");
        assert!(rig.speed(halt.last().unwrap()).abs() < 0.5, "{drive}");
        assert!(
            (45..=120 + max_gap(&halt)).contains(&(end - stop)),
            "{drive}: {}",
            end - stop
        );
        rig.wait(|r| r.handoff.status().state() == CellState::Idle, "idle");
        rig.stop();
    }
}

#[test]
fn tq_ramps_its_torque_within_the_speed_limit_and_wrong_motions_are_refused() {
    for (drive, extra, s) in MODELS {
        let mut rig = Rig::start(cell("tq", drive, extra, s, "tq"));
        let (started, finished) = run(
            &mut rig,
            ProfileMotion::Torque {
                torque: 20.0,
                slope: 200.0,
            },
        );
        assert_eq!(finished.value, 0, "{drive}");
        // 20 % at 200 %/s: 100 cycles of ramp (6074h) from the first 6071h (sent once 6087h
        // is in place), done after them.
        let span = rig.span(started, finished.cycle);
        let first = span.iter().position(|r| r.target_torque == 200).unwrap();
        assert!(
            span[first..].iter().all(|r| r.target_torque == 200),
            "{drive}"
        );
        // Done in the first cycle the loop runs once the ramp is over (a loaded machine's
        // overrun skips cycles: the ramp runs on in the drive meanwhile).
        let ramp_end = span[first].cycle + 100;
        assert!(finished.cycle >= ramp_end, "{drive}: {}", finished.cycle);
        let before = span
            .iter()
            .rev()
            .find(|r| r.cycle < finished.cycle)
            .unwrap();
        assert!(before.cycle < ramp_end + 2, "{drive}: {}", finished.cycle);
        // Halfway through the ramp 6077h is about 10 % (100), not the 20 % of a step.
        let mid = span
            .iter()
            .find(|r| r.cycle >= span[first].cycle + 50)
            .unwrap();
        assert!(
            (40..=160).contains(&mid.torque_actual),
            "{drive}: 6077h halfway {}",
            mid.torque_actual
        );
        // Run on: the speed stays within 2D20h (the axis' 100 mm/s).
        rig.wait(
            |r| {
                r.records
                    .last()
                    .is_some_and(|a| a.cycle >= finished.cycle + 300)
            },
            "run on",
        );
        let (v, _) = rig.peaks(&rig.span(started, finished.cycle + 300));
        assert!(v <= 100.0 * 1.02, "{drive}: {v}");
        // A pp move on a tq axis is refused; a halt ramps the torque back to 0.
        let (_, refused) = run(
            &mut rig,
            ProfileMotion::Move {
                target: 0,
                velocity: 1.0,
                acceleration: 1.0,
                deceleration: 1.0,
                immediate: true,
            },
        );
        assert_eq!(refused.value, 1, "{drive}: refused");
        let (h0, halted) = run(&mut rig, ProfileMotion::Halt(true));
        assert_eq!(halted.value, 0);
        let late = max_gap(&rig.span(h0, halted.cycle));
        assert!(
            (100..=102 + late).contains(&(halted.cycle - h0)),
            "{drive}: {}",
            halted.cycle - h0
        );
        rig.stop();
    }
}
