//! The non-RT planner thread: runs a program, plans each move with rsruckig (via
//! `cellrt-trajectory`), samples it at the cycle time into setpoint blocks and publishes them
//! through iceoryx2, keeping a lookahead ahead of the RT thread's cycle.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use iceoryx2::prelude::*;

use crate::handoff::{CellCommand, CellState, HomeRequest, HostEnd, ProfileCommand};
use crate::host::je_c::link::JecBridge;
use crate::host::je_c::JecAxes;
use crate::host::link::{CellLink, LocalLink, RemoteLink, StatusSnapshot};
use crate::host::motion::{MotionEngine, MotionError, MotionRequest, Progress};
use crate::host::operator::backend::profile::{
    halts as profile_halts, jog as profile_jog, send as send_profile, split_move, AxisModes,
};
use crate::host::operator::server::{Context, Followup, OperatorServer};
use crate::host::program::{AxisMove, DriveMove, MoveTarget, Program, Step, TorqueTarget};
use crate::rt::thread::{raise_planner_thread, PlannerPriorityRefused};
use crate::services;
use cellrt_cia402::fsa::FsaState;
use cellrt_cia402::homing::{HomeProcedure, HomingFailure};
use cellrt_cia402::statusword::Statusword;
use cellrt_config::{AxisRef, CellConfig};

mod je_c;

/// The engine's form of a move-like step's targets.
/// A move's targets by backend: the planned ones (RT loop axes) and the drives' own moves
/// (MR-JE-C axes).
fn by_backend(targets: &[AxisMove]) -> (Vec<MoveTarget>, Vec<DriveMove>) {
    let mut planned = Vec::new();
    let mut drive = Vec::new();
    for t in targets {
        match t {
            AxisMove::Planned(t) => planned.push(t.clone()),
            AxisMove::Drive(t) => drive.push(t.clone()),
        }
    }
    (planned, drive)
}

fn move_list(targets: &[MoveTarget]) -> Vec<(usize, f64, cellrt_trajectory::KinematicLimits)> {
    targets
        .iter()
        .map(|t| (t.axis, t.target, t.limits))
        .collect()
}

/// How often the planner looks at the cell while a motion runs.
const TICK: Duration = Duration::from_millis(1);

/// How often a program step whose motion the RT thread did not start (its first block came
/// too late) is started again before the program fails.
const MAX_RESTARTS: u32 = 3;

/// How long power on / power off may take before the program fails.
pub const POWER_TIMEOUT: Duration = Duration::from_secs(10);

/// A program step failed.
#[derive(Debug, Clone, thiserror::Error)]
#[error("program {program}, step {step} ({what}): {reason}")]
pub struct ProgramError {
    /// Program file.
    pub program: String,
    /// Step index.
    pub step: usize,
    /// Step kind.
    pub what: &'static str,
    /// What went wrong.
    pub reason: String,
}

/// Handle of the planner thread. The thread keeps its publisher until [`PlannerHandle::finish`],
/// so the RT thread never sees the peer leave while it runs (a leaving peer makes the next
/// iceoryx2 receive free memory; docs/architecture.md).
pub struct PlannerHandle {
    /// The planner thread's SCHED_FIFO priority in effect (0: SCHED_OTHER).
    pub priority: u8,
    /// Why the planner thread's priority was not raised, if it was asked for and refused.
    pub priority_refused: Option<PlannerPriorityRefused>,
    abort: Arc<AtomicBool>,
    release: Arc<AtomicBool>,
    handle: JoinHandle<()>,
    result_rx: std::sync::mpsc::Receiver<Result<(), ProgramError>>,
    result: Option<Result<(), ProgramError>>,
}

impl PlannerHandle {
    /// The program's result once it has ended.
    pub fn poll(&mut self) -> Option<&Result<(), ProgramError>> {
        if self.result.is_none() {
            self.result = self.result_rx.try_recv().ok();
        }
        self.result.as_ref()
    }

