//! The MR-JE-C axes of a `move` step: taken out of the step's targets (and its per-axis limits)
//! before the streamed axes are checked, each checked against its own range and limits. The
//! drive's own profile has no jerk: a jerk limit does not apply to them.

use std::collections::BTreeMap;
use std::path::Path;

use super::{DriveMove, RawLimit, TorqueTarget};
use cellrt_cia402::homing::HomeProcedure;
use cellrt_config::je_c_axis::JecHomingError;
use cellrt_config::{AxisRef, CellConfig, ConfigError};

/// Removes the MR-JE-C axes from `target` and from the per-axis `limits`, and returns them
/// checked.
pub(super) fn take_targets(
    path: &Path,
    key: &str,
    target: &mut BTreeMap<String, f64>,
    limits: [&mut Option<RawLimit>; 3],
    cell: &CellConfig,
) -> Result<Vec<DriveMove>, ConfigError> {
    let names: Vec<String> = target
        .keys()
        .filter(|n| cell.axis_ref(n).and_then(AxisRef::link).is_some())
        .cloned()
        .collect();
    let mut out = Vec::with_capacity(names.len());
    let [velocity, acceleration, jerk] = limits;
    for name in names {
        let axis = cell
            .axis_ref(&name)
            .and_then(AxisRef::link)
            .expect("filtered above");
        let a = &cell.axes.on_link()[axis];
        let value = target.remove(&name).expect("a key of target");
        let goal = a
            .move_target(value)
            .map_err(|e| ConfigError::new(path, format!("{key}.target.{name}"), e.to_string()))?;
        if !a.takes_move_limits() {
            for (lim, what) in [(&*velocity, "velocity"), (&*acceleration, "acceleration")] {
                let names_it = match lim {
                    None => false,
                    Some(RawLimit::All(_)) => true,
                    Some(RawLimit::PerAxis(m)) => m.contains_key(&name),
                };
                if names_it {
                    return Err(ConfigError::new(
                        path,
                        format!("{key}.{what}"),
                        format!("axis '{name}' runs point tables: each table has its own speed and ramps; give the step's {what} per axis, without '{name}'"),
                    ));
                }
            }
        }
        let pick = |lim: &mut Option<RawLimit>, default: f64, what: &str| {
            let v = match lim {
                None => return Ok(default),
                Some(RawLimit::All(v)) => *v,
                Some(RawLimit::PerAxis(m)) => match m.remove(&name) {
                    Some(v) => v,
                    None => return Ok(default),
                },
            };
            if !(v.is_finite() && v > 0.0 && v <= default) {
                return Err(ConfigError::new(
                    path,
                    format!("{key}.{what}"),
                    format!(
                        "{v} for axis '{name}': must be > 0 and at most its {what} limit {default}"
                    ),
                ));
            }
            Ok(v)
        };
        let velocity = pick(&mut *velocity, a.velocity, "velocity")?;
        let acceleration = pick(&mut *acceleration, a.acceleration, "acceleration")?;
        if let Some(RawLimit::PerAxis(m)) = &mut *jerk {
            m.remove(&name);
        }
        let (velocity, acceleration) = a.profile_of(goal, velocity, acceleration);
        out.push(DriveMove {
            axis,
            goal,
            velocity,
            acceleration,
        });
    }
    for lim in [velocity, acceleration, jerk] {
        if matches!(lim, Some(RawLimit::PerAxis(m)) if m.is_empty()) {
            *lim = None;
        }
    }
    Ok(out)
}

/// The homing procedure of MR-JE-C axis `axis` (link in `CellAxes::on_link`): hm with
/// [`HOMING_METHOD`](cellrt_config::je_c_axis::HOMING_METHOD); another method or a
/// Controlword2 edge (an MR-J3-T04 procedure) is refused naming the key.
pub(super) fn home_procedure(
    path: &Path,
    key: &str,
    axis: usize,
    method: Option<i8>,
    setting: bool,
    cell: &CellConfig,
) -> Result<HomeProcedure, ConfigError> {
    cell.axes.on_link()[axis]
        .homing_method(method, setting)
        .map(HomeProcedure::HomingMode)
        .map_err(|e| {
            let sub = match e {
                JecHomingError::Controlword2Edge { .. } => "setting",
                JecHomingError::Method { .. } => "method",
            };
            ConfigError::new(path, format!("{key}.{sub}"), e.to_string())
        })
}

/// Whether MR-JE-C axis `axis` (link in `CellAxes::on_link`) can jog at `velocity` in its mode
/// (its velocity limit is checked by the caller, as for every axis).
pub(super) fn check_jog(
    path: &Path,
    key: &str,
    axis: usize,
    velocity: f64,
    cell: &CellConfig,
) -> Result<(), ConfigError> {
    let a = &cell.axes.on_link()[axis];
    a.jog_command(velocity, a.acceleration)
        .map(|_| ())
        .map_err(|m| ConfigError::new(path, format!("{key}.axis"), m.to_string()))
}

/// The targets of a torque step whose axes are MR-JE-C axes, each checked against its tq
/// command (`None`: no MR-JE-C axis among them). Mixed with the cell's other axes it is
/// refused: the MR-JE-C drives hold their torque until the halt, on their own link threads.
pub(super) fn torque_targets(
    path: &Path,
    key: &str,
    target: &BTreeMap<String, f64>,
    cell: &CellConfig,
) -> Result<Option<Vec<TorqueTarget>>, ConfigError> {
    let je_c: Vec<(&String, usize)> = target
        .keys()
        .filter_map(|n| cell.axis_ref(n).and_then(AxisRef::link).map(|k| (n, k)))
        .collect();
    if je_c.is_empty() {
        return Ok(None);
    }
    if je_c.len() != target.len() {
        return Err(ConfigError::new(
            path,
            format!("{key}.target"),
            "MR-JE-C axes and the cell's other axes in one torque step: give them steps of their own",
        ));
    }
    je_c.into_iter()
        .map(|(name, k)| {
            let a = &cell.axes.on_link()[k];
            let torque = target[name];
            a.torque_command(torque).map_err(|e| {
                ConfigError::new(path, format!("{key}.target.{name}"), e.to_string())
            })?;
            Ok(TorqueTarget {
                axis: AxisRef::Link(k),
                torque,
                slope: a.torque.map_or(0.0, |t| t.slope),
            })
        })
        .collect::<Result<_, _>>()
        .map(Some)
}
