//! Profile position mode (pp) on the simulated drive: its inputs from the RxPDO, SDO values
//! or defaults, and the drive's own profile (`sim::profile_position`) on the plant.

use super::SimDrive;
use crate::pdo::objects::{
    RxField, POSITION_WINDOW, POSITION_WINDOW_TIME, PROFILE_ACCELERATION, PROFILE_DECELERATION,
    PROFILE_VELOCITY,
};
use crate::pdo::RxPdo;
use crate::sim::profile_position::{HaltOption, PositionUnit, PpCommand, PpFeedback};

impl SimDrive {
    /// An object pp reads: from the RxPDO where the map carries it, else the SDO value, else
    /// the profile's default.
    pub(super) fn pp_object(&self, cmd: &RxPdo, index: u16) -> Option<i64> {
        if self.profile.rx_pdo.maps(index) {
            if let Some(f) = RxField::of(index, 0) {
                return Some(cmd.get(f) as i64);
            }
        }
        self.sdo_value(index, 0)
            .or_else(|| self.profile.object(index, 0)?.default)
    }

    /// This cycle's pp inputs (sim units: counts, counts/s; 6083h/6084h ms time constants).
    pub(super) fn pp_command(&self, cmd: &RxPdo) -> PpCommand {
        let plant = self.params.plant;
        let pp = self.params.pp;
        let amax = plant.max_acceleration.abs();
        let ref_speed = pp
            .time_constant_speed
            .filter(|v| v.is_finite() && *v > 0.0)
            .unwrap_or(plant.max_velocity.abs());
        let ramp = |ms: Option<i64>| match ms {
            Some(ms) if ms > 0 => (ref_speed * 1000.0 / ms as f64).min(amax),
            _ => amax,
        };
        let mut velocity = self
            .pp_object(cmd, PROFILE_VELOCITY)
            .unwrap_or(i64::from(pp.profile_velocity)) as f64;
        if let Some(max) = self.pp_object(cmd, 0x607F) {
            velocity = velocity.min(max as f64);
        }
        let velocity = velocity.clamp(0.0, plant.max_velocity.abs());
        let deceleration = ramp(self.pp_object(cmd, PROFILE_DECELERATION));
        let window = self
            .pp_object(cmd, POSITION_WINDOW)
            .map_or(pp.position_window, |v| v as u32);
        let window_ms = self
            .pp_object(cmd, POSITION_WINDOW_TIME)
            .map_or(pp.position_window_time_ms, |v| v as u32);
        PpCommand {
            controlword: cmd.controlword.0,
            target: cmd.target_position,
            velocity,
            acceleration: ramp(self.pp_object(cmd, PROFILE_ACCELERATION)),
            deceleration,
            halt_deceleration: match pp.halt {
                HaltOption::ProfileDeceleration => deceleration,
                HaltOption::MaximumDeceleration => amax,
            },
            window,
            window_time_s: f64::from(window_ms) / 1000.0,
            relative_refused: match self.params.position_unit {
                PositionUnit::Degree => self.profile.relative_degree_warning,
                PositionUnit::Pulse => None,
            },
        }
    }

    /// pp in Operation enabled: the drive's own profile toward the accepted set-point
    /// (`sim::profile_position`), followed by the servo loop; following error checked as csp.
    pub(super) fn follow_profile_position(&mut self, cmd: &RxPdo, dt: f64) {
        let c = self.pp_command(cmd);
        let fb = PpFeedback {
            actual: self.position_actual(),
            position: self.plant.position(),
            velocity: self.plant.velocity(),
        };
        self.demand = self.pp.step(&c, fb, dt);
        let ff = self.params.velocity_feedforward * self.pp.velocity();
        self.plant.step(self.demand, ff, dt);
        self.prev_target = cmd.target_position;
        self.following_error = self.position_demand().wrapping_sub(self.position_actual());
        if self.following_error.unsigned_abs() > self.params.following_error_limit {
            self.raise(self.following_error_code());
        }
    }
}