    /// Ends the program (no more setpoints are published); the publisher stays open.
    pub fn stop_publishing(&self) {
        self.abort.store(true, Ordering::Release);
    }

    /// Stops the program if it still runs, releases the publisher and returns the result
    /// (an aborted program counts as successful).
    pub fn finish(self) -> Result<(), ProgramError> {
        self.abort.store(true, Ordering::Release);
        self.release.store(true, Ordering::Release);
        let panicked = self.handle.join().is_err();
        let result = self.result.or_else(|| self.result_rx.try_recv().ok());
        match result {
            Some(r) => r,
            None if panicked => Err(ProgramError {
                program: String::new(),
                step: 0,
                what: "planner",
                reason: "planner thread panicked".into(),
            }),
            None => Ok(()),
        }
    }
}

/// Starts the planner thread on `cell`: it runs `program` (the handle's result is the
/// program's), or without one serves the operator service until [`PlannerHandle::finish`].
pub fn spawn(
    cell: &CellConfig,
    program: Option<Program>,
    handoff: Arc<HostEnd>,
    je_c: JecAxes,
) -> std::io::Result<PlannerHandle> {
    let abort = Arc::new(AtomicBool::new(false));
    let abort2 = abort.clone();
    let cell = cell.clone();
    let release = Arc::new(AtomicBool::new(false));
    let release2 = release.clone();
    let (ready_tx, ready_rx) = std::sync::mpsc::channel::<Result<u8, PlannerPriorityRefused>>();
    let planner_priority = cell.rt.planner_priority;
    let (result_tx, result_rx) = std::sync::mpsc::channel();
    let handle = std::thread::Builder::new()
        .name("cellrt-planner".into())
        .spawn(move || {
            let priority = planner_priority.map_or(Ok(0), |p| raise_planner_thread(p).map(|()| p));
            let link = LocalLink::new(handoff, cell.axes.on_loop().len());
            let source = program
                .as_ref()
                .map(|p| p.source.display().to_string())
                .unwrap_or_default();
            let planner = Planner::new(&cell, Box::new(link), &abort2, source, je_c);
            let _ = ready_tx.send(priority);
            match planner {
                Ok(mut p) => {
                    let _ = result_tx.send(p.serve(program));
                    // Keep the publisher (inside `p`) until released.
                    while !release2.load(Ordering::Acquire) {
                        std::thread::sleep(Duration::from_millis(5));
                    }
                }
                Err(e) => {
                    let _ = result_tx.send(Err(e));
                }
            }
        })?;
    // Returns once the publisher exists, so the RT thread's warm-up sees it join.
    let priority = ready_rx.recv().unwrap_or(Ok(0));
    Ok(PlannerHandle {
        priority: *priority.as_ref().unwrap_or(&0),
        priority_refused: priority.err(),
        abort,
        release,
        handle,
        result_rx,
        result: None,
    })
}

/// Runs `program` from a planner process of its own: connects to the running controller of
/// `cell` (started with `--external-planner`) through its status and command services and
/// publishes setpoints on the cell's setpoint service; its MR-JE-C axes, run by the
/// controller, are reached through a [`JecBridge`]. Returns when the program ends, fails or
/// `abort` is set; without a program it serves the operator service until `abort` is set.
pub fn run_external(
    cell: &CellConfig,
    program: Option<&Program>,
    abort: &AtomicBool,
    connect_timeout: Duration,
) -> Result<(), ProgramError> {
    let source = program
        .map(|p| p.source.display().to_string())
        .unwrap_or_default();
    let fail = |reason: String| ProgramError {
        program: source.clone(),
        step: 0,
        what: "connect",
        reason,
    };
    let node = services::node(&cell.name, "link-client").map_err(|e| fail(e.to_string()))?;
    let link = RemoteLink::connect(
        &node,
        &cell.name,
        cell.cycle_time.as_nanos(),
        cell.axes.on_loop().len(),
        connect_timeout,
    )
    .map_err(|e| fail(e.to_string()))?;
    if let Some(p) = cell.rt.planner_priority {
        if let Err(refused) = raise_planner_thread(p) {
            tracing::warn!("{refused}");
        }
    }
    // The MR-JE-C axes' threads run in the controller; the bridge carries their commands and
    // feedback (dropped after the planner, so its last commands go out).
    let (_bridge, je_c) = if cell.axes.on_link().is_empty() {
        (None, JecAxes::default())
    } else {
        let (bridge, axes) =
            JecBridge::connect(cell, connect_timeout).map_err(|e| fail(e.to_string()))?;
        (Some(bridge), axes)
    };
    let mut planner = Planner::new(cell, Box::new(link), abort, source.clone(), je_c)?;
    planner.serve(program.cloned())
}

