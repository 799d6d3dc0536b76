//! Profile position mode (pp) on the simulated drive: its inputs from the RxPDO, SDO values
//! or defaults, and the drive's own profile (`motion::profile_position`) on the plant; the ramp,
//! speed-cap and HALT objects the profile modes (pp, pv) share.

use super::SimDrive;
use crate::motion::profile_position::{HaltOption, PositionUnit, PpCommand, PpFeedback};
use crate::motion::ramp::time_constant_rate;
use cellrt_cia402::pdo::objects::{
    RxField, HALT_OPTION_CODE, MAX_MOTOR_SPEED, MAX_PROFILE_VELOCITY, POSITION_WINDOW,
    POSITION_WINDOW_TIME, PROFILE_ACCELERATION, PROFILE_DECELERATION, PROFILE_VELOCITY,
    SOFTWARE_POSITION_LIMIT,
};
use cellrt_cia402::pdo::RxPdo;

impl SimDrive {
    /// An object the profile modes read: from the RxPDO where the map carries it, else the SDO value, else
    /// the profile's default.
    pub(super) fn pp_object(&self, cmd: &RxPdo, index: u16) -> Option<i64> {
        if self.profile.pdo.rx.maps(index) {
            if let Some(f) = RxField::of(index, 0) {
                return Some(cmd.get(f) as i64);
            }
        }
        self.sdo_value(index, 0)
            .or_else(|| self.object(index, 0)?.default)
    }

    /// The speed the 6083h/6084h/6085h time constants refer to ("rated speed"), counts/s:
    /// [`crate::motion::profile_position::PpParams::time_constant_speed`], else the plant's
    /// maximum speed.
    pub(super) fn rated_speed(&self) -> f64 {
        self.params
            .pp
            .time_constant_speed
            .filter(|v| v.is_finite() && *v > 0.0)
            .unwrap_or(self.params.plant.max_velocity.abs())
    }

    /// The rate (counts/s²) of a time constant of `ms` from 0 to the rated speed (MR-J4-TM
    /// manual §4.2: 6083h–6085h in ms); 0 ms or none: the plant's maximum acceleration.
    pub(super) fn time_constant_rate(&self, ms: Option<i64>) -> f64 {
        let amax = self.params.plant.max_acceleration.abs();
        ms.and_then(|ms| time_constant_rate(self.rated_speed(), ms))
            .map_or(amax, |rate| rate.min(amax))
    }

    /// The speed cap of the profile modes, counts/s: 607Fh (velocity unit, pp/pv), 6080h
    /// (r/min or mm/s, MR-J4-TM manual §4.2) where given, and the plant's maximum speed.
    pub(super) fn profile_speed_cap(&self, cmd: &RxPdo) -> f64 {
        let mut cap = self.params.plant.max_velocity.abs();
        if let Some(v) = self.pp_object(cmd, MAX_PROFILE_VELOCITY) {
            cap = cap.min(self.commanded_counts_per_s(v).abs());
        }
        cap.min(self.max_motor_speed())
    }

    /// 6080h Max motor speed in counts/s, where the model lists it and it has a value;
    /// unbounded otherwise.
    pub(super) fn max_motor_speed(&self) -> f64 {
        match self
            .sdo_value(MAX_MOTOR_SPEED, 0)
            .or_else(|| self.object(MAX_MOTOR_SPEED, 0)?.default)
        {
            Some(speed) => self.counts_of(speed as f64).abs(),
            None => f64::INFINITY,
        }
    }

    /// The HALT deceleration (counts/s²) of the profile modes: 605Dh where written or given a
    /// default, as CiA 402 codes it (1 profile deceleration, 2 quick-stop deceleration, 3/4
    /// current / voltage limit) [background]; elsewhere [`HaltOption`] (the Mitsubishi
    /// manuals leave the values out, MR-J4-TM manual §5.7).
    pub(super) fn halt_deceleration(&self, profile_deceleration: f64) -> f64 {
        let amax = self.params.plant.max_acceleration.abs();
        let code = self
            .sdo_value(HALT_OPTION_CODE, 0)
            .or_else(|| self.object(HALT_OPTION_CODE, 0)?.default);
        match code {
            Some(1) => profile_deceleration,
            Some(2) => self.time_constant_rate(self.quick_stop_time_ms().map(i64::from)),
            Some(3 | 4) => amax,
            _ => match self.params.pp.halt {
                HaltOption::ProfileDeceleration => profile_deceleration,
                HaltOption::MaximumDeceleration => amax,
            },
        }
    }

    /// 607Dh:1/2 where the model lists them and min < max (min = max, the default 0/0,
    /// disables them: MR-J4-TM spec §8.5, CiA 402 [background]).
    pub(super) fn software_position_limits(&self) -> Option<(i32, i32)> {
        let sub = |s: u8| {
            self.sdo_value(SOFTWARE_POSITION_LIMIT, s)
                .or_else(|| self.object(SOFTWARE_POSITION_LIMIT, s)?.default)
        };
        let (min, max) = (sub(1)? as i32, sub(2)? as i32);
        (min < max).then_some((min, max))
    }

    /// This cycle's pp inputs (sim units: counts, counts/s; 6081h/607Fh in the model's velocity
    /// unit, 6083h/6084h ms time constants).
    pub(super) fn pp_command(&self, cmd: &RxPdo) -> PpCommand {
        let pp = self.params.pp;
        let velocity = self.commanded_counts_per_s(
            self.pp_object(cmd, PROFILE_VELOCITY)
                .unwrap_or(i64::from(pp.profile_velocity)),
        );
        let velocity = velocity.clamp(0.0, self.profile_speed_cap(cmd));
        let deceleration = self.time_constant_rate(self.pp_object(cmd, PROFILE_DECELERATION));
        let window = self
            .pp_object(cmd, POSITION_WINDOW)
            .map_or(pp.position_window, |v| v as u32);
        let window_ms = self
            .pp_object(cmd, POSITION_WINDOW_TIME)
            .map_or(pp.position_window_time_ms, |v| v as u32);
        PpCommand {
            model: pp.model,
            controlword: cmd.controlword.0,
            target: cmd.target_position,
            velocity,
            acceleration: Some(self.time_constant_rate(self.pp_object(cmd, PROFILE_ACCELERATION))),
            deceleration: Some(deceleration),
            halt_deceleration: Some(self.halt_deceleration(deceleration)),
            window,
            window_time_s: f64::from(window_ms) / 1000.0,
            relative_refused: match self.params.position_unit {
                PositionUnit::Degree => self.profile.limits.relative_degree_warning,
                PositionUnit::Pulse => None,
            },
            limits: self.software_position_limits(),
        }
    }

    /// pp in Operation enabled: the drive's own profile toward the accepted set-point
    /// (`motion::profile_position`), followed by the servo loop; following error checked as csp.
    pub(super) fn follow_profile_position(&mut self, cmd: &RxPdo, dt: f64) {
        let c = self.pp_command(cmd);
        let fb = PpFeedback {
            actual: self.position_actual(),
            position: self.plant.position(),
            velocity: self.plant.velocity(),
            droop: self.demand - self.plant.position(),
            command_standing: self.pp.velocity() == 0.0,
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
