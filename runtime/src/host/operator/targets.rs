//! The axes, targets and limits an operator request names, checked against the cell.

use cellrt_trajectory::KinematicLimits;

use crate::config::{AxisConfig, CellConfig};

/// The limits a move-like request asks for (each axis' own limit where absent).
#[derive(Clone, Copy)]
pub(super) struct Asked {
    pub(super) velocity: Option<f64>,
    pub(super) acceleration: Option<f64>,
    pub(super) jerk: Option<f64>,
    /// Lower a limit above an axis limit to it instead of refusing.
    pub(super) clamp: bool,
}

/// Why the axes, targets or limits a request names do not fit the cell.
#[derive(Debug, thiserror::Error)]
pub enum TargetError {
    /// No axis of that name.
    #[error("unknown axis '{name}' (the cell has {axes})")]
    UnknownAxis {
        /// The name asked for.
        name: String,
        /// The cell's axis names, comma-separated.
        axes: String,
    },
    /// A target that is NaN or infinite.
    #[error("axis '{axis}': target {value} is not a finite number")]
    NotFinite {
        /// Axis name.
        axis: String,
        /// The target.
        value: f64,
    },
    /// A requested velocity, acceleration or jerk that is not a positive number.
    #[error("axis '{axis}': {what} {value} must be a finite number > 0")]
    BadLimit {
        /// Axis name.
        axis: String,
        /// "velocity", "acceleration" or "jerk".
        what: &'static str,
        /// The requested value.
        value: f64,
    },
    /// A requested limit above the axis limit, without `clamp`.
    #[error("axis '{axis}': {what} {value} {unit}{per} exceeds the axis limit {limit} {unit}{per} (add --clamp to use the limit)")]
    AboveLimit {
        /// Axis name.
        axis: String,
        /// "velocity", "acceleration" or "jerk".
        what: &'static str,
        /// The requested value.
        value: f64,
        /// The axis' unit.
        unit: String,
        /// "/s", "/s²" or "/s³".
        per: &'static str,
        /// The axis limit.
        limit: f64,
    },
}

/// The index of the axis `name`, or the cell's axis names.
pub(super) fn axis_index(cell: &CellConfig, name: &str) -> Result<usize, TargetError> {
    cell.axes
        .iter()
        .position(|a| a.name == name)
        .ok_or_else(|| {
            let names: Vec<&str> = cell.axes.iter().map(|a| a.name.as_str()).collect();
            TargetError::UnknownAxis {
                name: name.to_string(),
                axes: names.join(", "),
            }
        })
}

/// Per-move limits: the axis limits, lowered where the request asks; a request above the axis
/// limit is refused unless `clamp`.
pub(super) fn move_limits(a: &AxisConfig, asked: Asked) -> Result<KinematicLimits, TargetError> {
    let Asked {
        velocity,
        acceleration,
        jerk,
        clamp,
    } = asked;
    let pick = |what: &'static str, per: &'static str, req: Option<f64>, limit: f64| match req {
        None => Ok(limit),
        Some(v) if !(v.is_finite() && v > 0.0) => Err(TargetError::BadLimit {
            axis: a.name.clone(),
            what,
            value: v,
        }),
        Some(v) if v > limit && !clamp => Err(TargetError::AboveLimit {
            axis: a.name.clone(),
            what,
            value: v,
            unit: a.unit.clone(),
            per,
            limit,
        }),
        Some(v) => Ok(v.min(limit)),
    };
    Ok(KinematicLimits {
        velocity: pick("velocity", "/s", velocity, a.limits.velocity)?,
        acceleration: pick("acceleration", "/s²", acceleration, a.limits.acceleration)?,
        jerk: pick("jerk", "/s³", jerk, a.limits.jerk)?,
    })
}