struct Planner<'a> {
    cell: &'a CellConfig,
    link: Box<dyn CellLink + 'a>,
    abort: &'a AtomicBool,
    engine: MotionEngine,
    operator: OperatorServer,
    /// The operator halted or stopped the program in execution.
    program_aborted: bool,
    program_running: bool,
    _node: Node<ipc::Service>,
    source: String,
    step: usize,
    what: &'static str,
    /// The cell's MR-JE-C axes.
    je_c: JecAxes,
}

impl<'a> Planner<'a> {
    fn new(
        cell: &'a CellConfig,
        link: Box<dyn CellLink + 'a>,
        abort: &'a AtomicBool,
        source: String,
        je_c: JecAxes,
    ) -> Result<Self, ProgramError> {
        let fail = |e: services::ServiceError| ProgramError {
            program: source.clone(),
            step: 0,
            what: "planner",
            reason: e.to_string(),
        };
        let node = services::node(&cell.name, "planner").map_err(fail)?;
        let publisher = services::setpoint_publisher(&node, &cell.name, cell.axes.on_loop().len())
            .map_err(fail)?;
        let operator = OperatorServer::new(&node, &cell.name).map_err(fail)?;
        Ok(Planner {
            cell,
            link,
            abort,
            engine: MotionEngine::new(cell, publisher),
            operator,
            program_aborted: false,
            program_running: false,
            _node: node,
            source,
            step: 0,
            what: "",
            je_c,
        })
    }

    fn err(&self, reason: impl std::fmt::Display) -> ProgramError {
        ProgramError {
            program: self.source.clone(),
            step: self.step,
            what: self.what,
            reason: reason.to_string(),
        }
    }

    fn aborted(&self) -> bool {
        self.abort.load(Ordering::Acquire)
    }

    fn status(&mut self) -> Result<StatusSnapshot, ProgramError> {
        self.poll_operator();
        self.link.status().map_err(|e| self.err(e))
    }

    /// Runs `program` if given and returns its result; without one, serves the operator
    /// service (programs it starts included) until aborted.
    fn serve(&mut self, program: Option<Program>) -> Result<(), ProgramError> {
        let stay = program.is_none();
        let mut next = program;
        loop {
            if self.aborted() {
                return Ok(());
            }
            if let Some(p) = next.take() {
                self.source = p.source.display().to_string();
                self.program_aborted = false;
                self.program_running = true;
                let r = self.run(&p);
                self.program_running = false;
                self.operator
                    .finish_active(r.as_ref().err().map(|e| e.to_string()));
                if !stay {
                    return r;
                }
                if let Err(e) = r {
                    tracing::warn!("{e}");
                }
                continue;
            }
            if let Followup::RunProgram(p) = self.poll_operator() {
                next = Some(p);
                continue;
            }
            let mut ctx = Context {
                cell: self.cell,
                engine: &mut self.engine,
                link: self.link.as_mut(),
                program_running: false,
                je_c: &self.je_c,
            };
            self.operator.tick(&mut ctx);
            self.operator.wait(TICK);
            // An external planner serving the operator ends with its controller (a local link
            // always answers).
            if let Err(e) = self.link.status() {
                return Err(ProgramError {
                    program: String::new(),
                    step: 0,
                    what: "operator",
                    reason: e.to_string(),
                });
            }
        }
    }

