//! `cellrt bench loop` and `cellrt bench scaling`: the full cellrt loop (simulated MR-J5-G-N1
//! drives in csp, the planner, recording on) with N axes enabled and moving (at most 16 at once,
//! the planner's limit per move), from a generated configuration and program, through
//! `cellrt_runtime::host::controller::run`.

use std::fmt::Write as _;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Duration;

use cellrt_config::{CellConfig, MAX_AXES};
use cellrt_runtime::host::controller::{self, RunOptions};
use cellrt_runtime::host::program::Program;
use cellrt_runtime::rt::executive::RtCounters;
use cellrt_runtime::rt::histogram::Percentiles;
use cellrt_runtime::rt::thread::RtReport;
use cellrt_trajectory::MAX_MOVE_AXES;
use serde::Serialize;

use crate::error::BenchError;
use crate::latency;

/// Axis counts of `cellrt bench scaling`.
pub const SCALING_AXES: [usize; 5] = [1, 4, 16, 64, 256];

/// What to run.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct LoopOptions {
    /// Axes (1..=256).
    pub axes: usize,
    /// Cycle time, µs (one the drive supports: 125, 250, 500, 1000, 2000, 4000, 8000).
    pub interval_us: u32,
    /// Motion time, s (power-on and the final stop come on top).
    pub duration_s: f64,
    /// SCHED_FIFO priority.
    pub priority: u8,
    /// CPU of the RT thread.
    pub cpu: usize,
    /// Emulated MR-JE-C axes beside the loop (0..=[`MAX_JE_C`]), moved in the same steps.
    pub je_c: usize,
}

/// Most MR-JE-C axes a loop benchmark adds.
pub const MAX_JE_C: usize = 16;

/// The transports the benchmark's MR-JE-C axes take in turn (the RTU one at station 1).
const JE_C_TRANSPORTS: [&str; 4] = ["cclink-ief-basic", "modbus-tcp", "slmp", "modbus-rtu"];

impl LoopOptions {
    /// Validates raw command-line values (the cycle time is checked by the configuration).
    pub fn new(
        axes: usize,
        interval_us: u64,
        duration_s: f64,
        priority: u32,
        cpu: Option<usize>,
    ) -> Result<LoopOptions, BenchError> {
        if !(1..=MAX_AXES).contains(&axes) {
            return Err(BenchError::bad(format!(
                "--axes: must be 1..={MAX_AXES} (got {axes})"
            )));
        }
        let interval_us = u32::try_from(interval_us)
            .ok()
            .filter(|i| cellrt_cia402::CycleTime::from_micros(*i).is_ok())
            .ok_or_else(|| {
                BenchError::bad(format!(
                    "--interval: must be a cycle time of the drive: 125, 250, 500, 1000, 2000, 4000 or 8000 µs (got {interval_us})"
                ))
            })?;
        latency::validate_duration(duration_s)?;
        Ok(LoopOptions {
            axes,
            interval_us,
            duration_s,
            priority: latency::validate_priority(priority)?,
            cpu: latency::validate_cpu(cpu)?,
            je_c: 0,
        })
    }

    /// The same with `n` emulated MR-JE-C axes beside the loop.
    pub fn with_je_c(self, n: usize) -> Result<LoopOptions, BenchError> {
        if n > MAX_JE_C {
            return Err(BenchError::bad(format!(
                "--je-c: must be 0..={MAX_JE_C} (got {n})"
            )));
        }
        Ok(LoopOptions { je_c: n, ..self })
    }
}

/// Setpoint lookahead for `interval_us`: 1 s, within what the setpoint buffer holds (a loaded
/// machine can starve the non-RT planner for tens of milliseconds).
pub fn lookahead_ms(interval_us: u32) -> f64 {
    let max_cycles = (cellrt_runtime::services::SETPOINT_BUFFER_BLOCKS - 4)
        * cellrt_runtime::setpoints::BLOCK_CYCLES;
    let max_ms = max_cycles as f64 * f64::from(interval_us) / 1e3;
    (max_ms * 0.8).min(1000.0).floor()
}

/// Travel of axis `i` from 0, mm: 50..140, so the synchronised moves differ per axis.
fn travel(i: usize) -> f64 {
    50.0 + (i % 10) as f64 * 10.0
}

