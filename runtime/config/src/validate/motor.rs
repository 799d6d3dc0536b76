//! `[axes.motor]`: the motor's resolution and the drive's velocity unit, and the load-time
//! check that the axis' limits fit the drive's objects (nothing is clamped at run time).

use cellrt_cia402::drive_scaling::{DriveScaling, DriveScalingError, Motor};
use cellrt_cia402::mode::ModeOfOperation;
use cellrt_cia402::profiles::{MotorKind, Stated, VelocityUnit};
use cellrt_cia402::DriveProfile;

use super::axis_key::AxisKey;
use crate::plausible::{COUNTS_PER_MM, COUNTS_PER_REV, MOTOR_SPEED, REVS_PER_UNIT};
use crate::raw::RawAxis;
use crate::ConfigError;

/// What the velocity check needs of the already validated axis keys.
pub(super) struct VelocityDemand {
    /// The cyclic mode (csv and cst add the master's position correction to 60FFh).
    pub mode: ModeOfOperation,
    /// `limits.velocity` in counts/s.
    pub velocity_counts: f64,
    /// The largest position correction (gain × following-error limit) in counts/s.
    pub correction_counts: f64,
}

/// The axis' drive scaling from `[axes.motor]` and the model's units; refuses a missing
/// resolution, a velocity unit the manual fixes otherwise, and a velocity limit the drive's
/// I32 velocity objects (or the motor's `max_speed`) cannot carry.
pub(super) fn drive_units(
    at: &AxisKey<'_>,
    a: &RawAxis,
    profile: &DriveProfile,
    demand: VelocityDemand,
) -> Result<DriveScaling, ConfigError> {
    let m = &a.motor;
    let motor = match (m.counts_per_rev, m.counts_per_mm) {
        (Some(_), Some(_)) => {
            return Err(at.err(
                "motor.counts_per_mm",
                "give counts_per_rev (rotary) or counts_per_mm (linear), not both".into(),
            ))
        }
        (Some(c), None) => Some(Motor {
            kind: MotorKind::Rotary,
            counts_per: at.plausible("motor.counts_per_rev", &COUNTS_PER_REV, c)?,
        }),
        (None, Some(c)) if profile.units.linear_motors => Some(Motor {
            kind: MotorKind::Linear,
            counts_per: at.plausible("motor.counts_per_mm", &COUNTS_PER_MM, c)?,
        }),
        (None, Some(_)) => {
            return Err(at.err(
                "motor.counts_per_mm",
                format!(
                    "the {} manual states rotary motors only (r/min)",
                    profile.model
                ),
            ))
        }
        (None, None) => None,
    };
    if let Some(m) = &motor {
        // Checked positive and finite before.
        at.plausible(
            "counts_per_unit",
            &REVS_PER_UNIT,
            a.counts_per_unit / m.counts_per,
        )?;
    }
    let velocity = velocity_unit(at, a, profile)?;
    let scaling = DriveScaling::new(&profile.units, velocity, motor).map_err(|e| match e {
        DriveScalingError::MissingResolution { .. } => at.err(
            "motor.counts_per_rev",
            format!("axis '{}' ({}): {e}", a.name, profile.model),
        ),
        DriveScalingError::InvalidResolution(_) => at.err("motor", e.to_string()),
    })?;
    check_velocity(at, a, &scaling, demand)?;
    Ok(scaling)
}

/// `motor.velocity_unit`: allowed only where the manual leaves the unit open.
fn velocity_unit(
    at: &AxisKey<'_>,
    a: &RawAxis,
    profile: &DriveProfile,
) -> Result<VelocityUnit, ConfigError> {
    let Some(text) = &a.motor.velocity_unit else {
        return Ok(profile.units.velocity.value());
    };
    let Some(unit) = VelocityUnit::parse(text) else {
        return Err(at.err(
            "motor.velocity_unit",
            format!("{text:?} is not a velocity unit (e.g. \"0.01 r/min\", \"0.001 mm/s\", \"counts/s\")"),
        ));
    };
    match profile.units.velocity {
        Stated::Manual(fixed) if fixed != unit => Err(at.err(
            "motor.velocity_unit",
            format!(
                "the {} manual fixes the velocity objects at {} ({})",
                profile.model,
                fixed.name(MotorKind::Rotary),
                profile.units.source
            ),
        )),
        _ => Ok(unit),
    }
}

/// `limits.velocity` (plus the csv position correction) must fit 60FFh (I32) in the drive's
/// unit and stay within `motor.max_speed` (or, without one, the fastest a real motor can be).
fn check_velocity(
    at: &AxisKey<'_>,
    a: &RawAxis,
    scaling: &DriveScaling,
    demand: VelocityDemand,
) -> Result<(), ConfigError> {
    let corrected = matches!(
        demand.mode,
        ModeOfOperation::CyclicSyncVelocity | ModeOfOperation::CyclicSyncTorque
    );
    let peak = demand.velocity_counts
        + if corrected {
            demand.correction_counts
        } else {
            0.0
        };
    let unit = |s: &DriveScaling| {
        s.velocity_unit()
            .name(s.motor().map_or(MotorKind::Rotary, |m| m.kind))
    };
    if let Err(e) = scaling.velocity_to_drive(peak) {
        return Err(at.err(
            "limits.velocity",
            format!(
                "{} {}/s{} is {} LSB of {}, beyond the I32 range of the drive's velocity objects",
                a.limits.velocity,
                a.unit,
                if corrected {
                    " plus the csv position correction"
                } else {
                    ""
                },
                e.value,
                unit(scaling)
            ),
        ));
    }
    let max = match a.motor.max_speed {
        Some(max) => Some(at.plausible("motor.max_speed", &MOTOR_SPEED, max)?),
        None => None,
    };
    let speed = scaling.motor_speed(demand.velocity_counts);
    let (speed, max, bound) = match (speed, max) {
        (None, Some(_)) => {
            return Err(at.err(
                "motor.max_speed",
                "needs the motor's resolution (motor.counts_per_rev or counts_per_mm)".into(),
            ))
        }
        (None, None) => return Ok(()),
        (Some(speed), Some(max)) => (speed, max, format!("motor.max_speed = {max}")),
        (Some(speed), None) => (
            speed,
            MOTOR_SPEED.max,
            format!("{}, the fastest a real motor can be", MOTOR_SPEED.max),
        ),
    };
    if speed > max {
        let kind = scaling.motor().map_or(MotorKind::Rotary, |m| m.kind);
        return Err(at.err(
            "limits.velocity",
            format!(
                "{} {}/s is {speed:.3} {} at the motor, above {bound}",
                a.limits.velocity,
                a.unit,
                kind.speed_unit()
            ),
        ));
    }
    Ok(())
}
