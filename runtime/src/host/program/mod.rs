//! Programs: a TOML list of steps (power on, move, wait, power off) validated against a cell.
//!
//! ```toml
//! [[step]]
//! do = "power_on"
//! [[step]]
//! do = "move"
//! target = { x = 400.0, y = 250.0 }
//! velocity = { x = 300.0 }        # optional per-move limits: one number for every moved axis,
//! acceleration = 2000.0           # or a table per axis; never above the axis limit
//! [[step]]
//! do = "wait"
//! seconds = 0.5
//! [[step]]
//! do = "power_off"
//! ```
//!
//! `do = "reset"` clears a cell stopped by a watchdog (MC_Reset).
//!
//! `do = "torque"`, `target = { z = 30.0 }` (% of rated torque), `seconds = 0.5`: on axes in
//! cst, ramps to the torque at `limits.torque_slope`, holds it, ramps back to zero; an axis left
//! moving then brakes in csv with its controlled-stop ramp.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use cellrt_trajectory::limits::KinematicLimits;
use cellrt_trajectory::planner::MAX_MOVE_AXES;
use serde::Deserialize;

use cellrt_axes::cia402::homing::{choose_procedure, HomeProcedure, HomeSettingEdge};
use cellrt_axes::cia402::mode::ModeOfOperation;

use crate::config::{CellConfig, ConfigError};

/// Longest wait a program step may ask for, seconds.
pub const MAX_WAIT_SECONDS: f64 = 86_400.0;

/// A per-move limit: one value for every moved axis, or one per axis.
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
pub enum RawLimit {
    /// The same value for every moved axis.
    All(f64),
    /// A value per axis name.
    PerAxis(BTreeMap<String, f64>),
}

