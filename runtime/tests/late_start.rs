//! A program step whose first setpoint block reaches the RT thread after its start cycle (the
//! planner stalled, as a loaded machine does). Within `setpoints.max_start_slip_ms` the motion
//! starts from rest that late, all of it shifted; later, the RT thread refuses it before
//! anything moves, and the planner starts the step again instead of failing or waiting.

use std::path::Path;

use cellrt_config::CellConfig;
use cellrt_runtime::host::controller::{run, Outcome, RunOptions, Summary};
use cellrt_runtime::host::program::Program;

const PROGRAM: &str = r#"
[[step]]
do = "power_on"
[[step]]
do = "move"
target = { x = 700.0 }
[[step]]
do = "power_off"
"#;

/// The cell: the planner stalls `stall_ms` at its first publish; a first block may be
/// `slip_ms` late.
fn cell(tag: &str, stall_ms: u32, slip_ms: u32) -> CellConfig {
    let text = format!(
        r#"
[cell]
name = "late-start-{tag}-{pid}"
cycle_time_us = 1000
[setpoints]
# A long lookahead: the refused motion's blocks fill the stream ahead of the restarted one.
lookahead_ms = 1000
start_delay_ms = 20
max_start_slip_ms = {slip_ms}
[watchdogs]
max_consecutive_overruns = 0
[[axes]]
name = "x"
drive = "mr-j5-g-n1"
counts_per_unit = 1000
motor = {{ counts_per_rev = 10000 }}
limits = {{ position = [0.0, 800.0], velocity = 400.0, acceleration = 2000.0, jerk = 20000.0 }}
sim = {{ initial_position = 100.0 }}
[[inject]]
at_ms = 0
fault = "planner_stall"
duration_ms = {stall_ms}
"#,
        pid = std::process::id()
    );
    CellConfig::parse(Path::new("late-start.toml"), &text).unwrap()
}

fn run_program(cell: &CellConfig) -> Summary {
    let program = Program::parse(Path::new("p.toml"), PROGRAM, cell).unwrap();
    run(
        cell,
        RunOptions {
            program: Some(program),
            ..RunOptions::default()
        },
    )
    .unwrap()
}

/// The program completed without an underrun and x reached its target.
fn assert_completed(summary: &Summary) {
    let log = &summary.recording.event_log;
    assert_eq!(
        summary.outcome,
        Outcome::ProgramCompleted,
        "{:?}: {log:#?}",
        summary.program_error
    );
    assert_eq!(summary.counters.underruns, 0, "{log:#?}");
    let x = &summary.axes[0];
    assert!(
        (x.final_position - 700.0).abs() < 0.01,
        "x reached its target: {}",
        x.final_position
    );
}

#[test]
fn a_step_whose_first_block_came_later_than_the_slip_starts_again() {
    // The planner stalls 200 ms at its first publish: ten times the start delay, four times
    // the slip.
    let summary = run_program(&cell("again", 200, 50));
    assert_completed(&summary);
    let log = &summary.recording.event_log;
    assert!(
        log.iter()
            .any(|e| e.contains("setpoint_rejected: late_block")),
        "the first attempt was refused as late: {log:#?}"
    );
}

#[test]
fn a_step_whose_first_block_came_late_within_the_slip_starts_that_late() {
    // A 60 ms stall, three times the start delay, within the 500 ms slip: no refusal.
    let summary = run_program(&cell("slip", 60, 500));
    assert_completed(&summary);
    let log = &summary.recording.event_log;
    assert!(
        !log.iter().any(|e| e.contains("setpoint_rejected")),
        "nothing refused: {log:#?}"
    );
    let slipped = log.iter().filter(|e| e.contains("start_slipped")).count();
    assert_eq!(slipped, 1, "{log:#?}");
}
