//! The MR-JE-C link backend of the operator's requests (MC_Power, MC_MoveAbsolute /
//! MC_MoveRelative, MC_MoveVelocity, MC_TorqueControl, MC_Home, MC_Reset): each checked against
//! the axis' own range and limits, by the rules every backend shares (`targets`), and queued
//! for its link thread, which commands the drive's pp, pv, tq and hm (MR-JE-C manual §7.6.3,
//! §7.6.4). The drive's profile has no jerk: a jerk limit does not apply to them.

use cellrt_fieldbus::mr_je_c::cell::AxisCommand;

use super::super::targets::{jog_velocity, pick_limit, Asked, TargetError};
use super::LinkTarget;
use crate::host::je_c::jobs::{JobCounts, JobError, JobOutcome};
use crate::host::je_c::{stopped_text, JecAxes, JecQueueFull};
use cellrt_config::je_c_axis::{JecAxisConfig, JecCommandError, JecHomingError, JecMode};

/// Why an operator request on an MR-JE-C axis was refused or failed.
#[derive(Debug, thiserror::Error)]
pub(crate) enum LinkRequestError {
    /// A target, limit or velocity the rules of every backend refuse.
    #[error(transparent)]
    Target(#[from] TargetError),
    /// The axis was stopped by its watchdog or an alarm.
    #[error("axis '{axis}': {stopped}; reset it first")]
    Stopped { axis: String, stopped: String },
    /// The axis' servo is off.
    #[error("axis '{axis}' is not enabled (statusword {statusword:04X}h); power it on first")]
    NotEnabled { axis: String, statusword: u16 },
    /// The axis moves or runs a job: no servo off.
    #[error("axis '{axis}' is moving; halt it first")]
    Moving { axis: String },
    /// A relative move on an axis whose moves name a table or a station.
    #[error("axis '{axis}' runs {mode}: a move names its {what}, not a distance")]
    NoDistance {
        axis: String,
        mode: &'static str,
        what: &'static str,
    },
    /// A move's velocity or acceleration on a point-table axis.
    #[error("axis '{axis}' runs point tables: each table has its own speed and ramps (2801h–28FFh); leave out the move's velocity and acceleration")]
    TableLimits { axis: String },
    /// A homing the drive does not run.
    #[error(transparent)]
    Homing(#[from] JecHomingError),
    /// The axis' configuration refused the command.
    #[error(transparent)]
    Command(#[from] JecCommandError),
    /// The link thread's command queue is full.
    #[error(transparent)]
    QueueFull(#[from] JecQueueFull),
    /// A tracked job failed or its axis was stopped ([`JecAxes::job_error`]).
    #[error(transparent)]
    Job(#[from] JobError),
}

/// The axis can take a motion command: servo on, not stopped by its watchdog or an alarm.
fn ready(axes: &JecAxes, k: usize) -> Result<(), LinkRequestError> {
    let f = axes.feedback(k);
    let axis = axes.config(k).name.clone();
    if let Some(s) = f.stopped {
        return Err(LinkRequestError::Stopped {
            axis,
            stopped: stopped_text(s),
        });
    }
    if !f.enabled {
        return Err(LinkRequestError::NotEnabled {
            axis,
            statusword: f.inputs.statusword,
        });
    }
    Ok(())
}

/// A limit the request asks for, within the axis' own (the rule of every backend).
fn pick(
    c: &JecAxisConfig,
    what: (&'static str, &'static str),
    asked: Option<f64>,
    limit: f64,
    clamp: bool,
) -> Result<f64, LinkRequestError> {
    Ok(pick_limit(&c.name, &c.unit, what, asked, limit, clamp)?)
}

/// The pp commands of a move's MR-JE-C axes, each checked: ready, target finite and within
/// the axis' position range (after adding the current position when `relative`), velocity
/// and acceleration within its limits. Nothing is queued here.
pub(crate) fn move_commands(
    axes: &JecAxes,
    list: &[LinkTarget],
    relative: bool,
    asked: Asked,
) -> Result<Vec<(usize, AxisCommand)>, LinkRequestError> {
    let mut out = Vec::with_capacity(list.len());
    for (k, name, value) in list {
        let c = axes.config(*k);
        if !value.is_finite() {
            return Err(TargetError::NotFinite {
                axis: name.clone(),
                value: *value,
            }
            .into());
        }
        ready(axes, *k)?;
        let numbered = match c.mode {
            JecMode::PointTable => Some("point table"),
            JecMode::Indexer { .. } => Some("station"),
            _ => None,
        };
        let goal = match (relative, numbered) {
            (true, Some(what)) => {
                return Err(LinkRequestError::NoDistance {
                    axis: name.clone(),
                    mode: c.mode.name(),
                    what,
                })
            }
            (true, None) => c.move_target(c.units(axes.feedback(*k).inputs.position) + value)?,
            (false, _) => c.move_target(*value)?,
        };
        if !c.takes_move_limits() && (asked.velocity.is_some() || asked.acceleration.is_some()) {
            return Err(LinkRequestError::TableLimits { axis: name.clone() });
        }
        let velocity = pick(
            c,
            ("velocity", "/s"),
            asked.velocity,
            c.velocity,
            asked.clamp,
        )?;
        let acceleration = pick(
            c,
            ("acceleration", "/s²"),
            asked.acceleration,
            c.acceleration,
            asked.clamp,
        )?;
        out.push((*k, c.move_command(goal, velocity, acceleration)));
    }
    Ok(out)
}

/// The tq commands of a torque request's MR-JE-C axes, each checked: ready, torque within the
/// axis' `limits.torque`. Nothing is queued here.
pub(crate) fn torque_commands(
    axes: &JecAxes,
    list: &[LinkTarget],
) -> Result<Vec<(usize, AxisCommand)>, LinkRequestError> {
    list.iter()
        .map(|(k, _, torque)| {
            ready(axes, *k)?;
            Ok((*k, axes.config(*k).torque_command(*torque)?))
        })
        .collect()
}

/// The hm command of MR-JE-C axis `k`: ready, with method 37 (or none named) and no
/// Controlword2 edge.
pub(crate) fn home_command(
    axes: &JecAxes,
    k: usize,
    method: Option<i8>,
    setting: bool,
) -> Result<AxisCommand, LinkRequestError> {
    axes.config(k).homing_method(method, setting)?;
    ready(axes, k)?;
    Ok(AxisCommand::Home)
}

/// The pv command of a jog of MR-JE-C axis `k` at `velocity` unit/s.
pub(crate) fn velocity_command(
    axes: &JecAxes,
    k: usize,
    velocity: f64,
    acceleration: Option<f64>,
    clamp: bool,
) -> Result<AxisCommand, LinkRequestError> {
    let c = axes.config(k);
    let velocity = jog_velocity(&c.name, &c.unit, velocity, c.velocity, clamp)?;
    let acceleration = pick(
        c,
        ("acceleration", "/s²"),
        acceleration,
        c.acceleration,
        clamp,
    )?;
    ready(axes, k)?;
    Ok(c.jog_command(velocity, acceleration)?)
}

/// MC_Power of MR-JE-C axes `ks`: on needs an axis not stopped (reset first), off one that
/// whose motor stands and runs no job (halt first: servo off would stop it on the dynamic
/// brake).
pub(crate) fn power_check(axes: &JecAxes, ks: &[usize], on: bool) -> Result<(), LinkRequestError> {
    for &k in ks {
        let f = axes.feedback(k);
        let axis = axes.config(k).name.clone();
        match (on, f.stopped) {
            (true, Some(s)) => {
                return Err(LinkRequestError::Stopped {
                    axis,
                    stopped: stopped_text(s),
                })
            }
            (false, _) if f.busy || f.inputs.velocity != 0 => {
                return Err(LinkRequestError::Moving { axis })
            }
            _ => {}
        }
    }
    Ok(())
}

/// Queues each command; the first the link thread cannot take is the error.
pub(crate) fn send(
    axes: &JecAxes,
    commands: &[(usize, AxisCommand)],
) -> Result<(), LinkRequestError> {
    commands.iter().try_for_each(|&(k, c)| axes.command(k, c))?;
    Ok(())
}

/// MC_Reset of the MR-JE-C axes stopped by their watchdog or an alarm.
pub(crate) fn reset_stopped(axes: &JecAxes) -> Result<(), JecQueueFull> {
    (0..axes.len())
        .filter(|&k| axes.feedback(k).stopped.is_some())
        .try_for_each(|k| axes.command(k, AxisCommand::Reset))
}

/// The MR-JE-C axes a tracked move waits for: each axis' job counts when it was sent, so the
/// move ends when each has one more done, and fails on a failed job or a stop (judged as a
/// program's step judges them, `JecAxes::job_outcome`).
#[derive(Debug, Default)]
pub(crate) struct PendingMoves {
    /// Per axis its job counts before the command.
    pending: super::Pending<(usize, JobCounts)>,
    /// What the command does to them ("move", "homing"), for its failure.
    what: &'static str,
}

impl PendingMoves {
    /// Notes the job counts of `commands`' axes before they are sent, for command `id`, which
    /// `what` names.
    pub(crate) fn expect(
        &mut self,
        id: u64,
        what: &'static str,
        axes: &JecAxes,
        commands: &[(usize, AxisCommand)],
    ) {
        self.what = what;
        let before = commands
            .iter()
            .map(|&(k, _)| (k, axes.job_counts(k)))
            .collect();
        self.pending.expect(id, before);
    }

    /// Whether the move `active` still waits for an MR-JE-C axis; an error when one failed
    /// or was stopped. Forgets a move that is no longer the active command.
    pub(crate) fn progress(
        &mut self,
        active: Option<u64>,
        axes: &JecAxes,
    ) -> Result<bool, LinkRequestError> {
        let what = self.what;
        self.pending.progress(active, |&(k, counts)| {
            let outcome = axes.job_outcome(k, counts, 1);
            match axes.job_error(k, outcome, what) {
                Some(e) => super::AxisProgress::Failed(e.into()),
                None if outcome == JobOutcome::Pending => super::AxisProgress::Running,
                None => super::AxisProgress::Done,
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cellrt_config::CellConfig;
    use cellrt_fieldbus::mr_je_c::cell::{AxisFeedback, Inputs};

    /// The shipped config `name`.toml with `edit` applied, its MR-JE-C axes detached and
    /// enabled.
    fn enabled_axes(name: &str, edit: impl Fn(String) -> String) -> JecAxes {
        let path = format!("{}/../configs/{name}.toml", env!("CARGO_MANIFEST_DIR"));
        let text = edit(std::fs::read_to_string(&path).unwrap());
        let cell = CellConfig::parse(std::path::Path::new(&path), &text).unwrap();
        let axes = JecAxes::detached(&cell);
        for k in 0..axes.len() {
            axes.handle(k).set_feedback(AxisFeedback {
                enabled: true,
                inputs: Inputs {
                    statusword: 0x0637,
                    ..Inputs::default()
                },
                ..AxisFeedback::default()
            });
        }
        axes
    }

    fn relative(axes: &JecAxes, k: usize) -> String {
        let asked = Asked {
            velocity: None,
            acceleration: None,
            jerk: None,
            clamp: false,
        };
        let name = axes.config(k).name.clone();
        move_commands(axes, &[(k, name, 1.0)], true, asked)
            .unwrap_err()
            .to_string()
    }

    /// A relative move names a distance: refused on a point-table or indexer axis (a move
    /// there names a table or a station) and on a jog axis (no targets at all).
    #[test]
    fn relative_moves_are_refused_where_a_move_takes_no_distance() {
        let axes = enabled_axes("je-c-positioning", |t| t);
        assert_eq!(
            relative(&axes, 0),
            "axis 'feeder' runs point_table: a move names its point table, not a distance"
        );
        assert_eq!(
            relative(&axes, 1),
            "axis 'turret' runs indexer: a move names its station, not a distance"
        );
        let axes = enabled_axes("mixed-cell", |t| {
            let at = t.find("name = \"outfeed\"").unwrap();
            let (head, tail) = t.split_at(at);
            format!(
                "{head}{}",
                tail.replacen("mode = \"pp\"", "mode = \"jog\"", 1)
            )
        });
        assert_eq!(
            relative(&axes, 1),
            "axis 'outfeed' runs jg: it moves by jog only, not to targets"
        );
    }

    /// An MR-JE-C axis is refused by the rules every backend shares, in the same words as a
    /// streamed axis (`targets`): a limit above its own, a jog velocity outside ±its limit, a
    /// target that is not a number.
    #[test]
    fn refusals_on_a_link_axis_read_as_on_any_axis() {
        let axes = enabled_axes("mixed-cell", |t| t);
        let (infeed, outfeed) = (0, 1);
        let asked = |velocity| Asked {
            velocity,
            acceleration: None,
            jerk: None,
            clamp: false,
        };
        let e = move_commands(
            &axes,
            &[(infeed, "infeed".into(), 0.0)],
            false,
            asked(Some(300.0)),
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "axis 'infeed': velocity 300 mm/s exceeds the axis limit 200 mm/s (add --clamp to use the limit)"
        );
        let streamed = jog_velocity("x", "mm", 500.0, 400.0, false).unwrap_err();
        assert_eq!(
            streamed.to_string(),
            "axis 'x': velocity 500 mm/s exceeds the axis limit 400 mm/s (add --clamp to use the limit)"
        );
        let e = velocity_command(&axes, outfeed, -250.0, None, false).unwrap_err();
        assert_eq!(
            e.to_string(),
            "axis 'outfeed': velocity 250 mm/s exceeds the axis limit 150 mm/s (add --clamp to use the limit)"
        );
        assert!(velocity_command(&axes, outfeed, -250.0, None, true).is_ok());
        let e = move_commands(
            &axes,
            &[(infeed, "infeed".into(), f64::NAN)],
            false,
            asked(None),
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "axis 'infeed': target NaN is not a finite number"
        );
    }
}
