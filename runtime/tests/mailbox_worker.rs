//! No mailbox on the RT thread: an MR-J4-TM on the in-process emulated EtherCAT segment whose
//! firmware answers every SDO 50 ms late (`sim.sdo_response_ms`) is homed in its homing mode
//! while the cell runs. The 6098h write goes to the mailbox worker; the RT loop keeps cycling
//! while it is in flight (the emulated segment's clock only moves with the cyclic exchange, so
//! a loop that waited for the answer would never get it) and the homing starts once the drive
//! has answered, 50 cycles or more later.

#[allow(dead_code)] // the shared support: this test uses the event log
mod support;
use support::event_log::cycle_of;

use std::path::Path;

use cellrt_config::CellConfig;
use cellrt_runtime::host::controller::{run, Outcome, RunOptions};
use cellrt_runtime::host::program::Program;

const PROGRAM: &str = r#"
[[step]]
do = "power_on"
[[step]]
do = "home"
axis = "y"
[[step]]
do = "move"
target = { y = 120.0 }
[[step]]
do = "power_off"
"#;

fn cell(sdo_response_ms: u32) -> CellConfig {
    let text = format!(
        r#"
[cell]
name = "mailbox-worker-{sdo_response_ms}-{pid}"
cycle_time_us = 1000
[setpoints]
lookahead_ms = 1000
[watchdogs]
max_consecutive_overruns = 0
[ethercat]
interface = "in-process"
[[axes]]
name = "y"
drive = "mr-j4-tm"
transport = "ethercat"
mode = "csp"
unit = "mm"
counts_per_unit = 4194.304
limits = {{ position = [0.0, 600.0], velocity = 400.0, acceleration = 2000.0, jerk = 20000.0 }}
sim = {{ initial_position = 50.0, sdo_response_ms = {sdo_response_ms} }}
"#,
        pid = std::process::id()
    );
    CellConfig::parse(Path::new("mailbox-worker.toml"), &text).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn an_sdo_answered_50_ms_late_keeps_the_loop_cycling_and_the_homing_waits_for_it() {
    let cell = cell(50);
    let program = Program::parse(Path::new("p.toml"), PROGRAM, &cell).unwrap();
    let summary = run(
        &cell,
        RunOptions {
            program: Some(program),
            ..RunOptions::default()
        },
    )
    .expect("cell runs");
    let log = &summary.recording.event_log;
    assert_eq!(
        summary.outcome,
        Outcome::ProgramCompleted,
        "{:?}: {log:#?}",
        summary.program_error
    );
    let requested = cycle_of(log, "cell_state: homing").expect("the cell entered homing");
    let started = cycle_of(log, "homing_started").expect("the homing started");
    assert!(
        started >= requested + 50,
        "6098h answered 50 ms late: homing requested at cycle {requested}, started at {started}\n{log:#?}"
    );
    assert!(
        log.iter()
            .any(|l| l.contains("homing_finished") && !l.contains("refused")),
        "{log:#?}"
    );
    let y = &summary.axes[0];
    assert!(
        (y.final_position - 120.0).abs() < 0.05,
        "{}",
        y.final_position
    );
}
