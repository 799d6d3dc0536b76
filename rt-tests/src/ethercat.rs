//! `cellrt bench ethercat`: the full cellrt loop over EtherCAT with four emulated drives in
//! csp and in motion — on a veth pair with the segment (`cellrt drive-sim ethercat`) in a network
//! namespace of its own, or in-process — in rounds that alternate with `cellrt bench latency` on
//! the same CPU, so the exchange time and the loop's wakeup latency stand beside the plain wakeup
//! latency of the same minutes. Recording is on, as in `cellrt bench loop`. Lost frames and
//! working-counter errors are counted per round.

use std::fmt::Write as _;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Stdio};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Duration;

use cellrt_cia402::{profile, CycleTime, DriveModel, FrameCounters};
use cellrt_config::CellConfig;
use cellrt_runtime::host::controller::{self, RunError, RunOptions};
use cellrt_runtime::host::program::Program;
use cellrt_runtime::rt::histogram::{NsHistogram, Percentiles};
use serde::Serialize;

use crate::error::BenchError;
use crate::latency::{self, LatencyOptions};
use crate::loopbench::{self, LoopOptions};
use crate::netns::VethNamespace;

/// Drives on the benchmarked segment (the four-drive segment).
pub const DRIVES: usize = 4;

/// The EtherCAT models the segment is made of, in line order, where the cycle time allows them;
/// a model that does not support the cycle is replaced by the MR-J5-G-N1 (0.125–8 ms).
const MODELS: [DriveModel; DRIVES] = [
    DriveModel::MrJ3T04,
    DriveModel::MrJ4TM,
    DriveModel::MrJetGN1,
    DriveModel::MrJ5GN1,
];

/// The line line `cellrt drive-sim ethercat` prints once it serves the segment.
const DRIVE_SIM_READY: &str = "EtherCAT SubDevice(s) on";

/// Where the segment runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SegmentPlace {
    /// `cellrt drive-sim ethercat` in a network namespace, on the far end of a veth pair (root).
    Veth,
    /// The emulated segment in the controller's process (no network, no root).
    InProcess,
}

/// What to run.
#[derive(Debug, Clone, Serialize)]
pub struct EthercatBenchOptions {
    /// Cycle time, µs.
    pub interval_us: u32,
    /// EtherCAT time over all rounds, s.
    pub duration_s: f64,
    /// Rounds; each is an EtherCAT run then a latency run.
    pub rounds: u32,
    /// Length of each round's latency run, s.
    pub latency_s: f64,
    /// SCHED_FIFO priority of the RT thread (the emulator runs one above it).
    pub priority: u8,
    /// CPU of the RT thread, the emulator and the latency runs.
    pub cpu: usize,
    /// Where the segment runs.
    pub segment: SegmentPlace,
    /// The `cellrt` executable (it serves the segment with `drive-sim ethercat`).
    #[serde(skip)]
    pub exe: PathBuf,
}

impl EthercatBenchOptions {
    /// Validates raw command-line values; `latency_s` defaults to a third of a round.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        interval_us: u64,
        duration_s: f64,
        rounds: u32,
        latency_s: Option<f64>,
        priority: u32,
        cpu: Option<usize>,
        segment: SegmentPlace,
        exe: PathBuf,
    ) -> Result<EthercatBenchOptions, BenchError> {
        // The cycle time, priority and CPU are checked as `cellrt bench loop` checks them.
        let lo = LoopOptions::new(DRIVES, interval_us, duration_s, priority, cpu)?;
        if rounds == 0 || rounds > 1000 {
            return Err(BenchError::bad(format!(
                "--rounds: must be 1..=1000 (got {rounds})"
            )));
        }
        let round_s = duration_s / f64::from(rounds);
        if round_s < 1.0 {
            return Err(BenchError::bad(format!(
                "--duration: each of the {rounds} rounds needs at least 1 s of EtherCAT time (got {round_s:.3} s)"
            )));
        }
        let latency_s = latency_s.unwrap_or(round_s / 3.0);
        latency::validate_duration(latency_s).map_err(|_| {
            BenchError::bad(format!(
                "--latency-duration: must be a number of seconds in (0, {}] (got {latency_s})",
                latency::MAX_DURATION_S
            ))
        })?;
        Ok(EthercatBenchOptions {
            interval_us: lo.interval_us,
            duration_s,
            rounds,
            latency_s,
            priority: lo.priority,
            cpu: lo.cpu,
            segment,
            exe,
        })
    }

    fn round_s(&self) -> f64 {
        self.duration_s / f64::from(self.rounds)
    }
}

