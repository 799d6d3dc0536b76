//! The load-time check that an axis' acceleration, jerk and torque-slope limits mean something
//! at the cell's cycle: the drive receives one setpoint per cycle, so the most a limit can
//! allow is reaching the limit of the quantity below it within one cycle. A larger value is no
//! limit at all (the step between two setpoints is the same), so it is refused, naming the key.

use cellrt_cia402::CycleTime;
use cellrt_trajectory::limits::KinematicLimits;

use super::axis_key::AxisKey;
use crate::{ConfigError, TorqueLimits};

/// The limits of one axis to check, in the axis' unit.
pub(super) struct RampLimits<'a> {
    /// Velocity, acceleration and jerk limits.
    pub kinematic: &'a KinematicLimits,
    /// `limits.stop_deceleration` (defaults to the acceleration).
    pub stop_deceleration: f64,
    /// `limits.stop_jerk` (defaults to the jerk).
    pub stop_jerk: f64,
    /// `limits.torque` and `limits.torque_slope`, where given.
    pub torque: Option<&'a TorqueLimits>,
}

/// Refuses an acceleration (or stop deceleration) that reaches `limits.velocity`, a jerk (or
/// stop jerk) that reaches the acceleration, or a torque slope that reaches `limits.torque`
/// in less than one cycle.
pub(super) fn check(
    at: &AxisKey<'_>,
    unit: &str,
    cycle_time: CycleTime,
    l: &RampLimits<'_>,
) -> Result<(), ConfigError> {
    let k = l.kinematic;
    let (acc, jerk) = (format!("{unit}/s²"), format!("{unit}/s³"));
    let ramps = [
        (
            "limits.acceleration",
            k.acceleration,
            &acc,
            "limits.velocity",
            k.velocity,
            format!("{unit}/s"),
        ),
        (
            "limits.stop_deceleration",
            l.stop_deceleration,
            &acc,
            "limits.velocity",
            k.velocity,
            format!("{unit}/s"),
        ),
        (
            "limits.jerk",
            k.jerk,
            &jerk,
            "limits.acceleration",
            k.acceleration,
            acc.clone(),
        ),
        (
            "limits.stop_jerk",
            l.stop_jerk,
            &jerk,
            "limits.stop_deceleration",
            l.stop_deceleration,
            acc.clone(),
        ),
    ];
    for (key, rate, rate_unit, of, target, target_unit) in ramps {
        within_one_cycle(
            at,
            cycle_time,
            (key, rate, rate_unit),
            (of, target, &target_unit),
        )?;
    }
    if let Some(t) = l.torque {
        let (max, unit) = (t.max.0, "%".to_string());
        within_one_cycle(
            at,
            cycle_time,
            ("limits.torque_slope", t.slope, "%/s"),
            ("limits.torque", max, &unit),
        )?;
    }
    Ok(())
}

/// Refuses `rate` (key, value, unit) if it reaches `target` (key, value, unit) in less than one
/// cycle.
fn within_one_cycle(
    at: &AxisKey<'_>,
    cycle_time: CycleTime,
    (key, rate, rate_unit): (&str, f64, &str),
    (of, target, target_unit): (&str, f64, &str),
) -> Result<(), ConfigError> {
    let period = cycle_time.as_secs_f64();
    let most = target / period;
    if rate <= most {
        return Ok(());
    }
    Err(at.err(
        key,
        format!(
            "{rate} {rate_unit} reaches {of} ({target} {target_unit}) in {:.3e} s, less than one \
             {} µs cycle: one setpoint per cycle cannot carry it (at most {most} {rate_unit})",
            target / rate,
            period * 1e6
        ),
    ))
}

#[cfg(test)]
mod tests {
    use std::path::{Path, PathBuf};

    use crate::{CellConfig, ConfigError};

    fn configs_dir() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs")
    }

    /// `configs/NAME` with `axes[0].limits.KEY = value` set for each (key, value).
    fn with_limits(name: &str, set: &[(&str, f64)]) -> Result<CellConfig, ConfigError> {
        let path = configs_dir().join(name);
        let mut doc: toml::Table = std::fs::read_to_string(&path).unwrap().parse().unwrap();
        let axis = doc["axes"].as_array_mut().unwrap()[0]
            .as_table_mut()
            .unwrap();
        let limits = axis["limits"].as_table_mut().unwrap();
        for (key, value) in set {
            limits.insert(key.to_string(), toml::Value::Float(*value));
        }
        CellConfig::parse(&path, &toml::to_string(&doc).unwrap())
    }

    #[test]
    fn ramps_that_reach_their_target_within_a_cycle_are_refused_naming_the_key() {
        // Demo axis x: 1 ms cycle, 400 mm/s, 2000 mm/s², 20000 mm/s³.
        let e = with_limits("demo.toml", &[("acceleration", 1e18)]).unwrap_err();
        assert_eq!(e.key, "axes[0].limits.acceleration");
        assert!(
            e.message.contains("reaches limits.velocity (400 mm/s)")
                && e.message.contains("1000 µs cycle")
                && e.message.contains("at most 400000 mm/s²"),
            "{e}"
        );
        let e = with_limits("demo.toml", &[("jerk", 1e18)]).unwrap_err();
        assert_eq!(e.key, "axes[0].limits.jerk");
        assert!(e.message.contains("at most 2000000 mm/s³"), "{e}");
        let e = with_limits("demo.toml", &[("stop_deceleration", 400_001.0)]).unwrap_err();
        assert_eq!(e.key, "axes[0].limits.stop_deceleration");
        let e = with_limits("demo.toml", &[("stop_jerk", 1e9)]).unwrap_err();
        assert_eq!(e.key, "axes[0].limits.stop_jerk");
        assert!(
            e.message.contains("limits.stop_deceleration (2000 mm/s²)"),
            "{e}"
        );
        let e = with_limits("demo.toml", &[("torque", 100.0), ("torque_slope", 1e18)]).unwrap_err();
        assert_eq!(e.key, "axes[0].limits.torque_slope");
        assert!(
            e.message.contains("reaches limits.torque (100 %)")
                && e.message.contains("at most 100000 %/s"),
            "{e}"
        );
    }

    #[test]
    fn a_ramp_of_exactly_one_cycle_is_accepted() {
        let c = with_limits(
            "demo.toml",
            &[("acceleration", 400_000.0), ("jerk", 400_000_000.0)],
        )
        .expect("one cycle to full speed is a limit the setpoints carry");
        assert_eq!(c.axes.on_loop()[0].limits.acceleration, 400_000.0);
    }

    #[test]
    fn every_shipped_config_refuses_1e18_for_each_ramp_limit() {
        let mut checked = 0;
        for entry in std::fs::read_dir(configs_dir()).unwrap() {
            let name = entry.unwrap().file_name().into_string().unwrap();
            let text = std::fs::read_to_string(configs_dir().join(&name)).unwrap_or_default();
            if !name.ends_with(".toml") || !text.contains("[[axes]]") {
                continue;
            }
            for key in ["acceleration", "jerk", "torque_slope"] {
                let mut set = vec![(key, 1e18)];
                if key == "torque_slope" {
                    set.push(("torque", 100.0));
                }
                let e = with_limits(&name, &set).unwrap_err();
                assert_eq!(e.key, format!("axes[0].limits.{key}"), "{name}: {e}");
                assert!(e.message.contains("less than one"), "{name}: {e}");
            }
            checked += 1;
        }
        assert!(checked >= 10, "only {checked} shipped configs");
    }
}
