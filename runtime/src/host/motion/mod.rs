//! The motion engine of the non-RT side: turns motion requests (moves, jogs, halts, torque,
//! the feed override) into one continuous setpoint stream for the RT thread.
//!
//! A motion, for the RT thread, is a run of contiguous setpoint blocks with one motion id that
//! ends with a block flagged last. The engine keeps publishing at most the lookahead ahead of
//! the RT thread's cycle, sampling [`OnlineMotion`] once per cycle, so a request that arrives
//! during a motion changes the goal from the first cycle not yet published: the motion goes on
//! under the same id, continuous in position, velocity and acceleration (re-targeting). A
//! request arriving after the last block went out waits for the RT thread to finish that
//! motion (at most the lookahead) and starts the next one.

mod checks;
mod error;

use std::time::{Duration, Instant};

use cellrt_cia402::mode::ModeOfOperation;
use cellrt_cia402::Cycles;
use cellrt_trajectory::{
    plan_waypoints, AxisState, KinematicLimits, LineMove, MoveAxis, MoveSampler, OnlineAxis,
    OnlineMotion, TorqueRamp,
};

use crate::handoff::{CellState, EventKind};
use crate::host::link::{CellLink, StatusSnapshot};
use crate::services::SetpointPublisher;
use crate::setpoints::{AxisSetpoint, SetpointHeader, BLOCK_CYCLES, FLAG_LAST, FLAG_TORQUE};
use cellrt_config::CellConfig;
use error::refused;
pub use error::MotionError;

/// How long a request waits for the motion whose last block is out to finish.
pub const FINISH_WAIT: Duration = Duration::from_secs(2);

/// What a request asks of the motion.
#[derive(Debug, Clone, PartialEq)]
pub enum MotionRequest {
    /// Move the listed axes (index, target in units, limits in units), time-synchronised.
    Move(Vec<(usize, f64, KinematicLimits)>),
    /// Jog one axis at a signed velocity (units/s) with these limits.
    Jog {
        /// Axis index.
        axis: usize,
        /// Velocity, unit/s.
        velocity: f64,
        /// Limits of the ramp.
        limits: KinematicLimits,
    },
    /// Brake the listed axes (all when `None`) to rest and hold.
    Halt(Option<Vec<usize>>),
    /// A waypoint move from rest: (axis index, final target, limits) and the intermediate
    /// positions (one per listed axis each).
    Path {
        /// Axes with their final targets and limits.
        targets: Vec<(usize, f64, KinematicLimits)>,
        /// Intermediate positions.
        via: Vec<Vec<f64>>,
    },
    /// A straight line of an axis group (one unit) from rest: (axis index, end, axis limits
    /// for this move), the path speed at most `path_velocity`.
    Line {
        /// Axes of the group with their end positions and limits.
        targets: Vec<(usize, f64, KinematicLimits)>,
        /// Path velocity cap, unit/s.
        path_velocity: Option<f64>,
    },
    /// Torque on cst axes: (axis index, torque %, slope %/s), held `hold_s` seconds.
    Torque {
        /// Axes, torques and slopes.
        targets: Vec<(usize, f64, f64)>,
        /// Seconds at the target torque.
        hold_s: f64,
    },
}

impl MotionRequest {
    /// The axes the request sets in motion; `None` for a halt.
    fn moved_axes(&self) -> Option<Vec<usize>> {
        Some(match self {
            MotionRequest::Move(t) | MotionRequest::Path { targets: t, .. } => {
                t.iter().map(|t| t.0).collect()
            }
            MotionRequest::Line { targets, .. } => targets.iter().map(|t| t.0).collect(),
            MotionRequest::Torque { targets, .. } => targets.iter().map(|t| t.0).collect(),
            MotionRequest::Jog { axis, .. } => vec![*axis],
            MotionRequest::Halt(_) => return None,
        })
    }
}

/// Torque motion in progress: the ramps from its start, or a ramp down from a halt.
struct TorqueMotion {
    ramps: Vec<(usize, TorqueRamp)>,
    /// Cycle index of a halt and the torque of each ramp then.
    halted: Option<(u64, Vec<f64>)>,
    end: u64,
}

impl TorqueMotion {
    fn value(&self, index: usize, k: u64, period: f64) -> f64 {
        let (_, ramp) = &self.ramps[index];
        match &self.halted {
            Some((kh, at)) if k >= *kh => {
                let t = (k - kh) as f64 * period;
                let mag = (at[index].abs() - ramp.slope() * t).max(0.0);
                mag * at[index].signum()
            }
            _ => ramp.at(k as f64 * period),
        }
    }
}

