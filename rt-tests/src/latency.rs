//! The cyclictest-equivalent wakeup-latency loop: one thread set up like cellrt's RT thread
//! (`setup_current_thread`: affinity, SCHED_FIFO, mlockall, stack prefault; `/dev/cpu_dma_latency`
//! held at 0), sleeping to absolute deadlines with `clock_nanosleep(TIMER_ABSTIME)` and recording
//! wakeup − deadline into a preallocated histogram. The loop allocates nothing and makes no
//! syscall besides the sleep and the clock reads. A missed deadline is counted and skipped, never
//! caught up.

use std::sync::mpsc;
use std::thread::JoinHandle;

use cellrt_config::RtConfig;
use cellrt_runtime::rt::clock::{sleep_until, MonoTime};
use cellrt_runtime::rt::histogram::{NsHistogram, Percentiles};
use cellrt_runtime::rt::thread::{hold_cpu_dma_latency_zero, setup_current_thread, RtReport};
use serde::Serialize;

use crate::error::BenchError;
use crate::procscan;

/// Allowed `--interval`, µs.
pub const INTERVAL_US: std::ops::RangeInclusive<u64> = 50..=1_000_000;
/// Longest `--duration`, s (a day).
pub const MAX_DURATION_S: f64 = 86_400.0;
/// Default SCHED_FIFO priority (the same as `rt.priority`'s default).
pub const DEFAULT_PRIORITY: u8 = 80;
/// Stack of the measurement thread (the set-up prefaults 256 KiB of it).
const STACK_BYTES: usize = 2 * 1024 * 1024;

/// What to measure.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LatencyOptions {
    /// Period, µs.
    pub interval_us: u64,
    /// Length of the run, s.
    pub duration_s: f64,
    /// SCHED_FIFO priority.
    pub priority: u8,
    /// CPU to pin to.
    pub cpu: usize,
}

/// The last online CPU: the default for every benchmark (CPU 0 takes most interrupts and
/// housekeeping on a small machine).
pub fn default_cpu() -> usize {
    procscan::online_cpus().last().copied().unwrap_or(0)
}

/// Checks an interval (µs) against [`INTERVAL_US`].
pub fn validate_interval(interval_us: u64) -> Result<(), BenchError> {
    if !INTERVAL_US.contains(&interval_us) {
        return Err(BenchError::bad(format!(
            "--interval: must be {}..={} µs (got {interval_us})",
            INTERVAL_US.start(),
            INTERVAL_US.end()
        )));
    }
    Ok(())
}

/// Checks a duration in seconds: finite, > 0, at most a day.
pub fn validate_duration(duration_s: f64) -> Result<(), BenchError> {
    if !(duration_s.is_finite() && duration_s > 0.0 && duration_s <= MAX_DURATION_S) {
        return Err(BenchError::bad(format!(
            "--duration: must be a number of seconds in (0, {MAX_DURATION_S}] (got {duration_s})"
        )));
    }
    Ok(())
}

/// Checks a priority: 1..=99.
pub fn validate_priority(priority: u32) -> Result<u8, BenchError> {
    match u8::try_from(priority) {
        Ok(p) if (1..=99).contains(&p) => Ok(p),
        _ => Err(BenchError::bad(format!(
            "--priority: must be a SCHED_FIFO priority 1..=99 (got {priority})"
        ))),
    }
}

/// Checks that `cpu` is online; `None` picks [`default_cpu`].
pub fn validate_cpu(cpu: Option<usize>) -> Result<usize, BenchError> {
    let online = procscan::online_cpus();
    match cpu {
        None => Ok(default_cpu()),
        Some(c) if online.contains(&c) => Ok(c),
        Some(c) => Err(BenchError::bad(format!(
            "--cpu: CPU {c} does not exist or is offline (online: {})",
            online
                .iter()
                .map(|c| c.to_string())
                .collect::<Vec<_>>()
                .join(",")
        ))),
    }
}

impl LatencyOptions {
    /// Validates raw command-line values.
    pub fn new(
        interval_us: u64,
        duration_s: f64,
        priority: u32,
        cpu: Option<usize>,
    ) -> Result<LatencyOptions, BenchError> {
        validate_interval(interval_us)?;
        validate_duration(duration_s)?;
        let priority = validate_priority(priority)?;
        let cpu = validate_cpu(cpu)?;
        Ok(LatencyOptions {
            interval_us,
            duration_s,
            priority,
            cpu,
        })
    }
}

