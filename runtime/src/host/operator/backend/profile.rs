//! Operator requests on profile axes (pp/pv/tq): `move`, `velocity`, `torque` and `halt` turned
//! into the drive-side motions the RT thread runs (`handoff::ProfileCommand`), in counts, with
//! the request's (or the axis') limits as the drive's profile.

use cellrt_trajectory::{KinematicLimits, UnitsError};

use std::collections::BTreeMap;

use super::super::targets::{axis_index, TargetError};
use crate::handoff::{ProfileCommand, ProfileMotion};
use crate::host::link::{CellLink, LinkError, StatusSnapshot};
use cellrt_config::{AxisConfig, CellConfig, ProfileMode, DEFAULT_TORQUE_SLOPE};

/// A cst torque target: (axis, torque %, slope %/s).
type TorqueTarget = (usize, f64, f64);

/// A move's targets: (axis, target, limits).
pub(crate) type Targets = Vec<(usize, f64, KinematicLimits)>;

/// Why a motion of profile axes is refused or not handed to the RT thread.
#[derive(Debug, thiserror::Error)]
pub enum ProfileError {
    /// The request names no axis of the cell.
    #[error(transparent)]
    Axis(#[from] TargetError),
    /// A torque request names cst and tq axes together.
    #[error(
        "cst and tq axes in one command (the tq drive holds its torque, cst axes \
                    for `seconds`): send them apart"
    )]
    MixedTorque,
    /// The RT thread did not take a motion.
    #[error(transparent)]
    Link(#[from] LinkError),
    /// The axis' profile mode (as it runs now) does not take the request.
    #[error("axis '{axis}' runs in {now} (the drive's profile): {what} needs {needs}")]
    WrongMode {
        /// The axis.
        axis: String,
        /// The mode it runs in.
        now: &'static str,
        /// The request.
        what: &'static str,
        /// The modes that take it.
        needs: &'static str,
    },
    /// The target is not a position in counts.
    #[error("axis '{axis}': {source}")]
    Counts {
        /// The axis.
        axis: String,
        /// Why.
        source: UnitsError,
    },
    /// The torque is outside the axis' torque limit.
    #[error("torque {torque} % is outside the torque limit ±{max} % of axis '{axis}'")]
    TorqueLimit {
        /// The torque asked, %.
        torque: f64,
        /// The limit, %.
        max: f64,
        /// The axis.
        axis: String,
    },
}

/// The profile mode of each axis (`None`: streamed), as configured or as the RT thread runs it
/// now: a csp axis a run-time mode switch left in pp is a pp axis.
pub(crate) struct AxisModes(Vec<Option<ProfileMode>>);

impl AxisModes {
    /// As configured (what a program plans with: it runs only while no axis is switched).
    pub(crate) fn configured(cell: &CellConfig) -> AxisModes {
        AxisModes(
            cell.axes
                .on_loop()
                .iter()
                .map(|a| a.profile_objects.map(|p| p.mode))
                .collect(),
        )
    }

    /// As the RT thread runs them, by `status`.
    pub(crate) fn now(cell: &CellConfig, status: &StatusSnapshot) -> AxisModes {
        AxisModes(
            (0..cell.axes.on_loop().len())
                .map(|i| ProfileMode::of(status.mode_now(cell, i)))
                .collect(),
        )
    }

    /// The profile mode of axis `i`, `None` for a streamed (csp/csv/cst) axis.
    pub(crate) fn of(&self, i: usize) -> Option<ProfileMode> {
        self.0.get(i).copied().flatten()
    }
}

/// Splits a move into the pp axes' set-points and the streamed axes' targets; an axis in pv or
/// tq is refused.
pub(crate) fn split_move(
    cell: &CellConfig,
    modes: &AxisModes,
    list: Targets,
) -> Result<(Vec<ProfileCommand>, Targets), ProfileError> {
    let (drive_side, streamed): (Targets, Targets) =
        list.into_iter().partition(|t| modes.of(t.0).is_some());
    let commands = drive_side
        .iter()
        .map(|(i, target, limits)| {
            move_to(*i, &cell.axes.on_loop()[*i], modes.of(*i), *target, limits)
        })
        .collect::<Result<_, _>>()?;
    Ok((commands, streamed))
}

