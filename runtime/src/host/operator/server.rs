//! The operator service's server end: runs in the planner thread (the owner of the motion
//! engine), answers each request with accepted or rejected, and tracks the command in execution.

use cellrt_cia402::mode::ModeOfOperation;
use cellrt_cia402::profiles::status_do::StatusDo;
use cellrt_cia402::statusword::Statusword;
use cellrt_fieldbus::mr_je_c::cell::AxisCommand;
use cellrt_trajectory::limits::{MAX_MOTION_S, MIN_LIMIT_FRACTION};
use cellrt_trajectory::KinematicLimits;
use iceoryx2::prelude::*;

mod motion_requests;

use super::backend::{self, link, profile};
use super::bus_diag::DiagInFlight;
use super::sdo::{self, SdoInFlight};
use super::sdo_job::{SdoJob, SingleSdo};
use super::sdo_list::{ListInFlight, ListStart};
use super::targets::{
    axis_index, axis_ref, check_travel, jog_velocity, move_limits, Asked, TargetError,
};
use super::wire::{self, ActiveCommand, AxisStatus, FinishedCommand, Reply, Request, StatusReport};
use crate::handoff::{
    CellCommand, CellState, HomeRequest, ProfileCommand, ProfileMotion, SwitchableMode,
};
use crate::host::link::{CellLink, StatusSnapshot};
use crate::host::motion::{MotionEngine, MotionRequest, Progress};
use crate::host::program::Program;
use crate::services::{self, OperatorServerPort, ServiceError, OPERATOR_RESPONSE_BYTES};
use cellrt_cia402::homing::{choose_procedure, HomeSettingEdge, HomingFailure};
use cellrt_config::{AxisKind, AxisRef, CellConfig};
use std::collections::BTreeMap;
use std::path::Path;

