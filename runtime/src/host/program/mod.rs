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
//! `do = "mode"`, `axis = "y"`, `mode = "pp"` (or `"csp"`): switches a csp axis to pp at
//! standstill (later `move` steps send its drive set-points) and back.
//!
//! `do = "torque"`, `target = { z = 30.0 }` (% of rated torque), `seconds = 0.5`: on axes in
//! cst, ramps to the torque at `limits.torque_slope`, holds it, ramps back to zero; an axis left
//! moving then brakes in csv with its controlled-stop ramp.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use cellrt_trajectory::limits::KinematicLimits;
use serde::Deserialize;

use cellrt_cia402::homing::{HomeProcedure, HomeSettingEdge};

use cellrt_config::{AxisRef, CellConfig, ConfigError};

mod je_c;
mod validate;
use validate::expand;

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
    /// Switch a csp axis to pp or back at standstill (the drive's mode-switch rules).
    Mode {
        /// Axis name.
        axis: String,
        /// "pp" or "csp".
        mode: String,
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
    /// Enable the listed axes, whichever backend runs them (every axis when empty).
    PowerOn(Vec<AxisRef>),
    /// Clean shutdown of the listed axes, whichever backend runs them (every axis when empty).
    PowerOff(Vec<AxisRef>),
    /// Clear a stopped or faulted cell.
    Reset,
    /// Move the listed axes together, each as its backend carries a move out; the step ends
    /// when all are done.
    Move(Vec<AxisMove>),
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
        /// The axis.
        axis: AxisRef,
        /// Velocity, unit/s.
        velocity: f64,
        /// Seconds before the halt.
        seconds: f64,
    },
    /// Feed override, 0..=1.
    Override(f64),
    /// Switch axis `axis` (a csp axis whose drive runs pp) to `mode`.
    Mode {
        /// Axis index.
        axis: usize,
        /// The mode it switches to.
        mode: crate::handoff::SwitchableMode,
    },
    /// Home an axis with a procedure its drive's manual gives.
    Home {
        /// The axis.
        axis: AxisRef,
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
    /// The axis: in cst or tq on the RT loop, or an MR-JE-C axis in tq.
    pub axis: AxisRef,
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

/// One axis of a move step, as its backend carries the move out.
#[derive(Debug, Clone, PartialEq)]
pub enum AxisMove {
    /// An axis of the RT loop: the motion is planned (jerk-limited) and streamed, or handed to
    /// its drive's pp as set-points.
    Planned(MoveTarget),
    /// An MR-JE-C axis: its drive's own profile moves it over the link.
    Drive(DriveMove),
}

impl AxisMove {
    /// The axis.
    pub fn axis(&self) -> AxisRef {
        match self {
            AxisMove::Planned(t) => AxisRef::Loop(t.axis),
            AxisMove::Drive(t) => AxisRef::Link(t.axis),
        }
    }

    /// The position the axis ends at, units.
    pub fn target(&self) -> f64 {
        match self {
            AxisMove::Planned(t) => t.target,
            AxisMove::Drive(t) => t.target(),
        }
    }
}

/// One MR-JE-C axis of a move step (a pp, pt or idx move of its drive).
#[derive(Debug, Clone, PartialEq)]
pub struct DriveMove {
    /// Link in the cell's `CellAxes::on_link`.
    pub axis: usize,
    /// Where it goes: a position, a point table or a station.
    pub goal: cellrt_config::je_c_positioning::JecMoveTarget,
    /// Profile velocity, unit/s.
    pub velocity: f64,
    /// Acceleration and deceleration, unit/s².
    pub acceleration: f64,
}

impl DriveMove {
    /// The position the axis ends at, units.
    pub fn target(&self) -> f64 {
        self.goal.end_position()
    }
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
        let text =
            cellrt_config::input_file::read_text(path).map_err(|e| ConfigError::io(path, e))?;
        Self::parse(path, &text, cell)
    }

    /// Parses and validates program text.
    pub fn parse(path: &Path, text: &str, cell: &CellConfig) -> Result<Program, ConfigError> {
        let raw: RawProgram = cellrt_config::parse_toml(path, text)?;
        if raw.step.is_empty() {
            return Err(ConfigError::new(
                path,
                "step",
                "a program needs at least one [[step]]",
            ));
        }
        let mut steps = Vec::new();
        expand(path, "step", raw.step, cell, &mut steps)?;
        validate::check_profile_modes(path, &steps, cell)?;
        let steps = steps.into_iter().map(|(_, step)| step).collect();
        Ok(Program {
            source: path.to_path_buf(),
            steps,
        })
    }

    /// The last target axis `axis` is moved to (`None` when it is never moved, or when a jog,
    /// a homing or a torque step comes after its last move).
    pub fn final_target(&self, axis: AxisRef) -> Option<f64> {
        let mut out = None;
        for s in &self.steps {
            match s {
                Step::Move(targets) => {
                    if let Some(t) = targets.iter().find(|t| t.axis() == axis) {
                        out = Some(t.target());
                    }
                }
                Step::Line { targets, .. } | Step::Path { targets, .. } => {
                    if let Some(t) = targets.iter().find(|t| AxisRef::Loop(t.axis) == axis) {
                        out = Some(t.target);
                    }
                }
                Step::Jog { axis: a, .. } if *a == axis => out = None,
                Step::Home { axis: a, .. } if *a == axis && matches!(axis, AxisRef::Link(_)) => {
                    out = None
                }
                Step::Torque { targets, .. }
                    if matches!(axis, AxisRef::Link(_))
                        && targets.iter().any(|t| t.axis == axis) =>
                {
                    out = None
                }
                _ => {}
            }
        }
        out
    }
}

#[cfg(test)]
mod tests;
