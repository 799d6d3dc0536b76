//! One axis model: the same program text (power, home, move, jog with its halt, move, torque,
//! power off by name) runs on a cell of streamed axes (csp/csv/cst, setpoints from the RT loop), on a cell of
//! profile axes (pp/pv/tq, the drive's own generators over the cyclic bus) and on a cell of
//! emulated MR-JE-C axes (pp/pv/tq, driven over Modbus/TCP by their link threads), and ends
//! with the moved axis where the program's last move sent it. The program names axes only;
//! each backend decides how a step is carried out.
//!
//! `a` is moved and homed, `j` jogged, `t` holds a torque: an EtherCAT profile axis runs one
//! profile mode (a pp axis cannot jog), so the three tasks take three axes on every cell.

use std::path::Path;

use cellrt_config::{AxisRef, CellConfig};
use cellrt_runtime::host::controller::{run, Outcome, RunOptions, Summary};
use cellrt_runtime::host::program::Program;

/// The program every cell runs: `a` is homed on the spot (method 37, the one method every
/// backend here offers) and moved twice, `j` jogs and halts, `t` holds a torque.
const PROGRAM: &str = r#"
[[step]]
do = "power_on"
[[step]]
do = "home"
axis = "a"
method = 37
[[step]]
do = "move"
target = { a = 80.0 }
[[step]]
do = "jog"
axis = "j"
velocity = -40.0
seconds = 0.3
[[step]]
do = "move"
target = { a = 25.0 }
[[step]]
do = "torque"
target = { t = 10.0 }
seconds = 0.2
[[step]]
do = "power_off"
axes = ["t", "j", "a"]
"#;

/// Where the program's last move sends `a`, units.
const FINAL_A: f64 = 25.0;

/// The cell `one-TAG-PID` with the axes `a` and `t` as `axes` declares them.
fn cell(tag: &str, axes: &str) -> CellConfig {
    let text = format!(
        r#"
[cell]
name = "one-{tag}-{pid}"
cycle_time_us = 1000

[watchdogs]
max_consecutive_overruns = 0

[setpoints]
lookahead_ms = 1000
{axes}"#,
        pid = std::process::id()
    );
    CellConfig::parse(Path::new("one-program.toml"), &text).unwrap_or_else(|e| panic!("{e}"))
}

/// An MR-J4-TM axis `name` in `mode`, 10 mm per revolution of its 22-bit encoder; the torque
/// axis `t` with its torque limits (on the others they would cap the moves' torque).
fn j4(name: &str, mode: &str, extra: &str) -> String {
    let torque = if name == "t" {
        ", torque = 50.0, torque_slope = 500.0"
    } else {
        ""
    };
    format!(
        r#"
[[axes]]
name = "{name}"
drive = "mr-j4-tm"
mode = "{mode}"
{extra}
unit = "mm"
counts_per_unit = 419430.4
limits = {{ position = [-200.0, 200.0], velocity = 100.0, acceleration = 1000.0, jerk = 10000.0{torque} }}
sim = {{ initial_position = 0.0 }}
"#
    )
}

/// An emulated MR-JE-C axis `name` in `mode` over Modbus/TCP. The master's watchdog is off and the
/// answer deadline generous: the program's logic is under test, not a loaded machine's timing.
fn je_c(name: &str, mode: &str) -> String {
    let torque = if name == "t" { ", torque = 50.0" } else { "" };
    format!(
        r#"
[[axes]]
name = "{name}"
drive = "mr-je-c"
transport = "modbus-tcp"
mode = "{mode}"
unit = "mm"
counts_per_unit = 1310.72
limits = {{ position = [-200.0, 200.0], velocity = 100.0, acceleration = 1000.0, jerk = 10000.0{torque} }}
je_c = {{ emulate = true, watchdog_missed = 0, response_timeout_ms = 200 }}
"#
    )
}

/// Runs [`PROGRAM`] on `cell`; the summary.
fn run_program(cell: &CellConfig) -> (Summary, Program) {
    let program = Program::parse(Path::new("one-program.toml"), PROGRAM, cell)
        .unwrap_or_else(|e| panic!("{e}"));
    let options = RunOptions {
        program: Some(program.clone()),
        ..RunOptions::default()
    };
    (run(cell, options).expect("cell runs"), program)
}

/// The program completed, and `a` ended at [`FINAL_A`] (`final_position` of the summary).
fn ends_at_the_last_move(s: &Summary, program: &Program, a: AxisRef, final_position: f64) {
    assert_eq!(
        s.outcome,
        Outcome::ProgramCompleted,
        "{:?} {:?}",
        s.program_error,
        s.recording.event_log
    );
    assert_eq!(program.final_target(a), Some(FINAL_A));
    assert!(
        (final_position - FINAL_A).abs() < 0.05,
        "a ended at {final_position}, not {FINAL_A}"
    );
}

#[test]
fn streamed_axes_run_the_program() {
    let axes = j4("a", "csp", "") + &j4("j", "csv", "") + &j4("t", "cst", "");
    let cell = cell("streamed", &axes);
    let a = cell.axis_ref("a").unwrap();
    assert_eq!(a, AxisRef::Loop(0));
    let (s, program) = run_program(&cell);
    ends_at_the_last_move(&s, &program, a, s.axes[0].final_position);
}

#[test]
fn profile_axes_run_the_program() {
    let profile = "mode_group = \"profile\"\nmotor = { rated_speed = 3000 }";
    let axes = j4("a", "pp", profile) + &j4("j", "pv", profile) + &j4("t", "tq", profile);
    let cell = cell("profile", &axes);
    let a = cell.axis_ref("a").unwrap();
    assert!(
        cell.axes.on_loop()[0].profile_objects.is_some(),
        "a runs on its drive's pp"
    );
    let (s, program) = run_program(&cell);
    ends_at_the_last_move(&s, &program, a, s.axes[0].final_position);
}

#[test]
fn mr_je_c_axes_run_the_program() {
    // No axis on the RT loop: the loop runs the cell's clock, watchdogs and recording beside
    // the MR-JE-C threads.
    let axes = je_c("a", "pp") + &je_c("j", "pv") + &je_c("t", "tq");
    let cell = cell("je-c", &axes);
    let a = cell.axis_ref("a").unwrap();
    assert_eq!(a, AxisRef::Link(0));
    let (s, program) = run_program(&cell);
    ends_at_the_last_move(&s, &program, a, s.axes[0].final_position);
}