/// Why MC_Power of the RT axes was refused or could not be sent.
#[derive(Debug, thiserror::Error)]
enum PowerError {
    /// The cell's state does not allow it.
    #[error("the cell is {state}; {what}")]
    Blocked {
        state: &'static str,
        what: &'static str,
    },
    /// The RT thread did not take the command.
    #[error(transparent)]
    Link(#[from] crate::host::link::LinkError),
}

/// Why an `sdo`, `param` or `alarms` request could not start.
#[derive(Debug, thiserror::Error)]
enum JobError {
    /// Another one is in flight.
    #[error("{what}: another sdo request is in flight; try again")]
    InFlight { what: &'static str },
    /// A write while a program runs.
    #[error("{what}: a program is running; halt or stop it before writing")]
    ProgramRunning { what: &'static str },
    /// Not an sdo request at all.
    #[error("{what}: not an sdo request")]
    NotSdo { what: &'static str },
    /// The cell is homing (its own acyclic requests come first).
    #[error("{what}: the cell is homing; try again when the homing has ended")]
    Homing { what: &'static str },
    /// The transfer was refused or could not start.
    #[error(transparent)]
    Sdo(#[from] sdo::SdoError),
    /// The `param` request was refused.
    #[error(transparent)]
    Param(#[from] super::param::ParamError),
    /// The `alarms` request was refused.
    #[error(transparent)]
    Alarms(#[from] super::alarms::AlarmsError),
}

/// What the planner thread must do after a request.
pub enum Followup {
    /// Nothing.
    None,
    /// Run this program (already validated).
    RunProgram(Program),
    /// Abort the program in execution (halt or stop by the operator).
    AbortProgram,
}

/// The server: the iceoryx2 port and the command bookkeeping.
pub struct OperatorServer {
    port: OperatorServerPort,
    wake: iceoryx2::port::listener::Listener<ipc::Service>,
    next_id: u64,
    active: Option<ActiveCommand>,
    last_finished: Option<FinishedCommand>,
    /// The RT thread's homing sequence number when the active `home` was sent.
    home_seq: u32,
    /// The active `home` homes an MR-JE-C axis (followed by `je_c_moves`, not the RT thread).
    home_on_je_c: bool,
    status: services::OperatorStatusPublisher,
    last_status: std::time::Instant,
    /// The SDO transfer waiting for the drive's answer.
    sdo: SdoInFlight,
    /// The request whose transfers run (`sdo`, `param`, `alarms`) and its client.
    job: Option<(SdoJob, ActiveRequest)>,
    /// The `bus_diag` reading being taken, and the client's request to answer.
    diag: DiagInFlight,
    diag_client: Option<ActiveRequest>,
    /// The `sdo_list` walk in progress, and the client's request to answer.
    list: ListInFlight,
    list_client: Option<ActiveRequest>,
    /// The MR-JE-C axes the active move waits for.
    je_c_moves: link::PendingMoves,
    /// The drive-side motions the active command (a `move` of pp axes, a `mode` switch) waits
    /// for.
    profile_moves: profile::PendingProfile,
}

/// True if `axis` is in Operation enabled by its latest statusword.
fn operation_enabled(cell: &CellConfig, axis: &str, status: Option<&StatusSnapshot>) -> bool {
    let Some((i, s)) = axis_index(cell, axis).ok().zip(status) else {
        return false;
    };
    Statusword(s.live[i].statusword).state() == Some(cellrt_cia402::fsa::FsaState::OperationEnabled)
}

/// Answers the client whose request waited (`client`), if any; true if a reply went out.
fn respond_later(client: &mut Option<ActiveRequest>, reply: &Reply) -> bool {
    client.take().is_some_and(|active| {
        respond(&active, reply);
        true
    })
}

/// A client's request being answered.
type ActiveRequest = iceoryx2::active_request::ActiveRequest<ipc::Service, [u8], (), [u8], ()>;

/// What a request may touch.
pub struct Context<'a> {
    /// The cell.
    pub cell: &'a CellConfig,
    /// The motion engine.
    pub engine: &'a mut MotionEngine,
    /// The RT thread.
    pub link: &'a mut dyn CellLink,
    /// Whether a program runs.
    pub program_running: bool,
    /// The MR-JE-C axes.
    pub je_c: &'a crate::host::je_c::JecAxes,
}

impl OperatorServer {
    /// Opens the cell's operator service.
    pub fn new(node: &Node<ipc::Service>, cell: &str) -> Result<OperatorServer, ServiceError> {
        Ok(OperatorServer {
            port: services::operator_server(node, cell)?,
            wake: services::operator_wake_listener(node, cell)?,
            next_id: 1,
            active: None,
            last_finished: None,
            home_seq: 0,
            home_on_je_c: false,
            status: services::operator_status_publisher(node, cell)?,
            last_status: std::time::Instant::now() - super::STATUS_PERIOD,
            sdo: SdoInFlight::default(),
            job: None,
            diag: DiagInFlight::default(),
            diag_client: None,
            list: ListInFlight::default(),
            list_client: None,
            je_c_moves: link::PendingMoves::default(),
            profile_moves: profile::PendingProfile::default(),
        })
    }

    /// Sleeps up to `timeout`, waking early when a client signals a request.
    pub fn wait(&self, timeout: std::time::Duration) {
        if self.wake.timed_wait(|_| {}, timeout).is_err() {
            std::thread::sleep(timeout);
        }
    }

    /// Marks the command in execution as ended (`None`) or failed (`failure`: why, as the
    /// client reads it).
    pub fn finish_active(&mut self, failure: Option<String>) {
        if let Some(a) = self.active.take() {
            self.last_finished = Some(FinishedCommand {
                id: a.id,
                command: a.command,
                error: failure,
            });
        }
    }

    /// Follows the motion engine when no program drives it.
    pub fn tick(&mut self, ctx: &mut Context<'_>) {
        // A move's MR-JE-C axes: it ends when they and the streamed axes have.
        let active = self.active.as_ref().map(|a| a.id);
        let je_c_running = match self.je_c_moves.progress(active, ctx.je_c) {
            Err(e) => {
                self.finish_active(Some(e.to_string()));
                return;
            }
            Ok(running) => running,
        };
        let status = ctx.link.status();
        let profile_running = match status
            .as_ref()
            .map(|s| self.profile_moves.progress(active, s))
        {
            Ok(Err(i)) => {
                let failure = self.profile_failure(ctx, i);
                self.finish_active(Some(failure));
                return;
            }
            Ok(Ok(running)) => running,
            Err(_) => false,
        };
        if self.active.as_ref().is_some_and(|a| a.command == "mode") {
            if !profile_running {
                self.finish_active(None);
            }
            return;
        }
        if self.active.as_ref().is_some_and(|a| a.command == "home") {
            if self.home_on_je_c {
                if !je_c_running {
                    self.finish_active(None);
                }
                return;
            }
            if let Ok(s) = ctx.link.status() {
                let h = s.homing;
                if h.seq > self.home_seq && !h.running {
                    let r = match HomingFailure::from_u8(h.failure) {
                        None => Ok(()),
                        Some(f) => Err(f.as_str().to_string()),
                    };
                    self.finish_active(r.err());
                }
            }
            return;
        }
        match ctx.engine.tick(ctx.link) {
            Ok(Progress::Finished(_) | Progress::Idle) if je_c_running || profile_running => {}
            Ok(Progress::Finished(_)) => self.finish_active(None),
            Ok(Progress::Idle) => {
                if self
                    .active
                    .as_ref()
                    .is_some_and(|a| MOTION_COMMANDS.contains(&a.command.as_str()))
                {
                    self.finish_active(None);
                }
            }
            Ok(Progress::Running) => {}
            Err(e) => self.finish_active(Some(e.to_string())),
        }
    }

    /// Why the active command's drive-side motion on axis `i` failed.
    fn profile_failure(&self, ctx: &mut Context<'_>, i: usize) -> String {
        let axis = &ctx.cell.axes.on_loop()[i].name;
        if self.active.as_ref().is_some_and(|a| a.command == "mode") {
            let now = ctx
                .link
                .status()
                .map_or(ctx.cell.axes.on_loop()[i].mode, |s| s.mode_now(ctx.cell, i));
            return format!(
                "axis '{axis}' stays in {}: the RT thread refused the switch (the cell was not idle, or the axis not at rest in Operation enabled) or withdrew it (6061h did not show the mode within {:?}, or the drive faulted); see the events",
                now.as_str(),
                crate::rt::executive::MODE_SWITCH_TIMEOUT
            );
        }
        format!("axis '{axis}': its drive-side move was refused or cancelled (see the events)")
    }

    /// Answers every pending request; returns what the caller must do next.
    pub fn poll(&mut self, ctx: &mut Context<'_>) -> Followup {
        let mut followup = Followup::None;
        let mut answered = self.answer_sdo(ctx) | self.answer_diag(ctx) | self.answer_list(ctx);
        loop {
            let active = match self.port.receive() {
                Ok(Some(r)) => r,
                Ok(None) => break,
                Err(e) => {
                    tracing::warn!("operator service: receive failed: {e:?}");
                    break;
                }
            };
            let (reply, f) = match wire::decode_request(active.payload()) {
                Ok(
                    req @ (Request::Sdo { .. } | Request::Param { .. } | Request::Alarms { .. }),
                ) => match self.start_job(ctx, &req) {
                    Ok(job) => {
                        self.job = Some((job, active));
                        continue;
                    }
                    Err(e) => (Reply::rejected(e), Followup::None),
                },
                Ok(Request::BusDiag) => match self.diag.start(ctx.link) {
                    Ok(()) => {
                        self.diag_client = Some(active);
                        continue;
                    }
                    Err(e) => (Reply::rejected(e), Followup::None),
                },
                Ok(Request::SdoList { axis }) => match self.list.start(ctx.link, ctx.cell, &axis) {
                    Ok(ListStart::Walking) => {
                        self.list_client = Some(active);
                        continue;
                    }
                    Ok(ListStart::Answered(r)) => (Reply::SdoList(r), Followup::None),
                    Err(e) => (Reply::rejected(e), Followup::None),
                },
                Ok(req) => self.handle(req, ctx),
                Err(e) => (
                    Reply::Rejected {
                        reason: e.to_string(),
                    },
                    Followup::None,
                ),
            };
            if !matches!(f, Followup::None) {
                followup = f;
            }
            answered = true;
            respond(&active, &reply);
        }
        if answered || self.last_status.elapsed() >= super::STATUS_PERIOD {
            self.publish_status(ctx);
        }
        followup
    }

    /// Checks an `sdo`, `param` or `alarms` request and hands its first transfer to the RT
    /// thread; the rest and the reply follow in [`OperatorServer::answer_sdo`].
    fn start_job(&mut self, ctx: &mut Context<'_>, req: &Request) -> Result<SdoJob, JobError> {
        let what = req.name();
        if self.job.is_some() || self.sdo.busy() {
            return Err(JobError::InFlight { what });
        }
        if ctx.program_running && req.writes_to_a_drive() {
            return Err(JobError::ProgramRunning { what });
        }
        let status = ctx.link.status().ok();
        let mut job = match req {
            Request::Sdo {
                axis,
                index,
                sub,
                value,
            } => SdoJob::new(
                vec![sdo::check(ctx.cell, axis, *index, *sub, *value)?],
                SingleSdo,
            ),
            Request::Param { axis, op } => {
                let enabled = operation_enabled(ctx.cell, axis, status.as_ref());
                super::param::plan(ctx.cell, axis, op, enabled)?
            }
            Request::Alarms { axis, clear } => super::alarms::plan(ctx.cell, axis, *clear)?,
            _ => return Err(JobError::NotSdo { what }),
        };
        // A homing's own acyclic requests come first (the RT thread holds SDOs meanwhile).
        if status.is_some_and(|s| s.state == CellState::Homing) {
            return Err(JobError::Homing { what });
        }
        job.start_next(&mut self.sdo, ctx.link)?;
        Ok(job)
    }

    /// Takes the drive's answer to the transfer in flight (or the wait's timeout), starts the
    /// job's next transfer, and answers the client after the last; true if a reply went out.
    fn answer_sdo(&mut self, ctx: &mut Context<'_>) -> bool {
        let Some(result) = self.sdo.poll(ctx.link) else {
            return false;
        };
        let Some((mut job, active)) = self.job.take() else {
            return false;
        };
        let reply = match result {
            Ok(r) => {
                job.answered(r);
                match job.start_next(&mut self.sdo, ctx.link) {
                    Ok(true) => {
                        self.job = Some((job, active));
                        return false;
                    }
                    Ok(false) => job.finish(),
                    Err(e) => Reply::rejected(e),
                }
            }
            Err(e) => Reply::rejected(e),
        };
        respond(&active, &reply);
        true
    }

    /// Answers the `bus_diag` request once the reading came (or timed out); true if a reply
    /// went out.
    fn answer_diag(&mut self, ctx: &mut Context<'_>) -> bool {
        let Some(result) = self.diag.poll(ctx.link, ctx.cell) else {
            return false;
        };
        let reply = result.map_or_else(Reply::rejected, |r| Reply::BusDiag(Box::new(r)));
        respond_later(&mut self.diag_client, &reply)
    }

    /// Answers the `sdo_list` request once the walk ended (or timed out); true if a reply
    /// went out.
    fn answer_list(&mut self, ctx: &mut Context<'_>) -> bool {
        let Some(result) = self.list.poll(ctx.link, ctx.cell) else {
            return false;
        };
        let reply = result.map_or_else(Reply::rejected, |r| Reply::SdoList(Box::new(r)));
        respond_later(&mut self.list_client, &reply)
    }

    /// Publishes the status on the operator-status service.
    fn publish_status(&mut self, ctx: &mut Context<'_>) {
        self.last_status = std::time::Instant::now();
        let Ok(s) = ctx.link.status() else {
            return;
        };
        let bytes = wire::encode(&self.report(ctx, &s));
        if let Ok(sample) = self.status.loan_slice_uninit(bytes.len()) {
            let _ = sample.write_from_slice(&bytes).send();
        }
    }

    fn accept(&mut self, command: &str, tracked: bool) -> Reply {
        let id = self.next_id;
        self.next_id += 1;
        if tracked {
            self.track(id, command);
        }
        Reply::Accepted { id }
    }

    /// Command `id` becomes the one in execution, replacing any other (PLCopen "aborting"
    /// buffer mode).
    fn track(&mut self, id: u64, command: &str) {
        if let Some(a) = self.active.take() {
            self.last_finished = Some(FinishedCommand {
                id: a.id,
                command: a.command,
                error: Some(format!("replaced by command {id} ({command})")),
            });
        }
        self.active = Some(ActiveCommand {
            id,
            command: command.to_string(),
        });
    }

    fn handle(&mut self, req: Request, ctx: &mut Context<'_>) -> (Reply, Followup) {
        let name = req.name();
        if ctx.program_running
            && !matches!(
                req,
                Request::Status | Request::Halt { .. } | Request::Stop | Request::Override { .. }
            )
        {
            return rejected(format!(
                "{name}: a program is running; halt or stop it first"
            ));
        }
        let state = match ctx.link.status() {
            Ok(s) => s,
            Err(e) => return rejected(format!("{name}: the RT thread does not answer: {e}")),
        };
        match req {
            Request::Status => (
                Reply::Status(Box::new(self.report(ctx, &state))),
                Followup::None,
            ),
            Request::Power { on, axes } => self.power(ctx, &state, on, &axes),
            Request::Move {
                targets,
                relative,
                velocity,
                acceleration,
                jerk,
                clamp,
                line,
            } => {
                let asked = Asked {
                    velocity,
                    acceleration,
                    jerk,
                    clamp,
                };
                self.move_axes(ctx, &state, &targets, relative, line, asked)
            }
            Request::Path {
                waypoints,
                velocity,
                acceleration,
                jerk,
                clamp,
            } => {
                let asked = Asked {
                    velocity,
                    acceleration,
                    jerk,
                    clamp,
                };
                self.path(ctx, &state, &waypoints, asked)
            }
            Request::Velocity {
                axis,
                velocity,
                acceleration,
                clamp,
            } => self.velocity(ctx, &state, &axis, velocity, acceleration, clamp),
            Request::Torque { targets, seconds } => self.torque(ctx, &state, &targets, seconds),
            Request::Home {
                axis,
                method,
                setting,
            } => self.home(ctx, &state, &axis, method, setting),
            Request::Halt { axes } => self.halt(ctx, &state, &axes),
            Request::Stop => self.stop(ctx),
            Request::Reset => self.reset(ctx, &state),
            Request::Override { percent } => self.set_override(ctx, percent),
            Request::Program { path } => self.program(ctx, &state, &path),
            Request::Mode { axis, mode } => self.switch_mode(ctx, &state, &axis, &mode),
            Request::Capture => {
                if ctx.link.request_capture() {
                    (self.accept("capture", false), Followup::None)
                } else {
                    rejected(
                        "capture: this cell keeps no capture ring (it needs recording.mode = \"triggered\" and a recording)"
                            .into(),
                    )
                }
            }
            // Answered later, when the drive has: `poll` takes it before `handle`.
            Request::Sdo { .. }
            | Request::Param { .. }
            | Request::Alarms { .. }
            | Request::BusDiag
            | Request::SdoList { .. } => rejected(format!("{name}: not an immediate request")),
        }
    }

    /// MC_Power: the whole cell or the named axes, on or off, where the cell state allows it;
    /// the MR-JE-C axes among them (all of them for the whole cell) through their link threads.
    fn power(
        &mut self,
        ctx: &mut Context<'_>,
        state: &StatusSnapshot,
        on: bool,
        axes: &[String],
    ) -> (Reply, Followup) {
        let whole_cell = axes.is_empty();
        let named = match backend::name_axes(ctx.cell, axes) {
            Ok(n) => n,
            Err(e) => return rejected(format!("power: {e}")),
        };
        let je_c: Vec<usize> = if whole_cell {
            (0..ctx.je_c.len()).collect()
        } else {
            named.on_link
        };
        if let Err(e) = link::power_check(ctx.je_c, &je_c, on) {
            return rejected(format!("power: {e}"));
        }
        if whole_cell || !named.on_loop.is_empty() {
            if let Err(e) = self.power_rt_axes(ctx, state, on, &named.on_loop) {
                return rejected(format!("power: {e}"));
            }
        }
        let c = if on {
            AxisCommand::PowerOn
        } else {
            AxisCommand::PowerOff
        };
        if let Err(e) = je_c.iter().try_for_each(|&k| ctx.je_c.command(k, c)) {
            return rejected(format!("power: {e}"));
        }
        (self.accept("power", false), Followup::None)
    }

    /// The RT loop's part of MC_Power: slots `indices`, all of them when empty.
    fn power_rt_axes(
        &mut self,
        ctx: &mut Context<'_>,
        state: &StatusSnapshot,
        on: bool,
        indices: &[usize],
    ) -> Result<(), PowerError> {
        let blocked = if on {
            match state.state {
                CellState::Stopped | CellState::Faulted => Some("reset it first"),
                CellState::Moving
                | CellState::Stopping
                | CellState::Homing
                | CellState::Disabling => Some("wait for it to end first"),
                _ => None,
            }
        } else if indices.is_empty() {
            matches!(state.state, CellState::Moving | CellState::Stopping)
                .then_some("halt or stop the motion first")
        } else {
            (!matches!(
                state.state,
                CellState::Idle | CellState::Enabling | CellState::Disabled
            ))
            .then_some("single axes power off from idle: halt or stop the motion, or power off the whole cell")
        };
        if let Some(what) = blocked {
            return Err(PowerError::Blocked {
                state: state.state.as_str(),
                what,
            });
        }
        let cmds: Vec<CellCommand> = match (on, indices.is_empty()) {
            (true, true) => vec![CellCommand::PowerOn],
            (false, true) => vec![CellCommand::PowerOff],
            (true, false) => indices
                .iter()
                .map(|&i| CellCommand::PowerOnAxis(i as u16))
                .collect(),
            (false, false) => indices
                .iter()
                .map(|&i| CellCommand::PowerOffAxis(i as u16))
                .collect(),
        };
        cmds.into_iter().try_for_each(|cmd| ctx.link.command(cmd))?;
        Ok(())
    }

    fn report(&self, ctx: &mut Context<'_>, s: &StatusSnapshot) -> StatusReport {
        let axes = ctx
            .cell
            .axes
            .iter()
            .map(|axis| match axis.config {
                AxisKind::Loop(i, a) => {
                    let l = s.live[i];
                    let sc = a.scaling;
                    AxisStatus {
                        name: a.name.clone(),
                        backend: axis.backend().as_str().to_string(),
                        unit: a.unit.clone(),
                        mode: s.mode_now(ctx.cell, i).as_str().to_string(),
                        mode_display: ModeOfOperation::from_i8(l.mode_display)
                            .map_or("?", |m| m.as_str())
                            .to_string(),
                        powered: l.powered != 0,
                        fsa: Statusword(l.statusword)
                            .state()
                            .map(|f| f.as_str())
                            .unwrap_or("unknown")
                            .to_string(),
                        setpoint: sc.to_units(s.hold[i]),
                        position: sc.to_units(f64::from(l.position_actual)),
                        velocity: sc.to_units(a.drive_units.velocity_from_drive(l.velocity_actual)),
                        following_error: sc.to_units(f64::from(l.following_error)),
                        error_code: l.error_code,
                        alarm: (l.error_code != 0)
                            .then(|| a.profile.alarm_text(l.error_code).long()),
                        status_do: StatusDo(l.status_do)
                            .symbols_on()
                            .map(str::to_string)
                            .collect(),
                        link: None,
                    }
                }
                AxisKind::Link(k, _) => ctx.je_c.status(k),
            })
            .collect();
        StatusReport {
            cell: ctx.cell.name.clone(),
            cycle: s.cycle,
            cycle_time_us: ctx.cell.cycle_time.as_nanos() as f64 / 1e3,
            state: s.state.as_str().to_string(),
            stop_reason: s.stop_reason.map(|r| r.as_str().to_string()),
            override_percent: ctx.engine.feed_override() * 100.0,
            active_command: self.active.clone(),
            last_finished: self.last_finished.clone(),
            recent_events: ctx.link.recent_events(),
            axes,
        }
    }
}

/// Commands that end when their motion ends.
const MOTION_COMMANDS: [&str; 5] = ["move", "path", "velocity", "torque", "halt"];

/// The refusal of a request, with its reason.
/// Sends `reply` to the client of `active` (a failure is logged: the client times out).
fn respond(active: &ActiveRequest, reply: &Reply) {
    let bytes = wire::encode(reply);
    let sent = match active.loan_slice_uninit(bytes.len().max(1)) {
        Ok(r) => r
            .write_from_fn(|i| bytes.get(i).copied().unwrap_or(b' '))
            .send()
            .map_err(|e| format!("{e:?}")),
        Err(e) => Err(format!("{e:?}")),
    };
    if let Err(e) = sent {
        tracing::warn!(
            "operator service: reply of {} bytes (limit {OPERATOR_RESPONSE_BYTES}) not sent: {e}",
            bytes.len()
        );
    }
}

fn rejected(reason: String) -> (Reply, Followup) {
    (Reply::Rejected { reason }, Followup::None)
}

fn program_abort(program_running: bool) -> Followup {
    if program_running {
        Followup::AbortProgram
    } else {
        Followup::None
    }
}

/// One axis of a move-like request: index, target in units, limits, commanded position now.
type Resolved = (usize, f64, KinematicLimits, f64);

/// Resolves the named targets of a move-like request: axis names, finite targets (relative
/// ones from the commanded position), and each axis' limits from `limits_of`.
fn resolve_targets(
    ctx: &Context<'_>,
    state: &StatusSnapshot,
    targets: &BTreeMap<String, f64>,
    relative: bool,
    limits_of: impl Fn(&cellrt_config::AxisConfig) -> Result<KinematicLimits, TargetError>,
) -> Result<Vec<Resolved>, TargetError> {
    let mut list = Vec::with_capacity(targets.len());
    for (axis, value) in targets {
        let i = axis_index(ctx.cell, axis)?;
        let a = &ctx.cell.axes.on_loop()[i];
        let limits = limits_of(a)?;
        if !value.is_finite() {
            return Err(TargetError::NotFinite {
                axis: axis.clone(),
                value: *value,
            });
        }
        let here = ctx.engine.position(i, state, a);
        list.push((
            i,
            if relative { here + value } else { *value },
            limits,
            here,
        ));
    }
    Ok(list)
}
