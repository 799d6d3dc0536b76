//! The controller's non-RT link thread: publishes the cell status for other processes, forwards
//! their commands to the RT thread, and watches the planner's iceoryx2 node (planner connect and
//! loss are events; loss during motion makes the RT thread stop the axes). Under an external
//! planner it also relays the MR-JE-C axes' commands and feedback ([`JecRelay`]); the planner's
//! loss halts them.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use iceoryx2::node::{NodeState, NodeView};
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;

use crate::handoff::{
    CellCommand, EventKind, EventRecord, HomeRequest, HostEnd, ProfileCommand, UserSdo, NO_AXIS,
};
use crate::host::je_c::link::JecRelay;
use crate::host::je_c::JecAxes;
use crate::host::link::snapshot;
use crate::services::{self, ProfileLinkSample, SdoLinkSample, ServiceError, StatusSample};
use crate::setpoints::MAX_AXES;
use cellrt_config::CellConfig;

/// How often the planner's node is looked for.
pub const PLANNER_CHECK: Duration = Duration::from_millis(20);

/// Handle of the link thread.
pub struct LinkServer {
    stop: Arc<AtomicBool>,
    handle: JoinHandle<()>,
}

impl LinkServer {
    /// Starts the link thread; returns once its services exist. `je_c`: the running MR-JE-C
    /// axes an external planner commands through this thread (none: no MR-JE-C link).
    pub fn spawn(
        cell: &CellConfig,
        handoff: Arc<HostEnd>,
        je_c: Option<JecAxes>,
    ) -> Result<LinkServer, ServiceError> {
        let stop = Arc::new(AtomicBool::new(false));
        let stop2 = stop.clone();
        let cell = cell.clone();
        let (ready_tx, ready_rx) = std::sync::mpsc::channel();
        let handle = std::thread::Builder::new()
            .name("cellrt-link".into())
            .spawn(move || {
                let setup = (|| {
                    let node = services::node(&cell.name, "link")?;
                    let status = services::status_publisher(&node, &cell.name)?;
                    let commands = services::command_subscriber(&node, &cell.name)?;
                    let sdo = SdoRelay {
                        requests: services::sdo_request_subscriber(&node, &cell.name)?,
                        outcomes: services::sdo_outcome_publisher(&node, &cell.name)?,
                        waiting: None,
                        pending: None,
                    };
                    let profile = ProfileRelay {
                        commands: services::profile_command_subscriber(&node, &cell.name)?,
                        waiting: std::collections::VecDeque::with_capacity(2 * MAX_AXES),
                        axes: cell.axes.on_loop().len(),
                    };
                    let je_c = je_c
                        .map(|axes| JecRelay::new(&node, &cell, axes))
                        .transpose()?;
                    Ok::<_, ServiceError>((node, status, commands, sdo, profile, je_c))
                })();
                let (node, status, commands, mut sdo, mut profile, mut je_c) = match setup {
                    Ok(v) => {
                        let _ = ready_tx.send(Ok(()));
                        v
                    }
                    Err(e) => {
                        let _ = ready_tx.send(Err(e));
                        return;
                    }
                };
                let period =
                    Duration::from_nanos(cell.cycle_time.as_nanos()).max(Duration::from_millis(1));
                let n = cell.axes.on_loop().len();
                let planner_name = services::planner_node_name(&cell.name);
                let mut planner_alive = false;
                let mut last_check = Instant::now() - PLANNER_CHECK;
                while !stop2.load(Ordering::Acquire) {
                    let snap = snapshot(&handoff, n);
                    let sample = StatusSample {
                        cycle: snap.cycle,
                        cycle_time_ns: cell.cycle_time.as_nanos(),
                        state: snap.state as u8,
                        stop_reason: snap.stop_reason.map(|r| r as u8).unwrap_or(0),
                        motion_id: snap.motion_id,
                        motion_done: snap.motion_done,
                        motion_refused: snap.motion_refused,
                        motion_slip: snap.motion_slip,
                        axis_count: n as u32,
                        hold: snap.hold,
                        live: snap.live,
                        homing: snap.homing.encode(),
                        ..StatusSample::default()
                    };
                    let _ = status.send_copy(sample);
                    while let Ok(Some(c)) = commands.receive() {
                        let c = c.payload();
                        if c.code == services::HOME_COMMAND_CODE {
                            if let Some(request) = HomeRequest::decode(c.arg) {
                                handoff.request_homing(request);
                            }
                        } else if c.code == services::OVERRIDE_COMMAND_CODE {
                            if c.arg <= 1000 {
                                handoff.set_feed_override(f64::from(c.arg) / 1000.0);
                            } else {
                                push_event(&handoff, EventKind::CommandRefused, i64::from(c.code));
                            }
                        } else {
                            forward(&handoff, c.code);
                        }
                    }
                    sdo.pump(&handoff);
                    profile.pump(&handoff);
                    if let Some(r) = je_c.as_mut() {
                        r.pump();
                    }
                    if last_check.elapsed() >= PLANNER_CHECK {
                        last_check = Instant::now();
                        let alive = planner_is_alive(&planner_name);
                        if alive != planner_alive {
                            planner_alive = alive;
                            let kind = if alive {
                                EventKind::PlannerConnected
                            } else {
                                EventKind::PlannerLost
                            };
                            push_event(&handoff, kind, 0);
                            if alive {
                                let _ = handoff.send_command(CellCommand::PlannerConnected);
                            } else {
                                let _ = handoff.send_command(CellCommand::PlannerLost);
                                if let Some(r) = je_c.as_mut() {
                                    r.planner_lost();
                                }
                                node.try_cleanup_dead_nodes();
                            }
                        }
                    }
                    std::thread::sleep(period);
                }
            })
            .map_err(|e| ServiceError::thread(&e.to_string()))?;
        match ready_rx.recv() {
            Ok(Ok(())) => Ok(LinkServer { stop, handle }),
            Ok(Err(e)) => Err(e),
            Err(_) => Err(ServiceError::thread("link thread died during set-up")),
        }
    }

