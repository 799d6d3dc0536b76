//! The cell controller: wires the simulated bus, the RT thread, the recorder and the planner
//! together, runs until the program ends, the duration elapses or a signal arrives, then shuts
//! down cleanly (controlled stop, power off, recording finished) and summarises the run.

use crate::host::service::ServiceNotifier;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use serde::Serialize;

use crate::handoff::{self, CellCommand, CellState, HostEnd, RtEnd, StopReason};
use crate::host::faults::DriveFault;
use crate::host::link_server::LinkServer;
use crate::host::live::LiveServer;
use crate::host::live_page::LivePage;
use crate::host::planner::{self, PlannerHandle};
use crate::host::program::Program;
use crate::host::record::{Recorder, RecorderError, RecordingInfo};
use crate::rt::executive::{Executive, PhaseHook, RtCounters, RtStats};
use crate::rt::histogram::{NsHistogram, Percentiles};
use crate::rt::setpoint_stream::SetpointStream;
use crate::rt::thread::{hold_cpu_dma_latency_zero, setup_current_thread, ReservedCpu, RtReport};
use crate::services;
use cellrt_config::{AxisKind, CellConfig};

/// Stack size of the RT thread (the prefault touches part of it).
pub const RT_STACK_BYTES: usize = 4 * 1024 * 1024;

/// How to run a cell.
#[derive(Default)]
pub struct RunOptions {
    /// Program to run; `None` keeps the cell up until the duration or a signal.
    pub program: Option<Program>,
    /// Stop after this long.
    pub duration: Option<Duration>,
    /// Record to this MCAP file.
    pub record: Option<PathBuf>,
    /// Set by a signal handler to request a clean shutdown.
    pub shutdown: Arc<AtomicBool>,
    /// Test instrumentation called on the RT thread.
    pub hook: Option<PhaseHook>,
    /// Run no planner here: a `cellrt planner` process publishes the setpoints.
    pub external_planner: bool,
}

