//! The MR-JE-C axes under an external planner. Their threads stay in the controller (beside
//! their drives' links and emulators); the planner process commands them through detached
//! [`JecAxes`] (the same command queues and feedback cells, no thread behind them), so the
//! planner's and the operator's code is the same in both processes. Two relays carry the
//! cells across: [`JecBridge`], a thread of the planner process, sends each queued command
//! on the cell's `je-c-commands` service and stores the feedback from `je-c-feedback`;
//! [`JecRelay`], pumped by the controller's link thread, queues the commands for the axes'
//! threads in the order sent and publishes each axis' feedback when it changes (at least
//! every [`FEEDBACK_HEARTBEAT`]). A planner that dies gets its axes halted
//! ([`JecRelay::planner_lost`]); a controller that stops sending marks the planner's axes
//! [`Stopped::ControllerLost`], which fails the step waiting on them.

use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use cellrt_fieldbus::mr_je_c::cell::{AxisCommand, AxisHandle, Stopped};
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;

use super::JecAxes;
use crate::host::link::STATUS_TIMEOUT;
use crate::services::{
    self, je_c_shape, JecCommandSample, JecFeedbackSample, ServiceError, JE_C_LINK_VERSION,
};
use cellrt_config::CellConfig;

/// The longest the controller goes without sending an axis' feedback: the external planner's
/// sign that the controller still runs (it gives up after [`STATUS_TIMEOUT`]).
pub const FEEDBACK_HEARTBEAT: Duration = Duration::from_millis(20);
/// Commands waiting per axis while its thread's queue is full.
const WAITING: usize = 64;
/// How often the planner's bridge moves commands and feedback.
const BRIDGE_TICK: Duration = Duration::from_millis(1);

impl JecAxes {
    /// The MR-JE-C axes of `cell` with no threads behind them, for a process that reaches
    /// the axes' threads through a link ([`JecBridge`]).
    pub(crate) fn detached(cell: &CellConfig) -> JecAxes {
        JecAxes {
            axes: Arc::new(
                cell.axes
                    .on_link()
                    .iter()
                    .map(|c| (c.clone(), AxisHandle::detached()))
                    .collect(),
            ),
        }
    }

    pub(crate) fn handle(&self, k: usize) -> &AxisHandle {
        &self.axes[k].1
    }

    fn names(&self) -> String {
        let names: Vec<&str> = self.axes.iter().map(|(c, _)| c.name.as_str()).collect();
        names.join(", ")
    }
}

/// The controller's end of the MR-JE-C link, pumped by its link thread (its ports are not
/// `Send`: made in that thread).
pub struct JecRelay {
    axes: JecAxes,
    commands: Subscriber<ipc::Service, JecCommandSample, ()>,
    feedback: Publisher<ipc::Service, JecFeedbackSample, ()>,
    shape: u64,
    cell: String,
    /// Per axis: received, not yet taken by the axis' queue.
    waiting: Vec<VecDeque<AxisCommand>>,
    /// Per axis: commands refused (undecodable, too many waiting), sent back in the feedback.
    dropped: Vec<u64>,
    /// Per axis: the exchange count and time of the feedback sent last.
    sent: Vec<Option<(u64, Instant)>>,
    /// The planner's sequence number received last (0: none since it connected).
    last_seq: u64,
}

impl JecRelay {
    /// The relay of `cell`'s running MR-JE-C axes `axes`, its ports made on `node`.
    pub fn new(
        node: &Node<ipc::Service>,
        cell: &CellConfig,
        axes: JecAxes,
    ) -> Result<JecRelay, ServiceError> {
        let n = axes.len();
        Ok(JecRelay {
            commands: services::je_c_command_subscriber(node, &cell.name)?,
            feedback: services::je_c_feedback_publisher(node, &cell.name)?,
            shape: je_c_shape(cell.axes.on_link()),
            cell: cell.name.clone(),
            waiting: vec![VecDeque::with_capacity(WAITING); n],
            dropped: vec![0; n],
            sent: vec![None; n],
            last_seq: 0,
            axes,
        })
    }

