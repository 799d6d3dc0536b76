//! The non-RT planner thread: runs a program, plans each move with rsruckig (via
//! `cellrt-trajectory`), samples it at the cycle time into setpoint blocks and publishes them
//! through iceoryx2, keeping a lookahead ahead of the RT thread's cycle.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use cellrt_trajectory::planner::{plan_move, AxisState, MoveAxis};
use cellrt_trajectory::sampler::MoveSampler;
use cellrt_trajectory::torque::TorqueRamp;
use iceoryx2::prelude::*;

use crate::config::CellConfig;
use crate::handoff::{CellCommand, CellState, EventKind, Handoff};
use crate::link::{CellLink, LocalLink, RemoteLink, StatusSnapshot};
use crate::program::{MoveTarget, Program, Step, TorqueTarget};
use crate::services;
use crate::setpoints::{AxisSetpoint, SetpointHeader, BLOCK_CYCLES, FLAG_LAST, FLAG_TORQUE};

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
/// iceoryx2 receive free memory; ARCHITECTURE.md).
pub struct PlannerHandle {
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

/// Starts the planner thread running `program` on `cell`.
pub fn spawn(
    cell: &CellConfig,
    program: Program,
    handoff: Arc<Handoff>,
) -> std::io::Result<PlannerHandle> {
    let abort = Arc::new(AtomicBool::new(false));
    let abort2 = abort.clone();
    let cell = cell.clone();
    let release = Arc::new(AtomicBool::new(false));
    let release2 = release.clone();
    let (ready_tx, ready_rx) = std::sync::mpsc::channel::<()>();
    let (result_tx, result_rx) = std::sync::mpsc::channel();
    let handle = std::thread::Builder::new()
        .name("cellrt-planner".into())
        .spawn(move || {
            let link = LocalLink::new(handoff, cell.axes.len());
            let planner = Planner::new(&cell, Box::new(link), &abort2, &program);
            let _ = ready_tx.send(());
            match planner {
                Ok(mut p) => {
                    let _ = result_tx.send(p.run(&program));
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
    let _ = ready_rx.recv();
    Ok(PlannerHandle {
        abort,
        release,
        handle,
        result_rx,
        result: None,
    })
}

/// Runs `program` from a planner process of its own: connects to the running controller of
/// `cell` (started with `--external-planner`) through its status and command services and
/// publishes setpoints on the cell's setpoint service. Returns when the program ends, fails or
/// `abort` is set.
pub fn run_external(
    cell: &CellConfig,
    program: &Program,
    abort: &AtomicBool,
    connect_timeout: Duration,
) -> Result<(), ProgramError> {
    let fail = |reason: String| ProgramError {
        program: program.source.display().to_string(),
        step: 0,
        what: "connect",
        reason,
    };
    let node = services::node(&cell.name, "link-client").map_err(|e| fail(e.to_string()))?;
    let link = RemoteLink::connect(
        &node,
        &cell.name,
        cell.cycle_time.as_nanos(),
        cell.axes.len(),
        connect_timeout,
    )
    .map_err(fail)?;
    let mut planner = Planner::new(cell, Box::new(link), abort, program)?;
    planner.run(program)
}

struct Planner<'a> {
    cell: &'a CellConfig,
    link: Box<dyn CellLink + 'a>,
    abort: &'a AtomicBool,
    publisher: services::SetpointPublisher,
    _node: Node<ipc::Service>,
    source: String,
    step: usize,
    what: &'static str,
    /// Planner stalls still to inject: (cycle, duration ns).
    stalls: Vec<(u64, u64)>,
}

impl<'a> Planner<'a> {
    fn new(
        cell: &'a CellConfig,
        link: Box<dyn CellLink + 'a>,
        abort: &'a AtomicBool,
        program: &Program,
    ) -> Result<Self, ProgramError> {
        let fail = |e: services::ServiceError| ProgramError {
            program: program.source.display().to_string(),
            step: 0,
            what: "planner",
            reason: e.to_string(),
        };
        let node = services::node(&cell.name, "planner").map_err(fail)?;
        let publisher =
            services::setpoint_publisher(&node, &cell.name, cell.axes.len()).map_err(fail)?;
        Ok(Planner {
            cell,
            link,
            abort,
            publisher,
            _node: node,
            source: program.source.display().to_string(),
            step: 0,
            what: "",
            stalls: cell
                .inject
                .iter()
                .filter_map(|i| match i.fault {
                    crate::config::InjectedFault::PlannerStall { ns } => Some((i.cycle, ns)),
                    _ => None,
                })
                .collect(),
        })
    }

    fn err(&self, reason: impl Into<String>) -> ProgramError {
        ProgramError {
            program: self.source.clone(),
            step: self.step,
            what: self.what,
            reason: reason.into(),
        }
    }

    fn aborted(&self) -> bool {
        self.abort.load(Ordering::Acquire)
    }

    fn status(&mut self) -> Result<StatusSnapshot, ProgramError> {
        self.link.status().map_err(|e| self.err(e))
    }

    fn run(&mut self, program: &Program) -> Result<(), ProgramError> {
        for (i, step) in program.steps.iter().enumerate() {
            if self.aborted() {
                return Ok(());
            }
            self.step = i;
            match step {
                Step::PowerOn => {
                    self.what = "power_on";
                    self.command(CellCommand::PowerOn)?;
                    self.wait_for_state(CellState::Idle, POWER_TIMEOUT)?;
                }
                Step::PowerOff => {
                    self.what = "power_off";
                    self.command(CellCommand::PowerOff)?;
                    self.wait_for_state(CellState::Disabled, POWER_TIMEOUT)?;
                }
                Step::Reset => {
                    self.what = "reset";
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
                    self.run_move(targets)?;
                }
                Step::Torque { targets, hold_s } => {
                    self.what = "torque";
                    self.run_torque(targets, *hold_s)?;
                }
            }
        }
        Ok(())
    }

    fn command(&mut self, cmd: CellCommand) -> Result<(), ProgramError> {
        self.link.command(cmd).map_err(|e| self.err(e))
    }

    fn sleep(&self, d: Duration) {
        let end = Instant::now() + d;
        while !self.aborted() {
            let now = Instant::now();
            if now >= end {
                break;
            }
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

    fn run_move(&mut self, targets: &[MoveTarget]) -> Result<(), ProgramError> {
        let status = self.status()?;
        if status.state != CellState::Idle {
            return Err(self.err(format!(
                "the cell is {}, not idle (power on first, or reset after a stop)",
                status.state.as_str()
            )));
        }
        let n = self.cell.axes.len();
        let hold: Vec<f64> = status.hold[..n].to_vec();
        let axes: Vec<MoveAxis> = targets
            .iter()
            .map(|t| {
                let s = self.cell.axes[t.axis].scaling;
                MoveAxis {
                    start: AxisState {
                        position: s.to_units(hold[t.axis]),
                        velocity: 0.0,
                        acceleration: 0.0,
                    },
                    target: t.target,
                    limits: t.limits,
                }
            })
            .collect();
        let plan = plan_move(&axes).map_err(|e| self.err(format!("planning failed: {e}")))?;
        let period = self.cell.period();
        let sampler = MoveSampler::new(plan, period)
            .map_err(|e| self.err(format!("sampling failed: {e}")))?;
        let total = sampler.cycles();
        if total == 0 {
            return Ok(());
        }

        let hold: &[f64] = &hold;
        let cell = self.cell;
        let mut sample = vec![AxisState::default(); targets.len()];
        self.publish_motion(status.motion_id, status.cycle, total, 0, |k, row| {
            sampler.fill(k, &mut sample);
            for (i, sp) in row.iter_mut().enumerate() {
                *sp = AxisSetpoint {
                    position: hold[i],
                    velocity: 0.0,
                    torque: 0.0,
                };
            }
            for (t, s) in targets.iter().zip(&sample) {
                let sc = cell.axes[t.axis].scaling;
                row[t.axis] = AxisSetpoint {
                    position: sc.to_counts(s.position),
                    velocity: sc.to_counts(s.velocity),
                    torque: 0.0,
                };
            }
        })
    }

    /// A torque step: every target axis ramps to its torque, holds it, ramps back to zero; the
    /// other axes hold. Published as one [`FLAG_TORQUE`] motion.
    fn run_torque(&mut self, targets: &[TorqueTarget], hold_s: f64) -> Result<(), ProgramError> {
        let status = self.status()?;
        if status.state != CellState::Idle {
            return Err(self.err(format!(
                "the cell is {}, not idle (power on first, or reset after a stop)",
                status.state.as_str()
            )));
        }
        let ramps = targets
            .iter()
            .map(|t| TorqueRamp::new(t.torque, t.slope, hold_s))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| self.err(format!("torque profile: {e}")))?;
        let period = self.cell.period();
        let duration = ramps.iter().map(TorqueRamp::duration_s).fold(0.0, f64::max);
        // One cycle past the end so the last setpoint is zero torque.
        let total = (duration / period).ceil() as u64 + 1;
        let n = self.cell.axes.len();
        let hold: Vec<f64> = status.hold[..n].to_vec();
        self.publish_motion(
            status.motion_id,
            status.cycle,
            total,
            FLAG_TORQUE,
            |k, row| {
                for (i, sp) in row.iter_mut().enumerate() {
                    *sp = AxisSetpoint {
                        position: hold[i],
                        velocity: 0.0,
                        torque: 0.0,
                    };
                }
                for (t, r) in targets.iter().zip(&ramps) {
                    row[t.axis].torque = r.at(k as f64 * period);
                }
            },
        )
    }

    /// Publishes a motion of `total` cycles (cycle k = 1..=total filled by `fill`) in blocks,
    /// at most the lookahead ahead of the RT thread, then waits until the RT thread finished it.
    fn publish_motion(
        &mut self,
        last_motion_id: u32,
        now_cycle: u64,
        total: u64,
        flags: u32,
        mut fill: impl FnMut(u64, &mut [AxisSetpoint]),
    ) -> Result<(), ProgramError> {
        let n = self.cell.axes.len();
        let period = self.cell.period();
        let motion_id = last_motion_id.wrapping_add(1).max(1);
        let cycle_ns = self.cell.cycle_time.as_nanos() as f64;
        let delay = (self.cell.setpoints.start_delay * 1e9 / cycle_ns).ceil() as u64;
        let lookahead = ((self.cell.setpoints.lookahead * 1e9 / cycle_ns).ceil() as u64)
            .max(2 * BLOCK_CYCLES as u64);
        let start_cycle = now_cycle + delay.max(2);

        let mut rows = vec![AxisSetpoint::default(); BLOCK_CYCLES * n];
        let mut k = 1u64;
        while k <= total {
            let block_start = start_cycle + (k - 1);
            // Keep at most `lookahead` cycles ahead of the RT thread.
            loop {
                if self.aborted() {
                    return Ok(());
                }
                let now = self.check_running(motion_id, block_start)?;
                if block_start <= now + lookahead {
                    break;
                }
                std::thread::sleep(Duration::from_secs_f64((period / 2.0).min(1e-3)));
            }
            self.inject_stall()?;
            if self.aborted() {
                return Ok(());
            }
            let cycles = (total - k + 1).min(BLOCK_CYCLES as u64) as usize;
            for c in 0..cycles {
                fill(k + c as u64, &mut rows[c * n..(c + 1) * n]);
            }
            let mut loaned = self
                .publisher
                .loan_slice_uninit(cycles * n)
                .map_err(|e| self.err(format!("setpoint loan failed: {e:?}")))?;
            *loaned.user_header_mut() = SetpointHeader {
                motion_id,
                flags: flags
                    | if k + cycles as u64 > total {
                        FLAG_LAST
                    } else {
                        0
                    },
                start_cycle: block_start,
                cycles: cycles as u32,
                axis_count: n as u32,
            };
            loaned
                .write_from_slice(&rows[..cycles * n])
                .send()
                .map_err(|e| self.err(format!("setpoint publish failed: {e:?}")))?;
            k += cycles as u64;
        }

        // Wait for the RT thread to finish the motion.
        let end_cycle = start_cycle + total;
        loop {
            if self.aborted() {
                return Ok(());
            }
            let s = self.status()?;
            if s.motion_done == motion_id && s.state == CellState::Idle {
                return Ok(());
            }
            self.check_running(motion_id, end_cycle)?;
            std::thread::sleep(Duration::from_millis(1));
        }
    }

    /// Fault injection: stops publishing for a while once a scheduled planner stall is due.
    fn inject_stall(&mut self) -> Result<(), ProgramError> {
        let now = self.status()?.cycle;
        if let Some(pos) = self.stalls.iter().position(|(c, _)| *c <= now) {
            let (_, ns) = self.stalls.remove(pos);
            self.link.event(EventKind::FaultInjected, 3);
            self.sleep(Duration::from_nanos(ns));
        }
        Ok(())
    }

    /// Fails the step if the RT thread stopped the motion or never started it; returns the
    /// cell's current cycle.
    fn check_running(&mut self, motion_id: u32, next_cycle: u64) -> Result<u64, ProgramError> {
        let s = self.status()?;
        match s.state {
            CellState::Stopping | CellState::Stopped | CellState::Faulted => {
                let why = s.stop_reason.map(|r| r.as_str()).unwrap_or("unknown");
                Err(self.err(format!(
                    "motion {motion_id} was stopped by the RT thread ({why})"
                )))
            }
            CellState::Disabled | CellState::Disabling | CellState::Enabling => Err(self.err(
                format!("the cell is {} during motion {motion_id}", s.state.as_str()),
            )),
            CellState::Idle
                if s.motion_id != motion_id && s.cycle > next_cycle + 2 * BLOCK_CYCLES as u64 =>
            {
                Err(self.err(format!(
                    "the RT thread did not start motion {motion_id} (its first block was rejected; see the events)"
                )))
            }
            _ => Ok(s.cycle),
        }
    }
}
