//! How a planner reaches its cell: the same few operations in-process (atomics and the RT
//! command queue) or from another process (the cell's iceoryx2 status, command and SDO services).

use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::{Duration, Instant};

use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;

use crate::handoff::{
    CellCommand, CellState, EventKind, EventRecord, HomeRequest, HomingStatus, HostEnd,
    ProfileCommand, StopReason, UserSdo, UserSdoOutcome, NO_AXIS,
};
use crate::services::{
    self, CommandSample, LiveAxis, ProfileLinkSample, SdoLinkSample, ServiceError, StatusSample,
};
use crate::setpoints::MAX_AXES;

/// A remote cell whose status is older than this is considered gone.
pub const STATUS_TIMEOUT: Duration = Duration::from_millis(500);

/// Why a planner could not reach its cell.
#[derive(Debug, thiserror::Error)]
pub enum LinkError {
    /// The in-process command queue to the RT thread is full.
    #[error("command queue to the RT thread is full")]
    CommandQueueFull,
    /// The cell's status or command service could not be opened.
    #[error(transparent)]
    Service(#[from] ServiceError),
    /// The controller runs another cycle time or axis count than the planner's configuration.
    #[error("the controller of cell '{cell}' runs {axes} axes at {cycle_us} µs, but this configuration has {expected_axes} axes at {expected_cycle_us} µs: start the planner with the controller's configuration file")]
    OtherShape {
        /// Cell name.
        cell: String,
        /// The controller's axis count.
        axes: u32,
        /// The controller's cycle time, µs.
        cycle_us: u64,
        /// The configuration's axis count.
        expected_axes: usize,
        /// The configuration's cycle time, µs.
        expected_cycle_us: u64,
    },
    /// No controller published a status in time.
    #[error("no controller of cell '{cell}' answered within {timeout:?} (start `cellrt run <CONFIG> --external-planner` first)")]
    NoController {
        /// Cell name.
        cell: String,
        /// How long the planner waited.
        timeout: Duration,
    },
    /// A status sample with an unknown cell state.
    #[error("malformed status from cell '{0}'")]
    MalformedStatus(String),
    /// The controller published before but no longer.
    #[error("cell '{0}' stopped publishing its status (controller gone?)")]
    StatusStale(String),
    /// The controller has not published yet.
    #[error("no status from cell '{0}' yet")]
    NoStatus(String),
    /// The operation needs the planner in the controller's process.
    #[error("{0} needs the planner in the controller's process (not `--external-planner`)")]
    InProcessOnly(&'static str),
    /// The operator SDO slot to the RT thread is occupied.
    #[error("{0}")]
    SdoSlot(String),
    /// A command sample could not be sent.
    #[error("sending {command} to cell '{cell}': {detail}")]
    Send {
        /// The command's name.
        command: &'static str,
        /// Cell name.
        cell: String,
        /// The iceoryx2 error.
        detail: String,
    },
}

/// The cell's state as a planner needs it.
#[derive(Debug, Clone, Copy)]
pub struct StatusSnapshot {
    /// Last executed cycle.
    pub cycle: u64,
    /// Cell state.
    pub state: CellState,
    /// Why the last stop happened, since reset.
    pub stop_reason: Option<StopReason>,
    /// Motion running or last started.
    pub motion_id: u32,
    /// Last motion finished normally.
    pub motion_done: u32,
    /// Last motion whose first block the RT thread refused (never started).
    pub motion_refused: u32,
    /// Cycles `motion_id` started later than planned (its first block came late).
    pub motion_slip: u32,
    /// Hold position per axis, counts.
    pub hold: [f64; MAX_AXES],
    /// Latest feedback of each axis.
    pub live: [LiveAxis; MAX_AXES],
    /// The latest homing.
    pub homing: HomingStatus,
}

impl StatusSnapshot {
    /// The mode (6060h) the RT thread runs axis `i` of `cell` in: the configured one, or the
    /// one a run-time mode switch left it in; the configured one until the RT thread has said.
    pub fn mode_now(
        &self,
        cell: &cellrt_config::CellConfig,
        i: usize,
    ) -> cellrt_cia402::mode::ModeOfOperation {
        self.live
            .get(i)
            .and_then(|l| cellrt_cia402::mode::ModeOfOperation::from_i8(l.mode))
            .or_else(|| cell.axes.on_loop().get(i).map(|a| a.mode))
            .unwrap_or(cellrt_cia402::mode::ModeOfOperation::CyclicSyncPosition)
    }
}

/// A planner's connection to its cell.
pub trait CellLink {
    /// The latest status; an error if the cell cannot be reached.
    fn status(&mut self) -> Result<StatusSnapshot, LinkError>;
    /// Sends a command to the RT thread.
    fn command(&mut self, c: CellCommand) -> Result<(), LinkError>;
    /// Asks the RT thread to home an axis (taken in Idle).
    fn home(&mut self, request: HomeRequest) -> Result<(), LinkError>;
    /// Leaves an operator SDO request for the RT thread (in-process through the hand-off, from
    /// another process through the cell's SDO link services).
    fn sdo(&mut self, request: UserSdo) -> Result<(), LinkError> {
        let _ = request;
        Err(LinkError::InProcessOnly("sdo"))
    }
    /// Sends a profile axis' drive-side motion to the RT thread (in-process through the
    /// hand-off, from another process through the cell's profile command service).
    fn profile(&mut self, command: ProfileCommand) -> Result<(), LinkError>;
    /// Gives the RT thread the feed override (0..=1) for the profile axes' drives.
    fn feed_override(&mut self, value: f64) -> Result<(), LinkError>;
    /// The outcome of the operator SDO request `seq`, once published.
    fn sdo_outcome(&mut self, seq: u16) -> Option<UserSdoOutcome> {
        let _ = seq;
        None
    }
    /// The EtherCAT segment's diagnostics (in-process, on an EtherCAT cell only).
    fn bus_diagnostics(&self) -> Option<&cellrt_ethercat::master::BusDiagnostics> {
        None
    }
    /// The drives' dictionaries by SDO Information (in-process, on an EtherCAT cell only).
    fn dictionary_reader(&self) -> Option<&cellrt_ethercat::master::DictionaryReader> {
        None
    }
    /// Asks the recorder to write its capture ring now; false where it keeps none (or from
    /// another process).
    fn request_capture(&mut self) -> bool {
        false
    }
    /// The latest event lines (in-process only; empty from another process).
    fn recent_events(&mut self) -> Vec<String> {
        Vec::new()
    }
    /// Records an event of the planner's own (fault injection), where the link allows it.
    fn event(&mut self, kind: EventKind, value: i64);
}

/// The in-process link: the RT thread's status atomics and command queue.
pub struct LocalLink {
    handoff: Arc<HostEnd>,
    axes: usize,
}

impl LocalLink {
    /// Links to the RT thread behind `handoff`.
    pub fn new(handoff: Arc<HostEnd>, axes: usize) -> Self {
        LocalLink { handoff, axes }
    }
}

/// Reads the RT thread's status atomics into a snapshot.
pub fn snapshot(handoff: &HostEnd, axes: usize) -> StatusSnapshot {
    let s = handoff.status();
    let mut hold = [0.0; MAX_AXES];
    let mut live = [LiveAxis::default(); MAX_AXES];
    for (i, (h, l)) in hold.iter_mut().zip(live.iter_mut()).enumerate().take(axes) {
        *h = s.hold(i);
        let a = &s.live[i];
        // The ends first: a mode switch's end is counted after its new mode is stored, so a
        // snapshot that shows the end shows the mode.
        let profile_finished = a.profile_finished.load(Ordering::Acquire);
        let profile_failed = a.profile_failed.load(Ordering::Acquire);
        *l = LiveAxis {
            position_actual: a.position_actual.load(Ordering::Relaxed),
            velocity_actual: a.velocity_actual.load(Ordering::Relaxed),
            following_error: a.following_error.load(Ordering::Relaxed),
            statusword: a.statusword.load(Ordering::Relaxed),
            error_code: a.error_code.load(Ordering::Relaxed),
            mode_display: a.mode_display.load(Ordering::Relaxed),
            powered: u8::from(a.powered.load(Ordering::Relaxed)),
            mode: a.mode.load(Ordering::Acquire),
            reserved: 0,
            status_do: std::array::from_fn(|w| a.status_do[w].load(Ordering::Relaxed)),
            profile_finished,
            profile_failed,
        };
    }
    StatusSnapshot {
        cycle: s.cycle(),
        state: s.state(),
        stop_reason: s.stop_reason(),
        motion_id: s.motion_id.load(Ordering::Acquire),
        motion_slip: s.motion_slip.load(Ordering::Relaxed),
        motion_done: s.motion_done.load(Ordering::Acquire),
        motion_refused: s.motion_refused.load(Ordering::Acquire),
        hold,
        live,
        homing: HomingStatus::decode(s.homing.load(Ordering::Acquire)),
    }
}

impl CellLink for LocalLink {
    fn status(&mut self) -> Result<StatusSnapshot, LinkError> {
        Ok(snapshot(&self.handoff, self.axes))
    }

    fn command(&mut self, c: CellCommand) -> Result<(), LinkError> {
        self.handoff
            .send_command(c)
            .map_err(|_| LinkError::CommandQueueFull)
    }

    fn home(&mut self, request: HomeRequest) -> Result<(), LinkError> {
        self.handoff.request_homing(request);
        Ok(())
    }

    fn sdo(&mut self, request: UserSdo) -> Result<(), LinkError> {
        self.handoff
            .request_sdo(request)
            .map_err(|e| LinkError::SdoSlot(e.to_string()))
    }

    fn sdo_outcome(&mut self, seq: u16) -> Option<UserSdoOutcome> {
        self.handoff.sdo_outcome(seq)
    }

    fn bus_diagnostics(&self) -> Option<&cellrt_ethercat::master::BusDiagnostics> {
        self.handoff.bus_diagnostics()
    }

    fn dictionary_reader(&self) -> Option<&cellrt_ethercat::master::DictionaryReader> {
        self.handoff.dictionary_reader()
    }

    fn request_capture(&mut self) -> bool {
        self.handoff.request_capture()
    }

    fn profile(&mut self, command: ProfileCommand) -> Result<(), LinkError> {
        self.handoff
            .send_profile_command(command)
            .map_err(|_| LinkError::CommandQueueFull)
    }

    fn recent_events(&mut self) -> Vec<String> {
        self.handoff.recent_events()
    }

    fn feed_override(&mut self, value: f64) -> Result<(), LinkError> {
        self.handoff.set_feed_override(value);
        Ok(())
    }

    fn event(&mut self, kind: EventKind, value: i64) {
        let _ = self.handoff.push_event(EventRecord {
            cycle: self.handoff.status().cycle(),
            kind,
            axis: NO_AXIS,
            value,
        });
    }
}

/// The link from another process, over the cell's status and command services.
pub struct RemoteLink {
    status: Subscriber<ipc::Service, StatusSample, ()>,
    commands: Publisher<ipc::Service, CommandSample, ()>,
    /// Operator SDO requests to the controller and their outcomes back.
    sdo_requests: Publisher<ipc::Service, SdoLinkSample, ()>,
    sdo_outcomes: Subscriber<ipc::Service, SdoLinkSample, ()>,
    /// The latest outcome received (header, word).
    sdo_latest: Option<(u32, u64)>,
    /// Profile axes' drive-side motions to the controller.
    profile_commands: Publisher<ipc::Service, ProfileLinkSample, ()>,
    latest: Option<(StatusSnapshot, Instant)>,
    /// Cycle time (ns) and axis count the controller reported last.
    shape: (u64, u32),
    cell: String,
}

impl RemoteLink {
    /// Connects to `cell` through `node`, waiting up to `timeout` for its first status, and
    /// refuses a controller whose cycle time or axis count differs from the planner's
    /// configuration (its setpoints would be sampled for another cell).
    pub fn connect(
        node: &Node<ipc::Service>,
        cell: &str,
        cycle_time_ns: u64,
        axes: usize,
        timeout: Duration,
    ) -> Result<RemoteLink, LinkError> {
        let mut link = RemoteLink {
            status: services::status_subscriber(node, cell)?,
            commands: services::command_publisher(node, cell)?,
            sdo_requests: services::sdo_request_publisher(node, cell)?,
            sdo_outcomes: services::sdo_outcome_subscriber(node, cell)?,
            sdo_latest: None,
            profile_commands: services::profile_command_publisher(node, cell)?,
            latest: None,
            shape: (0, 0),
            cell: cell.to_string(),
        };
        let end = Instant::now() + timeout;
        loop {
            if link.status().is_ok() {
                let (ns, n) = link.shape;
                if ns != cycle_time_ns || n as usize != axes {
                    return Err(LinkError::OtherShape {
                        cell: cell.to_string(),
                        axes: n,
                        cycle_us: ns / 1000,
                        expected_axes: axes,
                        expected_cycle_us: cycle_time_ns / 1000,
                    });
                }
                return Ok(link);
            }
            if Instant::now() >= end {
                return Err(LinkError::NoController {
                    cell: cell.to_string(),
                    timeout,
                });
            }
            std::thread::sleep(Duration::from_millis(5));
        }
    }
}

impl CellLink for RemoteLink {
    fn status(&mut self) -> Result<StatusSnapshot, LinkError> {
        while let Ok(Some(sample)) = self.status.receive() {
            let s = sample.payload();
            let state = CellState::from_u8(s.state)
                .ok_or_else(|| LinkError::MalformedStatus(self.cell.clone()))?;
            self.shape = (s.cycle_time_ns, s.axis_count);
            self.latest = Some((
                StatusSnapshot {
                    cycle: s.cycle,
                    state,
                    stop_reason: StopReason::from_u8(s.stop_reason),
                    motion_id: s.motion_id,
                    motion_done: s.motion_done,
                    motion_refused: s.motion_refused,
                    motion_slip: s.motion_slip,
                    hold: s.hold,
                    live: s.live,
                    homing: HomingStatus::decode(s.homing),
                },
                Instant::now(),
            ));
        }
        match self.latest {
            Some((snap, at)) if at.elapsed() < STATUS_TIMEOUT => Ok(snap),
            Some(_) => Err(LinkError::StatusStale(self.cell.clone())),
            None => Err(LinkError::NoStatus(self.cell.clone())),
        }
    }

    fn command(&mut self, c: CellCommand) -> Result<(), LinkError> {
        self.commands
            .send_copy(CommandSample {
                code: c.event_value() as u32,
                arg: 0,
            })
            .map(|_| ())
            .map_err(|e| LinkError::Send {
                command: c.as_str(),
                cell: self.cell.clone(),
                detail: format!("{e:?}"),
            })
    }

    fn home(&mut self, request: HomeRequest) -> Result<(), LinkError> {
        self.commands
            .send_copy(CommandSample {
                code: services::HOME_COMMAND_CODE,
                arg: request.encode(),
            })
            .map(|_| ())
            .map_err(|e| LinkError::Send {
                command: "home",
                cell: self.cell.clone(),
                detail: format!("{e:?}"),
            })
    }

    /// Sends the override (‰) to the controller's link thread, which hands it to the RT thread.
    fn feed_override(&mut self, value: f64) -> Result<(), LinkError> {
        self.commands
            .send_copy(CommandSample {
                code: services::OVERRIDE_COMMAND_CODE,
                arg: (value.clamp(0.0, 1.0) * 1000.0).round() as u32,
            })
            .map(|_| ())
            .map_err(|e| LinkError::Send {
                command: "override",
                cell: self.cell.clone(),
                detail: format!("{e:?}"),
            })
    }

    /// Sends the motion to the controller's link thread, which queues it for the RT thread.
    fn profile(&mut self, command: ProfileCommand) -> Result<(), LinkError> {
        self.profile_commands
            .send_copy(ProfileLinkSample::from(command))
            .map(|_| ())
            .map_err(|e| LinkError::Send {
                command: "profile motion",
                cell: self.cell.clone(),
                detail: format!("{e:?}"),
            })
    }

    /// Sends the request to the controller's link thread, which relays it to the RT thread.
    fn sdo(&mut self, request: UserSdo) -> Result<(), LinkError> {
        let (header, word) = request.to_wire();
        self.sdo_requests
            .send_copy(SdoLinkSample { header, word })
            .map(|_| ())
            .map_err(|e| LinkError::Send {
                command: "sdo",
                cell: self.cell.clone(),
                detail: format!("{e:?}"),
            })
    }

    fn sdo_outcome(&mut self, seq: u16) -> Option<UserSdoOutcome> {
        while let Ok(Some(s)) = self.sdo_outcomes.receive() {
            self.sdo_latest = Some((s.payload().header, s.payload().word));
        }
        let (header, word) = self.sdo_latest?;
        UserSdoOutcome::from_wire(header, word, seq)
    }

    fn event(&mut self, _kind: EventKind, _value: i64) {}
}
