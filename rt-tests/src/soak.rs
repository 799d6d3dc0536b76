//! `cellrt bench soak`: a long run of the full cell (the `bench loop` cell: N simulated axes in
//! csp, the planner, recording on) with recording rotation, watching what a long run can break:
//! the process' resident memory, sampled at a fixed period (it must stay flat), records
//! dropped on the way to the recording (none), and overruns beside Debian's `cyclictest` run
//! for the same time on the other CPU (its wakeups later than one cycle are the overruns a loop
//! there would have had). Completed recording files are checked (present, non-empty) and
//! deleted as the run goes, the last two kept until the end, so the disk holds a bounded amount.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use cellrt_config::CellConfig;
use cellrt_runtime::host::controller::{self, RunOptions};
use cellrt_runtime::host::program::Program;
use cellrt_runtime::host::record::part_path;
use serde::Serialize;

use crate::loopbench::{config_text, program_text, LoopOptions};
use crate::{cyclictest, tools, BenchError};

/// SCHED_FIFO priority of the soak cell's planner thread.
const PLANNER_PRIORITY: u8 = 40;

/// What to run.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct SoakOptions {
    /// The cell (axes, interval, duration, RT CPU and priority).
    pub cell: LoopOptions,
    /// Recording rotation, s.
    pub rotate_s: u32,
    /// Memory sample period, s.
    pub sample_s: u32,
}

/// One memory sample.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct RssSample {
    /// Time since the cell started, s.
    pub t_s: f64,
    /// Resident set size, KiB (`VmRSS`).
    pub rss_kib: u64,
}

/// The cyclictest run beside the cell.
#[derive(Debug, Clone, Serialize)]
pub struct CyclictestSide {
    /// Its CPU.
    pub cpu: usize,
    /// Wakeups counted.
    pub samples: u64,
    /// Wakeups later than one cycle.
    pub late: u64,
    /// Largest latency, µs.
    pub max_us: f64,
}

/// What the soak measured.
#[derive(Debug, Clone, Serialize)]
pub struct SoakReport {
    /// What ran.
    pub options: SoakOptions,
    /// How the run ended.
    pub outcome: String,
    /// Cycles run.
    pub cycles: u64,
    /// Overruns of the cell's loop.
    pub overruns: u64,
    /// Records dropped between the RT thread and the recording.
    pub dropped_records: u64,
    /// Recording files written (all rotated parts).
    pub files: u32,
    /// Resident memory over the run.
    pub rss: Vec<RssSample>,
    /// RSS growth from the first sample after the warm-up (a tenth of the run) to the last,
    /// KiB.
    pub rss_growth_kib: i64,
    /// cyclictest beside the cell, if it could run (root, installed).
    pub cyclictest: Option<CyclictestSide>,
}

/// The resident set of this process, KiB.
fn rss_kib() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix("VmRSS:"))
                .and_then(|v| v.split_whitespace().next()?.parse().ok())
        })
        .unwrap_or(0)
}

/// Deletes completed parts (all but the newest two) after checking each is a non-empty file;
/// the number of the first part not yet deleted. A missing or empty part is an error.
fn prune(first: &Path, from: u32) -> Result<u32, BenchError> {
    let mut n = from;
    while part_path(first, n + 2).exists() {
        let p = part_path(first, n);
        let len = std::fs::metadata(&p).map(|m| m.len()).unwrap_or(0);
        if len == 0 {
            return Err(BenchError::failed(format!(
                "recording part {} is missing or empty",
                p.display()
            )));
        }
        std::fs::remove_file(&p)
            .map_err(|e| BenchError::failed(format!("cannot delete {}: {e}", p.display())))?;
        n += 1;
    }
    Ok(n)
}

/// Starts cyclictest on `cpu` for the soak's time, when it can run here.
fn start_cyclictest(
    opts: &SoakOptions,
    cpu: usize,
    histfile: &Path,
) -> Option<std::process::Child> {
    if !tools::is_root() {
        return None;
    }
    let bin = tools::find_in_path("cyclictest")?;
    let args = cyclictest::args(
        u64::from(opts.cell.interval_us),
        opts.cell.duration_s.ceil() as u64,
        opts.cell.priority,
        cpu,
        histfile,
    );
    cyclictest::spawn(&bin, &args).ok()
}