enum Kind {
    Online,
    Torque(TorqueMotion),
    /// A line and the cell indices of its axes.
    Line(Box<LineMove>, Vec<usize>),
    /// A planned (waypoint) move and the cell indices of its axes.
    Planned(Box<MoveSampler>, Vec<usize>),
}

/// The motion the RT thread is (about to be) running.
struct Active {
    motion_id: u32,
    start_cycle: u64,
    /// Next cycle index (1-based) to publish.
    next: u64,
    last_published: bool,
    kind: Kind,
}

/// What [`MotionEngine::tick`] saw.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Progress {
    /// No motion.
    Idle,
    /// A motion runs.
    Running,
    /// The motion ended this tick (the RT thread reported it done).
    Finished(u32),
}

/// The engine: the cell's online motion and the setpoint publisher.
pub struct MotionEngine {
    cell: CellConfig,
    publisher: SetpointPublisher,
    online: OnlineMotion,
    active: Option<Active>,
    rows: Vec<AxisSetpoint>,
    states: Vec<AxisState>,
    hold: Vec<f64>,
    /// Planner stalls still to inject: (cycle, duration ns).
    stalls: Vec<(u64, u64)>,
}

impl MotionEngine {
    /// An engine publishing on `publisher` for `cell`.
    pub fn new(cell: &CellConfig, publisher: SetpointPublisher) -> MotionEngine {
        let n = cell.axes.on_loop().len();
        let axes = cell
            .axes
            .on_loop()
            .iter()
            .map(|a| OnlineAxis {
                limits: a.limits,
                range: a.position,
            })
            .collect();
        let start: Vec<f64> = cell
            .axes
            .on_loop()
            .iter()
            .map(|a| a.position.min.max(0.0).min(a.position.max))
            .collect();
        MotionEngine {
            online: OnlineMotion::new(axes, cell.period(), &start),
            publisher,
            active: None,
            rows: vec![AxisSetpoint::default(); BLOCK_CYCLES * n],
            states: vec![AxisState::default(); n],
            hold: vec![0.0; n],
            stalls: cell
                .inject
                .iter()
                .filter_map(|i| match i.fault {
                    cellrt_config::InjectedFault::PlannerStall { ns } => Some((i.cycle, ns)),
                    _ => None,
                })
                .collect(),
            cell: cell.clone(),
        }
    }

    /// Whether a motion is in flight.
    pub fn is_busy(&self) -> bool {
        self.active.is_some()
    }

    /// The id of the motion in flight.
    pub fn motion_id(&self) -> Option<u32> {
        self.active.as_ref().map(|a| a.motion_id)
    }

    /// The cycle the motion in flight starts in (its first block's cycle).
    pub fn start_cycle(&self) -> Option<u64> {
        self.active.as_ref().map(|a| a.start_cycle)
    }

    /// The commanded position of axis `i` in units: where the motion in flight has got to in
    /// publishing, or the RT thread's hold position.
    pub fn position(
        &self,
        i: usize,
        status: &StatusSnapshot,
        axis: &cellrt_config::AxisConfig,
    ) -> f64 {
        match self.active.as_ref().map(|a| &a.kind) {
            Some(Kind::Online) => self.online.state(i).position,
            _ => axis.scaling.to_units(status.hold[i]),
        }
    }

    /// The feed override in effect, 0..=1.
    pub fn feed_override(&self) -> f64 {
        self.online.feed_override()
    }

    /// Sets the feed override (0..=1): a streamed motion in flight follows it smoothly, and the
    /// RT thread scales the profile axes' drive-side velocities (through `link`).
    pub fn set_override(&mut self, value: f64, link: &mut dyn CellLink) -> Result<(), MotionError> {
        self.online
            .set_override(value)
            .map_err(|e| MotionError::Refused(e.to_string()))?;
        link.feed_override(value)
            .map_err(|e| MotionError::Refused(e.to_string()))?;
        if let Some(Active {
            kind: Kind::Line(line, _),
            ..
        }) = self.active.as_mut()
        {
            line.set_override(value)
                .map_err(|e| MotionError::Refused(e.to_string()))?;
        }
        Ok(())
    }