/// The segment's models for a cycle time of `interval_us` (see [`MODELS`]).
pub fn models(interval_us: u32) -> [DriveModel; DRIVES] {
    let ct = CycleTime::from_micros(interval_us).ok();
    MODELS.map(|m| match ct {
        Some(ct) if profile(m).supports_cycle_time(ct) => m,
        _ => DriveModel::MrJ5GN1,
    })
}

/// The bench cell: `cellrt bench loop`'s four-axis cell with the axes on EtherCAT drives
/// (`models`) on `interface`, the overrun watchdog off.
pub fn config_text(name: &str, opts: &EthercatBenchOptions, interface: &str) -> String {
    let lo = loop_options(opts);
    let mut s = loopbench::config_text(name, &lo);
    for (i, m) in models(opts.interval_us).iter().enumerate() {
        s = s.replacen(
            &format!("name = \"a{i}\"\ndrive = \"mr-j5-g-n1\"\ntransport = \"sim\""),
            &format!(
                "name = \"a{i}\"\ndrive = \"{}\"\ntransport = \"ethercat\"",
                m.as_str()
            ),
            1,
        );
    }
    let _ = write!(s, "\n[ethercat]\ninterface = \"{interface}\"\n");
    s
}

fn loop_options(opts: &EthercatBenchOptions) -> LoopOptions {
    LoopOptions {
        axes: DRIVES,
        interval_us: opts.interval_us,
        duration_s: opts.round_s(),
        priority: opts.priority,
        cpu: opts.cpu,
        je_c: 0,
    }
}

/// One round's EtherCAT runs.
#[derive(Debug, Clone, Default, Serialize)]
pub struct EthercatRound {
    /// Runs it took (a run that a drive fault stopped is followed by another one).
    pub runs: u32,
    /// Bring-ups that failed (a host stall: mostly a timeout) and were tried again.
    pub bringup_retries: u32,
    /// Why runs stopped early (e.g. a drive's communication alarm after a host stall).
    pub stopped: Vec<String>,
    /// Cycles run.
    pub cycles: u64,
    /// Missed deadlines.
    pub overruns: u64,
    /// Drive faults seen.
    pub faults: u64,
    /// Frames sent, lost, with a wrong working counter.
    pub frames: FrameCounters,
    /// Exchange time percentiles.
    pub exchange_time: Percentiles,
    /// |DC phase error| percentiles: the cyclic frame against its place in the SYNC0 cycle.
    pub dc_phase_error: Percentiles,
    /// Wakeup latency of the cell's RT loop.
    pub wakeup_latency: Percentiles,
}

/// One round's latency run.
#[derive(Debug, Clone, Serialize)]
pub struct LatencyRound {
    /// Missed deadlines.
    pub overruns: u64,
    /// Wakeup latency.
    pub wakeup_latency: Percentiles,
}

/// The benchmark's result.
#[derive(Debug, Clone, Serialize)]
pub struct EthercatBenchReport {
    /// What was asked for.
    pub options: EthercatBenchOptions,
    /// The segment's models, in line order.
    pub models: Vec<&'static str>,
    /// What the RT set-up of the cell achieved (first round).
    pub rt: String,
    /// Per round: the EtherCAT run.
    pub ethercat: Vec<EthercatRound>,
    /// Per round: the latency run.
    pub latency: Vec<LatencyRound>,
    /// All rounds: exchange time.
    pub exchange_time: Percentiles,
    /// All rounds: |DC phase error| of the cyclic frames.
    pub dc_phase_error: Percentiles,
    /// All rounds: the cell loop's wakeup latency.
    pub loop_wakeup_latency: Percentiles,
    /// All rounds: `cellrt bench latency`.
    pub bench_latency: Percentiles,
    /// All rounds: frames.
    pub frames: FrameCounters,
}

/// Shortest run a round starts for the time it has left.
const MIN_RUN_NS: u64 = 500_000_000;

/// Bring-ups a run tries before the benchmark gives up: a host stall during bring-up times the
/// mailbox or EEPROM access out, which is the machine's, not the transport's.
const BRINGUP_ATTEMPTS: u32 = 10;