    /// Answers pending operator requests.
    fn poll_operator(&mut self) -> Followup {
        let mut ctx = Context {
            cell: self.cell,
            engine: &mut self.engine,
            link: self.link.as_mut(),
            program_running: self.program_running,
            je_c: &self.je_c,
        };
        let f = self.operator.poll(&mut ctx);
        if matches!(f, Followup::AbortProgram) {
            self.program_aborted = true;
        }
        f
    }

    fn run(&mut self, program: &Program) -> Result<(), ProgramError> {
        for (i, step) in program.steps.iter().enumerate() {
            if self.aborted() {
                return Ok(());
            }
            if self.program_aborted {
                return Err(self.err("the program was halted or stopped by the operator"));
            }
            self.step = i;
            match step {
                Step::PowerOn(axes) if axes.is_empty() => {
                    self.what = "power_on";
                    self.command(CellCommand::PowerOn)?;
                    self.wait_for_state(CellState::Idle, POWER_TIMEOUT)?;
                    self.je_c_power(&self.all_links(), true)?;
                }
                Step::PowerOff(axes) if axes.is_empty() => {
                    self.what = "power_off";
                    self.command(CellCommand::PowerOff)?;
                    self.wait_for_state(CellState::Disabled, POWER_TIMEOUT)?;
                    self.je_c_power(&self.all_links(), false)?;
                }
                Step::PowerOn(axes) | Step::PowerOff(axes) => {
                    let on = matches!(step, Step::PowerOn(_));
                    self.what = if on { "power_on" } else { "power_off" };
                    let on_loop: Vec<usize> = axes.iter().filter_map(|a| a.loop_slot()).collect();
                    let on_link: Vec<usize> = axes.iter().filter_map(|a| a.link()).collect();
                    for &a in &on_loop {
                        self.command(if on {
                            CellCommand::PowerOnAxis(a as u16)
                        } else {
                            CellCommand::PowerOffAxis(a as u16)
                        })?;
                    }
                    self.wait_power(&on_loop, on, POWER_TIMEOUT)?;
                    self.je_c_power(&on_link, on)?;
                }
                Step::Reset => {
                    self.what = "reset";
                    self.je_c_reset()?;
                    let state = self.status()?.state;
                    if matches!(state, CellState::Stopped | CellState::Faulted) {
                        self.command(CellCommand::Reset)?;
                        self.wait_reset(POWER_TIMEOUT)?;
                    }
                }
                Step::Wait(s) => {
                    self.what = "wait";
                    self.sleep(Duration::from_secs_f64(*s));
                }
                Step::Move(targets) => {
                    self.what = "move";
                    let (planned, drive) = by_backend(targets);
                    let before = self.je_c_start(&drive)?;
                    if !planned.is_empty() {
                        self.run_move(&planned)?;
                    }
                    self.je_c_wait(&drive, &before)?;
                }
                Step::Torque { targets, hold_s } => {
                    self.what = "torque";
                    if targets.iter().any(|t| matches!(t.axis, AxisRef::Link(_))) {
                        self.je_c_torque(targets, *hold_s)?;
                    } else {
                        self.run_torque(targets, *hold_s)?;
                    }
                }
                Step::Line {
                    targets,
                    path_velocity,
                } => {
                    self.what = "line";
                    self.run_motion(
                        MotionRequest::Line {
                            targets: move_list(targets),
                            path_velocity: *path_velocity,
                        },
                        None,
                    )?;
                }
                Step::Path { targets, via } => {
                    self.what = "path";
                    self.run_motion(
                        MotionRequest::Path {
                            targets: move_list(targets),
                            via: via.clone(),
                        },
                        None,
                    )?;
                }
                Step::Jog {
                    axis: AxisRef::Link(k),
                    velocity,
                    seconds,
                } => {
                    self.what = "jog";
                    self.je_c_jog(*k, *velocity, *seconds)?;
                }
                Step::Jog {
                    axis: AxisRef::Loop(axis),
                    velocity,
                    seconds,
                } => {
                    self.what = "jog";
                    let limits = self.cell.axes.on_loop()[*axis].limits;
                    if self.cell.axes.on_loop()[*axis].profile_objects.is_some() {
                        self.run_profile_jog(*axis, *velocity, *seconds)?;
                        continue;
                    }
                    self.run_motion(
                        MotionRequest::Jog {
                            axis: *axis,
                            velocity: *velocity,
                            limits,
                        },
                        Some(Duration::from_secs_f64(*seconds)),
                    )?;
                }
                Step::Home { axis, procedure } => {
                    self.what = "home";
                    match axis {
                        AxisRef::Loop(i) => self.run_home(*i, *procedure)?,
                        AxisRef::Link(k) => self.je_c_home(*k)?,
                    }
                }
                Step::Mode { axis, mode } => {
                    self.what = "mode";
                    self.run_mode_switch(*axis, *mode)?;
                }
                Step::Override(value) => {
                    self.what = "override";
                    if let Err(e) = self.engine.set_override(*value, self.link.as_mut()) {
                        return Err(self.err(e));
                    }
                    self.je_c.set_override(*value).map_err(|e| self.err(e))?;
                }
            }
        }
        Ok(())
    }