/// The cell could not run.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The recording file cannot be created at the path given (bad input: nothing ran).
    #[error("{0}")]
    RecordingPath(RecorderError),
    /// Recording failed while the cell ran or could not finish.
    #[error(transparent)]
    Recorder(#[from] RecorderError),
    /// Another controller runs this cell.
    #[error(transparent)]
    CellLock(#[from] crate::host::cell_lock::CellLockError),
    /// iceoryx2 set-up failed.
    #[error(transparent)]
    Service(#[from] services::ServiceError),
    /// A thread could not be started or died.
    #[error("{0}")]
    Thread(String),
    /// The operator socket (for other users) could not be served.
    #[error("operator socket: {0}")]
    OperatorSocket(#[source] crate::host::operator::socket::SocketError),
    /// The bus could not be opened (EtherCAT bring-up).
    #[error("{0}")]
    Bus(String),
    /// An MR-JE-C axis could not start.
    #[error(transparent)]
    JecAxis(#[from] crate::host::je_c::JecStartError),
    /// The live view could not listen.
    #[error("{0}")]
    Live(String),
}

/// How the run ended.
#[derive(Debug, Clone, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// The program ran to its end.
    ProgramCompleted,
    /// The program failed (the reason is in `program_error`).
    ProgramFailed,
    /// `--duration` elapsed.
    DurationElapsed,
    /// SIGINT or SIGTERM.
    Interrupted,
}

/// Final state of one axis.
#[derive(Debug, Clone, Serialize)]
pub struct AxisSummary {
    /// Axis name.
    pub name: String,
    /// How its motion was carried out (`streamed`, `profile`, `mr-je-c link`).
    pub backend: &'static str,
    /// Unit.
    pub unit: String,
    /// Final actual position, units.
    pub final_position: f64,
    /// The program's last target for this axis, units.
    pub target: Option<f64>,
    /// final_position − target, units.
    pub error: Option<f64>,
    /// Its MR-JE-C link, for an axis driven over one.
    pub link: Option<crate::host::je_c::LinkSummary>,
}

/// The histograms of a run's RT loop.
#[derive(Debug, Clone, Default)]
pub struct RunHistograms {
    /// Wakeup latency.
    pub wakeup_latency: NsHistogram,
    /// Loop body time.
    pub loop_time: NsHistogram,
    /// Bus exchange time.
    pub exchange_time: NsHistogram,
    /// |DC phase error| of the cyclic frames (EtherCAT).
    pub dc_phase_error: NsHistogram,
}

/// Everything the run reports at exit (printed, and written by `--summary-json`).
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    /// Cell name.
    pub cell: String,
    /// Cycle time, µs.
    pub cycle_time_us: u32,
    /// How the run ended.
    pub outcome: Outcome,
    /// Why the program failed, if it did.
    pub program_error: Option<String>,
    /// The step the program failed at and the drive faults that stopped it, if it failed.
    pub failed_step: Option<FailedStep>,
    /// Every drive fault of the run in words (the RT loop's first
    /// [`MAX_DRIVE_FAULTS`](crate::host::faults::MAX_DRIVE_FAULTS), then the MR-JE-C links').
    pub drive_faults: Vec<DriveFault>,
    /// What the RT set-up achieved.
    pub rt: RtReport,
    /// The process' privileges (root, or a user's capabilities).
    pub privileges: crate::host::privileges::Privileges,
    /// Counters.
    #[serde(flatten)]
    pub counters: RtCounters,
    /// Wakeup latency percentiles.
    pub wakeup_latency: Percentiles,
    /// Loop body time percentiles.
    pub loop_time: Percentiles,
    /// Bus exchange time percentiles (part of the loop body).
    pub exchange_time: Percentiles,
    /// Cyclic frames sent, lost and with a wrong working counter (EtherCAT cells).
    pub frames: Option<cellrt_cia402::FrameCounters>,
    /// |DC phase error| percentiles of the cyclic frames: how far each passed from its place
    /// in the SYNC0 cycle (EtherCAT cells with distributed clocks).
    pub dc_phase_error: Option<Percentiles>,
    /// The histograms behind the percentiles (for benchmarks that merge runs).
    #[serde(skip)]
    pub histograms: RunHistograms,
    /// Final cell state.
    pub final_state: String,
    /// Per axis, in configuration order, whichever backend moved it.
    pub axes: Vec<AxisSummary>,
    /// The recording.
    pub recording: RecordingInfo,
    /// The live view, when one ran.
    pub live: Option<LiveSummary>,
}

/// The step a failed program stopped at, and why in the drives' words.
#[derive(Debug, Clone, Serialize)]
pub struct FailedStep {
    /// The step's number, as the program error gives it.
    pub step: usize,
    /// The step's kind ("move", "power_on", …).
    pub what: &'static str,
    /// The drive faults the cell stood faulted by when the program failed (an axis on the RT
    /// loop since the last reset, or an MR-JE-C axis stopped by its drive's alarm); empty when
    /// the program failed for another reason.
    pub faults: Vec<DriveFault>,
}

/// What the live view passed on.
#[derive(Debug, Clone, Serialize)]
pub struct LiveSummary {
    /// Where it listened.
    pub address: String,
    /// The live page's URL, when it ran.
    pub page: Option<String>,
    /// Messages handed to its server (which drops a slow viewer's oldest itself).
    pub messages_sent: u64,
    /// Messages dropped before its server because its feeder did not keep up.
    pub messages_dropped: u64,
}

/// Runs `cell` until the program ends, the duration elapses or `shutdown` is set.
pub fn run(cell: &CellConfig, opts: RunOptions) -> Result<Summary, RunError> {
    let _lock = crate::host::cell_lock::CellLock::acquire(&cell.name)?;
    // A segment on a network interface is this cell's alone while it runs.
    let _interface = match cell.ethercat.as_ref().map(|e| &e.interface) {
        Some(cellrt_config::EthercatInterface::Nic(name)) => {
            Some(crate::host::cell_lock::InterfaceLock::acquire(name)?)
        }
        _ => None,
    };
    // Dropped before the lock: the socket is gone before another controller may take the cell.
    let _socket = crate::host::operator::socket::OperatorSocket::serve(&cell.name, &cell.operator)
        .map_err(RunError::OperatorSocket)?;
    // Before any thread starts: they all inherit the affinity without the RT CPU.
    let reserved = ReservedCpu::apply(&cell.rt);
    let (rt_handoff, handoff) = handoff::new(
        cell.axes.on_loop().len(),
        queue_cycles(cell),
        handoff::PerCycleRecords::for_run(opts.record.as_deref(), cell.live),
    );
    let handoff = Arc::new(handoff);
    let (live, page) = start_live(cell)?;
    let recording = Recording::start(
        cell,
        opts.record.as_deref(),
        handoff.clone(),
        live.as_ref().map(LiveServer::feed),
    )
    .map_err(RunError::RecordingPath)?;
    let bus =
        crate::host::cell_bus::CellBus::open(cell).map_err(|e| RunError::Bus(e.to_string()))?;
    record_bring_up_warnings(cell, &bus, &handoff);
    let je_c = crate::host::je_c::JecCell::start(cell)?;
    recording.attach_je_c(je_c.axes());
    if let Some(d) = bus.diagnostics() {
        handoff.set_bus_diagnostics(d);
    }
    if let Some(r) = bus.dictionary_reader() {
        handoff.set_dictionary_reader(r);
    }
    let (rt, mut report) = spawn_rt(cell, bus, rt_handoff, opts.hook)?;

    // The program's last target per axis, in configuration order.
    let targets: Vec<Option<f64>> = cell
        .axes
        .iter()
        .map(|a| opts.program.as_ref().and_then(|p| p.final_target(a.at)))
        .collect();
    // An external planner commands the MR-JE-C axes through the link thread.
    let je_c_link = (opts.external_planner && !cell.axes.on_link().is_empty()).then(|| je_c.axes());
    let link = LinkServer::spawn(cell, handoff.clone(), je_c_link)?;
    // Without a program the planner thread serves the operator service (unless an external
    // planner process provides the setpoints).
    let mut planner = if opts.external_planner {
        None
    } else {
        match planner::spawn(cell, opts.program, handoff.clone(), je_c.axes()) {
            Ok(p) => Some(p),
            Err(e) => {
                link.stop();
                return Err(RunError::Thread(format!("cannot start the planner: {e}")));
            }
        }
    };

    report.other_threads_cpus = reserved.others.clone();
    report.refused.extend(reserved.refused.clone());
    if let Some(p) = planner.as_ref() {
        report.planner_priority = p.priority;
        report
            .refused
            .extend(p.priority_refused.as_ref().map(ToString::to_string));
    }
    for r in &report.refused {
        tracing::warn!(cell = %cell.name, "{r}");
    }
    tracing::info!(cell = %cell.name, "{}", report.describe());
    let privileges = crate::host::privileges::Privileges::of_process();
    tracing::info!(cell = %cell.name, "privileges: {}", privileges.describe());
    let cycle = || handoff.status().cycle.load(Ordering::Acquire);
    let mut service = ServiceNotifier::from_env(Instant::now(), cycle());
    let rt = rt.go();
    service.ready(&format!(
        "cell '{}' running; {}",
        cell.name,
        report.describe()
    ));
    if let Some(i) = service.watchdog_interval() {
        tracing::info!("systemd watchdog fed every {i:?} while the RT loop runs");
    }
    let outcome = wait_for_end(
        &opts.shutdown,
        opts.duration,
        planner.as_mut(),
        &rt,
        &mut |now| service.poll(cycle(), now),
    );
    service.stopping();
    // Why the RT thread stopped the cell, read before the shutdown powers it off.
    let stopped_by = handoff.status().stop_reason();
    // Stop publishing before the controlled stop; release the publisher after the RT thread.
    if let Some(p) = planner.as_ref() {
        p.stop_publishing();
    }
    shutdown(cell, &handoff);
    let stats = rt
        .join()
        .map_err(|_| RunError::Thread("the RT thread panicked".into()))?
        .ok_or_else(|| RunError::Thread("the RT thread ended without statistics".into()))?;
    link.stop();
    let program_result = planner.map(|p| p.finish());
    let links = je_c.finish();
    let recording = recording.finish()?;

    let program_failure = program_result.and_then(|r| r.err());
    let program_error = program_failure.as_ref().map(ToString::to_string);
    let link_faults: Vec<DriveFault> = links.iter().filter_map(|l| l.fault.clone()).collect();
    let failed_step = program_failure.map(|e| {
        let mut faults = if stopped_by == Some(StopReason::DriveFault) {
            recording.drive_faults[recording.unreset_from.min(recording.drive_faults.len())..]
                .to_vec()
        } else {
            Vec::new()
        };
        faults.extend(link_faults.iter().cloned());
        FailedStep {
            step: e.step,
            what: e.what,
            faults,
        }
    });
    let drive_faults = recording
        .drive_faults
        .iter()
        .cloned()
        .chain(link_faults)
        .collect();
    let outcome = if program_error.is_some() && outcome != Outcome::Interrupted {
        Outcome::ProgramFailed
    } else {
        outcome
    };
    Ok(Summary {
        cell: cell.name.clone(),
        cycle_time_us: cell.cycle_time.as_micros(),
        outcome,
        program_error,
        failed_step,
        drive_faults,
        rt: report,
        privileges,
        counters: stats.counters,
        wakeup_latency: stats.latency.percentiles(),
        loop_time: stats.loop_time.percentiles(),
        exchange_time: stats.exchange_time.percentiles(),
        frames: stats.frames,
        dc_phase_error: (!stats.dc_phase_error.is_empty())
            .then(|| stats.dc_phase_error.percentiles()),
        axes: axis_summaries(cell, &stats, links, &targets),
        histograms: RunHistograms {
            wakeup_latency: stats.latency,
            loop_time: stats.loop_time,
            exchange_time: stats.exchange_time,
            dc_phase_error: stats.dc_phase_error,
        },
        final_state: stats.final_state.as_str().to_string(),
        recording,
        live: live.as_ref().map(|l| LiveSummary {
            address: l.addr.to_string(),
            page: page.as_ref().map(|p| format!("http://{}/", p.addr)),
            messages_sent: l.feed().sent(),
            messages_dropped: l.feed().dropped(),
        }),
    })
}

/// The live view and its page, when the cell has a live view. A page port the configuration
/// gave that cannot be served is an error; the default one (the live view's port + 1) taken by
/// something else is a warning, and the cell runs without the page.
fn start_live(cell: &CellConfig) -> Result<(Option<LiveServer>, Option<LivePage>), RunError> {
    let Some(addr) = cell.live else {
        return Ok((None, None));
    };
    let server = LiveServer::start(cell, addr).map_err(|e| RunError::Live(e.to_string()))?;
    tracing::info!(
        "live view on ws://{} (Foxglove WebSocket protocol)",
        server.addr
    );
    let page_addr = cell
        .live_page
        .addr(addr)
        .map_err(|e| RunError::Live(format!("live page: {e}")))?;
    let scales = crate::host::live_page::AxisScale::of_cell(cell);
    let page = match LivePage::start(&cell.name, &scales, page_addr, server.addr.port()) {
        Ok(p) => {
            tracing::info!("live page on http://{}/", p.addr);
            Some(p)
        }
        Err(e) if !cell.live_page.given() => {
            tracing::warn!("{e}; the cell runs without it (set [live] page_port)");
            None
        }
        Err(e) => return Err(RunError::Live(e.to_string())),
    };
    Ok((Some(server), page))
}

/// Each optional setting bring-up skipped becomes a `bring_up_warning` event of its axis at
/// cycle 0 (the recorder logs it and writes it into the recording).
fn record_bring_up_warnings(
    cell: &CellConfig,
    bus: &crate::host::cell_bus::CellBus,
    handoff: &HostEnd,
) {
    for w in bus.bring_up_warnings() {
        let axis = cell
            .axes
            .on_loop()
            .iter()
            .position(|a| a.name == w.axis)
            .map_or(handoff::NO_AXIS, |i| i as u16);
        handoff.push_event(handoff::EventRecord {
            cycle: 0,
            kind: handoff::EventKind::BringUpWarning,
            axis,
            value: handoff::encode_refused_sdo(&w.sdo),
        });
    }
}

/// Cycles the hand-off queues hold: the configured seconds of recording, at least 64.
fn queue_cycles(cell: &CellConfig) -> usize {
    (cell.recording.queue_seconds / cell.period())
        .ceil()
        .max(64.0) as usize
}

/// The run's recorder, finished exactly once: by [`Recording::finish`] at the end of the run,
/// or when dropped on an early exit, so every MCAP file gets its summary and indexes.
struct Recording(Option<Recorder>);

impl Recording {
    /// Records the MR-JE-C axes' exchanges too.
    fn attach_je_c(&self, axes: crate::host::je_c::JecAxes) {
        if let Some(r) = &self.0 {
            r.attach_je_c(axes);
        }
    }

    fn start(
        cell: &CellConfig,
        path: Option<&std::path::Path>,
        handoff: Arc<HostEnd>,
        live: Option<crate::host::live::LiveFeed>,
    ) -> Result<Recording, RecorderError> {
        Recorder::start_with_live(cell, path, handoff, live).map(|r| Recording(Some(r)))
    }

    fn finish(mut self) -> Result<RecordingInfo, RecorderError> {
        self.0.take().expect("finished once").finish()
    }
}

impl Drop for Recording {
    fn drop(&mut self) {
        if let Some(r) = self.0.take() {
            let _ = r.finish();
        }
    }
}

/// The RT thread between its set-up and the start of its loop: [`RtStart::go`] starts the
/// loop; dropped before, it tells the thread to end without looping and joins it.
struct RtStart {
    go: mpsc::Sender<bool>,
    thread: Option<JoinHandle<Option<RtStats>>>,
}

impl RtStart {
    fn go(mut self) -> JoinHandle<Option<RtStats>> {
        let _ = self.go.send(true);
        self.thread.take().expect("started once")
    }
}

impl Drop for RtStart {
    fn drop(&mut self) {
        if let Some(t) = self.thread.take() {
            let _ = self.go.send(false);
            let _ = t.join();
        }
    }
}

/// Spawns the RT thread and waits until it has set itself up (RT scheduling, its own iceoryx2
/// port: ports are not Send); it waits for [`RtStart::go`] to start the loop.
fn spawn_rt(
    cell: &CellConfig,
    bus: crate::host::cell_bus::CellBus,
    handoff: RtEnd,
    hook: Option<PhaseHook>,
) -> Result<(RtStart, RtReport), RunError> {
    let (ready_tx, ready_rx) = mpsc::channel::<Result<RtReport, services::ServiceError>>();
    let (go_tx, go_rx) = mpsc::channel::<bool>();
    let rt_cell = cell.clone();
    let thread = std::thread::Builder::new()
        .name("cellrt-rt".into())
        .stack_size(RT_STACK_BYTES)
        .spawn(move || -> Option<RtStats> {
            let mut report = setup_current_thread(&rt_cell.rt);
            let _dma = hold_cpu_dma_latency_zero(&mut report);
            let node = match services::node(&rt_cell.name, "rt") {
                Ok(n) => n,
                Err(e) => {
                    let _ = ready_tx.send(Err(e));
                    return None;
                }
            };
            let sub = match services::setpoint_subscriber(&node, &rt_cell.name) {
                Ok(s) => s,
                Err(e) => {
                    let _ = ready_tx.send(Err(e));
                    return None;
                }
            };
            let exec = Executive::new(&rt_cell, bus, SetpointStream::new(sub), handoff, hook);
            let _ = ready_tx.send(Ok(report));
            // Start the loop only once every peer of the setpoint service exists.
            if go_rx.recv() != Ok(true) {
                return None;
            }
            Some(exec.run())
        })
        .map_err(|e| RunError::Thread(format!("cannot start the RT thread: {e}")))?;
    let rt = RtStart {
        go: go_tx,
        thread: Some(thread),
    };
    match ready_rx.recv() {
        Ok(Ok(report)) => Ok((rt, report)),
        Ok(Err(e)) => Err(e.into()),
        Err(_) => Err(RunError::Thread("the RT thread died during set-up".into())),
    }
}

/// Waits until the run ends: a signal, the program's end, the duration, or the RT thread ended;
/// `tick` runs at every look (the service watchdog).
fn wait_for_end(
    shutdown: &AtomicBool,
    duration: Option<Duration>,
    mut planner: Option<&mut PlannerHandle>,
    rt: &JoinHandle<Option<RtStats>>,
    tick: &mut dyn FnMut(Instant),
) -> Outcome {
    let started = Instant::now();
    loop {
        std::thread::sleep(Duration::from_millis(5));
        tick(Instant::now());
        if shutdown.load(Ordering::Acquire) {
            return Outcome::Interrupted;
        }
        if let Some(r) = planner.as_mut().and_then(|p| p.poll()) {
            return if r.is_err() {
                Outcome::ProgramFailed
            } else {
                Outcome::ProgramCompleted
            };
        }
        if duration.is_some_and(|d| started.elapsed() >= d) {
            return Outcome::DurationElapsed;
        }
        if rt.is_finished() {
            return Outcome::ProgramFailed;
        }
    }
}

/// Each axis' final position against the program's last target.
fn axis_summaries(
    cell: &CellConfig,
    stats: &RtStats,
    links: Vec<crate::host::je_c::LinkSummary>,
    targets: &[Option<f64>],
) -> Vec<AxisSummary> {
    cell.axes
        .iter()
        .zip(targets)
        .map(|(axis, &target)| {
            let (final_position, link) = match axis.config {
                AxisKind::Loop(i, a) => (
                    a.scaling.to_units(f64::from(stats.final_positions[i])),
                    None,
                ),
                // One summary per link (`JecCell::finish`); NaN marks a link that left none.
                AxisKind::Link(k, _) => {
                    let link = links.get(k).cloned();
                    (link.as_ref().map_or(f64::NAN, |l| l.final_position), link)
                }
            };
            AxisSummary {
                name: axis.name().to_string(),
                backend: axis.backend().as_str(),
                unit: axis.unit().to_string(),
                final_position,
                target,
                error: target.map(|t| final_position - t),
                link,
            }
        })
        .collect()
}

/// Brings the cell to rest and powered off, then tells the RT thread to quit.
fn shutdown(cell: &CellConfig, handoff: &HostEnd) {
    let status = handoff.status();
    let wait = |pred: &dyn Fn(CellState) -> bool, timeout: Duration| {
        let end = Instant::now() + timeout;
        while !pred(status.state()) && Instant::now() < end {
            std::thread::sleep(Duration::from_millis(1));
        }
    };
    // Longest controlled stop of any axis from its velocity limit, plus margin.
    let stop_time = cell
        .axes
        .on_loop()
        .iter()
        .map(|a| a.limits.velocity / a.stop_deceleration)
        .fold(0.0, f64::max);
    let stop_timeout = Duration::from_secs_f64(stop_time + 2.0);

    if matches!(status.state(), CellState::Moving | CellState::Stopping) {
        let _ = handoff.send_command(CellCommand::Stop);
        wait(
            &|s| !matches!(s, CellState::Moving | CellState::Stopping),
            stop_timeout,
        );
    }
    if status.state() != CellState::Disabled {
        let _ = handoff.send_command(CellCommand::PowerOff);
        wait(&|s| s == CellState::Disabled, planner::POWER_TIMEOUT);
    }
    let _ = handoff.send_command(CellCommand::Quit);
}
