//! `cellrt bench`: the latency and loop benchmarks of `cellrt-rt-tests`, as a thin CLI.

use std::path::PathBuf;

use cellrt_rt_tests::{compare, latency, loopbench, plot, write_json, BenchError};
use clap::{Args, Subcommand};

use crate::exit::Exit;

/// `cellrt bench`.
#[derive(Debug, Args)]
pub struct BenchArgs {
    /// Which benchmark.
    #[command(subcommand)]
    pub command: BenchCommand,
}

/// Benchmarks.
#[derive(Debug, Subcommand)]
pub enum BenchCommand {
    /// Wakeup latency of an absolute-deadline sleep loop on a thread set up like the RT thread
    /// (the cyclictest equivalent).
    Latency(LatencyArgs),
    /// cyclictest and `cellrt bench latency` alternately, side by side, with a verdict.
    Compare(CompareArgs),
    /// The full cellrt loop with N simulated axes in motion and recording on.
    Loop(LoopArgs),
    /// Loop body time for 1, 4, 16, 64 and 256 axes.
    Scaling(ScalingArgs),
    /// Round trip of operator requests (status) to a running cell (`--cell NAME`).
    Operator(OperatorArgs),
    /// Setpoint block delivery (planner → RT reader) beside raw iceoryx2, alternating rounds.
    Ipc(IpcArgs),
    /// The cell loop over EtherCAT (4 emulated drives on a veth pair, or in-process): exchange
    /// time, lost frames and wakeup latency, in rounds alternating with `bench latency`.
    Ethercat(EthercatArgs),
    /// Round trip of each MR-JE-C transport (CC-Link IE Field Basic, SLMP, Modbus/TCP, Modbus
    /// RTU) to the emulated drive beside a raw UDP/TCP/pty echo, in the same ticks.
    #[command(name = "je-c")]
    JeC(JeCArgs),
    /// A long run of the loop cell with recording rotation: resident memory sampled, records
    /// dropped, overruns beside cyclictest on the other CPU.
    Soak(SoakArgs),
    /// What the live view costs: the loop cell in rounds without the live view, with it and no
    /// viewer, and with one viewer; CPU of the recorder, the live view and the viewer, and the
    /// RT loop's percentiles.
    Live(LiveArgs),
}

/// `cellrt bench live`.
#[derive(Debug, Args)]
pub struct LiveArgs {
    /// Number of simulated axes, 1..=256.
    #[arg(long, value_name = "N", default_value_t = 16)]
    pub axes: usize,
    #[command(flatten)]
    pub common: Common,
    /// Rounds of each mode.
    #[arg(long, value_name = "N", default_value_t = 3)]
    pub rounds: usize,
    /// Also write the result as JSON to this file.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
}

/// `cellrt bench soak`.
#[derive(Debug, Args)]
pub struct SoakArgs {
    /// Number of simulated axes, 1..=256.
    #[arg(long, value_name = "N", default_value_t = 16)]
    pub axes: usize,
    #[command(flatten)]
    pub common: Common,
    /// Recording rotation, seconds.
    #[arg(long, value_name = "SECONDS", default_value_t = 300)]
    pub rotate: u32,
    /// Write one recording file for the whole run (no rotation), to see what an unrotated
    /// recording holds in memory.
    #[arg(long, conflicts_with = "rotate")]
    pub no_rotate: bool,
    /// Memory sample period, seconds.
    #[arg(long, value_name = "SECONDS", default_value_t = 10)]
    pub sample: u32,
    /// Also write the result as JSON to this file.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
}

/// `cellrt bench je-c`.
#[derive(Debug, Args)]
pub struct JeCArgs {
    /// Time between ticks, ms (each path runs once per tick; the drive answers within 10 ms).
    #[arg(long, value_name = "MS", default_value_t = 10)]
    pub interval_ms: u64,
    /// Length of the run, seconds.
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = 10.0,
        allow_negative_numbers = true
    )]
    pub duration: f64,
    /// Only these paths (comma-separated: cclink, cclink-bare, udp-echo, slmp-udp, slmp-tcp,
    /// modbus-tcp, tcp-echo, modbus-rtu, pty-echo); all by default.
    #[arg(long, value_delimiter = ',')]
    pub paths: Vec<String>,
    /// Also write the result as JSON to this file.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
}