/// A program step as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(tag = "do", rename_all = "snake_case", deny_unknown_fields)]
pub enum RawStep {
    /// Enable the named axes (every axis when none).
    PowerOn {
        /// Axis names; empty = the whole cell.
        #[serde(default)]
        axes: Vec<String>,
    },
    /// Clean shutdown of the named axes (every axis when none).
    PowerOff {
        /// Axis names; empty = the whole cell.
        #[serde(default)]
        axes: Vec<String>,
    },
    /// Clear a stopped or faulted cell (MC_Reset); nothing to do otherwise.
    Reset,
    /// Jerk-limited synchronised move to absolute targets.
    Move {
        /// Axis name → target in units.
        target: BTreeMap<String, f64>,
        /// Per-move velocity limit.
        velocity: Option<RawLimit>,
        /// Per-move acceleration limit.
        acceleration: Option<RawLimit>,
        /// Per-move jerk limit.
        jerk: Option<RawLimit>,
    },
    /// Straight line of axes of one unit (a gantry) to absolute targets; `velocity` is the
    /// path speed.
    Line {
        /// Axis name → target in units.
        target: BTreeMap<String, f64>,
        /// Path speed limit, unit/s.
        velocity: Option<f64>,
        /// Per-axis acceleration limit.
        acceleration: Option<RawLimit>,
        /// Per-axis jerk limit.
        jerk: Option<RawLimit>,
    },
    /// Waypoint move: through every waypoint but the last, to the last at rest.
    Path {
        /// Axis name → position, per waypoint (all name the same axes).
        waypoints: Vec<BTreeMap<String, f64>>,
        /// Per-move velocity limit.
        velocity: Option<RawLimit>,
        /// Per-move acceleration limit.
        acceleration: Option<RawLimit>,
        /// Per-move jerk limit.
        jerk: Option<RawLimit>,
    },
    /// Jog one axis at a velocity for some seconds, then halt (MC_MoveVelocity, MC_Halt).
    Jog {
        /// Axis name.
        axis: String,
        /// Velocity, unit/s (signed).
        velocity: f64,
        /// Seconds at (or ramping to) the velocity before the halt.
        seconds: f64,
    },
    /// Feed override, 0–100 % (MC_SetOverride).
    Override {
        /// Percent.
        percent: f64,
    },
    /// MC_Home: in the drive's homing mode (hm), or by a Controlword2 edge (MR-J3-T04).
    Home {
        /// Axis name.
        axis: String,
        /// 6098h method (default: the model's data-set method).
        method: Option<i8>,
        /// Home setting by Controlword2 instead: "clear" (C_CR) or "clear_z" (C_CR2).
        setting: Option<HomeSettingEdge>,
    },
    /// Run the nested steps `count` times.
    Repeat {
        /// How many times (1..=10000).
        count: u32,
        /// The steps.
        steps: Vec<RawStep>,
    },
    /// Pause.
    Wait {
        /// Seconds.
        seconds: f64,
    },
    /// Torque on cst axes: ramp to the target at the axis' torque slope, hold, ramp back to 0.
    Torque {
        /// Axis name → torque in % of rated torque.
        target: BTreeMap<String, f64>,
        /// Seconds to hold the target torque.
        seconds: f64,
    },
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawProgram {
    step: Vec<RawStep>,
}

/// A validated program step.
#[derive(Debug, Clone, PartialEq)]
pub enum Step {
    /// Enable the listed axes (indices; every axis when empty).
    PowerOn(Vec<usize>),
    /// Clean shutdown of the listed axes (indices; every axis when empty).
    PowerOff(Vec<usize>),
    /// Clear a stopped or faulted cell.
    Reset,
    /// Move the listed axes (index, target in units, limits in units).
    Move(Vec<MoveTarget>),
    /// Pause for this many seconds.
    Wait(f64),
    /// Torque on cst axes, held for `hold_s` seconds between the ramps.
    Torque {
        /// The axes and their torques.
        targets: Vec<TorqueTarget>,
        /// Seconds at the target torque.
        hold_s: f64,
    },
    /// Straight line of the listed axes (one unit) to their targets.
    Line {
        /// The axes, targets and per-axis limits.
        targets: Vec<MoveTarget>,
        /// Path speed limit, unit/s.
        path_velocity: Option<f64>,
    },
    /// Waypoint move of the listed axes through `via` (one position per axis each).
    Path {
        /// The axes, final targets and limits.
        targets: Vec<MoveTarget>,
        /// Intermediate positions.
        via: Vec<Vec<f64>>,
    },
    /// Jog for `seconds`, then halt.
    Jog {
        /// Axis index.
        axis: usize,
        /// Velocity, unit/s.
        velocity: f64,
        /// Seconds before the halt.
        seconds: f64,
    },
    /// Feed override, 0..=1.
    Override(f64),
    /// Home an axis with a procedure its drive's manual gives.
    Home {
        /// Axis index.
        axis: usize,
        /// hm with a 6098h method, or a Controlword2 edge.
        procedure: HomeProcedure,
    },
}

/// Most steps a program may expand to (repeats included).
pub const MAX_PROGRAM_STEPS: usize = 100_000;

/// Most repetitions of one `repeat` step.
pub const MAX_REPEAT: u32 = 10_000;

/// One axis of a torque step.
#[derive(Debug, Clone, PartialEq)]
pub struct TorqueTarget {
    /// Axis index in the cell (an axis in cst).
    pub axis: usize,
    /// Torque in % of rated torque, within the axis' `limits.torque`.
    pub torque: f64,
    /// The axis' torque slope, %/s.
    pub slope: f64,
}

/// One axis of a move step.
#[derive(Debug, Clone, PartialEq)]
pub struct MoveTarget {
    /// Axis index in the cell.
    pub axis: usize,
    /// Target position in units.
    pub target: f64,
    /// Limits of this move (axis limits unless the step lowers them).
    pub limits: KinematicLimits,
}

/// A validated program.
#[derive(Debug, Clone, PartialEq)]
pub struct Program {
    /// Where it was read from.
    pub source: PathBuf,
    /// The steps in order.
    pub steps: Vec<Step>,
}

impl Program {
    /// Reads a program file and validates it against `cell`.
    pub fn load(path: &Path, cell: &CellConfig) -> Result<Program, ConfigError> {
        let text = std::fs::read_to_string(path).map_err(|e| ConfigError::io(path, e))?;
        Self::parse(path, &text, cell)
    }