    /// Applies `req`: changes the motion in flight or starts one. Refused (with the reason,
    /// nothing changed) when the cell cannot take it.
    pub fn submit(
        &mut self,
        req: MotionRequest,
        link: &mut dyn CellLink,
    ) -> Result<(), MotionError> {
        self.check_request(&req)?;
        self.check_live(&req, link)?;
        if self.active.as_ref().is_some_and(|a| a.last_published) {
            self.wait_finished(link)?;
        }
        if matches!(
            (&req, self.active.as_ref().map(|a| &a.kind)),
            (
                MotionRequest::Move(_) | MotionRequest::Jog { .. } | MotionRequest::Halt(_),
                Some(Kind::Planned(..))
            )
        ) {
            self.take_over_planned();
        }
        if self.settle_with_active(&req)? {
            return Ok(());
        }
        if self.active.is_none() {
            let status = link.status()?;
            if status.state != CellState::Idle {
                return Err(MotionError::NotIdle(status.state.as_str()));
            }
            let kind = self.new_motion(&req, &status)?;
            self.begin(&status, kind);
        }
        let r = match req {
            MotionRequest::Move(targets) => self.online.move_to(&targets),
            MotionRequest::Jog {
                axis,
                velocity,
                limits,
            } => self.online.jog(axis, velocity, limits),
            MotionRequest::Halt(axes) => self.online.halt(axes.as_deref()),
            MotionRequest::Torque { .. }
            | MotionRequest::Line { .. }
            | MotionRequest::Path { .. } => Ok(()),
        };
        r.map_err(|e| MotionError::Refused(self.describe(e)))
    }

    /// What `req` means for the motion in flight (a line move or torque command takes only a
    /// halt; lines, paths and torque need the cell at rest): `Ok(true)` when that settles it.
    fn settle_with_active(&mut self, req: &MotionRequest) -> Result<bool, MotionError> {
        let torque_active = matches!(self.active.as_ref().map(|a| &a.kind), Some(Kind::Torque(_)));
        let line_active = matches!(self.active.as_ref().map(|a| &a.kind), Some(Kind::Line(..)));
        match (req, self.active.is_some()) {
            (MotionRequest::Halt(_), false) => Ok(true),
            (MotionRequest::Halt(_), true) if line_active => {
                if let Some(Active {
                    kind: Kind::Line(line, _),
                    ..
                }) = self.active.as_mut()
                {
                    line.halt();
                }
                Ok(true)
            }
            (_, true) if line_active => Err(MotionError::Busy {
                active: "line move",
            }),
            (MotionRequest::Line { .. } | MotionRequest::Path { .. }, true) => Err(
                MotionError::NotAtRest(if matches!(req, MotionRequest::Line { .. }) {
                    "line"
                } else {
                    "waypoint path"
                }),
            ),
            (MotionRequest::Halt(_), true) if torque_active => {
                self.halt_torque();
                Ok(true)
            }
            (_, true) if torque_active => Err(MotionError::Busy {
                active: "torque command",
            }),
            (MotionRequest::Torque { .. }, true) => Err(MotionError::Busy { active: "motion" }),
            _ => Ok(false),
        }
    }

    /// Halts the torque command in flight: every axis ramps from where it is to zero at its
    /// slope (once; a second halt changes nothing).
    fn halt_torque(&mut self) {
        let period = self.cell.period();
        let Some(Active {
            next,
            kind: Kind::Torque(t),
            ..
        }) = self.active.as_mut()
        else {
            return;
        };
        if t.halted.is_none() {
            let k = *next;
            let at: Vec<f64> = (0..t.ramps.len()).map(|i| t.value(i, k, period)).collect();
            let ramp_s = t
                .ramps
                .iter()
                .zip(&at)
                .map(|((_, r), v)| v.abs() / r.slope())
                .fold(0.0, f64::max);
            t.end = k + (ramp_s / period).ceil() as u64 + 1;
            t.halted = Some((k, at));
        }
    }