/// Splits a torque request into the tq axes' commands and the cst axes' (axis, torque, slope);
/// both kinds in one request are refused (the tq drive holds its torque, cst axes only for the
/// request's `seconds`).
pub(crate) fn split_torque(
    cell: &CellConfig,
    modes: &AxisModes,
    targets: &BTreeMap<String, f64>,
) -> Result<(Vec<ProfileCommand>, Vec<TorqueTarget>), ProfileError> {
    let mut drive_side = Vec::new();
    let mut streamed = Vec::new();
    for (axis, t) in targets {
        let i = axis_index(cell, axis)?;
        let a = &cell.axes.on_loop()[i];
        if modes.of(i).is_some() {
            drive_side.push(torque(i, a, modes.of(i), *t)?);
        } else {
            streamed.push((i, *t, a.torque.map(|t| t.slope).unwrap_or(f64::NAN)));
        }
    }
    if !drive_side.is_empty() && !streamed.is_empty() {
        return Err(ProfileError::MixedTorque);
    }
    Ok((drive_side, streamed))
}

/// HALT for the profile axes among `axes` (all when `None`).
pub(crate) fn halts(
    cell: &CellConfig,
    modes: &AxisModes,
    axes: Option<&[usize]>,
) -> Vec<ProfileCommand> {
    (0..cell.axes.on_loop().len())
        .filter(|i| axes.is_none_or(|l| l.contains(i)))
        .filter(|&i| modes.of(i).is_some())
        .map(halt)
        .collect()
}

/// Sends drive-side motions to the RT thread, in order, to start in `start_cycle` (that of the
/// streamed motion they go with; 0: at once).
pub(crate) fn send(
    link: &mut dyn CellLink,
    commands: Vec<ProfileCommand>,
    start_cycle: u64,
) -> Result<(), ProfileError> {
    for c in commands {
        link.profile(ProfileCommand { start_cycle, ..c })?;
    }
    Ok(())
}

/// Whether an axis running `mode` (its profile mode; `None`: a cyclic mode, streamed) takes a
/// move: streamed axes and pp do; pv and tq are refused as the operator refuses them.
pub(crate) fn takes_move(a: &AxisConfig, mode: Option<ProfileMode>) -> Result<(), ProfileError> {
    match mode {
        None | Some(ProfileMode::Position) => Ok(()),
        Some(_) => Err(wrong_mode(a, mode, "move", "a csp, csv, cst or pp axis")),
    }
}

/// Whether an axis running `mode` (as [`takes_move`]) takes a velocity (a jog): streamed axes
/// and pv do; pp and tq are refused as the operator refuses them.
pub(crate) fn takes_velocity(
    a: &AxisConfig,
    mode: Option<ProfileMode>,
) -> Result<(), ProfileError> {
    match mode {
        None | Some(ProfileMode::Velocity) => Ok(()),
        Some(_) => Err(wrong_mode(
            a,
            mode,
            "velocity",
            "a csp, csv, cst or pv axis",
        )),
    }
}

/// A request the axis' profile mode (`mode`, as it runs now) does not take, naming what it
/// would need.
fn wrong_mode(
    a: &AxisConfig,
    mode: Option<ProfileMode>,
    what: &'static str,
    needs: &'static str,
) -> ProfileError {
    ProfileError::WrongMode {
        axis: a.name.clone(),
        now: mode.map_or(a.mode, ProfileMode::mode).as_str(),
        what,
        needs,
    }
}

/// `move` of a pp axis to `target` (units) with `limits`: a single set-point (it replaces a
/// move in progress, PLCopen "aborting").
fn move_to(
    i: usize,
    a: &AxisConfig,
    mode: Option<ProfileMode>,
    target: f64,
    limits: &KinematicLimits,
) -> Result<ProfileCommand, ProfileError> {
    if mode != Some(ProfileMode::Position) {
        return Err(wrong_mode(a, mode, "move", "a csp, csv, cst or pp axis"));
    }
    let s = a.scaling.counts_per_unit();
    let target = a
        .scaling
        .to_counts_i32(target)
        .map_err(|source| ProfileError::Counts {
            axis: a.name.clone(),
            source,
        })?;
    Ok(ProfileCommand {
        axis: i as u16,
        motion: ProfileMotion::Move {
            target,
            velocity: limits.velocity * s,
            acceleration: limits.acceleration * s,
            deceleration: limits.acceleration * s,
            immediate: true,
        },
        start_cycle: 0,
    })
}

