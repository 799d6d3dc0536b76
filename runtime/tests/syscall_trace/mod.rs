//! Tracing the RT thread's syscalls in steady state: `strace` attached to the RT thread alone
//! once it reaches steady state; the executive's `Exit` hook makes one marker syscall
//! (`getppid`), and every syscall traced before it is judged. Needs `strace` (CI installs it;
//! under CI its absence fails) and ptrace rights over the test's own threads.

use std::io::Read;
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicI32, Ordering};
use std::time::{Duration, Instant};

use cellrt_config::CellConfig;
use cellrt_runtime::host::controller::{run, RunOptions};
use cellrt_runtime::host::program::Program;
use cellrt_runtime::rt::executive::RtPhase;

/// The RT thread's id, published by the hook at steady state.
static RT_TID: AtomicI32 = AtomicI32::new(0);

/// The syscall the `Exit` hook makes so that the trace shows where steady state ended.
const MARKER: &str = "getppid";

/// The cycle sleep, and its restart after the attach: allowed in every steady state.
pub const SLEEP: [&str; 2] = ["clock_nanosleep", "restart_syscall"];

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

/// True (after saying so) where strace is missing outside CI: the caller skips.
pub fn strace_missing() -> bool {
    if Command::new("strace").arg("-V").output().is_ok() {
        return false;
    }
    assert!(
        std::env::var_os("CI").is_none(),
        "strace is missing under CI (.ci/run installs it)"
    );
    println!("SKIPPED: strace is not installed (apt-get install strace)");
    true
}

/// What the trace of one run showed.
pub struct SteadyTrace {
    /// The run's summary.
    pub summary: cellrt_runtime::host::controller::Summary,
    /// The syscalls before the marker, in order.
    pub steady: Vec<String>,
    /// The whole trace, for failure messages.
    pub text: String,
}

impl SteadyTrace {
    /// The cycle sleeps traced.
    pub fn sleeps(&self) -> usize {
        self.steady
            .iter()
            .filter(|n| *n == "clock_nanosleep")
            .count()
    }

    /// The syscalls traced that are not in `allowed`.
    pub fn others(&self, allowed: &[&str]) -> Vec<&str> {
        self.steady
            .iter()
            .map(String::as_str)
            .filter(|n| !allowed.contains(n))
            .collect()
    }
}

/// Runs `program` on `cell` with its RT thread traced from steady state to the exit marker;
/// `None` (after saying so) where this process has no ptrace rights over its threads.
pub fn trace_steady_state(cell: CellConfig, program: Program) -> Option<SteadyTrace> {
    let dir = tempfile::tempdir().unwrap();
    let record = dir.path().join("trace.mcap");
    RT_TID.store(0, Ordering::SeqCst);
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
        if runner.is_finished() {
            let r = runner.join().expect("run thread");
            panic!(
                "the cell ended before steady state: {:?}",
                r.map(|s| s.outcome)
            );
        }
        assert!(
            start.elapsed() < Duration::from_secs(60),
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
        return None;
    }
    let text = std::fs::read_to_string(&log).unwrap_or_default();
    let names: Vec<String> = text
        .lines()
        .filter_map(syscall_name)
        .map(str::to_owned)
        .collect();
    let end = names
        .iter()
        .position(|n| n == MARKER)
        .unwrap_or_else(|| panic!("no {MARKER} marker from the exit hook in the trace:\n{text}"));
    Some(SteadyTrace {
        summary,
        steady: names[..end].to_vec(),
        text,
    })
}
