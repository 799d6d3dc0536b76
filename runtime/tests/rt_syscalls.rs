//! Proves the syscall half of rule 1 of the RT thread: in steady state the loop makes no
//! syscall but its cycle sleep (no lock wait, no I/O, no logging), with motion, recording and
//! the planner active. `strace` is attached to the RT thread alone once it reaches steady
//! state; the executive's `Exit` hook makes one marker syscall (`getppid`), and every syscall
//! traced before it must be `clock_nanosleep` (or `restart_syscall`, the sleep the attach
//! interrupted). Needs `strace` (CI installs it; under CI its absence fails the test) and
//! ptrace rights over the test's own threads; says SKIPPED plainly where either is missing.

use std::io::Read;
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicI32, Ordering};
use std::time::{Duration, Instant};

use cellrt_runtime::config::CellConfig;
use cellrt_runtime::host::controller::{run, Outcome, RunOptions};
use cellrt_runtime::host::program::Program;
use cellrt_runtime::rt::executive::RtPhase;

/// The RT thread's id, published by the hook at steady state.
static RT_TID: AtomicI32 = AtomicI32::new(0);

/// The syscall the `Exit` hook makes so that the trace shows where steady state ended.
const MARKER: &str = "getppid";

/// Syscalls allowed in steady state: the cycle sleep, and its restart after the attach.
const ALLOWED: [&str; 2] = ["clock_nanosleep", "restart_syscall"];

const CELL: &str = include_str!("data/steady_cell.toml");

const PROGRAM: &str = include_str!("data/steady_program.toml");

fn hook(phase: RtPhase) {
    match phase {
        RtPhase::SteadyState => RT_TID.store(nix::unistd::gettid().as_raw(), Ordering::SeqCst),
        RtPhase::Exit => {
            let _ = nix::unistd::getppid();
        }
    }
}

/// The tracer of thread `tid` of this process, from its `TracerPid` line (0: none).
fn tracer_of(tid: i32) -> i32 {
    std::fs::read_to_string(format!("/proc/self/task/{tid}/status"))
        .ok()
        .and_then(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix("TracerPid:"))
                .and_then(|v| v.trim().parse().ok())
        })
        .unwrap_or(0)
}

/// The syscall name at the start of an strace line (`name(args) = r`), if it is one.
fn syscall_name(line: &str) -> Option<&str> {
    let name = line.split('(').next()?.trim();
    (!name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_'))
        .then_some(name)
}

#[test]
fn rt_loop_makes_no_syscall_but_its_sleep_in_steady_state() {
    if Command::new("strace").arg("-V").output().is_err() {
        assert!(
            std::env::var_os("CI").is_none(),
            "strace is missing under CI (.ci/run installs it)"
        );
        println!("SKIPPED: strace is not installed (apt-get install strace)");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let text = CELL.replace(
        "\"steady\"",
        &format!("\"nosyscall-{}\"", std::process::id()),
    );
    let cell = CellConfig::parse(Path::new("nosyscall.toml"), &text).unwrap();
    let program = Program::parse(Path::new("nosyscall-program.toml"), PROGRAM, &cell).unwrap();
    let record = dir.path().join("nosyscall.mcap");
    let runner = std::thread::spawn(move || {
        run(
            &cell,
            RunOptions {
                program: Some(program),
                record: Some(record),
                hook: Some(hook),
                ..RunOptions::default()
            },
        )
    });

    let start = Instant::now();
    let tid = loop {
        let tid = RT_TID.load(Ordering::SeqCst);
        if tid != 0 {
            break tid;
        }
        assert!(
            !runner.is_finished() && start.elapsed() < Duration::from_secs(60),
            "the RT loop never reached steady state"
        );
        std::thread::sleep(Duration::from_millis(1));
    };
    let log = dir.path().join("rt.strace");
    let mut strace = Command::new("strace")
        .args(["-qq", "-o"])
        .arg(&log)
        .args(["-p", &tid.to_string()])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("strace starts");
    let attached = Instant::now();
    while tracer_of(tid) == 0 && !runner.is_finished() {
        if let Ok(Some(_)) = strace.try_wait() {
            break;
        }
        assert!(
            attached.elapsed() < Duration::from_secs(20),
            "strace did not attach"
        );
        std::thread::sleep(Duration::from_millis(1));
    }
    let summary = runner.join().expect("run thread").expect("the cell runs");
    let status = strace.wait().expect("strace ends");
    let mut err = String::new();
    let _ = strace.stderr.take().unwrap().read_to_string(&mut err);
    if !status.success() && err.contains("Operation not permitted") {
        println!("SKIPPED: no ptrace rights over this process's threads: {err}");
        return;
    }
    assert_eq!(summary.outcome, Outcome::ProgramCompleted, "{summary:?}");

    let trace = std::fs::read_to_string(&log).unwrap_or_default();
    let names: Vec<&str> = trace.lines().filter_map(syscall_name).collect();
    let end = names
        .iter()
        .position(|n| *n == MARKER)
        .unwrap_or_else(|| panic!("no {MARKER} marker from the exit hook in the trace:\n{trace}"));
    let steady = &names[..end];
    let sleeps = steady.iter().filter(|n| **n == "clock_nanosleep").count();
    let others: Vec<&str> = steady
        .iter()
        .copied()
        .filter(|n| !ALLOWED.contains(n))
        .collect();
    assert!(
        sleeps >= 1000,
        "only {sleeps} cycles traced in steady state (status {status}, strace: {err})"
    );
    assert!(
        others.is_empty(),
        "the RT loop made syscalls other than its sleep in steady state: {others:?}\n{}",
        trace.lines().take(200).collect::<Vec<_>>().join("\n")
    );
}
