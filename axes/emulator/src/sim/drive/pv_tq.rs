//! Profile velocity (pv) and profile torque (tq) on the simulated drive: their inputs from the
//! RxPDO, SDO values, model defaults and [`SimDriveParams`](super::SimDriveParams), converted
//! from the model's units, and the drive's own ramps (`motion::profile_velocity`,
//! `motion::profile_torque`) on the plant.

use super::SimDrive;
use crate::motion::profile_torque::{HaltRelease, TqCommand};
use crate::motion::profile_velocity::PvCommand;
use cellrt_cia402::pdo::objects::{
    PROFILE_ACCELERATION, PROFILE_DECELERATION, TARGET_TORQUE, TARGET_VELOCITY, TORQUE_SLOPE,
};
use cellrt_cia402::pdo::RxPdo;

/// 606Dh Velocity window (MR-J4-TM manual §5.4.7).
const VELOCITY_WINDOW: u16 = 0x606D;
/// 606Eh Velocity window time, ms.
const VELOCITY_WINDOW_TIME: u16 = 0x606E;
/// 606Fh Velocity threshold.
const VELOCITY_THRESHOLD: u16 = 0x606F;
/// 6070h Velocity threshold time, ms.
const VELOCITY_THRESHOLD_TIME: u16 = 0x6070;

impl SimDrive {
    /// Restarts the drive-side profiles where the motor is (servo on, a mode switch).
    pub(super) fn reset_profiles(&mut self) {
        self.pp.reset(self.demand, self.prev_cw.0);
        self.pv.reset(self.plant.velocity());
        self.tq.reset();
    }

    /// 606Bh Velocity demand value in the model's velocity unit: the pv generator's output
    /// (the motor's command in the other modes is not reported).
    pub fn velocity_demand(&self) -> i32 {
        self.reported_velocity(self.pv.velocity())
    }

    /// 6074h Torque demand in 0.1 % of rated torque: the tq ramp's output.
    pub fn torque_demand(&self) -> i16 {
        self.tq.demand().round() as i16
    }

    /// This cycle's pv inputs in counts/s (60FFh, 607Fh, 606Dh, 606Fh in the model's velocity
    /// unit; 6080h in r/min; 6083h/6084h ms time constants; 606Eh/6070h ms).
    pub(super) fn pv_command(&self, cmd: &RxPdo) -> PvCommand {
        let pv = self.params.pv;
        let raw = self
            .pp_object(cmd, TARGET_VELOCITY)
            .unwrap_or(i64::from(cmd.target_velocity));
        let target = self.commanded_counts_per_s(raw);
        let cap = self.profile_speed_cap(cmd);
        let deceleration = self.time_constant_rate(self.pp_object(cmd, PROFILE_DECELERATION));
        let velocity = |index: u16, fallback: u32| {
            let v = self.pp_object(cmd, index).unwrap_or(i64::from(fallback));
            self.commanded_counts_per_s(v).abs()
        };
        let seconds = |index: u16, fallback: u32| {
            self.pp_object(cmd, index).unwrap_or(i64::from(fallback)) as f64 / 1000.0
        };
        PvCommand {
            model: pv.model,
            halt: cmd.controlword.halt(),
            target,
            limited_target: target.clamp(-cap, cap),
            acceleration: Some(self.time_constant_rate(self.pp_object(cmd, PROFILE_ACCELERATION))),
            deceleration: Some(deceleration),
            halt_deceleration: Some(self.halt_deceleration(deceleration)),
            window: velocity(VELOCITY_WINDOW, pv.velocity_window),
            window_time_s: seconds(VELOCITY_WINDOW_TIME, pv.velocity_window_time_ms),
            threshold: velocity(VELOCITY_THRESHOLD, pv.velocity_threshold),
            threshold_time_s: seconds(VELOCITY_THRESHOLD_TIME, pv.velocity_threshold_time_ms),
        }
    }

    /// pv in Operation enabled: the generator's velocity integrated into the position demand
    /// and fed forward, as csv.
    pub(super) fn follow_profile_velocity(&mut self, cmd: &RxPdo, dt: f64) {
        let c = self.pv_command(cmd);
        let v0 = self.pv.velocity();
        let v = self.pv.step(&c, self.plant.velocity(), dt);
        // The ramp's own distance (trapezoid rule): exact over a cycle, and over the several
        // cycles of a late exchange.
        self.demand += 0.5 * (v0 + v) * dt;
        self.plant.step(self.demand, v, dt);
        self.prev_target = cmd.target_position;
    }

    /// This cycle's tq inputs: 6071h and 6087h in 0.1 % and 0.1 %/s.
    pub(super) fn tq_command(&self, cmd: &RxPdo) -> TqCommand {
        let target = self
            .pp_object(cmd, TARGET_TORQUE)
            .unwrap_or(i64::from(cmd.target_torque));
        TqCommand {
            halt: cmd.controlword.halt(),
            target: target as i16 as f64,
            slope: self.pp_object(cmd, TORQUE_SLOPE).unwrap_or(0).max(0) as f64,
            zero_slope: self.params.tq.zero_slope,
            halt_release: HaltRelease::Resume,
        }
    }

    /// tq in Operation enabled: the ramped torque demand on the plant (300 % rated =
    /// `max_acceleration`, as cst) within the speed limit 2D20h and 6080h.
    pub(super) fn follow_profile_torque(&mut self, cmd: &RxPdo, dt: f64) {
        let c = self.tq_command(cmd);
        let torque = self.tq.step(&c, dt);
        let amax = self.params.plant.max_acceleration.abs();
        let limit = self.cst_velocity_limit(cmd).min(self.max_motor_speed());
        self.plant.step_torque(torque / 3000.0 * amax, limit, dt);
        self.demand = self.plant.position();
        self.prev_target = self.position_actual();
    }
}