    fn command(&mut self, cmd: CellCommand) -> Result<(), ProgramError> {
        self.link.command(cmd).map_err(|e| self.err(e))
    }

    fn sleep(&mut self, d: Duration) {
        let end = Instant::now() + d;
        while !self.aborted() && !self.program_aborted {
            let now = Instant::now();
            if now >= end {
                break;
            }
            self.poll_operator();
            std::thread::sleep((end - now).min(Duration::from_millis(10)));
        }
    }

    fn wait_for_state(&mut self, want: CellState, timeout: Duration) -> Result<(), ProgramError> {
        self.wait_for(|s| s == want, timeout).map_err(|e| {
            if e.reason.is_empty() {
                self.err(format!(
                    "cell did not become {} within {timeout:?}",
                    want.as_str()
                ))
            } else {
                e
            }
        })
    }

    /// Waits until the listed axes are powered and in Operation enabled (`on`), or unpowered
    /// and out of it, and the cell has settled.
    /// Every MR-JE-C link of the cell.
    fn all_links(&self) -> Vec<usize> {
        (0..self.je_c.len()).collect()
    }

    fn wait_power(
        &mut self,
        axes: &[usize],
        on: bool,
        timeout: Duration,
    ) -> Result<(), ProgramError> {
        let end = Instant::now() + timeout;
        loop {
            let s = self.status()?;
            let pending = axes.iter().find(|&&i| {
                let l = s.live[i];
                let enabled = Statusword(l.statusword).state() == Some(FsaState::OperationEnabled);
                (l.powered != 0) != on || enabled != on
            });
            let settled = !matches!(s.state, CellState::Enabling | CellState::Disabling);
            if (pending.is_none() && settled) || self.aborted() {
                return Ok(());
            }
            if s.state == CellState::Faulted {
                return Err(self.err("the cell faulted (see the events)"));
            }
            if Instant::now() >= end {
                let name = pending.map_or("", |&i| self.cell.axes.on_loop()[i].name.as_str());
                return Err(self.err(format!(
                    "timed out after {timeout:?}; axis '{name}' is not {}, the cell is {}",
                    if on { "powered" } else { "unpowered" },
                    s.state.as_str()
                )));
            }
            std::thread::sleep(Duration::from_millis(1));
        }
    }

