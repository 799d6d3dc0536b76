//! `cellrt bench soak`: a long run of the full cell (the `bench loop` cell: N simulated axes in
//! csp, the planner, recording on, rotated or not) as it runs in production: the live view
//! serving a connected Foxglove client that reads every message, and the operator's `status`
//! polled every second. It watches what a long run can break: the process' resident memory,
//! open files and threads, sampled at a fixed period (they must stay flat), records dropped on
//! the way to the recording (none), and overruns beside Debian's `cyclictest` run for the same
//! time on the other CPU (its wakeups later than one cycle are the overruns a loop there would
//! have had). Completed recording files are checked (present, non-empty) and deleted as the run
//! goes, the last two kept until the end, so the disk holds a bounded amount.

use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use cellrt_config::CellConfig;
use cellrt_runtime::host::controller::{self, RunOptions};
use cellrt_runtime::host::operator::client::{OperatorClient, REPLY_TIMEOUT};
use cellrt_runtime::host::operator::wire::{Reply, Request};
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
    /// Recording rotation, s; `None`: one file for the whole run.
    pub rotate_s: Option<u32>,
    /// Memory sample period, s.
    pub sample_s: u32,
}

/// One sample of the process' resources.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct RssSample {
    /// Time since the cell started, s.
    pub t_s: f64,
    /// Resident set size, KiB (`VmRSS`).
    pub rss_kib: u64,
    /// Open file descriptors (`/proc/self/fd`).
    pub fds: u64,
    /// Threads (`Threads` of `/proc/self/status`).
    pub threads: u64,
}

impl RssSample {
    /// The process now, `t_s` after the start.
    fn take(t_s: f64) -> Self {
        let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
        let field = |name: &str| -> u64 {
            status
                .lines()
                .find_map(|l| l.strip_prefix(name))
                .and_then(|v| v.split_whitespace().next()?.parse().ok())
                .unwrap_or(0)
        };
        let fds = std::fs::read_dir("/proc/self/fd").map_or(0, |d| d.count() as u64);
        RssSample {
            t_s,
            rss_kib: field("VmRSS:"),
            fds,
            threads: field("Threads:"),
        }
    }
}

/// What the live view's client and the operator's status polling saw.
#[derive(Debug, Clone, Serialize)]
pub struct Clients {
    /// Messages the live view's client received.
    pub live_messages: u64,
    /// Why the live view's client stopped early, if it did (the run's figures are kept).
    pub live_error: Option<String>,
    /// `status` requests answered.
    pub status_answered: u64,
    /// `status` requests unanswered or refused.
    pub status_failed: u64,
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
    /// Resident memory, open files and threads over the run.
    pub rss: Vec<RssSample>,
    /// RSS growth from the first sample after the warm-up (a tenth of the run) to the last,
    /// KiB.
    pub rss_growth_kib: i64,
    /// RSS growth rate after the warm-up, KiB per hour (least-squares slope of the samples).
    pub rss_slope_kib_per_h: f64,
    /// The live view's client and the status polling.
    pub clients: Clients,
    /// cyclictest beside the cell, if it could run (root, installed).
    pub cyclictest: Option<CyclictestSide>,
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
    if opts.rotate_s == Some(0) || opts.sample_s == 0 {
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
    let rotation = match opts.rotate_s {
        Some(s) => format!("[recording]\nrotate_seconds = {s}\n"),
        None => "[recording]\n".to_string(),
    };
    let live = SocketAddr::from(([127, 0, 0, 1], crate::livebench::free_port()?));
    let text = config_text(&name, &opts.cell)
        .replace("[recording]\n", &rotation)
        .replace(
            "[rt]\n",
            &format!("[rt]\nplanner_priority = {}\n", PLANNER_PRIORITY),
        )
        + &format!("\n[live]\nlisten = \"{live}\"\npage_port = 0\n");
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
    let clients = ClientThreads::start(&name, live, opts.cell.cpu, done.clone());
    let start = Instant::now();
    let mut rss = Vec::new();
    let mut pruned = 0;
    let period = Duration::from_secs(u64::from(opts.sample_s));
    let mut next = start + period;
    while !done.load(Ordering::Acquire) {
        std::thread::sleep(Duration::from_millis(200));
        if Instant::now() >= next {
            next += period;
            let s = RssSample::take(start.elapsed().as_secs_f64());
            progress(&s);
            rss.push(s);
            pruned = prune(&record, pruned)?;
        }
    }
    let clients = clients.finish()?;
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
        rss_slope_kib_per_h: slope_per_hour(&rss, opts.cell.duration_s),
        rss,
        clients,
        cyclictest,
    })
}

/// The live view's client and the status poller, on threads of their own off the RT CPU.
struct ClientThreads {
    stop: Arc<AtomicBool>,
    live: std::thread::JoinHandle<Result<(), BenchError>>,
    received: Arc<AtomicU64>,
    status: std::thread::JoinHandle<(u64, u64)>,
}

