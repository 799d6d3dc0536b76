//! The cell's MR-JE-C axes: for each, its emulated drive where the config asks for one, then
//! its thread (`cellrt-jec-NAME`), one exchange per link period over its transport, with the
//! drive-side time-out written at start-up. The planner and the summary reach the axes through
//! [`JecAxes`] (lock-free command queues and feedback cells); the RT thread never does.

pub mod connect;
pub mod emulated;
pub mod jobs;
pub mod link;

use std::sync::Arc;

use cellrt_fieldbus::mr_je_c::cell::control::FULL_FEED;
use cellrt_fieldbus::mr_je_c::cell::{
    AxisCommand, AxisControl, AxisFeedback, AxisHandle, AxisThread, StartError, StopReaction,
    Stopped,
};
use cellrt_fieldbus::mr_je_c::Alarm;
use serde::Serialize;

use crate::host::faults::DriveFault;
use cellrt_config::je_c_axis::{JecAxisConfig, JecMode};
use cellrt_config::{CellConfig, FaultReaction};
use emulated::Emulated;

/// An MR-JE-C axis that could not start.
#[derive(Debug, thiserror::Error)]
#[error("MR-JE-C axis '{axis}' ({transport}): {failure}")]
pub struct JecStartError {
    /// The axis' name.
    pub axis: String,
    /// Its transport's name.
    pub transport: &'static str,
    /// Why.
    #[source]
    pub failure: JecStartFailure,
}