/// Runs the soak; `progress` is told each memory sample.
pub fn run(
    opts: &SoakOptions,
    progress: &mut dyn FnMut(&RssSample),
) -> Result<SoakReport, BenchError> {
    if opts.rotate_s == 0 || opts.sample_s == 0 {
        return Err(BenchError::bad(
            "--rotate and --sample must be at least 1 s",
        ));
    }
    let dir = tempfile::tempdir()
        .map_err(|e| BenchError::failed(format!("cannot create a temp dir: {e}")))?;
    let name = format!("soak-{}", std::process::id());
    let cfg_path = dir.path().join("soak.toml");
    // The planner runs SCHED_FIFO below the RT thread: an hour on a shared machine must not
    // end in an underrun because a compiler starved the planner past the lookahead.
    let text = config_text(&name, &opts.cell)
        .replace(
            "[recording]\n",
            &format!("[recording]\nrotate_seconds = {}\n", opts.rotate_s),
        )
        .replace(
            "[rt]\n",
            &format!("[rt]\nplanner_priority = {}\n", PLANNER_PRIORITY),
        );
    let cell = CellConfig::parse(&cfg_path, &text).map_err(|e| BenchError::bad(e.to_string()))?;
    let prog_path = dir.path().join("soak-program.toml");
    let program = Program::parse(
        &prog_path,
        &program_text(opts.cell.axes, opts.cell.duration_s),
        &cell,
    )
    .map_err(|e| BenchError::failed(format!("generated program: {e}")))?;
    let record = dir.path().join(format!("{name}.mcap"));
    let other_cpu = if opts.cell.cpu == 0 { 1 } else { 0 };
    let histfile = dir.path().join("cyclictest.hist");
    let cyclictest = start_cyclictest(opts, other_cpu, &histfile);
    let shutdown = Arc::new(AtomicBool::new(false));
    let done = Arc::new(AtomicBool::new(false));
    let (run_cell, run_record, run_done) = (cell.clone(), record.clone(), done.clone());
    let duration = Duration::from_secs_f64(opts.cell.duration_s);
    let cell_thread = std::thread::spawn(move || {
        let r = controller::run(
            &run_cell,
            RunOptions {
                program: Some(program),
                duration: Some(duration),
                record: Some(run_record),
                shutdown,
                hook: None,
                external_planner: false,
            },
        );
        run_done.store(true, Ordering::Release);
        r
    });
    let start = Instant::now();
    let mut rss = Vec::new();
    let mut pruned = 0;
    let period = Duration::from_secs(u64::from(opts.sample_s));
    let mut next = start + period;
    while !done.load(Ordering::Acquire) {
        std::thread::sleep(Duration::from_millis(200));
        if Instant::now() >= next {
            next += period;
            let s = RssSample {
                t_s: start.elapsed().as_secs_f64(),
                rss_kib: rss_kib(),
            };
            progress(&s);
            rss.push(s);
            pruned = prune(&record, pruned)?;
        }
    }
    let summary = cell_thread
        .join()
        .map_err(|_| BenchError::failed("the cell's thread panicked"))?
        .map_err(|e| BenchError::failed(e.to_string()))?;
    let cyclictest = match cyclictest {
        Some(child) => {
            let p = cyclictest::finish(child, &histfile)?;
            let cycle = u64::from(opts.cell.interval_us);
            Some(CyclictestSide {
                cpu: other_cpu,
                samples: p.total,
                late: p.hist.buckets.range(cycle..).map(|(_, n)| n).sum(),
                max_us: p.hist.max_us,
            })
        }
        None => None,
    };
    let files = (0..)
        .take_while(|&n| n < pruned || part_path(&record, n).exists())
        .count() as u32;
    Ok(SoakReport {
        options: *opts,
        outcome: serde_json::to_value(&summary.outcome)
            .ok()
            .and_then(|v| v.as_str().map(str::to_string))
            .unwrap_or_default(),
        cycles: summary.counters.cycles,
        overruns: summary.counters.overruns,
        dropped_records: summary.counters.dropped_records,
        files,
        rss_growth_kib: growth(&rss, opts.cell.duration_s),
        rss,
        cyclictest,
    })
}

/// RSS change from the first sample after a tenth of the run to the last.
fn growth(rss: &[RssSample], duration_s: f64) -> i64 {
    let warm = rss.iter().find(|s| s.t_s >= duration_s / 10.0);
    match (warm, rss.last()) {
        (Some(a), Some(b)) => b.rss_kib as i64 - a.rss_kib as i64,
        _ => 0,
    }
}

/// The report as text.
pub fn render(r: &SoakReport) -> String {
    let o = &r.options;
    let mut s = format!(
        "== cellrt bench soak: {} axes at {} µs for {} s, recording rotated every {} s — {}\n",
        o.cell.axes, o.cell.interval_us, o.cell.duration_s, o.rotate_s, r.outcome
    );
    s += &format!(
        "cycles {}   overruns {}   dropped records {}   recording files {}\n",
        r.cycles, r.overruns, r.dropped_records, r.files
    );
    if let (Some(first), Some(last)) = (r.rss.first(), r.rss.last()) {
        let max = r.rss.iter().map(|x| x.rss_kib).max().unwrap_or(0);
        s += &format!(
            "RSS KiB   first {} (t {:.0} s)   last {} (t {:.0} s)   max {}   growth after warm-up {:+}\n",
            first.rss_kib, first.t_s, last.rss_kib, last.t_s, max, r.rss_growth_kib
        );
    }
    match &r.cyclictest {
        Some(c) => {
            s += &format!(
                "cyclictest on CPU {}: {} wakeups, {} later than one cycle, max {:.0} µs\n",
                c.cpu, c.samples, c.late, c.max_us
            )
        }
        None => s += "cyclictest: not run (needs root and Debian's rt-tests)\n",
    }
    s
}

/// Where part `n` of a soak's recording would be (for tests).
pub fn part(first: &Path, n: u32) -> PathBuf {
    part_path(first, n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn completed_parts_are_pruned_keeping_the_newest_two() {
        let dir = tempfile::tempdir().unwrap();
        let first = dir.path().join("r.mcap");
        for n in 0..5 {
            std::fs::write(part(&first, n), b"x").unwrap();
        }
        assert_eq!(prune(&first, 0).unwrap(), 3);
        assert!(!part(&first, 2).exists() && part(&first, 3).exists());
        assert!(part(&first, 4).exists());
        std::fs::write(part(&first, 5), b"").unwrap();
        std::fs::write(part(&first, 6), b"x").unwrap();
        std::fs::write(part(&first, 3), b"").unwrap();
        assert!(prune(&first, 3)
            .unwrap_err()
            .to_string()
            .contains("r.3.mcap"));
    }

    #[test]
    fn growth_is_measured_after_the_warm_up() {
        let s = |t_s, rss_kib| RssSample { t_s, rss_kib };
        let rss = [s(10.0, 100), s(400.0, 150), s(3600.0, 160)];
        assert_eq!(growth(&rss, 3600.0), 10);
        assert_eq!(growth(&[], 3600.0), 0);
    }
}