    /// The motion `req` starts from the cell at rest in `status`.
    fn new_motion(
        &self,
        req: &MotionRequest,
        status: &StatusSnapshot,
    ) -> Result<Kind, MotionError> {
        Ok(match req {
            MotionRequest::Torque { targets, hold_s } => self.torque_motion(targets, *hold_s)?,
            MotionRequest::Line {
                targets,
                path_velocity,
            } => self.line_motion(targets, *path_velocity, status)?,
            MotionRequest::Path { targets, via } => {
                let axes: Vec<MoveAxis> = targets
                    .iter()
                    .map(|&(i, target, limits)| MoveAxis {
                        start: AxisState {
                            position: self.cell.axes.on_loop()[i].scaling.to_units(status.hold[i]),
                            ..AxisState::default()
                        },
                        target,
                        limits,
                    })
                    .collect();
                let plan =
                    plan_waypoints(&axes, via).map_err(|e| MotionError::planning("path")(&e))?;
                let sampler = MoveSampler::new(plan, self.cell.period())
                    .map_err(|e| MotionError::planning("path")(&e))?;
                Kind::Planned(Box::new(sampler), targets.iter().map(|t| t.0).collect())
            }
            _ => Kind::Online,
        })
    }

    /// A torque command from rest: each axis ramps to its torque at its slope, holds it
    /// `hold_s` seconds and ramps back to zero.
    fn torque_motion(
        &self,
        targets: &[(usize, f64, f64)],
        hold_s: f64,
    ) -> Result<Kind, MotionError> {
        let ramps = targets
            .iter()
            .map(|&(axis, torque, slope)| TorqueRamp::new(torque, slope, hold_s).map(|r| (axis, r)))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| MotionError::planning("torque profile")(&e))?;
        let duration = ramps
            .iter()
            .map(|(_, r)| r.duration_s())
            .fold(0.0, f64::max);
        // One cycle past the end so the last setpoint is zero torque.
        let end = (duration / self.cell.period()).ceil() as u64 + 1;
        Ok(Kind::Torque(TorqueMotion {
            ramps,
            halted: None,
            end,
        }))
    }

    /// A straight line of an axis group from the hold positions in `status`.
    fn line_motion(
        &self,
        targets: &[(usize, f64, KinematicLimits)],
        path_velocity: Option<f64>,
        status: &StatusSnapshot,
    ) -> Result<Kind, MotionError> {
        let axes: Vec<usize> = targets.iter().map(|t| t.0).collect();
        let start: Vec<f64> = axes
            .iter()
            .map(|&i| self.cell.axes.on_loop()[i].scaling.to_units(status.hold[i]))
            .collect();
        let end: Vec<f64> = targets.iter().map(|t| t.1).collect();
        let limits: Vec<KinematicLimits> = targets.iter().map(|t| t.2).collect();
        for &(i, end, _) in targets {
            let a = &self.cell.axes.on_loop()[i];
            a.position.check(end).map_err(|e| {
                MotionError::Refused(format!("axis '{}' ({}): {e}", a.name, a.unit))
            })?;
        }
        let mut line = LineMove::new(&start, &end, &limits, path_velocity, self.cell.period())
            .map_err(|e| MotionError::planning("line")(&e))?;
        line.set_override(self.online.feed_override())
            .map_err(|e| MotionError::planning("line")(&e))?;
        Ok(Kind::Line(Box::new(line), axes))
    }

    /// A new motion from rest at the RT thread's hold positions.
    fn begin(&mut self, status: &StatusSnapshot, kind: Kind) {
        let n = self.cell.axes.on_loop().len();
        for (i, a) in self.cell.axes.on_loop().iter().enumerate() {
            self.hold[i] = status.hold[i];
            self.states[i] = AxisState {
                position: a.scaling.to_units(status.hold[i]),
                ..AxisState::default()
            };
        }
        let positions: Vec<f64> = self.states[..n].iter().map(|s| s.position).collect();
        self.online.reset(&positions);
        let cycle_ns = self.cell.cycle_time.as_nanos() as f64;
        let delay = (self.cell.setpoints.start_delay * 1e9 / cycle_ns).ceil() as u64;
        self.active = Some(Active {
            // After the last motion started or refused: a refused id is never used again.
            motion_id: status
                .motion_id
                .max(status.motion_refused)
                .wrapping_add(1)
                .max(1),
            start_cycle: status.cycle + delay.max(2),
            next: 1,
            last_published: false,
            kind,
        });
    }

    /// Turns the waypoint path in flight into an online motion at its last published state, so
    /// a halt or a new target continues from there without a step.
    fn take_over_planned(&mut self) {
        let Some(Active {
            next,
            kind: Kind::Planned(sampler, axes),
            ..
        }) = self.active.as_ref()
        else {
            return;
        };
        let mut states: Vec<AxisState> = self
            .cell
            .axes
            .on_loop()
            .iter()
            .zip(&self.hold)
            .map(|(a, h)| AxisState {
                position: a.scaling.to_units(*h),
                ..AxisState::default()
            })
            .collect();
        let mut group = [AxisState::default(); cellrt_trajectory::MAX_MOVE_AXES];
        sampler.fill(next.saturating_sub(1), &mut group[..axes.len()]);
        for (&i, st) in axes.iter().zip(&group) {
            states[i] = *st;
        }
        self.online.continue_from(&states);
        if let Some(a) = self.active.as_mut() {
            a.kind = Kind::Online;
        }
    }

    /// Waits (at most [`FINISH_WAIT`]) for the motion whose last block is out to end.
    fn wait_finished(&mut self, link: &mut dyn CellLink) -> Result<(), MotionError> {
        let end = Instant::now() + FINISH_WAIT;
        while self.active.is_some() {
            self.tick(link)?;
            if Instant::now() >= end {
                return Err(MotionError::PreviousNotFinished);
            }
            std::thread::sleep(Duration::from_millis(1));
        }
        Ok(())
    }

    /// Abandons the motion in flight without publishing more (after a stop or power off).
    pub fn abandon(&mut self) {
        self.active = None;
    }

    /// Publishes what the lookahead allows and follows the RT thread; fails (and drops the
    /// motion) when the RT thread stopped it or never started it.
    pub fn tick(&mut self, link: &mut dyn CellLink) -> Result<Progress, MotionError> {
        let Some(active) = self.active.as_ref() else {
            return Ok(Progress::Idle);
        };
        let id = active.motion_id;
        let s = link.status()?;
        let next_cycle = active.start_cycle + active.next - 1;
        if let Err(e) = check_running(&s, id, next_cycle, self.cell.setpoints.max_start_slip) {
            self.active = None;
            return Err(e);
        }
        if active.last_published {
            if s.motion_done == id && s.state == CellState::Idle {
                self.active = None;
                return Ok(Progress::Finished(id));
            }
            return Ok(Progress::Running);
        }
        let cycle_ns = self.cell.cycle_time.as_nanos() as f64;
        let lookahead = ((self.cell.setpoints.lookahead * 1e9 / cycle_ns).ceil() as u64)
            .max(2 * BLOCK_CYCLES as u64);
        let mut now = motion_cycle(&s, id);
        while let Some(a) = self.active.as_ref() {
            if a.last_published || a.start_cycle + a.next - 1 > now + lookahead {
                break;
            }
            if let Some(pos) = self.stalls.iter().position(|(c, _)| *c <= now) {
                let (_, ns) = self.stalls.remove(pos);
                link.event(
                    EventKind::FaultInjected,
                    cellrt_config::FaultKind::PlannerStall.code(),
                );
                std::thread::sleep(Duration::from_nanos(ns));
                now = motion_cycle(&link.status()?, id);
                continue;
            }
            self.publish_block()?;
        }
        Ok(Progress::Running)
    }

    /// Samples and publishes the next block of the active motion.
    fn publish_block(&mut self) -> Result<(), MotionError> {
        let n = self.cell.axes.on_loop().len();
        let period = self.cell.period();
        let Some(a) = self.active.as_mut() else {
            return Ok(());
        };
        let mut cycles = 0;
        let mut last = false;
        let flags = match &a.kind {
            Kind::Online | Kind::Line(..) | Kind::Planned(..) => 0,
            Kind::Torque(_) => FLAG_TORQUE,
        };
        while cycles < BLOCK_CYCLES && !last {
            let k = a.next + cycles as u64;
            let row = &mut self.rows[cycles * n..(cycles + 1) * n];
            match &mut a.kind {
                Kind::Line(line, axes) => {
                    let mut group = [AxisState::default(); cellrt_trajectory::MAX_MOVE_AXES];
                    line.step(&mut group[..axes.len()])
                        .map_err(|e| MotionError::planning("line")(&e))?;
                    group_row(row, &self.hold, &self.cell, axes, &group);
                    last = line.is_done();
                }
                Kind::Planned(sampler, axes) => {
                    let mut group = [AxisState::default(); cellrt_trajectory::MAX_MOVE_AXES];
                    sampler.fill(k, &mut group[..axes.len()]);
                    group_row(row, &self.hold, &self.cell, axes, &group);
                    last = k >= sampler.cycles();
                }
                Kind::Online => {
                    self.online
                        .step(&mut self.states)
                        .map_err(|e| MotionError::planning("planning failed")(&e))?;
                    for ((sp, st), ax) in row
                        .iter_mut()
                        .zip(&self.states)
                        .zip(self.cell.axes.on_loop())
                    {
                        *sp = AxisSetpoint {
                            position: ax.scaling.to_counts(st.position),
                            velocity: ax.scaling.to_counts(st.velocity),
                            torque: 0.0,
                        };
                    }
                    last = self.online.is_done();
                }
                Kind::Torque(t) => {
                    for (sp, h) in row.iter_mut().zip(&self.hold) {
                        *sp = AxisSetpoint {
                            position: *h,
                            velocity: 0.0,
                            torque: 0.0,
                        };
                    }
                    for (i, (axis, _)) in t.ramps.iter().enumerate() {
                        row[*axis].torque = t.value(i, k, period);
                    }
                    last = k >= t.end;
                }
            }
            cycles += 1;
        }
        let mut loaned =
            self.publisher
                .loan_slice_uninit(cycles * n)
                .map_err(|e| MotionError::Setpoints {
                    what: "loan",
                    detail: format!("{e:?}"),
                })?;
        *loaned.user_header_mut() = SetpointHeader {
            motion_id: a.motion_id,
            flags: flags | if last { FLAG_LAST } else { 0 },
            start_cycle: a.start_cycle + a.next - 1,
            cycles: cycles as u32,
            axis_count: n as u32,
        };
        loaned
            .write_from_slice(&self.rows[..cycles * n])
            .send()
            .map_err(|e| MotionError::Setpoints {
                what: "publish",
                detail: format!("{e:?}"),
            })?;
        a.next += cycles as u64;
        a.last_published = last;
        Ok(())
    }
}