    /// Parses and validates program text.
    pub fn parse(path: &Path, text: &str, cell: &CellConfig) -> Result<Program, ConfigError> {
        let raw: RawProgram = crate::config::parse_toml(path, text)?;
        if raw.step.is_empty() {
            return Err(ConfigError::new(
                path,
                "step",
                "a program needs at least one [[step]]",
            ));
        }
        let mut steps = Vec::new();
        expand(path, "step", raw.step, cell, &mut steps)?;
        Ok(Program {
            source: path.to_path_buf(),
            steps,
        })
    }

    /// The last target each axis is moved to, by axis index (`None` after a jog).
    pub fn final_targets(&self, axes: usize) -> Vec<Option<f64>> {
        let mut out = vec![None; axes];
        for s in &self.steps {
            match s {
                Step::Move(targets) | Step::Line { targets, .. } | Step::Path { targets, .. } => {
                    for t in targets {
                        out[t.axis] = Some(t.target);
                    }
                }
                Step::Jog { axis, .. } => out[*axis] = None,
                _ => {}
            }
        }
        out
    }
}

/// Validates `raw` (keys `{key}[i]`) into `out`, expanding repeats.
fn expand(
    path: &Path,
    key: &str,
    raw: Vec<RawStep>,
    cell: &CellConfig,
    out: &mut Vec<Step>,
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
                out.push(validate_step(path, &k, other, cell)?);
            }
        }
    }
    Ok(())
}

