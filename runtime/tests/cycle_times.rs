//! Every allowed cycle time runs: deadlines are exact multiples of the period from the first one
//! (integer nanoseconds, no accumulated rounding) and the measured mean wakeup period is within
//! 0.1 % of the nominal one. A functional check with a generous tolerance, not a benchmark.

use std::path::Path;
use std::time::Duration;

use cellrt_config::CellConfig;
use cellrt_runtime::host::controller::{run, RunOptions};
use cellrt_runtime::host::record::proto::CycleStats;
use cellrt_runtime::host::record::topics::CYCLE_TOPIC;
use prost::Message;

/// Cycles each cycle time runs for.
const CYCLES: u64 = 2000;

fn check(us: u32) {
    let text = format!(
        r#"
[cell]
name = "period-{us}-{pid}"
cycle_time_us = {us}
[watchdogs]
max_consecutive_overruns = 0
[[axes]]
name = "x"
drive = "mr-j5-g-n1"
motor = {{ counts_per_rev = 10000 }}  # position counts per motor revolution (10 mm lead)
counts_per_unit = 1000
limits = {{ position = [0.0, 100.0], velocity = 10.0, acceleration = 100.0, jerk = 1000.0 }}
"#,
        pid = std::process::id()
    );
    let cell = CellConfig::parse(Path::new("period.toml"), &text).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("p.mcap");
    let period_ns = u64::from(us) * 1000;
    let summary = run(
        &cell,
        RunOptions {
            duration: Some(Duration::from_nanos(period_ns * CYCLES)),
            record: Some(rec.clone()),
            ..RunOptions::default()
        },
    )
    .unwrap();
    assert_eq!(summary.cycle_time_us, us);

    let bytes = std::fs::read(&rec).unwrap();
    let cycles: Vec<CycleStats> = mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(|m| m.unwrap())
        .filter(|m| m.channel.topic == CYCLE_TOPIC)
        .map(|m| CycleStats::decode(&*m.data).unwrap())
        .collect();
    assert!(
        cycles.len() as u64 >= CYCLES * 9 / 10,
        "{us} µs: {} cycles",
        cycles.len()
    );
    let first = &cycles[0];
    for c in &cycles {
        assert_eq!(
            c.deadline_ns - first.deadline_ns,
            (c.cycle - first.cycle) * period_ns,
            "{us} µs: deadline of cycle {} drifted",
            c.cycle
        );
    }
    // Mean wakeup period over the run (robust to jitter: end points only, minus outliers'
    // effect on the two ends by using the medians of the first and last 50 wakeups).
    let wake = |c: &CycleStats| c.deadline_ns + u64::from(c.wakeup_latency_ns);
    let median = |s: &[CycleStats]| {
        let mut v: Vec<(u64, u64)> = s
            .iter()
            .map(|c| (wake(c) - c.cycle * period_ns, c.cycle))
            .collect();
        v.sort();
        v[v.len() / 2].0
    };
    let n = cycles.len();
    let head = median(&cycles[..50]);
    let tail = median(&cycles[n - 50..]);
    let span_cycles = cycles[n - 1].cycle - cycles[0].cycle;
    let mean_period = period_ns as f64 + (tail as f64 - head as f64) / span_cycles as f64;
    let err = (mean_period - period_ns as f64).abs() / period_ns as f64;
    assert!(
        err < 1e-3,
        "{us} µs: mean period {mean_period} ns ({err:e})"
    );
}

#[test]
fn period_125_us() {
    check(125);
}
#[test]
fn period_250_us() {
    check(250);
}
#[test]
fn period_500_us() {
    check(500);
}
#[test]
fn period_1_ms() {
    check(1000);
}
#[test]
fn period_2_ms() {
    check(2000);
}
#[test]
fn period_4_ms() {
    check(4000);
}
#[test]
fn period_8_ms() {
    check(8000);
}
