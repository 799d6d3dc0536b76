//! The recorder's memory stays bounded in an endless run: the MCAP writer's chunk index (kept
//! for each file's summary) is capped by rotating after `MAX_CHUNKS_PER_FILE` chunks, and the
//! summary's event log keeps its first `EVENT_LOG_LINES` lines while counting all events.

use std::path::Path;

use cellrt_config::CellConfig;
use cellrt_runtime::handoff::{self, CycleRecord, EventKind, EventRecord, RtEnd, NO_AXIS};
use cellrt_runtime::host::record::{Recorder, EVENT_LOG_LINES, MAX_CHUNKS_PER_FILE};

fn cell() -> CellConfig {
    let text = r#"
[cell]
name = "bounds"
cycle_time_us = 1000
[[axes]]
name = "x"
drive = "mr-j5-g-n1"
motor = { counts_per_rev = 10000 }
counts_per_unit = 1000
limits = { position = [0.0, 500.0], velocity = 100.0, acceleration = 1000.0, jerk = 10000.0 }
"#;
    CellConfig::parse(Path::new("bounds.toml"), text).unwrap()
}

/// Pushes until the recorder has taken it (the queue may be full for a moment).
fn push(done: impl Fn() -> bool) {
    while !done() {
        std::thread::sleep(std::time::Duration::from_micros(200));
    }
}

fn cycle_record(cycle: u64) -> CycleRecord {
    CycleRecord {
        cycle,
        deadline_ns: 1_000_000_000 + cycle * 1_000_000,
        ..CycleRecord::default()
    }
}

#[test]
fn a_file_holds_at_most_max_chunks_and_the_recording_rotates() {
    let mut cell = cell();
    // Every cycle closes its chunk: a chunk per cycle, counted exactly.
    cell.recording.flush_ms = 0;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bounds.mcap");
    let (rt, host): (RtEnd, _) = handoff::new(1, 1024, handoff::PerCycleRecords::Taken);
    let recorder = Recorder::start(&cell, Some(&path), std::sync::Arc::new(host)).unwrap();
    let cycles = MAX_CHUNKS_PER_FILE * 2 + 100;
    for c in 0..cycles {
        push(|| rt.push_cycle(cycle_record(c)));
    }
    let info = recorder.finish().unwrap();
    assert_eq!(info.cycle_messages, cycles);
    assert_eq!(info.files.len(), 3, "{:?}", info.files);
    let mut total = 0;
    for f in &info.files {
        let bytes = std::fs::read(f).unwrap();
        let summary = mcap::Summary::read(&bytes).unwrap().expect("a summary");
        let n = summary.chunk_indexes.len() as u64;
        assert!(
            n <= MAX_CHUNKS_PER_FILE + 1,
            "{}: {n} chunk indexes",
            f.display()
        );
        total += summary.stats.map_or(0, |s| s.message_count);
    }
    assert_eq!(total, cycles, "no message lost at a rotation");
}

#[test]
fn the_event_log_keeps_its_first_lines_and_counts_all_events() {
    let cell = cell();
    let (rt, host) = handoff::new(1, 64, handoff::PerCycleRecords::Taken);
    let recorder = Recorder::start(&cell, None, std::sync::Arc::new(host)).unwrap();
    let events = EVENT_LOG_LINES as u64 + 500;
    for c in 0..events {
        push(|| {
            rt.push_event(EventRecord {
                cycle: c,
                kind: EventKind::Overrun,
                axis: NO_AXIS,
                value: 2_000_000,
            })
        });
    }
    let info = recorder.finish().unwrap();
    assert_eq!(info.events, events);
    assert_eq!(info.event_log.len(), EVENT_LOG_LINES);
    assert!(
        info.event_log[0].starts_with("cycle 0: overrun"),
        "{}",
        info.event_log[0]
    );
}