    /// Queues the planner's commands for the axes' threads and publishes their feedback.
    pub fn pump(&mut self) {
        while let Ok(Some(sample)) = self.commands.receive() {
            let s = *sample.payload();
            self.take(s);
        }
        for (k, waiting) in self.waiting.iter_mut().enumerate() {
            while let Some(&c) = waiting.front() {
                if !self.axes.handle(k).command(c) {
                    break;
                }
                waiting.pop_front();
            }
        }
        let count = self.axes.len() as u16;
        for k in 0..self.axes.len() {
            let f = self.axes.feedback(k);
            let due = match self.sent[k] {
                Some((cycles, at)) => cycles != f.cycles || at.elapsed() >= FEEDBACK_HEARTBEAT,
                None => true,
            };
            if !due {
                continue;
            }
            let sample = JecFeedbackSample::new(self.shape, count, k as u16, &f, self.dropped[k]);
            if self.feedback.send_copy(sample).is_ok() {
                self.sent[k] = Some((f.cycles, Instant::now()));
            }
        }
    }

    /// One command sample: queued for its axis, or refused with a warning naming why.
    fn take(&mut self, s: JecCommandSample) {
        let cell = &self.cell;
        if s.version != JE_C_LINK_VERSION || s.shape != self.shape {
            tracing::warn!(
                "cell '{cell}': an MR-JE-C command from a planner of another configuration \
                 (link version {}, this controller's {JE_C_LINK_VERSION}) is refused",
                s.version
            );
            return;
        }
        if self.last_seq != 0 && s.seq > self.last_seq + 1 {
            tracing::warn!(
                "cell '{cell}': {} MR-JE-C commands of the planner were lost on the way",
                s.seq - self.last_seq - 1
            );
        }
        self.last_seq = s.seq;
        let k = usize::from(s.axis);
        if k >= self.axes.len() {
            tracing::warn!(
                "cell '{cell}': an MR-JE-C command for axis {k}, which it lacks, is refused"
            );
            return;
        }
        let name = &self.axes.config(k).name;
        match s.command() {
            Some(c) if self.waiting[k].len() < WAITING => self.waiting[k].push_back(c),
            Some(_) => {
                self.dropped[k] += 1;
                tracing::warn!(
                    "cell '{cell}': MR-JE-C axis '{name}': {WAITING} commands wait already; one more is refused"
                );
            }
            None => {
                self.dropped[k] += 1;
                tracing::warn!(
                    "cell '{cell}': MR-JE-C axis '{name}': a command that does not decode (kind {}) is refused",
                    s.kind
                );
            }
        }
    }

    /// The planner died or left: its waiting commands are dropped and every axis stops as
    /// `cellrt stop` stops it (Halt on its drive's ramp, 6084h; an indexer axis quick-stops);
    /// a new planner moves them again.
    pub fn planner_lost(&mut self) {
        for w in &mut self.waiting {
            w.clear();
        }
        self.last_seq = 0;
        match self.axes.stop_all() {
            Ok(()) => tracing::warn!(
                "cell '{}': planner lost: MR-JE-C axes {} stopped",
                self.cell,
                self.axes.names()
            ),
            Err(e) => tracing::error!("cell '{}': planner lost: {e}", self.cell),
        }
    }
}

