//! A program step whose first setpoint block reaches the RT thread after its start cycle (the
//! planner stalled, as a loaded machine does): the RT thread refuses the motion before anything
//! moves, and the planner starts the step again instead of failing the program or waiting.

use std::path::Path;

use cellrt_runtime::config::CellConfig;
use cellrt_runtime::host::controller::{run, Outcome, RunOptions};
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

#[test]
fn a_step_whose_first_block_came_late_starts_again() {
    // The planner stalls 200 ms at its first publish, ten times the start delay.
    let text = format!(
        r#"
[cell]
name = "late-start-{pid}"
cycle_time_us = 1000
[setpoints]
# A long lookahead: the refused motion's blocks fill the stream ahead of the restarted one.
lookahead_ms = 1000
start_delay_ms = 20
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
duration_ms = 200
"#,
        pid = std::process::id()
    );
    let cell = CellConfig::parse(Path::new("late-start.toml"), &text).unwrap();
    let program = Program::parse(Path::new("p.toml"), PROGRAM, &cell).unwrap();
    let summary = run(
        &cell,
        RunOptions {
            program: Some(program),
            ..RunOptions::default()
        },
    )
    .unwrap();
    let log = &summary.recording.event_log;
    assert_eq!(
        summary.outcome,
        Outcome::ProgramCompleted,
        "{:?}: {log:#?}",
        summary.program_error
    );
    assert!(
        log.iter()
            .any(|e| e.contains("setpoint_rejected: late_block")),
        "the first attempt was refused as late: {log:#?}"
    );
    assert_eq!(summary.counters.underruns, 0, "{log:#?}");
    let x = &summary.axes[0];
    assert!(
        (x.final_position - 700.0).abs() < 0.01,
        "x reached its target: {}",
        x.final_position
    );
}
