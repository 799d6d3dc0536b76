//! The syscall rule on EtherCAT: a cell whose MR-J4-TM sits on the far end of a veth pair (the
//! emulated segment serving raw frames on the peer) is homed twice in its homing mode and
//! moved in steady state: the mode changes csp → hm → csp go by the RxPDO's 6060h, the 6098h
//! writes run on the mailbox worker (their frames carried after the cyclic one), and the RT
//! thread makes no syscall but its sleep and the frames' send, wait and receive. Needs root
//! (the veth pair, raw sockets), `ip` and `strace`; says SKIPPED plainly where one is missing.

mod syscall_trace;

use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use cellrt_cia402::{profile, CycleTime, DriveModel};
use cellrt_config::CellConfig;
use cellrt_emulator::ethercat::{wire, FaultSchedule, Segment};
use cellrt_emulator::{SimDrive, SimDriveParams};
use cellrt_ethercat::raw_socket::RawSocket;
use cellrt_runtime::host::program::Program;
use cellrt_test_support::veth::VethPair;

/// The frames' send (`send` is `sendto`), the wait for the return and its receive.
const FRAME_IO: [&str; 3] = ["sendto", "ppoll", "recvfrom"];

const PROGRAM: &str = r#"
[[step]]
do = "power_on"
[[step]]
do = "wait"
seconds = 0.5
[[step]]
do = "home"
axis = "y"
[[step]]
do = "move"
target = { y = 150.0 }
[[step]]
do = "home"
axis = "y"
[[step]]
do = "move"
target = { y = 60.0 }
[[step]]
do = "power_off"
"#;

/// One run on a fresh veth pair; `None` where the trace could not be taken (said why).
fn traced_run(attempt: u32) -> Option<syscall_trace::SteadyTrace> {
    let name = format!("crs{}{attempt}", std::process::id() % 10_000);
    let Some(pair) = VethPair::create(&name) else {
        println!("SKIPPED: could not create a veth pair (`ip` from iproute2 missing?)");
        return None;
    };
    let ct = CycleTime::from_micros(2000).unwrap();
    let mut segment = Segment::new(vec![SimDrive::new(
        profile(DriveModel::MrJ4TM),
        SimDriveParams::default(),
        ct,
    )]);
    let mut faults = FaultSchedule::new(Vec::new(), ct, 1).unwrap();
    let socket = RawSocket::open(&pair.peer()).expect("emulator socket");
    let stop = Arc::new(AtomicBool::new(false));
    let stop2 = stop.clone();
    let emulator = std::thread::spawn(move || {
        // As `cellrt drive-sim` does: the drives' end answers at once, above the RT thread.
        cellrt_test_support::sched::fifo(81);
        wire::serve(
            &socket,
            &mut segment,
            &mut faults,
            // The traced loop runs late at times; its drive lives on the loop's clock.
            wire::HostStalls::Excused {
                cycle: ct.as_duration(),
            },
            &stop2,
        )
        .expect("serve");
    });
    let text = format!(
        r#"
[cell]
name = "syscalls-ethercat-{pid}-{attempt}"
cycle_time_us = 2000
[rt]
priority = 80
missed_deadlines = "stretch"
[setpoints]
lookahead_ms = 1000
[watchdogs]
max_consecutive_overruns = 0
[ethercat]
interface = "{name}"
frame_timeout_us = 100000
[[axes]]
name = "y"
drive = "mr-j4-tm"
transport = "ethercat"
mode = "csp"
unit = "mm"
counts_per_unit = 4194.304
limits = {{ position = [0.0, 600.0], velocity = 400.0, acceleration = 2000.0, jerk = 20000.0 }}
"#,
        pid = std::process::id()
    );
    let cell = CellConfig::parse(Path::new("syscalls-ethercat.toml"), &text)
        .unwrap_or_else(|e| panic!("{e}"));
    let program = Program::parse(Path::new("p.toml"), PROGRAM, &cell).unwrap();
    let trace = syscall_trace::trace_steady_state(cell, program);
    stop.store(true, Ordering::Release);
    emulator.join().unwrap();
    trace
}

#[test]
fn on_ethercat_the_rt_loop_makes_only_its_sleep_and_frame_io_while_homing() {
    if !nix::unistd::geteuid().is_root() {
        println!("SKIPPED: needs root (a veth pair and raw sockets)");
        return;
    }
    if syscall_trace::strace_missing() {
        return;
    }
    let allowed: Vec<&str> = syscall_trace::SLEEP
        .iter()
        .chain(&FRAME_IO)
        .copied()
        .collect();
    // The loop stretches its clock over the stalls strace adds, and the far-end drive
    // excuses them: one run, judged whatever the machine's load.
    let Some(trace) = traced_run(1) else {
        return;
    };
    let others = trace.others(&allowed);
    assert!(
        others.is_empty(),
        "the RT loop made syscalls other than its sleep and frame I/O: {others:?}\n{}",
        trace.text.lines().take(200).collect::<Vec<_>>().join("\n")
    );
    let log = &trace.summary.recording.event_log;
    assert!(
        log.iter()
            .any(|l| l.contains("homing_finished") && l.contains("attained")),
        "no homing completed: {log:#?}"
    );
    assert!(
        !log.iter().any(|l| l.contains(": drive_fault [")),
        "a drive fault: {log:#?}"
    );
    assert!(
        trace.sleeps() >= 100,
        "only {} cycles traced; events {log:?}",
        trace.sleeps()
    );
}