/// `cellrt bench ethercat`.
#[derive(Debug, Args)]
pub struct EthercatArgs {
    /// Cycle time, µs (125, 250, 500, 1000, 2000, 4000 or 8000).
    #[arg(long, value_name = "µs")]
    pub interval: u64,
    /// EtherCAT time over all rounds: seconds, or e.g. 90s, 10m.
    #[arg(
        long,
        value_name = "DURATION",
        allow_negative_numbers = true,
        value_parser = crate::numbers::duration_seconds
    )]
    pub duration: f64,
    /// Rounds; each runs the cell over EtherCAT, then `bench latency`.
    #[arg(long, value_name = "N", default_value_t = 5)]
    pub rounds: u32,
    /// Length of each round's `bench latency` run, seconds (default: a third of a round).
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true)]
    pub latency_duration: Option<f64>,
    /// SCHED_FIFO priority of the RT thread (the emulator runs one above it).
    #[arg(long, value_name = "N", default_value_t = u32::from(latency::DEFAULT_PRIORITY))]
    pub priority: u32,
    /// CPU of the RT thread, the emulator and the latency runs (default: the last online CPU).
    #[arg(long, value_name = "N")]
    pub cpu: Option<usize>,
    /// Run the segment in-process instead of on a veth pair (no network, no root).
    #[arg(long)]
    pub in_process: bool,
    /// Also write the result as JSON to this file.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
}

/// `cellrt bench ipc`.
#[derive(Debug, Args)]
pub struct IpcArgs {
    /// Axes per block (the payload is 16 cycles × axes × 24 bytes).
    #[arg(long, default_value_t = 4)]
    pub axes: usize,
    /// Rounds per side.
    #[arg(long, default_value_t = 4)]
    pub rounds: u32,
    /// Blocks per round.
    #[arg(long, default_value_t = 2000)]
    pub count: u32,
    /// Also write the result as JSON to this file.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
}

/// `cellrt bench operator`.
#[derive(Debug, Args)]
pub struct OperatorArgs {
    /// Requests to time.
    #[arg(long, default_value_t = 2000)]
    pub count: u32,
}

/// Options every latency benchmark shares.
#[derive(Debug, Args)]
pub struct Common {
    /// Period, µs.
    #[arg(long, value_name = "µs")]
    pub interval: u64,
    /// Length of the run (per round and side for `compare`): seconds, or e.g. 90s, 10m, 1h.
    #[arg(
        long,
        value_name = "DURATION",
        allow_negative_numbers = true,
        value_parser = crate::numbers::duration_seconds
    )]
    pub duration: f64,
    /// SCHED_FIFO priority, 1..=99.
    #[arg(long, value_name = "N", default_value_t = u32::from(latency::DEFAULT_PRIORITY))]
    pub priority: u32,
    /// CPU to pin to (default: the last online CPU).
    #[arg(long, value_name = "N")]
    pub cpu: Option<usize>,
}

/// `cellrt bench latency`.
#[derive(Debug, Args)]
pub struct LatencyArgs {
    #[command(flatten)]
    pub common: Common,
    /// Also write the result as JSON to this file.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
}

/// `cellrt bench compare`.
#[derive(Debug, Args)]
pub struct CompareArgs {
    #[command(flatten)]
    pub common: Common,
    /// Run under stress-ng load (installed with apt-get when missing and running as root).
    #[arg(long)]
    pub load: bool,
    /// Rounds; each runs cyclictest, then cellrt.
    #[arg(long, value_name = "N", default_value_t = 4)]
    pub rounds: u32,
    /// Draw both latency histograms into this SVG file.
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
    /// Also write the result as JSON to this file.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
}

/// `cellrt bench loop`.
#[derive(Debug, Args)]
pub struct LoopArgs {
    /// Number of simulated axes, 1..=256.
    #[arg(long, value_name = "N")]
    pub axes: usize,
    /// Also run the cell with N emulated MR-JE-C axes beside the loop (moved in the same
    /// steps), right after the run without, and print the loop p99 of both.
    #[arg(long = "je-c", value_name = "N", default_value_t = 0)]
    pub je_c: usize,
    #[command(flatten)]
    pub common: Common,
    /// Also write the result as JSON to this file.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
}

/// `cellrt bench scaling`.
#[derive(Debug, Args)]
pub struct ScalingArgs {
    #[command(flatten)]
    pub common: Common,
    /// Also write the rows as JSON to this file.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
}

