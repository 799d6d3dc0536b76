//! A full recorder hand-off queue: the RT thread counts every record it could not hand over
//! and, once a push succeeds again, records one `records_dropped` event with the count so far.

use std::path::Path;
use std::time::{Duration, Instant};

use cellrt_config::CellConfig;
use cellrt_runtime::handoff::{self, CellCommand, EventKind};
use cellrt_runtime::host::cell_bus::sim_bus;
use cellrt_runtime::rt::executive::Executive;
use cellrt_runtime::rt::setpoint_stream::SetpointStream;
use cellrt_runtime::services;

#[test]
fn dropped_records_are_counted_and_reported_once_the_queue_drains() {
    let text = format!(
        r#"
[cell]
name = "drops-{}"
cycle_time_us = 1000
[watchdogs]
max_consecutive_overruns = 0
[[axes]]
name = "x"
drive = "mr-j5-g-n1"
motor = {{ counts_per_rev = 10000 }}  # position counts per motor revolution (10 mm lead)
counts_per_unit = 1000
limits = {{ position = [0.0, 500.0], velocity = 100.0, acceleration = 1000.0, jerk = 10000.0 }}
"#,
        std::process::id()
    );
    let cell = CellConfig::parse(Path::new("drops.toml"), &text).unwrap();
    // Queues of 64 cycles that nobody drains (yet).
    let (h, handoff) = handoff::new(1, 64, handoff::PerCycleRecords::Taken);
    let node = services::node(&cell.name, "test").unwrap();
    let _publisher = services::setpoint_publisher(&node, &cell.name, 1).unwrap();
    let c = cell.clone();
    let rt = std::thread::spawn(move || {
        let node = services::node(&c.name, "rt").unwrap();
        let sub = services::setpoint_subscriber(&node, &c.name).unwrap();
        Executive::new(&c, sim_bus(&c), SetpointStream::new(sub), h, None).run()
    });
    let wait_cycle = |n: u64| {
        let end = Instant::now() + Duration::from_secs(20);
        while handoff.status().cycle() < n {
            assert!(Instant::now() < end, "the RT loop does not advance");
            std::thread::sleep(Duration::from_millis(5));
        }
    };
    wait_cycle(200);
    let mut events = Vec::new();
    while let Some(e) = handoff.pop_event() {
        events.push(e);
    }
    assert!(
        !events.iter().any(|e| e.kind == EventKind::RecordsDropped),
        "no event while the queue stays full"
    );
    // Drain: the next pushes succeed and the RT thread reports what it dropped.
    while handoff.pop_cycle().is_some() {}
    while handoff.pop_axis().is_some() {}
    let now = handoff.status().cycle();
    wait_cycle(now + 5);
    while let Some(e) = handoff.pop_event() {
        events.push(e);
    }
    let drops: Vec<_> = events
        .iter()
        .filter(|e| e.kind == EventKind::RecordsDropped)
        .collect();
    // One event per recovery from drops (the two queues drain one after the other, so a slow
    // test thread may see a second one), each with the running count.
    assert!(!drops.is_empty(), "{events:?}");
    assert!(drops[0].value > 100, "dropped so far: {}", drops[0].value);
    assert!(drops.windows(2).all(|w| w[1].value > w[0].value));
    // The cycle record written after the drain carries the same count.
    let rec = handoff.pop_cycle().expect("a cycle record after the drain");
    let last = drops.last().unwrap().value as u64;
    assert!(rec.dropped_records >= last);
    handoff.send_command(CellCommand::Quit).unwrap();
    let stats = rt.join().unwrap();
    assert!(stats.counters.dropped_records >= last);
}
