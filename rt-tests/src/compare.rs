//! `cellrt bench compare`: cyclictest and cellrt's latency loop, alternately (A B A B …), with
//! the same interval, priority, CPU and duration per round, optionally under `stress-ng` load;
//! both histograms go through the same 1 µs percentile arithmetic, and a verdict checks cellrt
//! against the targets p50 ≤ 1.1 × cyclictest p50 + 2 µs and p99 ≤ 1.25 × cyclictest p99 + 10 µs.

use std::time::Duration;

use cellrt_runtime::rt::thread::RtReport;
use serde::Serialize;

use crate::cyclictest;
use crate::error::BenchError;
use crate::hist::{UsHistogram, UsPercentiles};
use crate::latency::{self, LatencyOptions};
use crate::procscan::{self, Scan};
use crate::tools::{self, Load};

/// What to compare.
#[derive(Debug, Clone, Serialize)]
pub struct CompareOptions {
    /// Period, µs.
    pub interval_us: u64,
    /// Seconds per round and side (whole seconds: cyclictest's `-D`).
    pub duration_s: u64,
    /// SCHED_FIFO priority of both.
    pub priority: u8,
    /// CPU both are pinned to.
    pub cpu: usize,
    /// Run under `stress-ng`.
    pub load: bool,
    /// Rounds (each runs cyclictest, then cellrt).
    pub rounds: u32,
}

impl CompareOptions {
    /// Validates raw command-line values.
    pub fn new(
        interval_us: u64,
        duration_s: f64,
        priority: u32,
        cpu: Option<usize>,
        load: bool,
        rounds: u32,
    ) -> Result<CompareOptions, BenchError> {
        latency::validate_interval(interval_us)?;
        latency::validate_duration(duration_s)?;
        if duration_s.fract() != 0.0 {
            return Err(BenchError::bad(format!(
                "--duration: cyclictest takes whole seconds (got {duration_s})"
            )));
        }
        if !(1..=1000).contains(&rounds) {
            return Err(BenchError::bad(format!(
                "--rounds: must be 1..=1000 (got {rounds})"
            )));
        }
        Ok(CompareOptions {
            interval_us,
            duration_s: duration_s as u64,
            priority: latency::validate_priority(priority)?,
            cpu: latency::validate_cpu(cpu)?,
            load,
            rounds,
        })
    }
}

/// One side of one round.
#[derive(Debug, Clone, Serialize)]
pub struct RoundSide {
    /// Round number, from 1.
    pub round: u32,
    /// Percentiles of this round.
    pub latency: UsPercentiles,
    /// Whether another RT task was seen on the CPU during this round.
    pub contaminated: bool,
}

/// One tool's results over all rounds.
#[derive(Debug, Clone, Serialize)]
pub struct Side {
    /// Percentiles of all rounds' samples together.
    pub latency: UsPercentiles,
    /// Per round.
    pub rounds: Vec<RoundSide>,
    /// Missed deadlines (cellrt counts them; cyclictest's histogram does not).
    pub overruns: Option<u64>,
    /// Histogram (µs bucket, count), for plots.
    #[serde(skip)]
    pub hist: UsHistogram,
}

/// cellrt / cyclictest for each percentile.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Ratios {
    /// min.
    pub min: f64,
    /// p50.
    pub p50: f64,
    /// p99.
    pub p99: f64,
    /// p99.9.
    pub p999: f64,
    /// max.
    pub max: f64,
}

/// The targets and whether they are met.
#[derive(Debug, Clone, Serialize)]
pub struct Verdict {
    /// 1.1 × cyclictest p50 + 2 µs.
    pub p50_limit_us: f64,
    /// 1.25 × cyclictest p99 + 10 µs.
    pub p99_limit_us: f64,
    /// cellrt p50 within its limit.
    pub p50_ok: bool,
    /// cellrt p99 within its limit.
    pub p99_ok: bool,
    /// Both.
    pub pass: bool,
}