    /// Waits until a reset has cleared the Stopped or Faulted state and the cell has settled
    /// (the fault-reset hold of the slowest drive is part of it), so the next step's command is
    /// accepted; a cell that stays faulted fails after `timeout`.
    fn wait_reset(&mut self, timeout: Duration) -> Result<(), ProgramError> {
        let end = Instant::now() + timeout;
        loop {
            let s = self.status()?.state;
            // Settled: Idle (a stop reset with the drives still enabled) or Disabled (after a
            // fault reset or a drive-side reaction, once the drives have been disabled).
            if matches!(s, CellState::Idle | CellState::Disabled) || self.aborted() {
                return Ok(());
            }
            if Instant::now() >= end {
                return Err(self.err(format!(
                    "the reset did not clear the cell within {timeout:?}; it is {} (see the events)",
                    s.as_str()
                )));
            }
            std::thread::sleep(Duration::from_millis(1));
        }
    }

    /// Waits until the cell state satisfies `done`; fails on a fault (unless waited for) or
    /// after `timeout` (with an empty reason, filled in by the caller).
    fn wait_for(
        &mut self,
        done: impl Fn(CellState) -> bool,
        timeout: Duration,
    ) -> Result<(), ProgramError> {
        let end = Instant::now() + timeout;
        loop {
            let s = self.status()?.state;
            if done(s) || self.aborted() {
                return Ok(());
            }
            if s == CellState::Faulted {
                return Err(self.err("the cell faulted (see the events)"));
            }
            if Instant::now() >= end {
                return Err(self.err(format!(
                    "timed out after {timeout:?}; the cell is {}",
                    s.as_str()
                )));
            }
            std::thread::sleep(Duration::from_millis(1));
        }
    }

    /// Homes `axis` by `procedure` and waits for the RT thread's result.
    fn run_home(&mut self, axis: usize, procedure: HomeProcedure) -> Result<(), ProgramError> {
        let before = self.status()?;
        if before.state != CellState::Idle {
            return Err(self.err(format!(
                "the cell is {}, not idle (power on first)",
                before.state.as_str()
            )));
        }
        let request = HomeRequest {
            axis: axis as u16,
            procedure,
        };
        if let Err(e) = self.link.home(request) {
            return Err(self.err(e));
        }
        let end =
            Instant::now() + self.cell.axes.on_loop()[axis].homing.timeout + Duration::from_secs(5);
        loop {
            if self.aborted() {
                return Ok(());
            }
            let s = self.status()?;
            if s.homing.seq > before.homing.seq && !s.homing.running {
                return match HomingFailure::from_u8(s.homing.failure) {
                    None => Ok(()),
                    Some(f) => Err(self.err(f.as_str())),
                };
            }
            if s.state == CellState::Faulted {
                return Err(self.err("the cell faulted during homing (see the events)"));
            }
            if Instant::now() >= end {
                return Err(self.err("homing did not end in time"));
            }
            std::thread::sleep(TICK);
        }
    }

    /// A mode step: the RT thread switches the axis by the drive's mode-switch rules; the step
    /// ends when 6061h shows the mode, and fails where the switch was refused or withdrawn.
    fn run_mode_switch(
        &mut self,
        axis: usize,
        to: crate::handoff::SwitchableMode,
    ) -> Result<(), ProgramError> {
        let switch = ProfileCommand {
            axis: axis as u16,
            motion: crate::handoff::ProfileMotion::SwitchMode(to),
            start_cycle: 0,
        };
        let before = self.status()?;
        send_profile(self.link.as_mut(), vec![switch], 0).map_err(|e| self.err(e))?;
        self.wait_profile_axes(&[switch], &before)
    }

