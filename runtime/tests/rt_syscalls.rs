//! Proves the syscall half of rule 1 of the RT thread: in steady state the loop makes no
//! syscall but its cycle sleep (no lock wait, no I/O, no logging), with motion, recording and
//! the planner active (see `syscall_trace` for how the RT thread alone is traced). Says
//! SKIPPED plainly where strace or ptrace rights are missing.

mod syscall_trace;

use std::path::Path;

use cellrt_config::CellConfig;
use cellrt_runtime::host::controller::Outcome;
use cellrt_runtime::host::program::Program;

const CELL: &str = include_str!("data/steady_cell.toml");

const PROGRAM: &str = include_str!("data/steady_program.toml");

#[test]
fn rt_loop_makes_no_syscall_but_its_sleep_in_steady_state() {
    if syscall_trace::strace_missing() {
        return;
    }
    let text = CELL.replace(
        "\"steady\"",
        &format!("\"nosyscall-{}\"", std::process::id()),
    );
    let cell = CellConfig::parse(Path::new("nosyscall.toml"), &text).unwrap();
    let program = Program::parse(Path::new("nosyscall-program.toml"), PROGRAM, &cell).unwrap();
    let Some(trace) = syscall_trace::trace_steady_state(cell, program) else {
        return;
    };
    assert_eq!(
        trace.summary.outcome,
        Outcome::ProgramCompleted,
        "{:?}: {:#?}",
        trace.summary.program_error,
        trace.summary.recording.event_log
    );
    assert!(
        trace.sleeps() >= 1000,
        "only {} cycles traced in steady state",
        trace.sleeps()
    );
    let others = trace.others(&syscall_trace::SLEEP);
    assert!(
        others.is_empty(),
        "the RT loop made syscalls other than its sleep in steady state: {others:?}\n{}",
        trace.text.lines().take(200).collect::<Vec<_>>().join("\n")
    );
}