/// Why the planner's end of the MR-JE-C link could not connect to its controller.
#[derive(Debug, thiserror::Error)]
pub enum JecLinkError {
    /// The link thread could not be spawned.
    #[error("cell '{cell}': MR-JE-C link thread: {source}")]
    Thread {
        /// The cell's name.
        cell: String,
        /// Why.
        source: std::io::Error,
    },
    /// The link thread ended before it was set up.
    #[error("cell '{cell}': the MR-JE-C link thread ended during set-up")]
    SetUpEnded {
        /// The cell's name.
        cell: String,
    },
    /// iceoryx2 set-up failed.
    #[error(transparent)]
    Service(#[from] ServiceError),
    /// The controller sent no feedback of some axis in time.
    #[error("cell '{cell}': no feedback of its MR-JE-C axes ({axes}) from its controller within {timeout:?} (is it `cellrt run <CONFIG> --external-planner` of this configuration?)")]
    NoFeedback {
        /// The cell's name.
        cell: String,
        /// The axes' names.
        axes: String,
        /// How long the planner waited.
        timeout: Duration,
    },
    /// The controller's link is of another version.
    #[error("cell '{cell}': its controller's MR-JE-C link is version {version}, this planner's {}: run both from the same build", JE_C_LINK_VERSION)]
    Version {
        /// The cell's name.
        cell: String,
        /// The controller's link version.
        version: u32,
    },
    /// The controller runs another number of MR-JE-C axes.
    #[error("cell '{cell}': its controller runs {theirs} MR-JE-C axes, this planner's configuration has {ours} ({axes}): run the planner with the controller's configuration")]
    AxisCount {
        /// The cell's name.
        cell: String,
        /// The controller's count.
        theirs: usize,
        /// The planner's count.
        ours: usize,
        /// The planner's axes' names.
        axes: String,
    },
    /// The controller's MR-JE-C axes differ from the planner's.
    #[error("cell '{cell}': its controller's MR-JE-C axes differ from this planner's configuration ({axes}: names, order, transport or scaling): run the planner with the controller's configuration")]
    Shape {
        /// The cell's name.
        cell: String,
        /// The planner's axes' names.
        axes: String,
    },
}

/// The planner process' end of the MR-JE-C link: a thread (`cellrt-jec-link`) that carries
/// the detached axes' commands to the controller and their feedback back. Stopped on drop.
pub struct JecBridge {
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl JecBridge {
    /// Connects to the controller of `cell`: waits up to `timeout` for every MR-JE-C axis'
    /// feedback, refuses a controller of another link version or other MR-JE-C axes, and
    /// returns the bridge with the axes the planner commands.
    pub fn connect(
        cell: &CellConfig,
        timeout: Duration,
    ) -> Result<(JecBridge, JecAxes), JecLinkError> {
        let axes = JecAxes::detached(cell);
        let stop = Arc::new(AtomicBool::new(false));
        let (ready_tx, ready_rx) = std::sync::mpsc::channel::<Result<(), JecLinkError>>();
        let (mine, stop2, name) = (axes.clone(), stop.clone(), cell.name.clone());
        let cell = cell.clone();
        let thread = std::thread::Builder::new()
            .name("cellrt-jec-link".into())
            .spawn(move || {
                let mut bridge = match Bridge::connect(&cell, mine, timeout) {
                    Ok(b) => {
                        let _ = ready_tx.send(Ok(()));
                        b
                    }
                    Err(e) => {
                        let _ = ready_tx.send(Err(e));
                        return;
                    }
                };
                while !stop2.load(Ordering::Acquire) {
                    bridge.pump();
                    std::thread::sleep(BRIDGE_TICK);
                }
                // The last commands the planner queued before it ended.
                bridge.send_commands();
            })
            .map_err(|source| JecLinkError::Thread {
                cell: name.clone(),
                source,
            })?;
        let bridge = JecBridge {
            stop,
            thread: Some(thread),
        };
        match ready_rx.recv() {
            Ok(Ok(())) => Ok((bridge, axes)),
            Ok(Err(e)) => Err(e),
            Err(_) => Err(JecLinkError::SetUpEnded { cell: name }),
        }
    }
}

impl Drop for JecBridge {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Release);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// The bridge thread's state.
struct Bridge {
    axes: JecAxes,
    commands: Publisher<ipc::Service, JecCommandSample, ()>,
    feedback: Subscriber<ipc::Service, JecFeedbackSample, ()>,
    shape: u64,
    cell: String,
    seq: u64,
    /// Per axis: when its feedback came last, and whether it is marked controller-lost.
    seen: Vec<(Instant, bool)>,
    /// Per axis: the controller's count of its refused commands, seen last.
    dropped: Vec<u64>,
    _node: Node<ipc::Service>,
}

impl Bridge {
    fn connect(
        cell: &CellConfig,
        axes: JecAxes,
        timeout: Duration,
    ) -> Result<Bridge, JecLinkError> {
        let name = &cell.name;
        let setup = || {
            let node = services::node(name, "je-c-link")?;
            let commands = services::je_c_command_publisher(&node, name)?;
            let feedback = services::je_c_feedback_subscriber(&node, name)?;
            Ok::<_, ServiceError>((node, commands, feedback))
        };
        let (node, commands, feedback) = setup()?;
        let n = axes.len();
        let mut b = Bridge {
            shape: je_c_shape(cell.axes.on_link()),
            cell: name.clone(),
            seq: 0,
            seen: vec![(Instant::now(), true); n],
            dropped: vec![0; n],
            axes,
            commands,
            feedback,
            _node: node,
        };
        let end = Instant::now() + timeout;
        let mut heard = vec![false; n];
        while heard.iter().any(|h| !h) {
            while let Ok(Some(sample)) = b.feedback.receive() {
                let s = *sample.payload();
                b.check(&s)?;
                if let Some(k) = b.store(&s) {
                    heard[k] = true;
                }
            }
            if Instant::now() >= end {
                return Err(JecLinkError::NoFeedback {
                    cell: name.clone(),
                    axes: b.axes.names(),
                    timeout,
                });
            }
            std::thread::sleep(BRIDGE_TICK);
        }
        Ok(b)
    }