/// A cell of `axes` simulated MR-J5-G-N1 axes in csp named `a0…`, with the overrun watchdog off
/// (a noisy machine must not stop the benchmark) and recording to `record`.
pub fn config_text(name: &str, opts: &LoopOptions) -> String {
    let la = lookahead_ms(opts.interval_us);
    let mut s = format!(
        "[cell]\nname = \"{name}\"\ncycle_time_us = {}\n\n[rt]\ncpu = {}\npriority = {}\nlock_memory = true\n\n\
         [recording]\ncompression = \"zstd\"\n\n[setpoints]\nlookahead_ms = {la}\nstart_delay_ms = {}\n\n\
         [watchdogs]\nmax_consecutive_overruns = 0\n",
        opts.interval_us,
        opts.cpu,
        opts.priority,
        la.min(50.0)
    );
    for i in 0..opts.axes {
        let _ = write!(
            s,
            "\n[[axes]]\nname = \"a{i}\"\ndrive = \"mr-j5-g-n1\"\ntransport = \"sim\"\nmotor = {{ counts_per_rev = 10000 }}\nmode = \"csp\"\nunit = \"mm\"\n\
             counts_per_unit = 1000\nlimits = {{ position = [-500.0, 500.0], velocity = 400.0, acceleration = 4000.0, jerk = 40000.0 }}\n"
        );
    }
    for i in 0..opts.je_c {
        let transport = JE_C_TRANSPORTS[i % JE_C_TRANSPORTS.len()];
        let station = if transport == "modbus-rtu" {
            ", station = 1"
        } else {
            ""
        };
        // The master's watchdog off: a loaded machine must not stop the benchmark.
        let _ = write!(
            s,
            "\n[[axes]]\nname = \"c{i}\"\ndrive = \"mr-je-c\"\ntransport = \"{transport}\"\nmode = \"pp\"\nunit = \"mm\"\n\
             counts_per_unit = 1310.72\nlimits = {{ position = [-500.0, 500.0], velocity = 200.0, acceleration = 1000.0, jerk = 10000.0 }}\n\
             je_c = {{ emulate = true, watchdog_missed = 0{station} }}\n"
        );
    }
    s
}

/// Power on, then synchronised moves between −travel and +travel, enough to keep moving for
/// `duration_s` (the run is cut at the duration), then power off. The planner moves at most
/// [`MAX_MOVE_AXES`] axes per move, so with more axes the moves take groups of 16 in turn; every
/// axis is enabled, cycled and recorded all the time, at most 16 of them in motion.
pub fn program_text(axes: usize, duration_s: f64) -> String {
    program_text_with_je_c(axes, 0, duration_s)
}

/// [`program_text`] with `je_c` MR-JE-C axes `c0…` moved between −100 and +100 mm in every
/// move step, beside the streamed axes.
pub fn program_text_with_je_c(axes: usize, je_c: usize, duration_s: f64) -> String {
    // 2 × travel ≤ 280 mm at 400 mm/s, 4000 mm/s², 40 000 mm/s³: about 0.9 s per move.
    let moves = (duration_s / 0.5).ceil() as usize + 2;
    let groups: Vec<Vec<usize>> = (0..axes)
        .collect::<Vec<_>>()
        .chunks(MAX_MOVE_AXES)
        .map(<[usize]>::to_vec)
        .collect();
    let mut s = String::from("[[step]]\ndo = \"power_on\"\n");
    for m in 0..moves {
        let group = &groups[m % groups.len()];
        let sign = if (m / groups.len()).is_multiple_of(2) {
            1.0
        } else {
            -1.0
        };
        let targets: Vec<String> = group
            .iter()
            .map(|&i| format!("a{i} = {:.1}", sign * travel(i)))
            .chain((0..je_c).map(|i| format!("c{i} = {:.1}", sign * 100.0)))
            .collect();
        let _ = write!(
            s,
            "\n[[step]]\ndo = \"move\"\ntarget = {{ {} }}\n",
            targets.join(", ")
        );
    }
    s.push_str("\n[[step]]\ndo = \"power_off\"\n");
    s
}

/// What one loop benchmark measured.
#[derive(Debug, Clone, Serialize)]
pub struct LoopReport {
    /// What was asked for.
    pub options: LoopOptions,
    /// Cell name used.
    pub cell: String,
    /// How the run ended.
    pub outcome: String,
    /// Why the program failed, if it did.
    pub program_error: Option<String>,
    /// What the RT set-up achieved.
    pub rt: RtReport,
    /// Counters (cycles, overruns, underruns, …).
    pub counters: RtCounters,
    /// Wakeup latency percentiles.
    pub wakeup_latency: Percentiles,
    /// Loop body time percentiles (wakeup to the end of the bus exchange and record hand-off).
    pub loop_time: Percentiles,
    /// Loop body p50 / axes, µs.
    pub loop_p50_per_axis_us: f64,
    /// Loop body p99 / axes, µs.
    pub loop_p99_per_axis_us: f64,
    /// Recording size, bytes.
    pub recording_bytes: u64,
}