/// The whole comparison.
#[derive(Debug, Clone, Serialize)]
pub struct CompareReport {
    /// What was asked for.
    pub options: CompareOptions,
    /// `uname -r -v`.
    pub kernel: String,
    /// cyclictest version and command.
    pub cyclictest_command: cyclictest::Invocation,
    /// The load command, if any.
    pub load_command: Option<String>,
    /// What cellrt's thread set-up achieved.
    pub cellrt_rt: RtReport,
    /// cellrt's loop.
    pub cellrt: Side,
    /// cyclictest.
    pub cyclictest: Side,
    /// cellrt / cyclictest.
    pub ratios: Ratios,
    /// The targets.
    pub verdict: Verdict,
    /// RT tasks seen on the CPU during the measurements.
    pub scan: Scan,
    /// Whether any of them can have disturbed the measurement.
    pub contaminated: bool,
}

/// Applies the targets.
pub fn verdict(cellrt: &UsPercentiles, cyclictest: &UsPercentiles) -> Verdict {
    let p50_limit_us = 1.1 * cyclictest.p50_us + 2.0;
    let p99_limit_us = 1.25 * cyclictest.p99_us + 10.0;
    let p50_ok = cellrt.p50_us <= p50_limit_us;
    let p99_ok = cellrt.p99_us <= p99_limit_us;
    Verdict {
        p50_limit_us,
        p99_limit_us,
        p50_ok,
        p99_ok,
        pass: p50_ok && p99_ok,
    }
}

fn ratio(a: f64, b: f64) -> f64 {
    if b > 0.0 {
        a / b
    } else {
        f64::NAN
    }
}

/// When to scan /proc during a round: early enough that short rounds are covered.
fn scan_delay(duration_s: u64) -> Duration {
    Duration::from_millis((duration_s * 1000 / 2).min(1000))
}

fn kernel() -> String {
    let read = |f: &str| {
        std::fs::read_to_string(format!("/proc/sys/kernel/{f}"))
            .map(|s| s.trim().to_string())
            .unwrap_or_default()
    };
    format!("{} {}", read("osrelease"), read("version"))
}

/// One side of one round as measured, before it joins its [`Side`].
struct Measured {
    round: u32,
    hist: UsHistogram,
    scan: Scan,
}

impl Measured {
    /// The progress line of this side (`name` padded to align the two sides).
    fn line(&self, name: &str, rounds: u32, extra: &str) -> String {
        let p = self.hist.percentiles();
        format!(
            "round {}/{rounds} {name}  p50 {:.0} µs  p99 {:.0} µs  max {:.0} µs{extra}{}",
            self.round,
            p.p50_us,
            p.p99_us,
            p.max_us,
            if self.scan.contaminated() {
                "  (contaminated)"
            } else {
                ""
            }
        )
    }
}

impl Side {
    /// Adds a round's histogram and per-round percentiles; its scan joins `scan`.
    fn add(&mut self, m: Measured, scan: &mut Scan) {
        self.rounds.push(RoundSide {
            round: m.round,
            latency: m.hist.percentiles(),
            contaminated: m.scan.contaminated(),
        });
        self.hist.merge(&m.hist);
        scan.merge(m.scan);
    }
}

/// One cyclictest run of the round, scanned for competing RT threads while it runs; with the
/// command line it ran.
fn cyclictest_round(
    opts: &CompareOptions,
    bin: &std::path::Path,
    dir: &std::path::Path,
    round: u32,
) -> Result<(Measured, String), BenchError> {
    let histfile = dir.join(format!("cyclictest-{round}.hist"));
    let args = cyclictest::args(
        opts.interval_us,
        opts.duration_s,
        opts.priority,
        opts.cpu,
        &histfile,
    );
    let command = format!("cyclictest {}", args.join(" "));
    let child = cyclictest::spawn(bin, &args)?;
    let child_pid = child.id() as i32;
    std::thread::sleep(scan_delay(opts.duration_s));
    let me = std::process::id() as i32;
    let scan = procscan::scan(opts.cpu, opts.priority, &[child_pid, me], &[]);
    let parsed = cyclictest::finish(child, &histfile)?;
    Ok((
        Measured {
            round,
            hist: parsed.hist,
            scan,
        },
        command,
    ))
}

