//! The engine's refusals before anything changes: an axis not powered, a request the
//! configuration does not allow (axes, modes, limits), and planner failures in one line.

use super::*;

impl MotionEngine {
    /// Refuses motion of an axis whose MC_Power is off (the RT thread would refuse its
    /// setpoints and stop the cell), or that a run-time mode switch left in pp (the drive
    /// positions it by its own profile; the setpoint stream would not reach it).
    pub(super) fn check_live(
        &self,
        req: &MotionRequest,
        link: &mut dyn CellLink,
    ) -> Result<(), MotionError> {
        let Some(moved) = req.moved_axes() else {
            return Ok(());
        };
        let status = link.status()?;
        if let Some(&i) = moved.iter().find(|&&i| status.live[i].powered == 0) {
            return Err(MotionError::NotPowered(
                self.cell.axes.on_loop()[i].name.clone(),
            ));
        }
        let switched = moved.iter().find(|&&i| {
            cellrt_config::ProfileMode::of(status.mode_now(&self.cell, i)).is_some()
                && self.cell.axes.on_loop()[i].profile_objects.is_none()
        });
        match switched {
            Some(&i) => Err(refused(format!(
                "axis '{0}' was switched to pp at run time: streamed moves, jogs and torque \
                 commands need it in csp (`cellrt mode {0} csp`)",
                self.cell.axes.on_loop()[i].name
            ))),
            None => Ok(()),
        }
    }

    /// Refusals that depend on the configuration only (before anything changes).
    pub(super) fn check_request(&self, req: &MotionRequest) -> Result<(), MotionError> {
        self.check_streamed(req)?;
        let axes = self.cell.axes.on_loop();
        match req {
            // A cst axis positions in csv between torque commands (`AxisChannel::drive_command`).
            MotionRequest::Move(targets) => {
                if targets.is_empty() {
                    return Err(refused("a move needs at least one axis target"));
                }
                if let Some(&(i, _, _)) = targets.iter().find(|t| t.0 >= axes.len()) {
                    return Err(MotionError::UnknownAxis(i));
                }
            }
            MotionRequest::Jog { axis, .. } => {
                if *axis >= axes.len() {
                    return Err(MotionError::UnknownAxis(*axis));
                }
            }
            MotionRequest::Halt(_) => {}
            MotionRequest::Path { targets, via } => {
                if targets.is_empty() || targets.len() > cellrt_trajectory::MAX_MOVE_AXES {
                    return Err(refused(format!(
                        "a waypoint path needs 1 to {} axes (got {})",
                        cellrt_trajectory::MAX_MOVE_AXES,
                        targets.len()
                    )));
                }
                if let Some(&(i, _, _)) = targets.iter().find(|t| t.0 >= axes.len()) {
                    return Err(MotionError::UnknownAxis(i));
                }
                for (w, point) in via.iter().enumerate() {
                    if point.len() != targets.len() {
                        return Err(refused(format!(
                            "waypoint {w} has {} positions for {} axes",
                            point.len(),
                            targets.len()
                        )));
                    }
                    for (&(i, _, _), &p) in targets.iter().zip(point) {
                        let a = &axes[i];
                        a.position.check(p).map_err(|e| {
                            refused(format!("waypoint {w}: axis '{}' ({}): {e}", a.name, a.unit))
                        })?;
                    }
                }
                for &(i, t, _) in targets {
                    let a = &axes[i];
                    a.position
                        .check(t)
                        .map_err(|e| refused(format!("axis '{}' ({}): {e}", a.name, a.unit)))?;
                }
            }
            MotionRequest::Line { targets, .. } => {
                if targets.len() < 2 || targets.len() > cellrt_trajectory::MAX_MOVE_AXES {
                    return Err(refused(format!(
                        "a line needs 2 to {} axes (got {})",
                        cellrt_trajectory::MAX_MOVE_AXES,
                        targets.len()
                    )));
                }
                if let Some(&(i, _, _)) = targets.iter().find(|t| t.0 >= axes.len()) {
                    return Err(MotionError::UnknownAxis(i));
                }
                let unit = &axes[targets[0].0].unit;
                if let Some(&(i, _, _)) = targets.iter().find(|t| &axes[t.0].unit != unit) {
                    return Err(refused(format!(
                        "a line needs axes of one unit: '{}' is in {}, '{}' in {}",
                        axes[targets[0].0].name, unit, axes[i].name, axes[i].unit
                    )));
                }
            }
            MotionRequest::Torque { targets, .. } => {
                if targets.is_empty() {
                    return Err(refused("a torque command needs at least one axis"));
                }
                for &(i, torque, _) in targets {
                    let a = axes.get(i).ok_or(MotionError::UnknownAxis(i))?;
                    let limits = a
                        .torque
                        .filter(|_| a.mode == ModeOfOperation::CyclicSyncTorque);
                    let Some(limits) = limits else {
                        return Err(refused(format!(
                            "axis '{}' runs in {}; torque needs an axis with mode = \"cst\"",
                            a.name,
                            a.mode.as_str()
                        )));
                    };
                    if !torque.is_finite() || torque.abs() > limits.max.0 {
                        return Err(refused(format!(
                            "torque {torque} % is outside the torque limit ±{} % of axis '{}'",
                            limits.max.0, a.name
                        )));
                    }
                }
            }
        }
        Ok(())
    }

    /// Refuses streamed motion of a profile axis (pp/pv/tq): the drive moves it by its own
    /// profile, the setpoint stream does not reach it.
    fn check_streamed(&self, req: &MotionRequest) -> Result<(), MotionError> {
        let Some(moved) = req.moved_axes() else {
            return Ok(());
        };
        let profile_axis = moved
            .iter()
            .filter_map(|&i| self.cell.axes.on_loop().get(i))
            .find(|a| a.profile_objects.is_some());
        match profile_axis {
            Some(a) => Err(refused(format!(
                "axis '{}' runs in {} (the drive's own profile): streamed moves, jogs and torque \
                 commands drive csp/csv/cst axes only",
                a.name,
                a.mode.as_str()
            ))),
            None => Ok(()),
        }
    }

    /// Names the axis in an online-motion refusal.
    pub(super) fn describe(&self, e: cellrt_trajectory::OnlineError) -> String {
        use cellrt_trajectory::OnlineError as E;
        let axis = match &e {
            E::NotFinite { axis, .. } | E::Limits { axis, .. } => Some(*axis),
            E::VelocityAboveLimit { axis, .. } => Some(*axis),
            _ => None,
        };
        let text = error::one_line(&e.to_string());
        match axis.and_then(|i| self.cell.axes.on_loop().get(i)) {
            Some(a) => text.replacen(
                &format!("axis {}", axis.unwrap_or(0)),
                &format!("axis '{}' ({})", a.name, a.unit),
                1,
            ),
            None => text,
        }
    }
}
