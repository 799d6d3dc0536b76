//! `[axes.homing]` and the switches of `[axes.sim]` (`home_dog`, `positive_limit`,
//! `negative_limit`) with the simulated drive's `travel_after_dog`: checked against the
//! model's manual (`profiles::homing_methods`) and converted to counts and the drive's units.

use cellrt_cia402::drive_scaling::DriveScaling;
use cellrt_cia402::homing::choose_method;
use cellrt_cia402::profiles::homing_methods::{check_emulated, homing_model};
use cellrt_cia402::DriveProfile;
use cellrt_emulator::sim::homing_switches::HomingSwitches;
use cellrt_trajectory::units::Scaling;

use super::axis_key::AxisKey;
use crate::homing::{AxisHoming, HomingObjects, DEFAULT_HOMING_TIMEOUT, MAX_HOMING_TIMEOUT_S};
use crate::raw::RawAxis;
use crate::ConfigError;

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

/// `sim.travel_after_dog` (unit, ≥ 0) in counts: the simulated drive's "travel distance after
/// proximity dog" (MR-J4-TM manual §5.4.9(4); `cellrt_emulator::HomingParams`), 0 when absent.
pub(super) fn travel_after_dog(
    at: &AxisKey<'_>,
    a: &RawAxis,
    scaling: Scaling,
) -> Result<u32, ConfigError> {
    let Some(v) = a.sim.travel_after_dog else {
        return Ok(0);
    };
    // A length: its counts whichever way the axis counts.
    let counts = scaling.to_counts(v).abs();
    if !(v >= 0.0 && counts.is_finite() && counts <= f64::from(u32::MAX)) {
        return Err(at.err(
            "sim.travel_after_dog",
            format!(
                "{v} is not a travel distance (≥ 0, at most {} counts)",
                u32::MAX
            ),
        ));
    }
    Ok(counts.round() as u32)
}