/// One cellrt latency run of the round on its own thread, scanned like cyclictest's; with the
/// RT set-up that took effect and its overruns.
fn cellrt_round(
    opts: &CompareOptions,
    lat_opts: LatencyOptions,
    round: u32,
) -> Result<(Measured, RtReport, u64), BenchError> {
    let running = latency::spawn(lat_opts)?;
    std::thread::sleep(scan_delay(opts.duration_s));
    let scan = procscan::scan(opts.cpu, opts.priority, &[], &[running.tid]);
    let run = running.join()?;
    Ok((
        Measured {
            round,
            hist: UsHistogram::from_ns(&run.latency),
            scan,
        },
        run.rt,
        run.overruns,
    ))
}

/// Runs the comparison; `progress` gets one line per finished round side.
pub fn run(
    opts: &CompareOptions,
    mut progress: impl FnMut(&str),
) -> Result<CompareReport, BenchError> {
    let bin = tools::ensure_tool("cyclictest", "rt-tests")?;
    let version = cyclictest::version(&bin);
    let dir = tempfile::tempdir()
        .map_err(|e| BenchError::failed(format!("cannot create a temp dir: {e}")))?;
    let mut load = if opts.load {
        // Both sides of every round, plus start-up slack; stopped as soon as we are done.
        let seconds = u64::from(opts.rounds) * 2 * (opts.duration_s + 2) + 10;
        let l = Load::start(seconds, dir.path())?;
        std::thread::sleep(Duration::from_secs(1));
        Some(l)
    } else {
        None
    };
    let lat_opts = LatencyOptions {
        interval_us: opts.interval_us,
        duration_s: opts.duration_s as f64,
        priority: opts.priority,
        cpu: opts.cpu,
    };
    let mut cellrt = Side {
        latency: UsPercentiles::default(),
        rounds: Vec::new(),
        overruns: Some(0),
        hist: UsHistogram::default(),
    };
    let mut cyc = Side {
        latency: UsPercentiles::default(),
        rounds: Vec::new(),
        overruns: None,
        hist: UsHistogram::default(),
    };
    let mut scan = Scan::default();
    let mut cellrt_rt = RtReport::default();
    let mut command = String::new();
    for round in 1..=opts.rounds {
        // A: cyclictest, then B: cellrt, in this process on its own thread.
        let (a, cmd) = cyclictest_round(opts, &bin, dir.path(), round)?;
        command = cmd;
        progress(&a.line("cyclictest", opts.rounds, ""));
        cyc.add(a, &mut scan);
        let (b, rt, overruns) = cellrt_round(opts, lat_opts, round)?;
        progress(&b.line("cellrt    ", opts.rounds, &format!("  overruns {overruns}")));
        cellrt.add(b, &mut scan);
        cellrt.overruns = Some(cellrt.overruns.unwrap_or(0) + overruns);
        cellrt_rt = rt;
    }
    let load_command = load.as_ref().map(|l| l.command.clone());
    if let Some(l) = load.as_mut() {
        l.stop();
    }
    cellrt.latency = cellrt.hist.percentiles();
    cyc.latency = cyc.hist.percentiles();
    let (a, b) = (&cellrt.latency, &cyc.latency);
    let ratios = Ratios {
        min: ratio(a.min_us, b.min_us),
        p50: ratio(a.p50_us, b.p50_us),
        p99: ratio(a.p99_us, b.p99_us),
        p999: ratio(a.p999_us, b.p999_us),
        max: ratio(a.max_us, b.max_us),
    };
    let verdict = verdict(a, b);
    let contaminated = scan.contaminated();
    Ok(CompareReport {
        options: opts.clone(),
        kernel: kernel(),
        cyclictest_command: cyclictest::Invocation {
            version,
            command: command.replace(&dir.path().display().to_string(), "$TMP"),
        },
        load_command,
        cellrt_rt,
        cellrt,
        cyclictest: cyc,
        ratios,
        verdict,
        scan,
        contaminated,
    })
}