/// `velocity` of a pv axis: runs at `velocity` (unit/s) ramping at `limits.acceleration`.
pub(crate) fn jog(
    i: usize,
    a: &AxisConfig,
    mode: Option<ProfileMode>,
    velocity: f64,
    limits: &KinematicLimits,
) -> Result<ProfileCommand, ProfileError> {
    if mode != Some(ProfileMode::Velocity) {
        return Err(wrong_mode(
            a,
            mode,
            "velocity",
            "a csp, csv, cst or pv axis",
        ));
    }
    let s = a.scaling.counts_per_unit();
    Ok(ProfileCommand {
        axis: i as u16,
        motion: ProfileMotion::Jog {
            velocity: velocity * s,
            acceleration: limits.acceleration * s,
            deceleration: limits.acceleration * s,
        },
        start_cycle: 0,
    })
}

/// `torque` on a tq axis: `torque` % at the axis' `limits.torque_slope` (or the default),
/// within `limits.torque` where configured. The drive holds it until a halt or stop.
fn torque(
    i: usize,
    a: &AxisConfig,
    mode: Option<ProfileMode>,
    torque: f64,
) -> Result<ProfileCommand, ProfileError> {
    if mode != Some(ProfileMode::Torque) {
        return Err(wrong_mode(a, mode, "torque", "a cst or tq axis"));
    }
    if let Some(max) = a.torque.map(|t| t.max.0) {
        if !torque.is_finite() || torque.abs() > max {
            return Err(ProfileError::TorqueLimit {
                torque,
                max,
                axis: a.name.clone(),
            });
        }
    }
    Ok(ProfileCommand {
        axis: i as u16,
        motion: ProfileMotion::Torque {
            torque,
            slope: a.torque.map_or(DEFAULT_TORQUE_SLOPE, |t| t.slope),
        },
        start_cycle: 0,
    })
}

/// `halt` of a profile axis: HALT (controlword bit 8), the drive stops per its 605Dh.
fn halt(i: usize) -> ProfileCommand {
    ProfileCommand {
        axis: i as u16,
        motion: ProfileMotion::Halt(true),
        start_cycle: 0,
    }
}

/// The drive-side motions a tracked command waits for: per axis, its ended and failed counts
/// (the status' `profile_finished`, `profile_failed`) before the command was sent. The command
/// ends once each axis has ended one more.
#[derive(Debug, Default)]
pub(crate) struct PendingProfile(super::Pending<EndsBefore>);

/// An axis and its ended and failed drive-side motions before a command: `(axis, ended,
/// failed)`.
type EndsBefore = (usize, u32, u32);

impl PendingProfile {
    /// Notes the counts of `commands`' axes in `before` (a status read before they are sent)
    /// for command `id`.
    pub(crate) fn expect(&mut self, id: u64, commands: &[ProfileCommand], before: &StatusSnapshot) {
        let axes = commands
            .iter()
            .map(|c| usize::from(c.axis))
            .filter_map(|i| {
                before
                    .live
                    .get(i)
                    .map(|l| (i, l.profile_finished, l.profile_failed))
            })
            .collect();
        self.0.expect(id, axes);
    }

    /// Whether command `active` still waits for an axis; `Err(axis)` when one of its motions
    /// was refused or cancelled. Forgets a command that is no longer the active one.
    pub(crate) fn progress(
        &mut self,
        active: Option<u64>,
        now: &StatusSnapshot,
    ) -> Result<bool, usize> {
        self.0.progress(active, |&(i, finished, failed)| {
            let l = &now.live[i];
            if l.profile_failed != failed {
                super::AxisProgress::Failed(i)
            } else if l.profile_finished == finished {
                super::AxisProgress::Running
            } else {
                super::AxisProgress::Done
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::host::operator::sdo::tests::shipped;

    #[test]
    fn a_request_the_axis_mode_does_not_take_names_the_mode_it_needs() {
        let cell = shipped("ethercat-cell.toml");
        let a = &cell.axes.on_loop()[1];
        let limits = a.limits;
        let e = jog(1, a, None, 1.0, &limits).unwrap_err();
        assert!(
            matches!(
                &e,
                ProfileError::WrongMode {
                    what: "velocity",
                    ..
                }
            ),
            "{e:?}"
        );
        assert!(
            e.to_string()
                .starts_with(&format!("axis '{}' runs in ", a.name)),
            "{e}"
        );
        let modes = AxisModes::configured(&cell);
        let e = split_torque(&cell, &modes, &BTreeMap::from([("w".to_string(), 1.0)])).unwrap_err();
        assert!(matches!(e, ProfileError::Axis(_)), "{e:?}");
    }
}