fn validate_step(
    path: &Path,
    key: &str,
    step: RawStep,
    cell: &CellConfig,
) -> Result<Step, ConfigError> {
    Ok(match step {
        RawStep::Torque { target, seconds } => {
            if target.is_empty() {
                return Err(ConfigError::new(
                    path,
                    format!("{key}.target"),
                    "a torque step needs at least one axis target",
                ));
            }
            if !(seconds.is_finite() && (0.0..=MAX_WAIT_SECONDS).contains(&seconds)) {
                return Err(ConfigError::new(
                    path,
                    format!("{key}.seconds"),
                    format!(
                        "must be a number of seconds in 0..={MAX_WAIT_SECONDS} (got {seconds})"
                    ),
                ));
            }
            let mut targets = Vec::with_capacity(target.len());
            for (name, torque) in target {
                let k = format!("{key}.target.{name}");
                let axis = axis_of(path, k.clone(), &name, cell)?;
                let a = &cell.axes[axis];
                let Some(limits) = a
                    .torque
                    .filter(|_| a.mode == ModeOfOperation::CyclicSyncTorque)
                else {
                    return Err(ConfigError::new(
                        path,
                        k,
                        format!(
                            "axis '{name}' runs in {}; a torque step needs an axis with mode = \"cst\"",
                            a.mode.as_str()
                        ),
                    ));
                };
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
                    axis,
                    torque,
                    slope: limits.slope,
                });
            }
            Step::Torque {
                targets,
                hold_s: seconds,
            }
        }
        RawStep::PowerOn { axes } => Step::PowerOn(power_axes(path, key, &axes, cell)?),
        RawStep::PowerOff { axes } => Step::PowerOff(power_axes(path, key, &axes, cell)?),
        RawStep::Reset => Step::Reset,
        RawStep::Wait { seconds } => {
            if !seconds.is_finite() || !(0.0..=MAX_WAIT_SECONDS).contains(&seconds) {
                return Err(ConfigError::new(
                    path,
                    format!("{key}.seconds"),
                    format!(
                        "must be a number of seconds in 0..={MAX_WAIT_SECONDS} (got {seconds})"
                    ),
                ));
            }
            Step::Wait(seconds)
        }
        RawStep::Move {
            target,
            velocity,
            acceleration,
            jerk,
        } => Step::Move(move_targets(
            path,
            key,
            target,
            [&velocity, &acceleration, &jerk],
            cell,
        )?),
        RawStep::Line {
            target,
            velocity,
            acceleration,
            jerk,
        } => {
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
            let targets = move_targets(path, key, target, [&None, &acceleration, &jerk], cell)?;
            let unit = &cell.axes[targets[0].axis].unit;
            if let Some(t) = targets.iter().find(|t| &cell.axes[t.axis].unit != unit) {
                return Err(ConfigError::new(
                    path,
                    format!("{key}.target.{}", cell.axes[t.axis].name),
                    format!(
                        "a line needs axes of one unit: '{}' is in {}, '{}' in {unit}",
                        cell.axes[t.axis].name,
                        cell.axes[t.axis].unit,
                        cell.axes[targets[0].axis].name
                    ),
                ));
            }
            Step::Line {
                targets,
                path_velocity: velocity,
            }
        }
        RawStep::Path {
            mut waypoints,
            velocity,
            acceleration,
            jerk,
        } => {
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
            let targets = move_targets(path, key, last, [&velocity, &acceleration, &jerk], cell)?;
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
                    let a = &cell.axes[t.axis];
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
            Step::Path { targets, via }
        }
        RawStep::Jog {
            axis,
            velocity,
            seconds,
        } => {
            let i = axis_of(path, format!("{key}.axis"), &axis, cell)?;
            let limit = cell.axes[i].limits.velocity;
            if !velocity.is_finite() || velocity.abs() > limit {
                return Err(ConfigError::new(
                    path,
                    format!("{key}.velocity"),
                    format!("{velocity} is outside ±{limit}, the velocity limit of axis '{axis}'"),
                ));
            }
            if !(seconds.is_finite() && (0.0..=MAX_WAIT_SECONDS).contains(&seconds)) {
                return Err(ConfigError::new(
                    path,
                    format!("{key}.seconds"),
                    format!(
                        "must be a number of seconds in 0..={MAX_WAIT_SECONDS} (got {seconds})"
                    ),
                ));
            }
            Step::Jog {
                axis: i,
                velocity,
                seconds,
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
            let i = axis_of(path, format!("{key}.axis"), &axis, cell)?;
            let procedure =
                choose_procedure(cell.axes[i].profile, method, setting).map_err(|e| {
                    ConfigError::new(path, format!("{key}.axis"), format!("axis '{axis}': {e}"))
                })?;
            Step::Home { axis: i, procedure }
        }
        RawStep::Repeat { .. } => unreachable!("expanded by `expand`"),
    })
}

/// The index of axis `name` in `cell`, or an error at `key` naming the cell's axes.
fn axis_of(
    path: &Path,
    key: impl Into<String>,
    name: &str,
    cell: &CellConfig,
) -> Result<usize, ConfigError> {
    cell.axis_index(name).ok_or_else(|| {
        ConfigError::new(
            path,
            key,
            format!(
                "axis '{name}' is not in cell '{}' (axes: {})",
                cell.name,
                cell.axis_names()
            ),
        )
    })
}

