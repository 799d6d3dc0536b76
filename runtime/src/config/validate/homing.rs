//! `[axes.homing]` and the switches of `[axes.sim]` (`home_dog`, `positive_limit`,
//! `negative_limit`): checked against the model's manual (`profiles::homing_methods`) and
//! converted to counts and the drive's units.

use cellrt_axes::drive_scaling::DriveScaling;
use cellrt_axes::profiles::homing_methods::{check_emulated, homing_model};
use cellrt_axes::sim::homing_switches::HomingSwitches;
use cellrt_axes::DriveProfile;
use cellrt_trajectory::units::Scaling;

use super::axis_key::AxisKey;
use crate::config::homing::{AxisHoming, HomingObjects};
use crate::config::raw::RawAxis;
use crate::config::ConfigError;

/// 6099h Homing speeds.
const HOMING_SPEEDS: u16 = 0x6099;
/// 609Ah Homing acceleration.
const HOMING_ACCELERATION: u16 = 0x609A;

/// `sim.home_dog`, `sim.positive_limit`, `sim.negative_limit` in counts: finite, the dog's ends
/// in order, the negative limit below the positive one.
pub(super) fn switches(
    at: &AxisKey<'_>,
    a: &RawAxis,
    scaling: Scaling,
) -> Result<HomingSwitches, ConfigError> {
    let counts = |key: &str, v: f64| {
        if !v.is_finite() {
            return Err(at.err(key, format!("{v} is not a position")));
        }
        scaling
            .to_counts_i32(v)
            .map(f64::from)
            .map_err(|e| at.err(key, e.to_string()))
    };
    let home_dog = match a.sim.home_dog {
        Some([from, to]) => {
            let (f, t) = (counts("sim.home_dog", from)?, counts("sim.home_dog", to)?);
            if f >= t {
                return Err(at.err(
                    "sim.home_dog",
                    format!("[from, to] must rise (got [{from}, {to}])"),
                ));
            }
            Some([f, t])
        }
        None => None,
    };
    let positive_limit = a
        .sim
        .positive_limit
        .map(|v| counts("sim.positive_limit", v))
        .transpose()?;
    let negative_limit = a
        .sim
        .negative_limit
        .map(|v| counts("sim.negative_limit", v))
        .transpose()?;
    if let (Some(p), Some(n)) = (positive_limit, negative_limit) {
        if n >= p {
            return Err(at.err(
                "sim.negative_limit",
                "must lie below sim.positive_limit".to_string(),
            ));
        }
    }
    Ok(HomingSwitches {
        home_dog,
        positive_limit,
        negative_limit,
    })
}

/// `[axes.homing]`: `method` listed by the model's manual and emulated; `switch_speed` and
/// `creep_speed` (unit/s, at most `limits.velocity`) in the drive's velocity unit;
/// `acceleration_ms` (609Ah, ms); `shift` (unit, ≥ 0) only where the model has the object.
pub(super) fn homing(
    at: &AxisKey<'_>,
    a: &RawAxis,
    profile: &'static DriveProfile,
    scaling: Scaling,
    drive_units: &DriveScaling,
) -> Result<AxisHoming, ConfigError> {
    let Some(h) = &a.homing else {
        return Ok(AxisHoming::default());
    };
    if let Some(m) = h.method {
        check_emulated(profile, m)
            .map_err(|e| at.err("homing.method", format!("axis '{}': {e}", a.name)))?;
    }
    let mut objects = HomingObjects::default();
    for (key, sub, v) in [
        ("homing.switch_speed", 1, h.switch_speed),
        ("homing.creep_speed", 2, h.creep_speed),
    ] {
        let Some(v) = v else { continue };
        let v = at.positive(key, v)?;
        if v > a.limits.velocity {
            return Err(at.err(
                key,
                format!("{v} exceeds limits.velocity {}", a.limits.velocity),
            ));
        }
        let raw = drive_units
            .velocity_to_drive(v * scaling.counts_per_unit())
            .ok()
            .and_then(|r| u32::try_from(r).ok())
            .ok_or_else(|| at.err(key, format!("{v} does not fit 6099h:{sub}")))?;
        objects.push(HOMING_SPEEDS, sub, raw);
    }
    if let Some(ms) = h.acceleration_ms {
        objects.push(HOMING_ACCELERATION, 0, ms);
    }
    if let Some(shift) = h.shift {
        let Some(index) = homing_model(profile.model).shift_object else {
            return Err(at.err(
                "homing.shift",
                format!(
                    "the {} manual names the home position shift distance but gives no object for it",
                    profile.name
                ),
            ));
        };
        let counts = scaling.to_counts(shift);
        if !(counts.is_finite() && counts >= 0.0 && counts <= f64::from(u32::MAX)) {
            return Err(at.err(
                "homing.shift",
                format!("{shift} is not a shift distance (≥ 0, {index:04X}h is U32 pulses)"),
            ));
        }
        objects.push(index, 0, counts.round() as u32);
    }
    Ok(AxisHoming {
        method: h.method,
        objects,
    })
}