/// Why an MR-JE-C axis could not start.
#[derive(Debug, thiserror::Error)]
pub enum JecStartFailure {
    /// Its emulated drive could not start.
    #[error("emulator: {0}")]
    Emulator(#[source] std::io::Error),
    /// A real drive without a configured address.
    #[error("no address")]
    NoAddress,
    /// Its exchange with the drive could not be opened.
    #[error(transparent)]
    Open(#[from] connect::OpenError),
    /// Its thread could not start.
    #[error(transparent)]
    Thread(#[from] StartError),
}

/// An MR-JE-C axis' command that could not be queued.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("MR-JE-C axis '{axis}': command queue full")]
pub struct JecQueueFull {
    /// The axis' name.
    pub axis: String,
}

/// One running MR-JE-C axis.
struct JecAxis {
    config: JecAxisConfig,
    // Stopped before its emulated drive.
    thread: AxisThread,
    emulated: Option<Emulated>,
}

/// The cell's MR-JE-C axes, running.
#[derive(Default)]
pub struct JecCell {
    axes: Vec<JecAxis>,
}

fn reaction(r: FaultReaction) -> StopReaction {
    match r {
        FaultReaction::ControlledStop => StopReaction::Halt,
        FaultReaction::QuickStop => StopReaction::QuickStop,
        FaultReaction::Disable => StopReaction::Disable,
    }
}

impl JecCell {
    /// Starts every MR-JE-C axis of `cell` (none: nothing runs).
    pub fn start(cell: &CellConfig) -> Result<JecCell, JecStartError> {
        let mut axes = Vec::with_capacity(cell.axes.on_link().len());
        for c in cell.axes.on_link() {
            let fail = |failure: JecStartFailure| JecStartError {
                axis: c.name.clone(),
                transport: c.transport.name(),
                failure,
            };
            let (emulated, reach) = if c.emulate {
                let (e, r) = emulated::start(c).map_err(|e| fail(JecStartFailure::Emulator(e)))?;
                (Some(e), r)
            } else {
                let reach = match connect::open_line(c).map_err(|e| fail(e.into()))? {
                    Some(r) => r,
                    None => {
                        connect::configured(c).ok_or_else(|| fail(JecStartFailure::NoAddress))?
                    }
                };
                (None, reach)
            };
            let io = connect::open(c, reach).map_err(|e| fail(e.into()))?;
            let mut control = AxisControl::new(c.watchdog_missed, reaction(c.watchdog_reaction));
            match c.mode {
                JecMode::Pp => {}
                JecMode::Pv => control = control.starting_in_pv(),
                JecMode::Tq => control = control.starting_in_tq(c.speed_limit()),
                JecMode::Jog | JecMode::PointTable | JecMode::Indexer { .. } => {}
            }
            if let Some(m) = c.mode.positioning() {
                control = control.starting_in_positioning(m);
            }
            let parameters = connect::start_up_parameters(c);
            let thread = AxisThread::start(&c.name, io, &parameters, control, c.period)
                .map_err(|e| fail(e.into()))?;
            axes.push(JecAxis {
                config: c.clone(),
                thread,
                emulated,
            });
        }
        Ok(JecCell { axes })
    }

    /// The handles the planner commands the axes with.
    pub fn axes(&self) -> JecAxes {
        JecAxes {
            axes: Arc::new(
                self.axes
                    .iter()
                    .map(|a| (a.config.clone(), a.thread.handle.clone()))
                    .collect(),
            ),
        }
    }

    /// The emulated drive of axis `name`, if it has one.
    pub fn emulated(&self, name: &str) -> Option<&Emulated> {
        self.axes
            .iter()
            .find(|a| a.config.name == name)
            .and_then(|a| a.emulated.as_ref())
    }

    /// The end of the run: every axis brought to standstill and powered off (within a few
    /// link periods), its link summarised (by link), its thread and emulated drive stopped.
    pub fn finish(self) -> Vec<LinkSummary> {
        let axes = self.axes();
        let _ = axes.command_all(AxisCommand::PowerOff);
        let end = std::time::Instant::now() + std::time::Duration::from_millis(500);
        while (0..axes.len()).any(|k| axes.feedback(k).enabled) && std::time::Instant::now() < end {
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        self.summary()
    }

    /// Each axis' link and final position for the run's summary, by link.
    pub fn summary(&self) -> Vec<LinkSummary> {
        self.axes
            .iter()
            .map(|a| {
                let f = a.thread.handle.feedback();
                LinkSummary::of(&a.config, &f, a.emulated.as_ref())
            })
            .collect()
    }
}

/// The MR-JE-C axes as the planner and the operator see them.
#[derive(Clone, Default)]
pub struct JecAxes {
    axes: Arc<Vec<(JecAxisConfig, AxisHandle)>>,
}

impl JecAxes {
    /// How many.
    pub fn len(&self) -> usize {
        self.axes.len()
    }

    /// None at all.
    pub fn is_empty(&self) -> bool {
        self.axes.is_empty()
    }

    /// Axis `k`'s configuration.
    pub fn config(&self, k: usize) -> &JecAxisConfig {
        &self.axes[k].0
    }

    /// Axis `k`'s latest feedback.
    pub fn feedback(&self, k: usize) -> AxisFeedback {
        self.axes[k].1.feedback()
    }

    /// Axis `k`'s oldest exchange record not yet recorded.
    pub fn pop_record(&self, k: usize) -> Option<cellrt_fieldbus::mr_je_c::cell::ExchangeRecord> {
        self.axes[k].1.pop_record()
    }

    /// Queues `c` for axis `k`.
    pub fn command(&self, k: usize, c: AxisCommand) -> Result<(), JecQueueFull> {
        if self.axes[k].1.command(c) {
            Ok(())
        } else {
            Err(JecQueueFull {
                axis: self.axes[k].0.name.clone(),
            })
        }
    }

    /// The feed override `value` (0–1) for every axis: their drives' commanded speeds scaled
    /// ([`AxisCommand::Override`]).
    pub fn set_override(&self, value: f64) -> Result<(), JecQueueFull> {
        let permille = (value.clamp(0.0, 1.0) * f64::from(FULL_FEED)).round() as u16;
        self.command_all(AxisCommand::Override { permille })
    }

    /// MC_Stop for every axis: each its [`JecAxisConfig::stop_command`].
    pub fn stop_all(&self) -> Result<(), JecQueueFull> {
        (0..self.len()).try_for_each(|k| self.command(k, self.config(k).stop_command()))
    }

    /// Queues `c` for every axis.
    pub fn command_all(&self, c: AxisCommand) -> Result<(), JecQueueFull> {
        (0..self.len()).try_for_each(|k| self.command(k, c))
    }
}

impl JecAxes {
    /// The state of axis `k` for `cellrt status`.
    pub fn status(&self, k: usize) -> crate::host::operator::wire::AxisStatus {
        use crate::host::operator::wire::{AxisStatus, LinkStatus};
        let (c, h) = &self.axes[k];
        let f = h.feedback();
        let state = cellrt_cia402::statusword::Statusword(f.inputs.statusword).state();
        let position = c.units(f.inputs.position);
        AxisStatus {
            name: c.name.clone(),
            backend: cellrt_config::Backend::Link.as_str().to_string(),
            unit: c.unit.clone(),
            mode: c.mode.name().to_string(),
            mode_display: "?".to_string(),
            powered: f.enabled,
            fsa: state.map_or("unknown", |s| s.as_str()).to_string(),
            setpoint: position,
            position,
            velocity: f64::from(f.inputs.velocity) / 100.0 / 60.0 * c.counts_per_rev
                / c.counts_per_unit,
            following_error: 0.0,
            error_code: f.inputs.alarm,
            alarm: (f.inputs.alarm != 0).then(|| Alarm::text_of(f.inputs.alarm).long()),
            status_do: Vec::new(),
            link: Some(LinkStatus {
                transport: c.transport.name().to_string(),
                busy: f.busy,
                stopped: f.stopped.map(stopped_text),
                exchanges: f.cycles,
                missed: f.missed,
                missed_in_row: f.missed_in_row,
                round_trip_us: f.round_trip_ns as f64 / 1000.0,
            }),
        }
    }
}

/// The MR-JE-C link of an axis at the end of a run, and where the axis ended.
#[derive(Debug, Clone, Serialize)]
pub struct LinkSummary {
    /// Final position, units.
    #[serde(skip)]
    pub final_position: f64,
    /// Transport.
    pub transport: &'static str,
    /// Exchanges run.
    pub exchanges: u64,
    /// Exchanges without an answer.
    pub missed: u64,
    /// Exchanges the drive refused.
    pub refused: u64,
    /// The longest round trip, µs.
    pub max_round_trip_us: f64,
    /// Why the axis was stopped, if it was.
    pub stopped: Option<String>,
    /// The emulated drive's alarm at the end, in words.
    pub drive_alarm: Option<String>,
    /// The drive alarm that stopped the axis, in words.
    pub fault: Option<DriveFault>,
}

impl LinkSummary {
    fn of(c: &JecAxisConfig, f: &AxisFeedback, e: Option<&Emulated>) -> Self {
        LinkSummary {
            final_position: c.units(f.inputs.position),
            transport: c.transport.name(),
            exchanges: f.cycles,
            missed: f.missed,
            refused: f.refused,
            max_round_trip_us: f.max_round_trip_ns as f64 / 1000.0,
            stopped: f.stopped.map(stopped_text),
            drive_alarm: e
                .and_then(Emulated::alarm)
                .map(|a| Alarm::text_of(a.current2()).to_string()),
            fault: match f.stopped {
                Some(Stopped::DriveAlarm(code)) => {
                    Some(DriveFault::new(&c.name, None, Some(Alarm::text_of(code))))
                }
                _ => None,
            },
        }
    }
}

/// Why an axis was stopped, in words.
pub fn stopped_text(s: Stopped) -> String {
    match s {
        Stopped::CommunicationLost(n) => {
            format!("communication lost ({n} answers missed in a row)")
        }
        Stopped::DriveAlarm(code) => format!("drive alarm {}", Alarm::text_of(code).long()),
        Stopped::ControllerLost => format!(
            "the controller stopped sending its feedback (none for {:?}; has `cellrt run` ended?)",
            crate::host::link::STATUS_TIMEOUT
        ),
    }
}