/// One run of the bench cell for `seconds` (with its own `cellrt drive-sim` on a veth pair);
/// a bring-up that timed out is tried again. Returns the summary and the bring-ups retried.
fn run_once(
    opts: &EthercatBenchOptions,
    ns: Option<&VethNamespace>,
    cell: &CellConfig,
    cfg_path: &Path,
    prog_path: &Path,
    record: &Path,
    seconds: f64,
) -> Result<(controller::Summary, u32), BenchError> {
    let mut retries = 0;
    let mut last_bringup_error = String::new();
    loop {
        let program = Program::parse(prog_path, &loopbench::program_text(DRIVES, seconds), cell)
            .map_err(|e| BenchError::failed(format!("generated program: {e}")))?;
        let sim = match ns {
            Some(ns) => Some(start_drive_sim(&opts.exe, ns, cfg_path)?),
            None => None,
        };
        let summary = controller::run(
            cell,
            RunOptions {
                program: Some(program),
                duration: Some(Duration::from_secs_f64(seconds)),
                record: Some(record.to_path_buf()),
                shutdown: Arc::new(AtomicBool::new(false)),
                hook: None,
                external_planner: false,
            },
        );
        let sim_tail = sim.map(|(child, lines)| stop_drive_sim(child, lines));
        let _ = std::fs::remove_file(record);
        match summary {
            Ok(s) => return Ok((s, retries)),
            // A bring-up that a host stall upset: mostly a mailbox or EEPROM timeout; once an
            // SDO abort for the device state was seen as well (noted in the closing note of
            // the session that saw it), so any bring-up error is tried again, a few times.
            Err(RunError::Bus(e)) if retries + 1 < BRINGUP_ATTEMPTS => {
                retries += 1;
                eprintln!(
                    "cellrt bench ethercat: bring-up failed, trying again: {e}{}",
                    sim_tail
                        .map(|t| format!(" (drive-sim: {})", t.join(" / ")))
                        .unwrap_or_default()
                );
                last_bringup_error = e;
            }
            Err(e) => {
                let earlier = if retries > 0 {
                    format!(" (after {retries} failed bring-up(s), the last: {last_bringup_error})")
                } else {
                    String::new()
                };
                return Err(BenchError::failed(format!(
                    "{e}{earlier}{}",
                    sim_tail
                        .map(|t| format!(" (drive-sim: {})", t.join(" / ")))
                        .unwrap_or_default()
                )));
            }
        }
    }
}

/// `cellrt drive-sim ethercat` serving `cfg` on the far end of `ns`, started and ready.
fn start_drive_sim(
    exe: &Path,
    ns: &VethNamespace,
    cfg: &Path,
) -> Result<(Child, std::io::Lines<BufReader<std::process::ChildStderr>>), BenchError> {
    let mut child = ns
        .command(exe)
        .args(["drive-sim", "ethercat", "--interface", &ns.far, "--cell"])
        .arg(cfg)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| BenchError::failed(format!("cannot start cellrt drive-sim: {e}")))?;
    let Some(stderr) = child.stderr.take() else {
        return Err(BenchError::failed("cellrt drive-sim: no stderr pipe"));
    };
    let mut lines = BufReader::new(stderr).lines();
    let mut seen = Vec::new();
    for line in lines.by_ref().map_while(Result::ok) {
        if line.contains(DRIVE_SIM_READY) {
            return Ok((child, lines));
        }
        seen.push(line);
    }
    let _ = child.wait();
    Err(BenchError::failed(format!(
        "cellrt drive-sim did not start: {}",
        seen.join(" / ")
    )))
}

fn stop_drive_sim(
    mut child: Child,
    lines: std::io::Lines<BufReader<std::process::ChildStderr>>,
) -> Vec<String> {
    // SAFETY: kill has no memory preconditions; the pid is our child's.
    unsafe { libc::kill(child.id() as i32, libc::SIGINT) };
    let rest = lines.map_while(Result::ok).collect();
    let _ = child.wait();
    rest
}

/// What every run of the benchmark shares: the segment's place, the cell and its files.
struct BenchSetup {
    ns: Option<VethNamespace>,
    dir: tempfile::TempDir,
    cell: CellConfig,
    cfg_path: PathBuf,
    prog_path: PathBuf,
}