    /// Stops the link thread.
    pub fn stop(self) {
        self.stop.store(true, Ordering::Release);
        let _ = self.handle.join();
    }
}

/// An external planner's operator SDO requests, relayed to the RT thread through the hand-off's
/// slot, and their outcomes back: one in flight; a request the slot cannot take yet waits.
struct SdoRelay {
    requests: Subscriber<ipc::Service, SdoLinkSample, ()>,
    outcomes: Publisher<ipc::Service, SdoLinkSample, ()>,
    /// Received, not yet taken by the slot (a newer request replaces it).
    waiting: Option<UserSdo>,
    /// Handed to the RT thread; its outcome not yet published.
    pending: Option<u16>,
}

impl SdoRelay {
    fn pump(&mut self, handoff: &HostEnd) {
        while let Ok(Some(r)) = self.requests.receive() {
            let r = r.payload();
            if let Some(sdo) = UserSdo::from_wire(r.header, r.word) {
                self.waiting = Some(sdo);
            }
        }
        if let Some(sdo) = self.waiting {
            if handoff.request_sdo(sdo).is_ok() {
                self.waiting = None;
                self.pending = Some(sdo.seq);
            }
        }
        if let Some(seq) = self.pending {
            if let Some(outcome) = handoff.sdo_outcome(seq) {
                let (header, word) = outcome.to_wire(seq);
                if self
                    .outcomes
                    .send_copy(SdoLinkSample { header, word })
                    .is_ok()
                {
                    self.pending = None;
                }
            }
        }
    }
}

/// An external planner's profile axis motions, queued for the RT thread in the order they came;
/// those the hand-off's queue cannot take yet wait here. A sample that does not decode, or
/// names an axis the cell does not have, or finds 2 × `MAX_AXES` waiting, is refused with a
/// `command_refused` event.
struct ProfileRelay {
    commands: Subscriber<ipc::Service, ProfileLinkSample, ()>,
    waiting: std::collections::VecDeque<ProfileCommand>,
    axes: usize,
}

impl ProfileRelay {
    fn pump(&mut self, handoff: &HostEnd) {
        while let Ok(Some(sample)) = self.commands.receive() {
            match sample.payload().command() {
                Some(c) if usize::from(c.axis) < self.axes && self.waiting.len() < 2 * MAX_AXES => {
                    self.waiting.push_back(c)
                }
                _ => push_event(
                    handoff,
                    EventKind::CommandRefused,
                    i64::from(services::PROFILE_COMMAND_CODE),
                ),
            }
        }
        while let Some(c) = self.waiting.pop_front() {
            if let Err(c) = handoff.send_profile_command(c) {
                self.waiting.push_front(c);
                break;
            }
        }
    }
}

/// Forwards a command from another process; `quit` and unknown codes are refused.
fn forward(handoff: &HostEnd, code: u32) {
    match CellCommand::from_code(i64::from(code)) {
        Some(CellCommand::Quit | CellCommand::PlannerLost | CellCommand::PlannerConnected)
        | None => {
            push_event(handoff, EventKind::CommandRefused, i64::from(code));
        }
        Some(c) => {
            if handoff.send_command(c).is_err() {
                push_event(handoff, EventKind::CommandRefused, i64::from(code));
            }
        }
    }
}

fn push_event(handoff: &HostEnd, kind: EventKind, value: i64) {
    let _ = handoff.push_event(EventRecord {
        cycle: handoff.status().cycle(),
        kind,
        axis: NO_AXIS,
        value,
    });
}

/// Whether a live node named `name` exists (in-process or in another process).
fn planner_is_alive(name: &str) -> bool {
    let mut alive = false;
    let _ = Node::<ipc::Service>::list(&services::config(), |state| {
        if let NodeState::Alive(view) = &state {
            if view
                .details()
                .as_ref()
                .is_some_and(|d| d.name().as_str() == name)
            {
                alive = true;
                return CallbackProgression::Stop;
            }
        }
        CallbackProgression::Continue
    });
    alive
}