/// The axes of a power step: indices of the named axes, each once; empty = the whole cell.
fn power_axes(
    path: &Path,
    key: &str,
    names: &[String],
    cell: &CellConfig,
) -> Result<Vec<usize>, ConfigError> {
    let mut list = Vec::with_capacity(names.len());
    for name in names {
        let i = axis_of(path, format!("{key}.axes"), name, cell)?;
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
        let a = &cell.axes[axis];
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

#[cfg(test)]
mod tests {
    use super::*;

    fn cell(axes: usize) -> CellConfig {
        let mut text = String::from("[cell]\nname = \"p\"\ncycle_time_us = 1000\n");
        for i in 0..axes {
            text.push_str(&format!(
                "[[axes]]\nname = \"a{i}\"\ndrive = \"mr-j5-g-n1\"\ncounts_per_unit = 1000\nlimits = {{ position = [0.0, 100.0], velocity = 10.0, acceleration = 100.0, jerk = 1000.0 }}\n"
            ));
        }
        CellConfig::parse(Path::new("c.toml"), &text).unwrap()
    }

    fn program(targets: usize) -> String {
        let t: Vec<String> = (0..targets).map(|i| format!("a{i} = 1.0")).collect();
        format!("[[step]]\ndo = \"move\"\ntarget = {{ {} }}\n", t.join(", "))
    }

    #[test]
    fn a_move_of_more_axes_than_the_planner_takes_is_refused_up_front() {
        let c = cell(20);
        Program::parse(Path::new("p.toml"), &program(MAX_MOVE_AXES), &c).unwrap();
        let e = Program::parse(Path::new("p.toml"), &program(MAX_MOVE_AXES + 1), &c).unwrap_err();
        assert_eq!(e.key, "step[0].target");
        assert!(e.message.contains("at most"), "{e}");
    }

    fn parse(text: &str) -> Result<Program, ConfigError> {
        Program::parse(Path::new("p.toml"), text, &cell(3))
    }

    #[test]
    fn power_steps_name_axes_or_the_whole_cell() {
        let p = parse(
            "[[step]]\ndo = \"power_on\"\naxes = [\"a2\", \"a0\"]\n[[step]]\ndo = \"power_off\"\naxes = [\"a0\"]\n[[step]]\ndo = \"power_on\"\n",
        )
        .unwrap();
        assert_eq!(
            p.steps,
            vec![
                Step::PowerOn(vec![2, 0]),
                Step::PowerOff(vec![0]),
                Step::PowerOn(vec![])
            ]
        );
        let e = parse("[[step]]\ndo = \"power_on\"\naxes = [\"q\"]\n").unwrap_err();
        assert_eq!(e.key, "step[0].axes");
        assert!(e.message.contains("axis 'q' is not in cell"), "{e}");
        let e = parse("[[step]]\ndo = \"power_off\"\naxes = [\"a1\", \"a1\"]\n").unwrap_err();
        assert!(e.message.contains("named twice"), "{e}");
        let e = parse("[[step]]\ndo = \"power_on\"\naxis = \"a1\"\n").unwrap_err();
        assert!(e.message.contains("unknown field"), "{e}");
    }

    #[test]
    fn repeat_expands_its_steps_count_times() {
        let p = parse(
            "[[step]]\ndo = \"repeat\"\ncount = 3\n[[step.steps]]\ndo = \"move\"\ntarget = { a0 = 1.0 }\n[[step.steps]]\ndo = \"override\"\npercent = 50\n[[step]]\ndo = \"power_off\"\n",
        )
        .unwrap();
        assert_eq!(p.steps.len(), 7);
        assert_eq!(p.steps[1], Step::Override(0.5));
        assert!(matches!(p.steps[4], Step::Move(_)));
        assert_eq!(p.steps[6], Step::PowerOff(vec![]));
        let e = parse("[[step]]\ndo = \"repeat\"\ncount = 0\n[[step.steps]]\ndo = \"power_on\"\n")
            .unwrap_err();
        assert_eq!(e.key, "step[0].count");
        let e = parse("[[step]]\ndo = \"repeat\"\ncount = 2\nsteps = []\n").unwrap_err();
        assert_eq!(e.key, "step[0].steps");
        let e = parse(
            "[[step]]\ndo = \"repeat\"\ncount = 2\n[[step.steps]]\ndo = \"move\"\ntarget = { q = 1.0 }\n",
        )
        .unwrap_err();
        assert_eq!(e.key, "step[0].steps[0].target.q");
        let e = parse(
            "[[step]]\ndo = \"repeat\"\ncount = 10000\n[[step.steps]]\ndo = \"repeat\"\ncount = 10000\n[[step.steps.steps]]\ndo = \"power_on\"\n",
        )
        .unwrap_err();
        assert!(e.message.contains("more than"), "{e}");
    }

    #[test]
    fn line_path_jog_and_override_steps_are_checked() {
        let p = parse(
            "[[step]]\ndo = \"line\"\ntarget = { a0 = 5.0, a1 = 6.0 }\nvelocity = 4.0\n\
             [[step]]\ndo = \"path\"\nwaypoints = [{ a0 = 1.0, a1 = 2.0 }, { a0 = 3.0, a1 = 4.0 }]\n\
             [[step]]\ndo = \"jog\"\naxis = \"a2\"\nvelocity = -5.0\nseconds = 1.0\n",
        )
        .unwrap();
        assert!(
            matches!(&p.steps[0], Step::Line { targets, path_velocity: Some(v) } if targets.len() == 2 && *v == 4.0)
        );
        assert!(
            matches!(&p.steps[1], Step::Path { targets, via } if via == &vec![vec![1.0, 2.0]] && targets[1].target == 4.0)
        );
        assert_eq!(
            p.steps[2],
            Step::Jog {
                axis: 2,
                velocity: -5.0,
                seconds: 1.0
            }
        );
        for (text, key) in [
            (
                "[[step]]\ndo = \"line\"\ntarget = { a0 = 5.0 }\n",
                "step[0].target",
            ),
            (
                "[[step]]\ndo = \"line\"\ntarget = { a0 = 5.0, a1 = 1.0 }\nvelocity = -1.0\n",
                "step[0].velocity",
            ),
            (
                "[[step]]\ndo = \"path\"\nwaypoints = [{ a0 = 1.0 }, { a0 = 3.0, a1 = 4.0 }]\n",
                "step[0].waypoints[0]",
            ),
            (
                "[[step]]\ndo = \"path\"\nwaypoints = [{ a0 = 101.0 }, { a0 = 3.0 }]\n",
                "step[0].waypoints[0].a0",
            ),
            (
                "[[step]]\ndo = \"path\"\nwaypoints = []\n",
                "step[0].waypoints",
            ),
            (
                "[[step]]\ndo = \"jog\"\naxis = \"a0\"\nvelocity = 11.0\nseconds = 1.0\n",
                "step[0].velocity",
            ),
            (
                "[[step]]\ndo = \"jog\"\naxis = \"zz\"\nvelocity = 1.0\nseconds = 1.0\n",
                "step[0].axis",
            ),
            (
                "[[step]]\ndo = \"override\"\npercent = 101\n",
                "step[0].percent",
            ),
        ] {
            let e = parse(text).unwrap_err();
            assert_eq!(e.key, key, "{text}: {e}");
        }
    }

    #[test]
    fn per_move_limits_may_lower_but_never_raise_the_axis_limit() {
        let c = cell(2);
        let ok = "[[step]]\ndo = \"move\"\ntarget = { a0 = 5.0 }\nvelocity = 5.0\n";
        let p = Program::parse(Path::new("p.toml"), ok, &c).unwrap();
        let Step::Move(t) = &p.steps[0] else { panic!() };
        assert_eq!(t[0].limits.velocity, 5.0);
        let bad = "[[step]]\ndo = \"move\"\ntarget = { a0 = 5.0 }\nvelocity = { a0 = 50.0 }\n";
        let e = Program::parse(Path::new("p.toml"), bad, &c).unwrap_err();
        assert_eq!(e.key, "step[0].velocity");
        let stray = "[[step]]\ndo = \"move\"\ntarget = { a0 = 5.0 }\njerk = { a1 = 5.0 }\n";
        let e = Program::parse(Path::new("p.toml"), stray, &c).unwrap_err();
        assert_eq!(e.key, "step[0].jerk.a1");
    }
}
