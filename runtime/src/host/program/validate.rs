//! Validation of program steps against a cell: every key is checked and every error names it.

use std::collections::BTreeMap;
use std::path::Path;

use cellrt_cia402::homing::choose_procedure;
use cellrt_cia402::mode::ModeOfOperation;
use cellrt_trajectory::limits::{KinematicLimits, MIN_LIMIT_FRACTION};
use cellrt_trajectory::planner::MAX_MOVE_AXES;

use super::{
    AxisMove, MoveTarget, RawLimit, RawStep, Step, TorqueTarget, MAX_PROGRAM_STEPS, MAX_REPEAT,
    MAX_WAIT_SECONDS,
};
use cellrt_config::{AxisRef, CellConfig, ConfigError};

/// Validates `raw` (keys `{key}[i]`) into `out`, expanding repeats.
pub(super) fn expand(
    path: &Path,
    key: &str,
    raw: Vec<RawStep>,
    cell: &CellConfig,
    out: &mut Vec<(String, Step)>,
) -> Result<(), ConfigError> {
    for (i, step) in raw.into_iter().enumerate() {
        let k = format!("{key}[{i}]");
        match step {
            RawStep::Repeat { count, steps } => {
                if !(1..=MAX_REPEAT).contains(&count) {
                    return Err(ConfigError::new(
                        path,
                        format!("{k}.count"),
                        format!("must be 1..={MAX_REPEAT} (got {count})"),
                    ));
                }
                if steps.is_empty() {
                    return Err(ConfigError::new(
                        path,
                        format!("{k}.steps"),
                        "a repeat needs at least one step",
                    ));
                }
                let mut body = Vec::new();
                expand(path, &format!("{k}.steps"), steps, cell, &mut body)?;
                if out.len() + body.len() * count as usize > MAX_PROGRAM_STEPS {
                    return Err(ConfigError::new(
                        path,
                        format!("{k}.count"),
                        format!("the program would run more than {MAX_PROGRAM_STEPS} steps"),
                    ));
                }
                for _ in 0..count {
                    out.extend(body.iter().cloned());
                }
            }
            other => {
                if out.len() >= MAX_PROGRAM_STEPS {
                    return Err(ConfigError::new(
                        path,
                        k,
                        format!("the program would run more than {MAX_PROGRAM_STEPS} steps"),
                    ));
                }
                let step = validate_step(path, &k, other, cell)?;
                out.push((k, step));
            }
        }
    }
    Ok(())
}