/// Runs `cellrt bench`.
pub fn run(args: BenchArgs, cell: Option<String>) -> Exit {
    let result = match args.command {
        BenchCommand::Operator(a) => run_operator(a, cell.as_deref()),
        BenchCommand::Ipc(a) => run_ipc(a),
        BenchCommand::JeC(a) => run_je_c(a),
        BenchCommand::Soak(a) => run_soak(a),
        BenchCommand::Latency(a) => run_latency(a),
        BenchCommand::Compare(a) => run_compare(a),
        BenchCommand::Loop(a) => run_loop(a),
        BenchCommand::Live(a) => run_live(a),
        BenchCommand::Scaling(a) => run_scaling(a),
        BenchCommand::Ethercat(a) => run_ethercat(a),
    };
    match result {
        Ok(()) => Exit::Ok,
        Err(BenchError::BadInput(e)) => {
            eprintln!("error: {e}");
            Exit::BadInput
        }
        Err(BenchError::Failed(e)) => {
            eprintln!("error: {e}");
            Exit::Failed
        }
    }
}

fn run_ipc(a: IpcArgs) -> Result<(), BenchError> {
    let report = cellrt_rt_tests::ipc::run(a.axes, a.rounds, a.count)?;
    print!("{}", cellrt_rt_tests::ipc::render(&report));
    write_json(a.json.as_deref(), &report)
}

fn run_je_c(a: JeCArgs) -> Result<(), BenchError> {
    let opts = cellrt_rt_tests::je_c::JeCBenchOptions {
        interval_ms: a.interval_ms,
        duration_s: a.duration,
        paths: a.paths,
    };
    let report = cellrt_rt_tests::je_c::run(&opts)?;
    print!("{}", cellrt_rt_tests::je_c::render(&report));
    write_json(a.json.as_deref(), &report)
}

/// Times `count` status requests (request out, reply decoded) and prints the percentiles.
fn run_operator(a: OperatorArgs, cell: Option<&str>) -> Result<(), BenchError> {
    use cellrt_runtime::host::operator::client::{OperatorClient, REPLY_TIMEOUT};
    use cellrt_runtime::host::operator::wire::Request;
    if a.count == 0 {
        return Err(BenchError::bad("--count: must be > 0"));
    }
    let client = OperatorClient::connect(cell).map_err(|e| BenchError::Failed(e.to_string()))?;
    let mut us = Vec::with_capacity(a.count as usize);
    for _ in 0..a.count {
        let t = std::time::Instant::now();
        client
            .request(&Request::Status, REPLY_TIMEOUT)
            .map_err(|e| BenchError::Failed(e.to_string()))?;
        us.push(t.elapsed().as_secs_f64() * 1e6);
    }
    us.sort_by(f64::total_cmp);
    let q = |p: f64| us[((us.len() - 1) as f64 * p).round() as usize];
    println!(
        "operator round trip (status request → reply), cell {}, {} requests: min {:.1} µs  p50 {:.1} µs  p99 {:.1} µs  max {:.1} µs",
        client.cell(),
        us.len(),
        us[0],
        q(0.5),
        q(0.99),
        us[us.len() - 1]
    );
    Ok(())
}

fn run_ethercat(a: EthercatArgs) -> Result<(), BenchError> {
    use cellrt_rt_tests::ethercat::{self as bench, EthercatBenchOptions, SegmentPlace};
    let exe = std::env::current_exe()
        .map_err(|e| BenchError::failed(format!("cannot find the cellrt executable: {e}")))?;
    let opts = EthercatBenchOptions::new(
        a.interval,
        a.duration,
        a.rounds,
        a.latency_duration,
        a.priority,
        a.cpu,
        if a.in_process {
            SegmentPlace::InProcess
        } else {
            SegmentPlace::Veth
        },
        exe,
    )?;
    println!("{}", bench::render_header(&opts));
    let report = bench::run(&opts, &mut |row| println!("{row}"))?;
    print!("{}", bench::render_totals(&report));
    write_json(a.json.as_deref(), &report)
}

fn run_latency(a: LatencyArgs) -> Result<(), BenchError> {
    let c = &a.common;
    let opts = latency::LatencyOptions::new(c.interval, c.duration, c.priority, c.cpu)?;
    let run = latency::run(opts)?;
    let report = run.report(opts);
    for r in &report.rt.refused {
        tracing::warn!("{r}");
    }
    print!("{}", latency::render(&report));
    write_json(a.json.as_deref(), &report)
}