/// What one run measured.
#[derive(Debug, Clone)]
pub struct LatencyRun {
    /// What the thread set-up achieved.
    pub rt: RtReport,
    /// Wakeup latency, ns.
    pub latency: NsHistogram,
    /// Missed deadlines (skipped).
    pub overruns: u64,
}

/// The JSON and printed form of a run.
#[derive(Debug, Clone, Serialize)]
pub struct LatencyReport {
    /// What was asked for.
    pub options: LatencyOptions,
    /// What the thread set-up achieved.
    pub rt: RtReport,
    /// Wakeup latency percentiles (`count` is the number of wakeups).
    pub wakeup_latency: Percentiles,
    /// Missed deadlines (counted and skipped).
    pub overruns: u64,
    /// Non-empty histogram buckets: (upper bound ns, count).
    pub histogram_ns: Vec<(u64, u64)>,
}

impl LatencyRun {
    /// The report of this run.
    pub fn report(&self, options: LatencyOptions) -> LatencyReport {
        LatencyReport {
            options,
            rt: self.rt.clone(),
            wakeup_latency: self.latency.percentiles(),
            overruns: self.overruns,
            histogram_ns: self.latency.buckets(),
        }
    }
}

/// A measurement running on its own thread.
#[derive(Debug)]
pub struct Running {
    /// Thread id of the measurement thread (to exclude it from the /proc scan).
    pub tid: i32,
    handle: JoinHandle<LatencyRun>,
}

impl Running {
    /// Waits for the end of the run.
    pub fn join(self) -> Result<LatencyRun, BenchError> {
        self.handle
            .join()
            .map_err(|_| BenchError::failed("the measurement thread panicked"))
    }
}

/// Starts a measurement thread; returns once it is set up and measuring.
pub fn spawn(opts: LatencyOptions) -> Result<Running, BenchError> {
    let (tid_tx, tid_rx) = mpsc::channel();
    let handle = std::thread::Builder::new()
        .name("cellrt-bench".into())
        .stack_size(STACK_BYTES)
        .spawn(move || {
            let mut rt = setup_current_thread(&RtConfig {
                cpu: Some(opts.cpu),
                priority: opts.priority,
                planner_priority: None,
                lock_memory: true,
                reserve_cpu: false,
                missed_deadlines: Default::default(),
            });
            let _dma = hold_cpu_dma_latency_zero(&mut rt);
            let mut latency = NsHistogram::new();
            let _ = tid_tx.send(procscan::gettid());
            let overruns = measure(opts, &mut latency);
            LatencyRun {
                rt,
                latency,
                overruns,
            }
        })
        .map_err(|e| BenchError::failed(format!("cannot start the measurement thread: {e}")))?;
    let tid = tid_rx
        .recv()
        .map_err(|_| BenchError::failed("the measurement thread died during set-up"))?;
    Ok(Running { tid, handle })
}

/// Runs a measurement on a new thread and waits for it.
pub fn run(opts: LatencyOptions) -> Result<LatencyRun, BenchError> {
    spawn(opts)?.join()
}

/// The loop: allocation-free; returns the number of missed deadlines.
fn measure(opts: LatencyOptions, latency: &mut NsHistogram) -> u64 {
    let period = opts.interval_us * 1000;
    let duration = (opts.duration_s * 1e9) as u64;
    let start = MonoTime::now().plus(period);
    let end = start.plus(duration);
    let mut deadline = start;
    let mut overruns = 0u64;
    while deadline < end {
        sleep_until(deadline);
        let wake = MonoTime::now();
        latency.record(wake.since(deadline));
        let mut next = deadline.plus(period);
        if wake >= next {
            let missed = wake.since(next) / period + 1;
            overruns += missed;
            next = next.plus(missed * period);
        }
        deadline = next;
    }
    overruns
}

/// The report as the table `cellrt bench latency` prints.
pub fn render(r: &LatencyReport) -> String {
    use std::fmt::Write;
    let p = &r.wakeup_latency;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "== cellrt bench latency: {} µs for {} s on CPU {}, SCHED_FIFO {}",
        r.options.interval_us, r.options.duration_s, r.options.cpu, r.options.priority
    );
    let _ = writeln!(s, "rt          {}", r.rt.describe());
    for refused in &r.rt.refused {
        let _ = writeln!(s, "warning     {refused}");
    }
    let _ = writeln!(s, "wakeups     {}   overruns {}", p.count, r.overruns);
    let _ = writeln!(
        s,
        "latency µs  min {:.1}   p50 {:.1}   p99 {:.1}   p99.9 {:.1}   max {:.1}",
        p.min_us, p.p50_us, p.p99_us, p.p999_us, p.max_us
    );
    s
}