/// Runs the full loop with generated config and program; recording goes to a temp file that
/// is deleted afterwards.
pub fn run(opts: &LoopOptions) -> Result<LoopReport, BenchError> {
    use std::sync::atomic::{AtomicU32, Ordering};
    static RUN: AtomicU32 = AtomicU32::new(0);
    let name = format!(
        "bench-{}-{}",
        std::process::id(),
        RUN.fetch_add(1, Ordering::Relaxed)
    );
    let dir = tempfile::tempdir()
        .map_err(|e| BenchError::failed(format!("cannot create a temp dir: {e}")))?;
    let cfg_path = dir.path().join("bench.toml");
    let cfg_text = config_text(&name, opts);
    let cell =
        CellConfig::parse(&cfg_path, &cfg_text).map_err(|e| BenchError::bad(e.to_string()))?;
    let prog_path = dir.path().join("bench-program.toml");
    let text = program_text_with_je_c(opts.axes, opts.je_c, opts.duration_s);
    let program = Program::parse(&prog_path, &text, &cell)
        .map_err(|e| BenchError::failed(format!("generated program: {e}")))?;
    let record = dir.path().join(format!("{name}.mcap"));
    let summary = controller::run(
        &cell,
        RunOptions {
            program: Some(program),
            duration: Some(Duration::from_secs_f64(opts.duration_s)),
            record: Some(record.clone()),
            shutdown: Arc::new(AtomicBool::new(false)),
            hook: None,
            external_planner: false,
        },
    )
    .map_err(|e| BenchError::failed(e.to_string()))?;
    // Every part of the recording (a long run rotates).
    let recording_bytes = summary.recording.bytes;
    let outcome = serde_json::to_value(&summary.outcome)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default();
    let n = opts.axes as f64;
    Ok(LoopReport {
        options: *opts,
        cell: name,
        outcome,
        program_error: summary.program_error,
        rt: summary.rt,
        counters: summary.counters,
        wakeup_latency: summary.wakeup_latency,
        loop_time: summary.loop_time,
        loop_p50_per_axis_us: summary.loop_time.p50_us / n,
        loop_p99_per_axis_us: summary.loop_time.p99_us / n,
        recording_bytes,
    })
}

/// The report of one loop run.
pub fn render(r: &LoopReport) -> String {
    let mut s = String::new();
    let o = &r.options;
    let c = &r.counters;
    let _ = writeln!(
        s,
        "== cellrt bench loop: {} axes (mr-j5-g-n1, csp, sim){} at {} µs for {} s, recording on — {}",
        o.axes,
        if o.je_c > 0 {
            format!(" + {} emulated MR-JE-C axes", o.je_c)
        } else {
            String::new()
        },
        o.interval_us,
        o.duration_s,
        r.outcome
    );
    if let Some(e) = &r.program_error {
        let _ = writeln!(s, "program     failed: {e}");
    }
    let _ = writeln!(s, "rt          {}", r.rt.describe());
    let _ = writeln!(
        s,
        "cycles      {}   overruns {}   underruns {}   rejected {}   faults {}   dropped records {}",
        c.cycles, c.overruns, c.underruns, c.rejected_setpoints, c.faults, c.dropped_records
    );
    let w = &r.wakeup_latency;
    let _ = writeln!(
        s,
        "wakeup µs   min {:.1}   p50 {:.1}   p99 {:.1}   p99.9 {:.1}   max {:.1}",
        w.min_us, w.p50_us, w.p99_us, w.p999_us, w.max_us
    );
    let l = &r.loop_time;
    let _ = writeln!(
        s,
        "loop µs     min {:.1}   p50 {:.1}   p99 {:.1}   p99.9 {:.1}   max {:.1}",
        l.min_us, l.p50_us, l.p99_us, l.p999_us, l.max_us
    );
    let _ = writeln!(
        s,
        "per axis    p50 {:.2} µs   p99 {:.2} µs   recording {:.1} MiB",
        r.loop_p50_per_axis_us,
        r.loop_p99_per_axis_us,
        r.recording_bytes as f64 / 1048576.0
    );
    s
}

/// The scaling table.
pub fn render_scaling(rows: &[LoopReport]) -> String {
    let mut s = String::new();
    if let Some(r) = rows.first() {
        let _ = writeln!(
            s,
            "== cellrt bench scaling: {} µs, {} s per row, recording on",
            r.options.interval_us, r.options.duration_s
        );
    }
    let _ = writeln!(
        s,
        "| axes | loop p50 µs | loop p99 µs | p50 µs/axis | p99 µs/axis | wakeup p50 µs | wakeup p99 µs | overruns | underruns |"
    );
    let _ = writeln!(
        s,
        "|-----:|------------:|------------:|------------:|------------:|--------------:|--------------:|---------:|----------:|"
    );
    for r in rows {
        let _ = writeln!(
            s,
            "| {:>4} | {:>11.1} | {:>11.1} | {:>11.2} | {:>11.2} | {:>13.1} | {:>13.1} | {:>8} | {:>9} |",
            r.options.axes,
            r.loop_time.p50_us,
            r.loop_time.p99_us,
            r.loop_p50_per_axis_us,
            r.loop_p99_per_axis_us,
            r.wakeup_latency.p50_us,
            r.wakeup_latency.p99_us,
            r.counters.overruns,
            r.counters.underruns
        );
    }
    s
}

/// The RT loop with and without MR-JE-C axes beside it, from one run of both.
pub fn render_je_c_delta(without: &LoopReport, with: &LoopReport) -> String {
    let (a, b) = (without.loop_time.p99_us, with.loop_time.p99_us);
    format!(
        "mr-je-c     loop p99 {a:.1} µs without, {b:.1} µs with {} MR-JE-C axes: {:+.1} µs ({} the ≤ 1 µs condition)\n",
        with.options.je_c,
        b - a,
        if b - a <= 1.0 { "meets" } else { "misses" }
    )
}