/// The side-by-side table.
pub fn render(r: &CompareReport) -> String {
    use std::fmt::Write;
    let o = &r.options;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "== cellrt bench compare: {} µs, {} × {} s per side, CPU {}, SCHED_FIFO {}, {}",
        o.interval_us,
        o.rounds,
        o.duration_s,
        o.cpu,
        o.priority,
        if o.load { "under load" } else { "idle" }
    );
    let _ = writeln!(s, "kernel      {}", r.kernel);
    let _ = writeln!(
        s,
        "cyclictest  {}: {}",
        r.cyclictest_command.version, r.cyclictest_command.command
    );
    if let Some(l) = &r.load_command {
        let _ = writeln!(s, "load        {l}");
    }
    let _ = writeln!(s, "cellrt      {}", r.cellrt_rt.describe());
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "| µs         | {:>8} | {:>8} | {:>8} | {:>8} | {:>8} | {:>9} |",
        "min", "p50", "p99", "p99.9", "max", "samples"
    );
    let _ = writeln!(
        s,
        "|------------|----------|----------|----------|----------|----------|-----------|"
    );
    for (name, p) in [
        ("cyclictest", &r.cyclictest.latency),
        ("cellrt", &r.cellrt.latency),
    ] {
        let _ = writeln!(
            s,
            "| {name:<10} | {:>8.0} | {:>8.0} | {:>8.0} | {:>8.0} | {:>8.0} | {:>9} |",
            p.min_us, p.p50_us, p.p99_us, p.p999_us, p.max_us, p.count
        );
    }
    let q = &r.ratios;
    let _ = writeln!(
        s,
        "| ratio      | {:>8.2} | {:>8.2} | {:>8.2} | {:>8.2} | {:>8.2} |           |",
        q.min, q.p50, q.p99, q.p999, q.max
    );
    let _ = writeln!(s);
    let v = &r.verdict;
    let mark = |ok: bool| if ok { "ok" } else { "MISSED" };
    let _ = writeln!(
        s,
        "target      p50 {:.0} ≤ {:.1} µs (1.1 × cyclictest + 2): {}",
        r.cellrt.latency.p50_us,
        v.p50_limit_us,
        mark(v.p50_ok)
    );
    let _ = writeln!(
        s,
        "target      p99 {:.0} ≤ {:.1} µs (1.25 × cyclictest + 10): {}",
        r.cellrt.latency.p99_us,
        v.p99_limit_us,
        mark(v.p99_ok)
    );
    let _ = writeln!(
        s,
        "overruns    cellrt {} (missed deadlines, skipped)",
        r.cellrt.overruns.unwrap_or(0)
    );
    if r.contaminated {
        let _ = writeln!(s, "CONTAMINATED: other RT tasks may run on CPU {}:", o.cpu);
        for t in &r.scan.contaminating {
            let _ = writeln!(
                s,
                "  pid {} tid {} {} {} {} (cpus {})",
                t.pid, t.tid, t.comm, t.policy, t.priority, t.cpus_allowed
            );
        }
    } else {
        let _ = writeln!(
            s,
            "clean       no other RT task that could preempt the measurement on CPU {} ({} harmless kernel RT threads ignored)",
            o.cpu,
            r.scan.ignored.len()
        );
    }
    let _ = writeln!(
        s,
        "verdict     {}{}",
        if v.pass { "PASS" } else { "FAIL" },
        if r.contaminated {
            " (contaminated run)"
        } else {
            ""
        }
    );
    s
}