/// The segment (a veth pair with a namespace, or in-process) and the bench cell's config.
fn set_up(opts: &EthercatBenchOptions) -> Result<BenchSetup, BenchError> {
    let ns = match opts.segment {
        SegmentPlace::Veth => Some(
            VethNamespace::create(&format!("bench{}", std::process::id() % 100_000)).map_err(
                |why| {
                    BenchError::failed(format!(
                        "veth bench: {why} (use --in-process to run without a network)"
                    ))
                },
            )?,
        ),
        SegmentPlace::InProcess => None,
    };
    let interface = ns
        .as_ref()
        .map_or(cellrt_config::IN_PROCESS_INTERFACE.to_string(), |n| {
            n.near.clone()
        });
    let dir = tempfile::tempdir()
        .map_err(|e| BenchError::failed(format!("cannot create a temp dir: {e}")))?;
    let name = format!("bench-ecat-{}", std::process::id());
    let cfg_path = dir.path().join("bench-ethercat.toml");
    let cfg_text = config_text(&name, opts, &interface);
    std::fs::write(&cfg_path, &cfg_text)
        .map_err(|e| BenchError::failed(format!("cannot write {}: {e}", cfg_path.display())))?;
    let cell =
        CellConfig::parse(&cfg_path, &cfg_text).map_err(|e| BenchError::bad(e.to_string()))?;
    let prog_path = dir.path().join("bench-program.toml");
    Ok(BenchSetup {
        ns,
        dir,
        cell,
        cfg_path,
        prog_path,
    })
}

/// The histograms of one round, to be merged into the whole run's.
#[derive(Default)]
struct RoundHistograms {
    exchange: NsHistogram,
    dc_phase: NsHistogram,
    wakeup: NsHistogram,
}

/// One round of the cell: runs until the round's time is used, a drive fault ending a run (a
/// host stall long enough for the drives' communication check) counted and followed by a fresh
/// segment for the time left. `rt` gets the RT thread's description of the first run.
fn ethercat_round(
    opts: &EthercatBenchOptions,
    setup: &BenchSetup,
    round: u32,
    rt: &mut String,
) -> Result<(EthercatRound, RoundHistograms), BenchError> {
    let mut h = RoundHistograms::default();
    let mut e = EthercatRound::default();
    let round_ns = (opts.round_s() * 1e9) as u64;
    let mut done_ns = 0u64;
    while done_ns + MIN_RUN_NS <= round_ns {
        e.runs += 1;
        let left_s = (round_ns - done_ns) as f64 / 1e9;
        let record = setup
            .dir
            .path()
            .join(format!("round-{round}-{}.mcap", e.runs));
        let (summary, retries) = run_once(
            opts,
            setup.ns.as_ref(),
            &setup.cell,
            &setup.cfg_path,
            &setup.prog_path,
            &record,
            left_s,
        )
        .map_err(|e| BenchError::failed(format!("round {round}: {e}")))?;
        e.bringup_retries += retries;
        if rt.is_empty() {
            *rt = summary.rt.describe();
        }
        done_ns += (summary.counters.cycles + summary.counters.overruns)
            * u64::from(opts.interval_us)
            * 1000;
        h.exchange.merge(&summary.histograms.exchange_time);
        h.dc_phase.merge(&summary.histograms.dc_phase_error);
        h.wakeup.merge(&summary.histograms.wakeup_latency);
        let f = summary.frames.unwrap_or_default();
        e.frames.frames += f.frames;
        e.frames.lost += f.lost;
        e.frames.wkc_errors += f.wkc_errors;
        e.cycles += summary.counters.cycles;
        e.overruns += summary.counters.overruns;
        e.faults += summary.counters.faults;
        if let Some(err) = summary.program_error {
            e.stopped.push(err);
        }
        if summary.counters.cycles == 0 {
            break;
        }
    }
    e.exchange_time = h.exchange.percentiles();
    e.dc_phase_error = h.dc_phase.percentiles();
    e.wakeup_latency = h.wakeup.percentiles();
    Ok((e, h))
}

