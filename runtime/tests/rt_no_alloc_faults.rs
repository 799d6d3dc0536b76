//! Rule 1 of the RT thread on the fault paths: the watchdogs and every fault reaction
//! (controlled stop after an underrun, quick stop after consecutive overruns, disable after a
//! drive fault with the group reaction, then power off) allocate nothing on the RT thread.

mod common;

use std::path::Path;
use std::sync::atomic::Ordering;

use cellrt_config::CellConfig;
use cellrt_runtime::host::controller::{run, Outcome, RunOptions};
use cellrt_runtime::host::program::Program;
use common::{hook, marked_heap_calls, LOOPS_EXITED};

const PROGRAM: &str = r#"
[[step]]
do = "power_on"
[[step]]
do = "move"
target = { x = 700.0, y = 500.0 }
"#;

fn cell(tag: &str, watchdogs: &str, inject: &str) -> CellConfig {
    let text = format!(
        r#"
[cell]
name = "noalloc-f{tag}-{pid}"
cycle_time_us = 1000
[setpoints]
lookahead_ms = 1000
[watchdogs]
{watchdogs}
[[axes]]
name = "x"
drive = "mr-j5-g-n1"
motor = {{ counts_per_rev = 10000 }}  # position counts per motor revolution (10 mm lead)
counts_per_unit = 1000
limits = {{ position = [0.0, 800.0], velocity = 400.0, acceleration = 2000.0, jerk = 20000.0 }}
[[axes]]
name = "y"
drive = "mr-j3-t04"
counts_per_unit = 1000
limits = {{ position = [0.0, 800.0], velocity = 400.0, acceleration = 2000.0, jerk = 20000.0 }}
[[inject]]
{inject}
"#,
        pid = std::process::id()
    );
    CellConfig::parse(Path::new("noalloc-faults.toml"), &text).unwrap()
}

fn run_one(cell: &CellConfig, expect_in_error: &str) {
    let program = Program::parse(Path::new("p.toml"), PROGRAM, cell).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let summary = run(
        cell,
        RunOptions {
            program: Some(program),
            record: Some(dir.path().join("r.mcap")),
            hook: Some(hook),
            ..RunOptions::default()
        },
    )
    .unwrap();
    assert_eq!(summary.outcome, Outcome::ProgramFailed, "{summary:?}");
    let err = summary.program_error.clone().unwrap();
    assert!(err.contains(expect_in_error), "{err}");
    assert_eq!(summary.final_state, "disabled");
}

#[test]
fn fault_reactions_do_not_allocate_on_the_rt_thread() {
    run_one(
        &cell(
            "u",
            "max_consecutive_overruns = 0",
            "at_ms = 600\nfault = \"planner_stall\"\nduration_ms = 3000",
        ),
        "underrun",
    );
    run_one(
        &cell(
            "o",
            "max_consecutive_overruns = 3\noverrun_reaction = \"quick_stop\"",
            "at_ms = 700\nfault = \"stall\"\nduration_ms = 8",
        ),
        "overrun",
    );
    run_one(
        &cell(
            "d",
            "max_consecutive_overruns = 0\ndrive_fault_reaction = \"disable\"",
            "at_ms = 700\nfault = \"drive_alarm\"\naxis = \"y\"\ncode = 0x0052",
        ),
        "drive_fault",
    );
    run_one(
        &cell(
            "c",
            "max_consecutive_overruns = 0",
            "at_ms = 700\nfault = \"counter_corruption\"\naxis = \"y\"\nduration_ms = 30",
        ),
        // The master's counter check or the drive's own AL.34, whichever fires first.
        "stopped by the RT thread",
    );
    assert_eq!(LOOPS_EXITED.load(Ordering::Relaxed), 4);
    assert_eq!(
        marked_heap_calls(),
        0,
        "the RT loop allocated on a fault path"
    );
}