/// One cycle's setpoints for a motion of an axis group: the group's `states` (units) on its
/// `axes`, every other axis holding.
fn group_row(
    row: &mut [AxisSetpoint],
    hold: &[f64],
    cell: &CellConfig,
    axes: &[usize],
    states: &[AxisState],
) {
    for (sp, h) in row.iter_mut().zip(hold) {
        *sp = AxisSetpoint {
            position: *h,
            velocity: 0.0,
            torque: 0.0,
        };
    }
    for (&i, st) in axes.iter().zip(states) {
        let sc = cell.axes.on_loop()[i].scaling;
        row[i] = AxisSetpoint {
            position: sc.to_counts(st.position),
            velocity: sc.to_counts(st.velocity),
            torque: 0.0,
        };
    }
}

/// The RT thread's latest cycle on motion `id`'s timeline: the cycle its blocks name, which
/// runs behind when the motion started late (`setpoints.max_start_slip_ms`).
fn motion_cycle(s: &StatusSnapshot, id: u32) -> u64 {
    if s.motion_id == id {
        s.cycle.saturating_sub(u64::from(s.motion_slip))
    } else {
        s.cycle
    }
}

/// Fails if the RT thread stopped motion `id` or never started it (`max_slip`: how late the RT
/// thread may still start it, `setpoints.max_start_slip_ms`).
fn check_running(
    s: &StatusSnapshot,
    id: u32,
    next_cycle: u64,
    max_slip: Cycles,
) -> Result<(), MotionError> {
    let cycle = motion_cycle(s, id);
    match s.state {
        CellState::Stopping | CellState::Stopped | CellState::Faulted => {
            let why = s.stop_reason.map(|r| r.as_str()).unwrap_or("unknown");
            Err(MotionError::StoppedByRt { id, why })
        }
        CellState::Disabled | CellState::Disabling | CellState::Enabling => {
            Err(MotionError::LeftPower {
                state: s.state.as_str(),
                id,
            })
        }
        CellState::Idle if s.motion_refused == id => Err(MotionError::NotStarted(id)),
        // Idle past the motion's last block without reporting it done: never wait for it.
        CellState::Idle
            if s.motion_id == id
                && s.motion_done != id
                && cycle > next_cycle + 2 * BLOCK_CYCLES as u64 =>
        {
            Err(MotionError::EndNotReported(id))
        }
        CellState::Idle
            if s.motion_id != id
                && s.motion_done != id
                && cycle > next_cycle + 2 * BLOCK_CYCLES as u64 + u64::from(max_slip.0) =>
        {
            Err(MotionError::NotStarted(id))
        }
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests;