/// Runs the benchmark; `progress` is told what each round measured as it ends.
pub fn run(
    opts: &EthercatBenchOptions,
    progress: &mut dyn FnMut(&str),
) -> Result<EthercatBenchReport, BenchError> {
    let setup = set_up(opts)?;
    let lat_opts = LatencyOptions {
        interval_us: u64::from(opts.interval_us),
        duration_s: opts.latency_s,
        priority: opts.priority,
        cpu: opts.cpu,
    };
    let mut all = RoundHistograms::default();
    let mut bench_wakeup = NsHistogram::new();
    let mut frames = FrameCounters::default();
    let mut rt = String::new();
    let mut ethercat = Vec::new();
    let mut lat_rounds = Vec::new();
    for round in 1..=opts.rounds {
        let (e, h) = ethercat_round(opts, &setup, round, &mut rt)?;
        all.exchange.merge(&h.exchange);
        all.dc_phase.merge(&h.dc_phase);
        all.wakeup.merge(&h.wakeup);
        frames.frames += e.frames.frames;
        frames.lost += e.frames.lost;
        frames.wkc_errors += e.frames.wkc_errors;
        let lat = latency::run(lat_opts)?;
        bench_wakeup.merge(&lat.latency);
        let l = LatencyRound {
            overruns: lat.overruns,
            wakeup_latency: lat.latency.percentiles(),
        };
        progress(&render_round(round, &e, &l));
        ethercat.push(e);
        lat_rounds.push(l);
    }
    Ok(EthercatBenchReport {
        options: opts.clone(),
        models: models(opts.interval_us)
            .iter()
            .map(|m| m.as_str())
            .collect(),
        rt,
        ethercat,
        latency: lat_rounds,
        exchange_time: all.exchange.percentiles(),
        dc_phase_error: all.dc_phase.percentiles(),
        loop_wakeup_latency: all.wakeup.percentiles(),
        bench_latency: bench_wakeup.percentiles(),
        frames,
    })
}

/// The table row of one round (printed as it ends).
pub fn render_round(round: u32, e: &EthercatRound, l: &LatencyRound) -> String {
    let x = &e.exchange_time;
    let w = &e.wakeup_latency;
    let b = &l.wakeup_latency;
    let mut s = format!(
        "| {round:>5} | {:>8} | {:>5} | {:>4} | {:>8} | {:>8.1} | {:>8.1} | {:>8.1} | {:>8.1} | {:>8.1} | {:>8.1} | {:>8.1} | {:>8.1} | {:>4} | {:>6}",
        e.cycles,
        e.frames.lost,
        e.frames.wkc_errors,
        e.overruns,
        x.p50_us,
        x.p99_us,
        x.max_us,
        e.dc_phase_error.p99_us,
        w.p50_us,
        w.p99_us,
        b.p50_us,
        b.p99_us,
        e.runs,
        e.faults
    );
    if e.bringup_retries > 0 {
        let _ = write!(
            s,
            "\n|       | {} bring-up(s) failed (host stall) and were tried again",
            e.bringup_retries
        );
    }
    for why in &e.stopped {
        let _ = write!(s, "\n|       | stopped: {why}");
    }
    s
}

/// The header of the round table.
pub fn render_header(opts: &EthercatBenchOptions) -> String {
    let place = match opts.segment {
        SegmentPlace::Veth => {
            "veth pair, segment in a network namespace (cellrt drive-sim ethercat)"
        }
        SegmentPlace::InProcess => "in-process segment",
    };
    let models: Vec<&str> = models(opts.interval_us)
        .iter()
        .map(|m| m.as_str())
        .collect();
    format!(
        "== cellrt bench ethercat: {} drives ({}) in csp at {} µs, {place}; {} rounds of {:.0} s EtherCAT + {:.0} s latency on CPU {}, SCHED_FIFO {}\n\
         | round |   cycles |  lost |  wkc | overruns | exch p50 | exch p99 | exch max |  dc p99  | wake p50 | wake p99 | lat p50  | lat p99  | runs | faults |\n\
         |------:|---------:|------:|-----:|---------:|---------:|---------:|---------:|---------:|---------:|---------:|---------:|---------:|-----:|-------:|",
        DRIVES,
        models.join(", "),
        opts.interval_us,
        opts.rounds,
        opts.round_s(),
        opts.latency_s,
        opts.cpu,
        opts.priority
    )
}

/// The totals over all rounds.
pub fn render_totals(r: &EthercatBenchReport) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "rt          {}", r.rt);
    let _ = writeln!(
        s,
        "frames      {} sent   {} lost   {} working-counter errors",
        r.frames.frames, r.frames.lost, r.frames.wkc_errors
    );
    let row = |s: &mut String, what: &str, p: &Percentiles| {
        let _ = writeln!(
            s,
            "{what:<28} p50 {:>7.1}   p99 {:>7.1}   p99.9 {:>7.1}   max {:>8.1}   ({} samples)",
            p.p50_us, p.p99_us, p.p999_us, p.max_us, p.count
        );
    };
    row(&mut s, "exchange time µs", &r.exchange_time);
    row(&mut s, "|DC phase error| µs", &r.dc_phase_error);
    row(&mut s, "cell loop wakeup µs", &r.loop_wakeup_latency);
    row(&mut s, "cellrt bench latency µs", &r.bench_latency);
    s
}
