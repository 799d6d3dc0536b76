//! The axes, targets and limits an operator request names, checked against the cell.

use cellrt_trajectory::limits::MIN_LIMIT_FRACTION;
use cellrt_trajectory::KinematicLimits;

use cellrt_config::{AxisConfig, AxisRef, Backend, CellConfig};

/// The limits a move-like request asks for (each axis' own limit where absent).
#[derive(Clone, Copy)]
pub(crate) struct Asked {
    pub(crate) velocity: Option<f64>,
    pub(crate) acceleration: Option<f64>,
    pub(crate) jerk: Option<f64>,
    /// Lower a limit above an axis limit to it instead of refusing.
    pub(crate) clamp: bool,
}

/// Why the axes, targets or limits a request names do not fit the cell.
#[derive(Debug, thiserror::Error)]
pub enum TargetError {
    /// No axis of that name.
    #[error("unknown axis '{}' (the cell has {axes})", cellrt_config::echo::Echo(.name))]
    UnknownAxis {
        /// The name asked for.
        name: String,
        /// The cell's axis names, comma-separated.
        axes: String,
    },
    /// A request the RT loop carries out, on an axis another backend runs.
    #[error("axis '{axis}' is not on the RT loop ({}): this request is for the loop's axes", backend.as_str())]
    NotOnLoop {
        /// Axis name.
        axis: String,
        /// The backend that runs it.
        backend: Backend,
    },
    /// A request only streamed setpoints carry out (a line, a path) on an axis its drive's own
    /// profile moves.
    #[error("axis '{axis}' is moved by its drive's own profile ({}): {what} needs streamed axes", backend.as_str())]
    NotStreamed {
        /// Axis name.
        axis: String,
        /// The backend that runs it.
        backend: Backend,
        /// What needs streamed axes ("a line").
        what: &'static str,
    },
    /// An axis a request names twice.
    #[error("axis '{axis}' named twice")]
    Twice {
        /// Axis name.
        axis: String,
    },
    /// A jog velocity that is NaN or infinite.
    #[error("axis '{axis}': velocity {velocity} is not a finite number")]
    VelocityNotFinite {
        /// Axis name.
        axis: String,
        /// The velocity asked.
        velocity: f64,
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
    #[error("axis '{axis}': {what} {value:?} must be a finite number > 0")]
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
    #[error("axis '{axis}': {what} {value:?} {unit}{per} is too small to plan with (at least {min:.3e} {unit}{per}, a millionth of the axis limit)")]
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
    /// A move its limits would make take longer than
    /// [`cellrt_trajectory::limits::MAX_MOTION_S`] (refused before anything moves).
    #[error("{what}: {source}")]
    TooLong {
        /// What travels: "axis 'x' (mm)", "the line (mm)".
        what: String,
        /// The travel and the limit that make it too long.
        source: cellrt_trajectory::LimitsError,
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

/// Refuses a travel of `distance` within `limits` that would take longer than a motion may
/// ([`KinematicLimits::check_travel`]), naming `what` travels ("axis 'x' (mm)").
pub(crate) fn check_travel(
    what: impl FnOnce() -> String,
    distance: f64,
    limits: &KinematicLimits,
) -> Result<(), TargetError> {
    limits
        .check_travel(distance)
        .map_err(|source| TargetError::TooLong {
            what: what(),
            source,
        })
}

/// The axis `name`, whichever backend runs it, or the cell's axis names.
pub(crate) fn axis_ref(cell: &CellConfig, name: &str) -> Result<AxisRef, TargetError> {
    cell.axis_ref(name).ok_or_else(|| TargetError::UnknownAxis {
        name: name.to_string(),
        axes: cell.axes.names(),
    })
}

/// The RT-loop slot of the axis `name`, for a request the RT loop carries out (`what`); an
/// axis another backend runs is refused naming it.
pub(crate) fn axis_index(cell: &CellConfig, name: &str) -> Result<usize, TargetError> {
    let at = axis_ref(cell, name)?;
    at.loop_slot().ok_or_else(|| TargetError::NotOnLoop {
        axis: name.to_string(),
        backend: cell.axes.get(at).backend(),
    })
}

/// A limit a request asks for (`asked`), within the axis' own (`limit`): refused when not a
/// positive number, too small to plan with, or above the limit unless `clamp`. One rule for
/// every backend.
pub(crate) fn pick_limit(
    axis: &str,
    unit: &str,
    (what, per): (&'static str, &'static str),
    asked: Option<f64>,
    limit: f64,
    clamp: bool,
) -> Result<f64, TargetError> {
    match asked {
        None => Ok(limit),
        Some(v) if !(v.is_finite() && v > 0.0) => Err(TargetError::BadLimit {
            axis: axis.to_string(),
            what,
            value: v,
        }),
        Some(v) if v < limit * MIN_LIMIT_FRACTION => Err(TargetError::BelowPlannable {
            axis: axis.to_string(),
            what,
            value: v,
            unit: unit.to_string(),
            per,
            min: limit * MIN_LIMIT_FRACTION,
        }),
        Some(v) if v > limit && !clamp => Err(TargetError::AboveLimit {
            axis: axis.to_string(),
            what,
            value: v,
            unit: unit.to_string(),
            per,
            limit,
        }),
        Some(v) => Ok(v.min(limit)),
    }
}

/// A jog's signed velocity within ±`limit`: refused when not finite, or outside unless
/// `clamp` (then lowered to it). One rule for every backend.
pub(crate) fn jog_velocity(
    axis: &str,
    unit: &str,
    velocity: f64,
    limit: f64,
    clamp: bool,
) -> Result<f64, TargetError> {
    if !velocity.is_finite() {
        return Err(TargetError::VelocityNotFinite {
            axis: axis.to_string(),
            velocity,
        });
    }
    if velocity.abs() > limit && !clamp {
        return Err(TargetError::AboveLimit {
            axis: axis.to_string(),
            what: "velocity",
            value: velocity.abs(),
            unit: unit.to_string(),
            per: "/s",
            limit,
        });
    }
    Ok(velocity.clamp(-limit, limit))
}

/// Per-move limits: the axis limits, lowered where the request asks; a request above the axis
/// limit is refused unless `clamp`.
pub(crate) fn move_limits(a: &AxisConfig, asked: Asked) -> Result<KinematicLimits, TargetError> {
    let Asked {
        velocity,
        acceleration,
        jerk,
        clamp,
    } = asked;
    let pick = |what, req, limit| pick_limit(&a.name, &a.unit, what, req, limit, clamp);
    Ok(KinematicLimits {
        velocity: pick(("velocity", "/s"), velocity, a.limits.velocity)?,
        acceleration: pick(("acceleration", "/s²"), acceleration, a.limits.acceleration)?,
        jerk: pick(("jerk", "/s³"), jerk, a.limits.jerk)?,
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