    /// Refuses a controller of another link version or other MR-JE-C axes.
    fn check(&self, s: &JecFeedbackSample) -> Result<(), JecLinkError> {
        let cell = self.cell.clone();
        if s.version != JE_C_LINK_VERSION {
            return Err(JecLinkError::Version {
                cell,
                version: s.version,
            });
        }
        if usize::from(s.axis_count) != self.axes.len() {
            return Err(JecLinkError::AxisCount {
                cell,
                theirs: usize::from(s.axis_count),
                ours: self.axes.len(),
                axes: self.axes.names(),
            });
        }
        if s.shape != self.shape {
            return Err(JecLinkError::Shape {
                cell,
                axes: self.axes.names(),
            });
        }
        Ok(())
    }

    /// Stores a sample of the right shape as its axis' feedback; the axis' index.
    fn store(&mut self, s: &JecFeedbackSample) -> Option<usize> {
        let k = usize::from(s.axis);
        if self.check(s).is_err() || k >= self.axes.len() {
            return None;
        }
        let f = s.feedback()?;
        self.axes.handle(k).set_feedback(f);
        self.seen[k] = (Instant::now(), false);
        if s.commands_dropped > self.dropped[k] {
            tracing::warn!(
                "cell '{}': the controller refused {} MR-JE-C commands for axis '{}' (see its log)",
                self.cell,
                s.commands_dropped - self.dropped[k],
                self.axes.config(k).name
            );
            self.dropped[k] = s.commands_dropped;
        }
        Some(k)
    }

    fn pump(&mut self) {
        while let Ok(Some(sample)) = self.feedback.receive() {
            let s = *sample.payload();
            self.store(&s);
        }
        self.send_commands();
        for k in 0..self.axes.len() {
            let (at, lost) = self.seen[k];
            if !lost && at.elapsed() >= STATUS_TIMEOUT {
                let mut f = self.axes.feedback(k);
                f.stopped = Some(Stopped::ControllerLost);
                self.axes.handle(k).set_feedback(f);
                self.seen[k].1 = true;
                tracing::warn!(
                    "cell '{}': no feedback of MR-JE-C axis '{}' from the controller for {STATUS_TIMEOUT:?}",
                    self.cell,
                    self.axes.config(k).name
                );
            }
        }
    }

    /// Sends every queued command, in each axis' order.
    fn send_commands(&mut self) {
        for k in 0..self.axes.len() {
            while let Some(c) = self.axes.handle(k).take_command() {
                self.seq += 1;
                let sample = JecCommandSample::new(self.seq, self.shape, k as u16, c);
                if let Err(e) = self.commands.send_copy(sample) {
                    tracing::error!(
                        "cell '{}': MR-JE-C axis '{}': {c:?} not sent to the controller: {e:?}",
                        self.cell,
                        self.axes.config(k).name
                    );
                }
            }
        }
    }
}
