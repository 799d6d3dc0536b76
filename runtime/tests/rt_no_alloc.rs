//! Proves rule 1 of the RT thread: zero heap allocations in the loop body in steady state,
//! over more than 10,000 cycles with motion, recording, power on and power off active, and
//! operator SDO reads (`cellrt sdo`) carried by the RT thread meanwhile.
//!
//! A counting global allocator counts only on the RT thread, between the executive's
//! `SteadyState` and `Exit` phase hooks.

mod common;

use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use cellrt_config::CellConfig;
use cellrt_runtime::host::controller::{run, Outcome, RunOptions};
use cellrt_runtime::host::operator::client::{running_cells, OperatorClient};
use cellrt_runtime::host::operator::wire::{Reply, Request, SdoAnswer};
use cellrt_runtime::host::program::Program;
use cellrt_runtime::rt::executive::WARMUP_CYCLES;
use common::{hook, marked_heap_calls, LOOPS_EXITED};

const CELL: &str = include_str!("data/steady_cell.toml");

const PROGRAM: &str = include_str!("data/steady_program.toml");

#[test]
fn rt_loop_body_does_not_allocate_in_steady_state() {
    let dir = tempfile::tempdir().unwrap();
    let text = CELL.replace("\"steady\"", &format!("\"noalloc-{}\"", std::process::id()));
    let cell = CellConfig::parse(Path::new("noalloc.toml"), &text).unwrap();
    let program = Program::parse(Path::new("noalloc-program.toml"), PROGRAM, &cell).unwrap();
    let record = dir.path().join("noalloc.mcap");
    let done = Arc::new(AtomicBool::new(false));
    let reads = std::thread::spawn(sdo_reads(cell.name.clone(), done.clone()));
    let summary = run(
        &cell,
        RunOptions {
            program: Some(program),
            record: Some(record.clone()),
            hook: Some(hook),
            ..RunOptions::default()
        },
    )
    .expect("cell runs");
    done.store(true, Ordering::Release);
    let answered = reads.join().unwrap();
    assert!(answered >= 3, "only {answered} sdo reads answered");

    assert_eq!(summary.outcome, Outcome::ProgramCompleted, "{summary:?}");
    assert_eq!(
        LOOPS_EXITED.load(Ordering::Relaxed),
        1,
        "exit hook ran once"
    );
    let steady = summary.counters.cycles - WARMUP_CYCLES;
    assert!(steady >= 10_000, "only {steady} steady-state cycles");
    // Motion and recording really happened inside the counted window.
    let moves: Vec<&String> = summary
        .recording
        .event_log
        .iter()
        .filter(|l| l.contains("motion_started"))
        .collect();
    assert_eq!(moves.len(), 4, "{:?}", summary.recording.event_log);
    let in_window = moves
        .iter()
        .filter(|m| {
            let cycle: u64 = m
                .trim_start_matches("cycle ")
                .split(':')
                .next()
                .unwrap()
                .parse()
                .unwrap();
            cycle > WARMUP_CYCLES
        })
        .count();
    assert!(
        in_window >= 3,
        "motion must run inside the counted window: {moves:?}"
    );
    assert_eq!(summary.recording.cycle_messages, summary.counters.cycles);
    assert_eq!(summary.counters.dropped_records, 0);
    assert_eq!(
        marked_heap_calls(),
        0,
        "the RT loop allocated in steady state"
    );
}

/// Reads 6041h of axis x by the operator service every 50 ms while the cell runs; the number
/// of reads the drive answered.
fn sdo_reads(cell: String, done: Arc<AtomicBool>) -> impl FnOnce() -> u32 {
    move || {
        while !done.load(Ordering::Acquire) && !running_cells().contains(&cell) {
            std::thread::sleep(Duration::from_millis(10));
        }
        let Ok(client) = OperatorClient::connect(Some(&cell)) else {
            return 0;
        };
        let read = Request::Sdo {
            axis: "x".into(),
            index: 0x6041,
            sub: 0,
            value: None,
        };
        let mut answered = 0;
        while !done.load(Ordering::Acquire) {
            if let Ok(Reply::Sdo(r)) = client.request(&read, Duration::from_secs(5)) {
                answered += u32::from(matches!(r.outcome, SdoAnswer::Read { .. }));
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        answered
    }
}
