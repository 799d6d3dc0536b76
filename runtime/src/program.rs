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
    /// Enable every axis.
    PowerOn,
    /// Clean shutdown of every axis.
    PowerOff,
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
    /// Enable every axis.
    PowerOn,
    /// Clean shutdown of every axis.
    PowerOff,
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
}

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
        let steps = raw
            .step
            .into_iter()
            .enumerate()
            .map(|(i, s)| validate_step(path, &format!("step[{i}]"), s, cell))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Program {
            source: path.to_path_buf(),
            steps,
        })
    }

    /// The last target each axis is moved to, by axis index.
    pub fn final_targets(&self, axes: usize) -> Vec<Option<f64>> {
        let mut out = vec![None; axes];
        for s in &self.steps {
            if let Step::Move(targets) = s {
                for t in targets {
                    out[t.axis] = Some(t.target);
                }
            }
        }
        out
    }
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
                let Some(axis) = cell.axis_index(&name) else {
                    return Err(ConfigError::new(
                        path,
                        k,
                        format!(
                            "axis '{name}' is not in cell '{}' (axes: {})",
                            cell.name,
                            cell.axis_names()
                        ),
                    ));
                };
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
        RawStep::PowerOn => Step::PowerOn,
        RawStep::PowerOff => Step::PowerOff,
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
        } => {
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
                let Some(axis) = cell.axis_index(&name) else {
                    return Err(ConfigError::new(
                        path,
                        format!("{key}.target.{name}"),
                        format!(
                            "axis '{name}' is not in cell '{}' (axes: {})",
                            cell.name,
                            cell.axis_names()
                        ),
                    ));
                };
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
                    velocity: pick(&velocity, a.limits.velocity, "velocity")?,
                    acceleration: pick(&acceleration, a.limits.acceleration, "acceleration")?,
                    jerk: pick(&jerk, a.limits.jerk, "jerk")?,
                };
                out.push(MoveTarget {
                    axis,
                    target: pos,
                    limits,
                });
            }
            Step::Move(out)
        }
    })
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
