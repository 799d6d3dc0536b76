//! The axes, targets and limits an operator request names, checked against the cell.

use cellrt_trajectory::KinematicLimits;

use cellrt_config::{AxisConfig, CellConfig};

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
    /// A requested limit too small for the planner: below [`MIN_LIMIT_FRACTION`] of the axis
    /// limit.
    #[error("axis '{axis}': {what} {value} {unit}{per} is too small to plan with (at least {min} {unit}{per}, a millionth of the axis limit)")]
    BelowPlannable {
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
        /// The smallest value taken.
        min: f64,
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

/// The smallest per-move limit taken, as a fraction of the axis limit: below it the planner's
/// arithmetic degenerates (a velocity of 1e-300 unit/s is not a move).
pub const MIN_LIMIT_FRACTION: f64 = 1e-6;

/// The index of the axis `name`, or the cell's axis names.
pub(super) fn axis_index(cell: &CellConfig, name: &str) -> Result<usize, TargetError> {
    cell.axes
        .on_loop()
        .iter()
        .position(|a| a.name == name)
        .ok_or_else(|| {
            let names: Vec<&str> = cell
                .axes
                .on_loop()
                .iter()
                .map(|a| a.name.as_str())
                .collect();
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
        Some(v) if v < limit * MIN_LIMIT_FRACTION => Err(TargetError::BelowPlannable {
            axis: a.name.clone(),
            what,
            value: v,
            unit: a.unit.clone(),
            per,
            min: limit * MIN_LIMIT_FRACTION,
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

#[cfg(test)]
mod tests {
    use super::*;

    fn x_axis() -> AxisConfig {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs/demo.toml");
        let text = std::fs::read_to_string(&path).unwrap();
        CellConfig::parse(&path, &text).unwrap().axes.on_loop()[0].clone()
    }

    fn asked(velocity: Option<f64>, jerk: Option<f64>) -> Asked {
        Asked {
            velocity,
            acceleration: None,
            jerk,
            clamp: false,
        }
    }

    #[test]
    fn limits_the_planner_cannot_use_are_refused_by_name() {
        let x = x_axis(); // velocity 400 mm/s, jerk 20000 mm/s³
        for (a, what) in [
            (asked(Some(1e-300), None), "velocity"),
            (asked(Some(5e-324), None), "velocity"),
            (asked(None, Some(1e-300)), "jerk"),
        ] {
            let e = move_limits(&x, a).unwrap_err();
            assert!(
                matches!(e, TargetError::BelowPlannable { what: w, .. } if w == what),
                "{e}"
            );
            assert!(e.to_string().contains("too small to plan"), "{e}");
        }
        for v in [f64::NAN, f64::INFINITY, 0.0, -1.0] {
            assert!(matches!(
                move_limits(&x, asked(Some(v), None)),
                Err(TargetError::BadLimit { .. })
            ));
        }
        // A millionth of the axis limit is still taken.
        let ok = move_limits(&x, asked(Some(400.0e-6), None)).unwrap();
        assert_eq!(ok.velocity, 400.0e-6);
    }
}