    /// A move step: the pp axes' drives get their set-points, the streamed axes their motion
    /// (it starts within the planner's start delay of them); the step ends when all are done.
    fn run_move(&mut self, targets: &[MoveTarget]) -> Result<(), ProgramError> {
        let before = self.status()?;
        // The modes the axes run in now: a mode step may have switched one to pp.
        let (drive_side, streamed) = split_move(
            self.cell,
            &AxisModes::now(self.cell, &before),
            move_list(targets),
        )
        .map_err(|e| self.err(e))?;
        if streamed.is_empty() {
            send_profile(self.link.as_mut(), drive_side.clone(), 0).map_err(|e| self.err(e))?;
        } else {
            self.run_motion_with(MotionRequest::Move(streamed), None, &drive_side)?;
        }
        self.wait_profile_axes(&drive_side, &before)
    }

    /// A torque step on tq axes: their drives ramp to the torque at the axis' slope (6087h),
    /// hold it `hold_s`, then HALT ramps it back to 0; the step ends when every ramp is over.
    fn run_profile_torque(
        &mut self,
        targets: &[(usize, f64, f64)],
        hold_s: f64,
    ) -> Result<(), ProgramError> {
        use crate::handoff::ProfileMotion;
        let ramps: Vec<ProfileCommand> = targets
            .iter()
            .map(|&(axis, torque, slope)| ProfileCommand {
                axis: axis as u16,
                motion: ProfileMotion::Torque { torque, slope },
                start_cycle: 0,
            })
            .collect();
        let before = self.status()?;
        send_profile(self.link.as_mut(), ramps.clone(), 0).map_err(|e| self.err(e))?;
        self.wait_profile_axes(&ramps, &before)?;
        if !self.serve_for(hold_s)? {
            return Ok(());
        }
        let axes: Vec<usize> = targets.iter().map(|&(axis, ..)| axis).collect();
        let halts = profile_halts(self.cell, &AxisModes::configured(self.cell), Some(&axes));
        send_profile(self.link.as_mut(), halts.clone(), 0).map_err(|e| self.err(e))?;
        let all: Vec<ProfileCommand> = ramps.into_iter().chain(halts).collect();
        self.wait_profile_axes(&all, &before)
    }

    /// Serves the operator and watches the cell for `seconds`; false if the program was aborted
    /// meanwhile.
    fn serve_for(&mut self, seconds: f64) -> Result<bool, ProgramError> {
        let until = Instant::now() + Duration::from_secs_f64(seconds);
        while Instant::now() < until {
            if self.aborted() {
                return Ok(false);
            }
            self.status()?;
            std::thread::sleep(TICK);
        }
        Ok(true)
    }

    /// A jog step on a pv axis: its drive runs at `velocity` for `seconds`, then HALT; the step
    /// ends when the drive stands.
    fn run_profile_jog(
        &mut self,
        axis: usize,
        velocity: f64,
        seconds: f64,
    ) -> Result<(), ProgramError> {
        let a = &self.cell.axes.on_loop()[axis];
        let jog = profile_jog(
            axis,
            a,
            AxisModes::configured(self.cell).of(axis),
            velocity,
            &a.limits,
        )
        .map_err(|e| self.err(e))?;
        let before = self.status()?;
        send_profile(self.link.as_mut(), vec![jog], 0).map_err(|e| self.err(e))?;
        if !self.serve_for(seconds)? {
            return Ok(());
        }
        let halt = profile_halts(self.cell, &AxisModes::configured(self.cell), Some(&[axis]));
        send_profile(self.link.as_mut(), halt.clone(), 0).map_err(|e| self.err(e))?;
        // The jog ended (velocity reached, or superseded by the halt), then the halt.
        self.wait_profile_axes(&[jog, halt[0]], &before)
    }