/// Time between two `status` requests.
const STATUS_PERIOD: Duration = Duration::from_secs(1);

impl ClientThreads {
    /// Connects the live view's client to `live` and polls cell `name`'s status every second
    /// until the cell is `done`.
    fn start(name: &str, live: SocketAddr, rt_cpu: usize, done: Arc<AtomicBool>) -> Self {
        let received = Arc::new(AtomicU64::new(0));
        let (stop, count) = (done.clone(), received.clone());
        let live =
            std::thread::spawn(move || crate::livebench::viewer(live, rt_cpu, &stop, &count));
        let (cell, stop) = (name.to_string(), done.clone());
        let status = std::thread::spawn(move || {
            let (mut answered, mut failed) = (0u64, 0u64);
            let mut client = None;
            loop {
                std::thread::sleep(STATUS_PERIOD);
                if stop.load(Ordering::Acquire) {
                    break;
                }
                if client.is_none() {
                    client = OperatorClient::connect(Some(&cell)).ok();
                }
                match client
                    .as_ref()
                    .map(|c| c.request(&Request::Status, REPLY_TIMEOUT))
                {
                    Some(Ok(Reply::Status(_))) => answered += 1,
                    // Before the operator service is up, or after the cell has ended.
                    None => {}
                    Some(_) => failed += 1,
                }
            }
            (answered, failed)
        });
        ClientThreads {
            stop: done,
            live,
            received,
            status,
        }
    }

    /// Waits for both to end (they end with the cell).
    fn finish(self) -> Result<Clients, BenchError> {
        self.stop.store(true, Ordering::Release);
        let live_error = self
            .live
            .join()
            .map_err(|_| BenchError::failed("the live view's client panicked"))?
            .err()
            .map(|e| e.to_string());
        let (status_answered, status_failed) = self
            .status
            .join()
            .map_err(|_| BenchError::failed("the status poller panicked"))?;
        Ok(Clients {
            live_messages: self.received.load(Ordering::Relaxed),
            live_error,
            status_answered,
            status_failed,
        })
    }
}

/// Least-squares slope of RSS over time after the warm-up (a tenth of the run), KiB per hour.
fn slope_per_hour(rss: &[RssSample], duration_s: f64) -> f64 {
    let v: Vec<(f64, f64)> = rss
        .iter()
        .filter(|s| s.t_s >= duration_s / 10.0)
        .map(|s| (s.t_s, s.rss_kib as f64))
        .collect();
    let n = v.len() as f64;
    if v.len() < 2 {
        return 0.0;
    }
    let (mt, mr) = (
        v.iter().map(|p| p.0).sum::<f64>() / n,
        v.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let cov: f64 = v.iter().map(|p| (p.0 - mt) * (p.1 - mr)).sum();
    let var: f64 = v.iter().map(|p| (p.0 - mt) * (p.0 - mt)).sum();
    if var == 0.0 {
        0.0
    } else {
        cov / var * 3600.0
    }
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
    let rotation = match o.rotate_s {
        Some(s) => format!("rotated every {s} s"),
        None => "not rotated".to_string(),
    };
    let mut s = format!(
        "== cellrt bench soak: {} axes at {} µs for {} s, recording {rotation}, live view with one client, status every {} s — {}\n",
        o.cell.axes, o.cell.interval_us, o.cell.duration_s, STATUS_PERIOD.as_secs(), r.outcome
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
        s += &format!(
            "RSS slope after warm-up {:+.0} KiB/h   open files first {} last {}   threads first {} last {}\n",
            r.rss_slope_kib_per_h, first.fds, last.fds, first.threads, last.threads
        );
    }
    let c = &r.clients;
    s += &format!(
        "live view client: {} messages{}   status: {} answered, {} failed\n",
        c.live_messages,
        c.live_error
            .as_deref()
            .map(|e| format!(" (stopped early: {e})"))
            .unwrap_or_default(),
        c.status_answered,
        c.status_failed
    );
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
        let s = |t_s, rss_kib| RssSample {
            t_s,
            rss_kib,
            fds: 0,
            threads: 0,
        };
        let rss = [s(10.0, 100), s(400.0, 150), s(3600.0, 160)];
        assert_eq!(growth(&rss, 3600.0), 10);
        assert_eq!(growth(&[], 3600.0), 0);
        // 10 KiB over 3200 s after the warm-up: 11.25 KiB/h; the warm-up sample is left out.
        assert!((slope_per_hour(&rss, 3600.0) - 11.25).abs() < 1e-9);
        assert_eq!(slope_per_hour(&rss[..1], 3600.0), 0.0);
        let flat = [s(400.0, 150), s(800.0, 150), s(1200.0, 150)];
        assert_eq!(slope_per_hour(&flat, 3600.0), 0.0);
    }
}