/// `[axes.homing]`: `method` listed by the model's manual and emulated; `switch_speed` and
/// `creep_speed` (unit/s, at most `limits.velocity`) in the drive's velocity unit;
/// `acceleration_ms` (609Ah, ms); `shift` (unit, ≥ 0) only where the model has the object;
/// `timeout_s`.
pub(super) fn homing(
    at: &AxisKey<'_>,
    a: &RawAxis,
    profile: &DriveProfile,
    scaling: Scaling,
    drive_units: &DriveScaling,
) -> Result<AxisHoming, ConfigError> {
    let Some(h) = &a.homing else {
        return Ok(AxisHoming::default());
    };
    if let Some(m) = h.method {
        check_emulated(profile, m)
            .and_then(|()| choose_method(profile, Some(m)).map(|_| ()))
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
    let timeout = match h.timeout_s {
        None => DEFAULT_HOMING_TIMEOUT,
        Some(t) if t.is_finite() && t > 0.0 && t <= MAX_HOMING_TIMEOUT_S => {
            std::time::Duration::from_secs_f64(t)
        }
        Some(t) => {
            return Err(at.err(
                "homing.timeout_s",
                format!("{t} is not a homing time (s, 0 < t ≤ {MAX_HOMING_TIMEOUT_S})"),
            ))
        }
    };
    Ok(AxisHoming {
        method: h.method,
        objects,
        timeout,
    })
}

#[cfg(test)]
mod tests {
    use crate::{CellConfig, ConfigError};
    use std::path::Path;

    fn parse(drive: &str, extra: &str) -> Result<CellConfig, ConfigError> {
        let motor = if drive == "mr-j4-tm" {
            "motor = { rated_speed = 3000 }"
        } else {
            "motor = { counts_per_rev = 10000, rated_speed = 3000 }"
        };
        let text = format!(
            r#"
[cell]
name = "homing-keys"
cycle_time_us = 1000
[[axes]]
name = "x"
drive = "{drive}"
{motor}
unit = "mm"
counts_per_unit = 1000.0
limits = {{ position = [0.0, 500.0], velocity = 100.0, acceleration = 1000.0, jerk = 10000.0 }}
{extra}
"#
        );
        CellConfig::parse(Path::new("h.toml"), &text)
    }

    fn refused(drive: &str, extra: &str) -> ConfigError {
        parse(drive, extra).expect_err(extra)
    }

    #[test]
    fn methods_the_manual_does_not_list_are_refused_naming_the_key() {
        let e = refused("mr-j4-tm", "homing = { method = -17 }");
        assert_eq!(e.key, "axes[0].homing.method");
        assert!(e.message.contains("MR-J4") && e.message.contains("no homing method -17"));
        // Every method the MR-J4-TM lists is emulated (§5.4.9(4)): the count and stopper
        // types load.
        for method in [-2, -4, 28] {
            let extra = format!("homing = {{ method = {method} }}");
            assert!(parse("mr-j4-tm", &extra).is_ok(), "{method}");
        }
        let e = refused("mr-jet-g-n1", "homing = { method = 37 }");
        assert_eq!(e.key, "axes[0].homing.method");
        assert!(e.message.contains("§8.3"), "{}", e.message);
        let e = refused("mr-j5-g-n1", "homing = { method = 35 }");
        assert!(e.message.contains("Function manual"), "{}", e.message);
        // The MR-J3-T04 lists −1, but its default TxPDO lacks 6061h: not from a cell.
        let e = refused("mr-j3-t04", "homing = { method = -1 }");
        assert!(e.message.contains("6061h"), "{}", e.message);
    }

    #[test]
    fn speeds_shift_and_switches_are_checked_naming_the_key() {
        let e = refused("mr-j4-tm", "homing = { switch_speed = 150.0 }");
        assert_eq!(e.key, "axes[0].homing.switch_speed");
        let e = refused("mr-j4-tm", "homing = { creep_speed = -1.0 }");
        assert_eq!(e.key, "axes[0].homing.creep_speed");
        let e = refused("mr-j4-tm", "homing = { shift = 1.0 }");
        assert_eq!(e.key, "axes[0].homing.shift");
        assert!(e.message.contains("no object"), "{}", e.message);
        let e = refused("mr-j3-t04", "homing = { shift = -1.0 }");
        assert_eq!(e.key, "axes[0].homing.shift");
        let e = refused("mr-j4-tm", "sim = { home_dog = [20.0, 10.0] }");
        assert_eq!(e.key, "axes[0].sim.home_dog");
        let e = refused(
            "mr-j4-tm",
            "sim = { positive_limit = 10.0, negative_limit = 10.0 }",
        );
        assert_eq!(e.key, "axes[0].sim.negative_limit");
        let e = refused("mr-j4-tm", "homing = { timeout_s = 0.0 }");
        assert_eq!(e.key, "axes[0].homing.timeout_s");
        let e = refused("mr-j4-tm", "homing = { method = 35, speed = 1 }");
        assert!(e.message.contains("speed"), "{}", e.message);
    }

    #[test]
    fn the_objects_go_in_the_drives_units_in_order() {
        // MR-J4-TM, 4194304 counts/rev, 1000 counts/mm: 60 mm/s = 60000 counts/s = 0.858 r/min
        // → 86 in 0.01 r/min (6099h, MR-J4-TM manual §5.4.9); 6 mm/s → 9.
        let c = parse(
            "mr-j4-tm",
            "homing = { method = -1, switch_speed = 60.0, creep_speed = 6.0, acceleration_ms = 200 }\n\
             sim = { home_dog = [100.0, 120.0], positive_limit = 400.0, negative_limit = 10.0 }",
        )
        .unwrap();
        let h = c.axes.on_loop()[0].homing;
        assert_eq!(h.method, Some(-1));
        assert_eq!(h.objects.get(0), Some((0x6099, 1, 86)));
        assert_eq!(h.objects.get(1), Some((0x6099, 2, 9)));
        assert_eq!(h.objects.get(2), Some((0x609A, 0, 200)));
        assert_eq!(h.objects.get(3), None);
        assert_eq!(h.timeout, std::time::Duration::from_secs(10));
        let s = c.axes.on_loop()[0].sim.switches;
        assert_eq!(s.home_dog, Some([100_000.0, 120_000.0]));
        assert_eq!(s.positive_limit, Some(400_000.0));
        let j3 = parse("mr-j3-t04", "homing = { shift = 2.5 }").unwrap();
        assert_eq!(
            j3.axes.on_loop()[0].homing.objects.get(0),
            Some((0x2080, 0, 2500))
        );
    }
}