    /// Waits until each profile axis sent one of `commands` since `before` reports it ended;
    /// one refused or cancelled fails the step.
    fn wait_profile_axes(
        &mut self,
        commands: &[ProfileCommand],
        before: &StatusSnapshot,
    ) -> Result<(), ProgramError> {
        loop {
            if self.aborted() || commands.is_empty() {
                return Ok(());
            }
            let s = self.status()?;
            let mut all = true;
            for (k, c) in commands.iter().enumerate() {
                let (now, then) = (
                    s.live[usize::from(c.axis)],
                    before.live[usize::from(c.axis)],
                );
                // As many ends on the axis as commands sent to it (each command ends once).
                let sent = commands[..=k].iter().filter(|o| o.axis == c.axis).count() as u32;
                if now.profile_failed != then.profile_failed {
                    let name = &self.cell.axes.on_loop()[usize::from(c.axis)].name;
                    return Err(self.err(format!(
                        "axis '{name}': its drive-side command was refused or cancelled (see the events)"
                    )));
                }
                all &= now.profile_finished.wrapping_sub(then.profile_finished) >= sent;
            }
            if all {
                return Ok(());
            }
            if matches!(s.state, CellState::Faulted | CellState::Stopped) {
                return Err(self.err(format!("the cell is {}", s.state.as_str())));
            }
            std::thread::sleep(TICK);
        }
    }

    /// A torque step: every target axis ramps to its torque, holds it, ramps back to zero; the
    /// other axes hold.
    fn run_torque(&mut self, targets: &[TorqueTarget], hold_s: f64) -> Result<(), ProgramError> {
        let targets: Vec<(usize, f64, f64)> = targets
            .iter()
            .filter_map(|t| match t.axis {
                AxisRef::Loop(i) => Some((i, t.torque, t.slope)),
                AxisRef::Link(_) => None,
            })
            .collect();
        if targets
            .iter()
            .any(|&(i, ..)| self.cell.axes.on_loop()[i].profile_objects.is_some())
        {
            return self.run_profile_torque(&targets, hold_s);
        }
        let req = MotionRequest::Torque { targets, hold_s };
        self.run_motion(req, None)
    }

    /// Hands `req` to the motion engine and follows it until the RT thread finished it; with
    /// `halt_after`, halts it after that long (a jog).
    fn run_motion(
        &mut self,
        req: MotionRequest,
        halt_after: Option<Duration>,
    ) -> Result<(), ProgramError> {
        self.run_motion_with(req, halt_after, &[])
    }

    /// [`Self::run_motion`] with profile axes' drive-side motions that start in the motion's
    /// first cycle (sent once it is submitted; a restarted motion does not send them again).
    fn run_motion_with(
        &mut self,
        req: MotionRequest,
        halt_after: Option<Duration>,
        drive_side: &[ProfileCommand],
    ) -> Result<(), ProgramError> {
        if let Err(e) = self.engine.submit(req.clone(), self.link.as_mut()) {
            return Err(self.err(e));
        }
        let start = self.engine.start_cycle().unwrap_or(0);
        send_profile(self.link.as_mut(), drive_side.to_vec(), start).map_err(|e| self.err(e))?;
        let halt_at = halt_after.map(|d| Instant::now() + d);
        let mut halted = false;
        let mut restarts = 0;
        loop {
            if self.aborted() {
                return Ok(());
            }
            if !halted && halt_at.is_some_and(|t| Instant::now() >= t) {
                halted = true;
                if let Err(e) = self
                    .engine
                    .submit(MotionRequest::Halt(None), self.link.as_mut())
                {
                    return Err(self.err(e));
                }
            }
            self.poll_operator();
            match self.engine.tick(self.link.as_mut()) {
                Ok(Progress::Running) => {}
                Ok(Progress::Idle | Progress::Finished(_)) => return Ok(()),
                // Its first block reached the RT thread too late (a stalled machine): nothing
                // moved, so the step starts over, a bounded number of times.
                Err(MotionError::NotStarted(id)) if !halted && restarts < MAX_RESTARTS => {
                    restarts += 1;
                    tracing::warn!(
                        "motion {id} did not start (its first block was refused); starting the step again ({restarts}/{MAX_RESTARTS})"
                    );
                    if let Err(e) = self.engine.submit(req.clone(), self.link.as_mut()) {
                        return Err(self.err(e));
                    }
                }
                Err(e) => return Err(self.err(e)),
            }
            std::thread::sleep(TICK);
        }
    }
}