fn run_compare(a: CompareArgs) -> Result<(), BenchError> {
    let c = &a.common;
    let opts =
        compare::CompareOptions::new(c.interval, c.duration, c.priority, c.cpu, a.load, a.rounds)?;
    if let Some(p) = &a.plot {
        if p.extension().and_then(|e| e.to_str()) != Some("svg") {
            return Err(BenchError::bad(format!(
                "--plot: must name an .svg file (got {})",
                p.display()
            )));
        }
    }
    let report = compare::run(&opts, |line| eprintln!("cellrt: {line}"))?;
    print!("{}", compare::render(&report));
    if let Some(p) = &a.plot {
        let title = format!(
            "wakeup latency at {} µs, CPU {}, SCHED_FIFO {}, {} × {} s{}",
            opts.interval_us,
            opts.cpu,
            opts.priority,
            opts.rounds,
            opts.duration_s,
            if opts.load {
                ", stress-ng load"
            } else {
                ", idle"
            }
        );
        plot::histograms_svg(
            p,
            &title,
            &[
                ("cyclictest", &report.cyclictest.hist),
                ("cellrt", &report.cellrt.hist),
            ],
        )?;
        println!("plot        {}", p.display());
    }
    write_json(a.json.as_deref(), &report)
}

fn run_loop(a: LoopArgs) -> Result<(), BenchError> {
    let c = &a.common;
    let opts = loopbench::LoopOptions::new(a.axes, c.interval, c.duration, c.priority, c.cpu)?;
    let with_je_c = opts.with_je_c(a.je_c)?;
    let report = loopbench::run(&opts)?;
    print!("{}", loopbench::render(&report));
    if a.je_c == 0 {
        return write_json(a.json.as_deref(), &report);
    }
    let with = loopbench::run(&with_je_c)?;
    print!("{}", loopbench::render(&with));
    print!("{}", loopbench::render_je_c_delta(&report, &with));
    write_json(a.json.as_deref(), &[report, with])
}

fn run_live(a: LiveArgs) -> Result<(), BenchError> {
    let c = &a.common;
    let cell = loopbench::LoopOptions::new(a.axes, c.interval, c.duration, c.priority, c.cpu)?;
    let report = cellrt_rt_tests::livebench::run(&cell, a.rounds, &mut |r| {
        eprintln!(
            "cellrt: {:?}: recorder {:.1} %, live server {:.1} %, wakeup p99 {:.1} µs",
            r.mode, r.cpu.recorder_pct, r.cpu.live_server_pct, r.wakeup_latency.p99_us
        );
    })?;
    print!("{}", cellrt_rt_tests::livebench::render(&report));
    write_json(a.json.as_deref(), &report)
}

fn run_soak(a: SoakArgs) -> Result<(), BenchError> {
    let c = &a.common;
    let cell = loopbench::LoopOptions::new(a.axes, c.interval, c.duration, c.priority, c.cpu)?;
    let opts = cellrt_rt_tests::soak::SoakOptions {
        cell,
        rotate_s: (!a.no_rotate).then_some(a.rotate),
        sample_s: a.sample,
    };
    let report = cellrt_rt_tests::soak::run(&opts, &mut |s| {
        eprintln!(
            "cellrt: t {:.0} s  RSS {} KiB  open files {}  threads {}",
            s.t_s, s.rss_kib, s.fds, s.threads
        );
    })?;
    print!("{}", cellrt_rt_tests::soak::render(&report));
    write_json(a.json.as_deref(), &report)
}

fn run_scaling(a: ScalingArgs) -> Result<(), BenchError> {
    let c = &a.common;
    let mut rows = Vec::new();
    for axes in loopbench::SCALING_AXES {
        let opts = loopbench::LoopOptions::new(axes, c.interval, c.duration, c.priority, c.cpu)?;
        let r = loopbench::run(&opts)?;
        eprintln!(
            "cellrt: {axes} axes: loop p50 {:.1} µs, p99 {:.1} µs",
            r.loop_time.p50_us, r.loop_time.p99_us
        );
        rows.push(r);
    }
    print!("{}", loopbench::render_scaling(&rows));
    write_json(a.json.as_deref(), &rows)
}