/// Follows the mode each axis of the RT loop runs in through the expanded `steps` (its
/// configured mode, then each `mode` step's), and refuses a move or a jog its drive's profile
/// mode at that point does not take (a jog of a pp axis, a move of a pv axis), naming the step's
/// key, before anything moves.
pub(super) fn check_profile_modes(
    path: &Path,
    steps: &[(String, Step)],
    cell: &CellConfig,
) -> Result<(), ConfigError> {
    use crate::host::operator::backend::profile::{takes_move, takes_velocity};
    let mut modes: Vec<ModeOfOperation> = cell.axes.on_loop().iter().map(|a| a.mode).collect();
    let profile = |modes: &[ModeOfOperation], i: usize| cellrt_config::ProfileMode::of(modes[i]);
    for (key, step) in steps {
        match step {
            Step::Mode { axis, mode } => modes[*axis] = mode.mode(),
            Step::Jog {
                axis: AxisRef::Loop(i),
                ..
            } => takes_velocity(&cell.axes.on_loop()[*i], profile(&modes, *i))
                .map_err(|e| ConfigError::new(path, format!("{key}.axis"), e.to_string()))?,
            Step::Move(targets) => {
                for t in targets {
                    if let AxisMove::Planned(t) = t {
                        let a = &cell.axes.on_loop()[t.axis];
                        takes_move(a, profile(&modes, t.axis)).map_err(|e| {
                            ConfigError::new(
                                path,
                                format!("{key}.target.{}", a.name),
                                e.to_string(),
                            )
                        })?;
                    }
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// One step (not a repeat) validated at `key`.
fn validate_step(
    path: &Path,
    key: &str,
    step: RawStep,
    cell: &CellConfig,
) -> Result<Step, ConfigError> {
    Ok(match step {
        RawStep::Torque { target, seconds } => torque_step(path, key, target, seconds, cell)?,
        RawStep::PowerOn { axes } => Step::PowerOn(power_axes(path, key, &axes, cell)?),
        RawStep::PowerOff { axes } => Step::PowerOff(power_axes(path, key, &axes, cell)?),
        RawStep::Reset => Step::Reset,
        RawStep::Wait { seconds } => Step::Wait(step_seconds(path, key, seconds)?),
        RawStep::Move {
            mut target,
            mut velocity,
            mut acceleration,
            mut jerk,
        } => {
            let limits = [&mut velocity, &mut acceleration, &mut jerk];
            let drive = super::je_c::take_targets(path, key, &mut target, limits, cell)?;
            let planned = if drive.is_empty() || !target.is_empty() {
                move_targets(path, key, target, [&velocity, &acceleration, &jerk], cell)?
            } else {
                Vec::new()
            };
            let planned = planned.into_iter().map(AxisMove::Planned);
            Step::Move(
                planned
                    .chain(drive.into_iter().map(AxisMove::Drive))
                    .collect(),
            )
        }
        RawStep::Line {
            target,
            velocity,
            acceleration,
            jerk,
        } => line_step(path, key, target, velocity, [&acceleration, &jerk], cell)?,
        RawStep::Path {
            waypoints,
            velocity,
            acceleration,
            jerk,
        } => path_step(
            path,
            key,
            waypoints,
            [&velocity, &acceleration, &jerk],
            cell,
        )?,
        RawStep::Jog {
            axis: name,
            velocity,
            seconds,
        } => {
            let axis = axis_ref_of(path, format!("{key}.axis"), &name, cell)?;
            let limit = cell.velocity_limit(axis);
            if !velocity.is_finite() || velocity.abs() > limit {
                return Err(ConfigError::new(
                    path,
                    format!("{key}.velocity"),
                    format!("{velocity} is outside ±{limit}, the velocity limit of axis '{name}'"),
                ));
            }
            if let AxisRef::Link(k) = axis {
                super::je_c::check_jog(path, key, k, velocity, cell)?;
            }
            Step::Jog {
                axis,
                velocity,
                seconds: step_seconds(path, key, seconds)?,
            }
        }
        RawStep::Override { percent } => {
            if !(percent.is_finite() && (0.0..=100.0).contains(&percent)) {
                return Err(ConfigError::new(
                    path,
                    format!("{key}.percent"),
                    format!("must be 0–100 % (got {percent})"),
                ));
            }
            Step::Override(percent / 100.0)
        }
        RawStep::Home {
            axis,
            method,
            setting,
        } => {
            let i = match axis_ref_of(path, format!("{key}.axis"), &axis, cell)? {
                AxisRef::Loop(i) => i,
                AxisRef::Link(k) => {
                    let procedure =
                        super::je_c::home_procedure(path, key, k, method, setting.is_some(), cell)?;
                    return Ok(Step::Home {
                        axis: AxisRef::Link(k),
                        procedure,
                    });
                }
            };
            // `[axes.homing] method` where the step names neither a method nor an edge.
            let method = method.or(cell.axes.on_loop()[i]
                .homing
                .method
                .filter(|_| setting.is_none()));
            let procedure = choose_procedure(&*cell.axes.on_loop()[i].profile, method, setting)
                .map_err(|e| {
                    ConfigError::new(path, format!("{key}.axis"), format!("axis '{axis}': {e}"))
                })?;
            Step::Home {
                axis: AxisRef::Loop(i),
                procedure,
            }
        }
        RawStep::Mode { axis, mode } => {
            let i = axis_of(path, format!("{key}.axis"), &axis, cell)?;
            let Some(mode) = crate::handoff::SwitchableMode::parse(&mode) else {
                return Err(ConfigError::new(
                    path,
                    format!("{key}.mode"),
                    format!("'{mode}' is not a mode an axis switches to at run time (csp or pp)"),
                ));
            };
            cellrt_config::profile_axis::pp_switch(&cell.axes.on_loop()[i])
                .map_err(|e| ConfigError::new(path, format!("{key}.axis"), e.to_string()))?;
            Step::Mode { axis: i, mode }
        }
        RawStep::Repeat { .. } => unreachable!("expanded by `expand`"),
    })
}

/// `seconds` of a wait, jog or torque step: 0..=[`MAX_WAIT_SECONDS`].
fn step_seconds(path: &Path, key: &str, seconds: f64) -> Result<f64, ConfigError> {
    if seconds.is_finite() && (0.0..=MAX_WAIT_SECONDS).contains(&seconds) {
        return Ok(seconds);
    }
    Err(ConfigError::new(
        path,
        format!("{key}.seconds"),
        format!("must be a number of seconds in 0..={MAX_WAIT_SECONDS} (got {seconds})"),
    ))
}

/// A torque step: axes in cst, or axes in tq (their drives ramp the torque, MR-J4-TM manual
/// §5.4.8; not both kinds in one step), each torque within the axis' torque limit.
fn torque_step(
    path: &Path,
    key: &str,
    target: BTreeMap<String, f64>,
    seconds: f64,
    cell: &CellConfig,
) -> Result<Step, ConfigError> {
    if target.is_empty() {
        return Err(ConfigError::new(
            path,
            format!("{key}.target"),
            "a torque step needs at least one axis target",
        ));
    }
    let hold_s = step_seconds(path, key, seconds)?;
    if let Some(targets) = super::je_c::torque_targets(path, key, &target, cell)? {
        return Ok(Step::Torque { targets, hold_s });
    }
    let mut targets = Vec::with_capacity(target.len());
    for (name, torque) in target {
        let k = format!("{key}.target.{name}");
        let axis = axis_of(path, k.clone(), &name, cell)?;
        let a = &cell.axes.on_loop()[axis];
        let torque_mode = matches!(
            a.mode,
            ModeOfOperation::CyclicSyncTorque | ModeOfOperation::ProfileTorque
        );
        let Some(limits) = a.torque.filter(|_| torque_mode) else {
            return Err(ConfigError::new(
                path,
                k,
                format!(
                    "axis '{name}' runs in {}; a torque step needs an axis with mode = \"cst\" or \"tq\" and limits.torque",
                    a.mode.as_str()
                ),
            ));
        };
        if targets.first().is_some_and(
            |t: &TorqueTarget| matches!(t.axis, AxisRef::Loop(j) if cell.axes.on_loop()[j].mode != a.mode),
        ) {
            return Err(ConfigError::new(
                path,
                k,
                "cst and tq axes in one torque step (a tq drive ramps by itself): make two steps"
                    .to_string(),
            ));
        }
        if !torque.is_finite() || torque.abs() > limits.max.0 {
            return Err(ConfigError::new(
                path,
                k,
                format!(
                    "torque {torque} % is outside the torque limit ±{} % of axis '{name}'",
                    limits.max.0
                ),
            ));
        }
        targets.push(TorqueTarget {
            axis: AxisRef::Loop(axis),
            torque,
            slope: limits.slope,
        });
    }
    Ok(Step::Torque { targets, hold_s })
}

/// A line: two or more axes of one unit; `velocity` is the path speed.
fn line_step(
    path: &Path,
    key: &str,
    target: BTreeMap<String, f64>,
    velocity: Option<f64>,
    [acceleration, jerk]: [&Option<RawLimit>; 2],
    cell: &CellConfig,
) -> Result<Step, ConfigError> {
    if target.len() < 2 {
        return Err(ConfigError::new(
            path,
            format!("{key}.target"),
            "a line needs at least two axes",
        ));
    }
    if let Some(v) = velocity.filter(|v| !(v.is_finite() && *v > 0.0)) {
        return Err(ConfigError::new(
            path,
            format!("{key}.velocity"),
            format!("the path speed must be a finite number > 0 (got {v})"),
        ));
    }
    let targets = move_targets(path, key, target, [&None, acceleration, jerk], cell)?;
    // Along any line the path may run as fast as its slowest axis' limit.
    let slowest = targets
        .iter()
        .map(|t| t.limits.velocity)
        .fold(f64::INFINITY, f64::min);
    if let Some(v) = velocity.filter(|v| *v < slowest * MIN_LIMIT_FRACTION) {
        return Err(ConfigError::new(
            path,
            format!("{key}.velocity"),
            format!(
                "the path speed {v:?} is too small to plan with (at least {:.3e}, a millionth of the slowest axis' velocity limit)",
                slowest * MIN_LIMIT_FRACTION
            ),
        ));
    }
    let unit = &cell.axes.on_loop()[targets[0].axis].unit;
    if let Some(t) = targets
        .iter()
        .find(|t| &cell.axes.on_loop()[t.axis].unit != unit)
    {
        return Err(ConfigError::new(
            path,
            format!("{key}.target.{}", cell.axes.on_loop()[t.axis].name),
            format!(
                "a line needs axes of one unit: '{}' is in {}, '{}' in {unit}",
                cell.axes.on_loop()[t.axis].name,
                cell.axes.on_loop()[t.axis].unit,
                cell.axes.on_loop()[targets[0].axis].name
            ),
        ));
    }
    Ok(Step::Line {
        targets,
        path_velocity: velocity,
    })
}

/// A path: the last waypoint is the target; every waypoint before it names the same axes,
/// within their position ranges.
fn path_step(
    path: &Path,
    key: &str,
    mut waypoints: Vec<BTreeMap<String, f64>>,
    limits: [&Option<RawLimit>; 3],
    cell: &CellConfig,
) -> Result<Step, ConfigError> {
    let Some(last) = waypoints.pop() else {
        return Err(ConfigError::new(
            path,
            format!("{key}.waypoints"),
            "a path needs at least one waypoint (the last is the target)",
        ));
    };
    if waypoints.len() > cellrt_trajectory::MAX_WAYPOINTS {
        return Err(ConfigError::new(
            path,
            format!("{key}.waypoints"),
            format!(
                "at most {} waypoints before the target",
                cellrt_trajectory::MAX_WAYPOINTS
            ),
        ));
    }
    let names: Vec<String> = last.keys().cloned().collect();
    let targets = move_targets(path, key, last, limits, cell)?;
    let mut via = Vec::with_capacity(waypoints.len());
    for (w, point) in waypoints.into_iter().enumerate() {
        let k = format!("{key}.waypoints[{w}]");
        if point.len() != names.len() || names.iter().any(|n| !point.contains_key(n)) {
            return Err(ConfigError::new(
                path,
                k,
                format!("must name the target's axes ({})", names.join(", ")),
            ));
        }
        let mut row = Vec::with_capacity(names.len());
        for (name, t) in names.iter().zip(&targets) {
            let v = point[name];
            let a = &cell.axes.on_loop()[t.axis];
            if !v.is_finite() || a.position.check(v).is_err() {
                return Err(ConfigError::new(
                    path,
                    format!("{k}.{name}"),
                    format!(
                        "{v} {} is outside the position range [{}, {}] of axis '{name}'",
                        a.unit, a.position.min, a.position.max
                    ),
                ));
            }
            row.push(v);
        }
        via.push(row);
    }
    Ok(Step::Path { targets, via })
}

/// The index of axis `name` in `cell`, or an error at `key` naming the cell's axes.
fn axis_of(
    path: &Path,
    key: impl Into<String>,
    name: &str,
    cell: &CellConfig,
) -> Result<usize, ConfigError> {
    cell.axis_index(name)
        .ok_or_else(|| not_in_cell(path, key, name, cell))
}

/// The axis called `name`, whichever backend runs it; refused naming `key` when the cell has
/// none.
fn axis_ref_of(
    path: &Path,
    key: impl Into<String>,
    name: &str,
    cell: &CellConfig,
) -> Result<AxisRef, ConfigError> {
    cell.axis_ref(name)
        .ok_or_else(|| not_in_cell(path, key, name, cell))
}

/// The refusal of an axis name the cell does not have, listing the axes it has.
fn not_in_cell(path: &Path, key: impl Into<String>, name: &str, cell: &CellConfig) -> ConfigError {
    ConfigError::new(
        path,
        key,
        format!(
            "axis '{name}' is not in cell '{}' (axes: {})",
            cell.name,
            cell.axes.names()
        ),
    )
}

/// The axes of a power step: indices of the named axes, each once; empty = the whole cell.
fn power_axes(
    path: &Path,
    key: &str,
    names: &[String],
    cell: &CellConfig,
) -> Result<Vec<AxisRef>, ConfigError> {
    let mut list = Vec::with_capacity(names.len());
    for name in names {
        let i = axis_ref_of(path, format!("{key}.axes"), name, cell)?;
        if list.contains(&i) {
            return Err(ConfigError::new(
                path,
                format!("{key}.axes"),
                format!("axis '{name}' is named twice"),
            ));
        }
        list.push(i);
    }
    Ok(list)
}

/// Validates the targets and per-move limits of a move-like step.
fn move_targets(
    path: &Path,
    key: &str,
    target: BTreeMap<String, f64>,
    [velocity, acceleration, jerk]: [&Option<RawLimit>; 3],
    cell: &CellConfig,
) -> Result<Vec<MoveTarget>, ConfigError> {
    if target.is_empty() {
        return Err(ConfigError::new(
            path,
            format!("{key}.target"),
            "a move needs at least one axis target",
        ));
    }
    if target.len() > MAX_MOVE_AXES {
        return Err(ConfigError::new(
                    path,
                    format!("{key}.target"),
                    format!(
                        "a move plans at most {MAX_MOVE_AXES} axes at once ({} given); split it into several steps",
                        target.len()
                    ),
                ));
    }
    for (name, lim) in [
        ("velocity", &velocity),
        ("acceleration", &acceleration),
        ("jerk", &jerk),
    ] {
        if let Some(RawLimit::PerAxis(m)) = lim {
            if let Some(bad) = m.keys().find(|k| !target.contains_key(*k)) {
                return Err(ConfigError::new(
                    path,
                    format!("{key}.{name}.{bad}"),
                    format!("axis '{bad}' is not moved by this step"),
                ));
            }
        }
    }
    let mut out = Vec::with_capacity(target.len());
    for (name, pos) in target {
        let axis = axis_of(path, format!("{key}.target.{name}"), &name, cell)?;
        let a = &cell.axes.on_loop()[axis];
        a.position.check(pos).map_err(|_| {
            ConfigError::new(
                path,
                format!("{key}.target.{name}"),
                format!(
                    "target {pos} {} is outside the position range [{}, {}] of axis '{name}'",
                    a.unit, a.position.min, a.position.max
                ),
            )
        })?;
        let pick = |lim: &Option<RawLimit>, default: f64, what: &str| {
            let v = match lim {
                None => return Ok(default),
                Some(RawLimit::All(v)) => *v,
                Some(RawLimit::PerAxis(m)) => match m.get(&name) {
                    Some(v) => *v,
                    None => return Ok(default),
                },
            };
            let k = format!("{key}.{what}");
            if !v.is_finite() || v <= 0.0 {
                return Err(ConfigError::new(
                    path,
                    k,
                    format!("must be a finite number > 0 (got {v})"),
                ));
            }
            if v < default * MIN_LIMIT_FRACTION {
                return Err(ConfigError::new(
                    path,
                    k,
                    format!(
                        "{v:?} is too small to plan with (at least {:.3e}, a millionth of the {what} limit of axis '{name}')",
                        default * MIN_LIMIT_FRACTION
                    ),
                ));
            }
            if v > default {
                return Err(ConfigError::new(
                            path,
                            k,
                            format!(
                                "{v} is above the {what} limit {default} of axis '{name}' (per-move limits may only lower it)"
                            ),
                        ));
            }
            Ok(v)
        };
        let limits = KinematicLimits {
            velocity: pick(velocity, a.limits.velocity, "velocity")?,
            acceleration: pick(acceleration, a.limits.acceleration, "acceleration")?,
            jerk: pick(jerk, a.limits.jerk, "jerk")?,
        };
        out.push(MoveTarget {
            axis,
            target: pos,
            limits,
        });
    }
    Ok(out)
}
