//! The modes of operation in Operation enabled: the mode switch with its zero-speed gate, csp,
//! csv and cst on the plant, the torque limits, the following-error and overspeed alarms.

use super::{InternalTorqueLimits, SimDrive};
use crate::device::pds::end_of_stop;
use crate::sim::fsoe::{FsoeSlave, StoStop};
use cellrt_cia402::fsa::FsaState;
use cellrt_cia402::mode::ModeOfOperation;
use cellrt_cia402::pdo::objects::{
    POSITION_OFFSET, PROFILE_DECELERATION, QUICK_STOP_DECELERATION, QUICK_STOP_OPTION,
};
use cellrt_cia402::pdo::RxPdo;
use cellrt_cia402::profiles::TorqueLimitSelection;

/// The lowest speed the simulated drive's S_ZSP accepts as standstill, counts/s.
pub(super) const STANDSTILL: f64 = 1.0;

impl SimDrive {
    /// 6060h → 6061h: supported modes are taken when the zero-speed gate allows (§4.3);
    /// 0, unknown and unsupported values keep the previous display (TV-8 "6061h keeps the old value").
    pub(super) fn switch_mode(&mut self, raw: i8) {
        let Some(mode) = ModeOfOperation::from_i8(raw) else {
            return;
        };
        if mode == self.mode_display || !self.profile.supports_mode(mode) {
            return;
        }
        let old = self.mode_display;
        let gated = cellrt_cia402::mode_switch::switch_needs_zero_speed(old, mode);
        if gated && !self.at_zero_speed() {
            return;
        }
        self.mode_display = mode;
        self.demand = self.plant.position();
        self.plant.set_last_command(self.demand);
        self.prev_target = self.position_actual().wrapping_sub(self.position_offset());
        self.reset_profiles();
    }

    /// 60B0h Position offset, added to 607Ah in csp (MR-J5-G-N1 manual §7.4 rule 2, MR-JET-G-N1 manual
    /// §4.3 rule 3: "607Ah + 60B0h follow 6064h"); only on models that list 60B0h, 0 unless
    /// written by SDO.
    pub fn position_offset(&self) -> i32 {
        let Some(default) = self.position_offset_default else {
            return 0;
        };
        self.sdo_value(POSITION_OFFSET, 0).or(default).unwrap_or(0) as i32
    }

    /// 605Ah Quick stop option code: the written value, else the model's default (none where
    /// the manual states none).
    pub(super) fn quick_stop_option(&self) -> Option<i64> {
        self.sdo_value(QUICK_STOP_OPTION, 0)
            .or(self.quick_stop_option_default)
    }

    pub(super) fn run_plant(&mut self, cmd: &RxPdo, dt: f64) {
        self.following_error = 0;
        if self.state != FsaState::QuickStopActive {
            self.quick_stop_ramp = None;
        }
        if let Some(stop) = self.fsoe.filter(FsoeSlave::sto).map(|f| f.sto_stop()) {
            // STO: energy cut, no torque from the drive.
            match stop {
                StoStop::Coast => self.plant.coast(dt),
                StoStop::DynamicBrake => self.plant.hold(dt),
            }
            self.demand = self.plant.position();
            return;
        }
        match self.state {
            FsaState::OperationEnabled => self.follow(cmd, dt),
            FsaState::QuickStopActive => {
                self.quick_stop(dt);
                let stays = self
                    .profile
                    .quirks
                    .quick_stop_stays_active(self.quick_stop_option());
                let stopped = self.stopped() && self.quick_stop_ramp.is_none_or(|r| r == 0.0);
                // (12) automatic at the end of the quick stop (option codes 1–4, §3.1);
                // codes 5–8 stay in Quick stop active where the drive honours them.
                self.state = end_of_stop(self.state, stopped, stays);
                if self.state != FsaState::QuickStopActive {
                    self.quick_stop_ramp = None;
                }
            }
            FsaState::FaultReactionActive => {
                self.plant.hold(dt);
                // (14) automatic after the fault reaction.
                self.state = end_of_stop(self.state, self.stopped(), false);
            }
            _ => self.plant.hold(dt),
        }
    }

    /// Quick stop active: on a model whose 6085h is a time constant (MR-J4-TM manual §4.2, §8.1:
    /// ms from the rated speed to 0) the motor follows the ramp 605Ah selects
    /// ([`SimDrive::quick_stop_deceleration`]); elsewhere it stops at the plant's maximum
    /// deceleration.
    fn quick_stop(&mut self, dt: f64) {
        let Some(decel) = self.quick_stop_deceleration() else {
            self.plant.hold(dt);
            return;
        };
        let r = *self.quick_stop_ramp.get_or_insert(self.plant.velocity());
        if r == 0.0 {
            self.plant.hold(dt);
            self.demand = self.plant.position();
            return;
        }
        let next = r - r.signum() * decel * dt;
        let next = if next * r <= 0.0 { 0.0 } else { next };
        self.quick_stop_ramp = Some(next);
        self.demand += 0.5 * (r + next) * dt;
        self.plant.step(self.demand, next, dt);
    }

    /// The quick-stop deceleration (counts/s²) by 605Ah, on a model whose 6085h is a time
    /// constant: 1 the profile deceleration 6084h, 3/4 the current limit (the plant's maximum
    /// deceleration), 2 and every other code the 6085h ramp (MR-J4-TM manual §8.1 gives 605Ah
    /// default 2 and no value table, §5.6 MISSING: the CiA 402 codes [background]).
    pub fn quick_stop_deceleration(&self) -> Option<f64> {
        let ms = self.quick_stop_time_ms()?;
        let last = self.last_cmd;
        Some(match self.quick_stop_option() {
            Some(1) => self.time_constant_rate(self.pp_object(&last, PROFILE_DECELERATION)),
            Some(3 | 4) => self.params.plant.max_acceleration.abs(),
            _ => self.time_constant_rate(Some(i64::from(ms))),
        })
    }

    /// 6085h Quick stop deceleration in ms (its SDO value, else the default), on a model whose
    /// acceleration objects are time constants; `None` elsewhere.
    pub fn quick_stop_time_ms(&self) -> Option<u32> {
        use cellrt_cia402::profiles::{AccelerationUnit, Stated};
        let o = self.object(QUICK_STOP_DECELERATION, 0)?;
        if self.profile.units.acceleration != Stated::Manual(AccelerationUnit::TimeConstantMs) {
            return None;
        }
        let v = self.sdo_value(QUICK_STOP_DECELERATION, 0).or(o.default)?;
        u32::try_from(v).ok()
    }

    /// S_ZSP as the mode-switch gate and the stroke end see it: at or below `zero_speed`, and
    /// never above [`STANDSTILL`] (a servo loop settles asymptotically; a motor turning slower
    /// than that reads 606Ch = 0 and stands still by any drive's measure).
    pub(super) fn at_zero_speed(&self) -> bool {
        self.plant.velocity().abs() <= self.params.zero_speed.max(STANDSTILL)
    }

    pub(super) fn stopped(&self) -> bool {
        self.plant.velocity().abs() <= self.params.zero_speed
    }

    pub(super) fn overspeed_limit(&self) -> f64 {
        self.params
            .overspeed_limit
            .unwrap_or(1.2 * self.params.plant.max_velocity.abs())
    }

    pub(super) fn following_error_code(&self) -> u16 {
        self.params
            .alarm_codes
            .map_or(self.profile.limits.following_error_alarm, |c| c.0)
    }

    pub(super) fn overspeed_code(&self) -> u16 {
        self.params
            .alarm_codes
            .map_or(self.profile.limits.overspeed_alarm, |c| c.1)
    }

    /// Servo on in the current mode. csp follows 607Ah, csv integrates 60FFh (in the model's
    /// velocity unit, clamped at the overspeed limit), cst applies 6071h (0.1 % rated, 300 % = `max_acceleration`) within the
    /// speed limit 2D20h (the model's velocity unit, `units`); pp, pv and tq run the drive's own
    /// profiles (`motion::profile_position`, `motion::profile_velocity`, `motion::profile_torque`).
    /// HALT (bit 8) stops and holds where the model honours it in the cyclic modes.
    pub(super) fn follow(&mut self, cmd: &RxPdo, dt: f64) {
        if self.profile.limits.power_warnings.is_some() && !self.power.em1 {
            // EM1 OFF: base off, dynamic-brake stop; the commands stay live (§3.7).
            self.plant.hold(dt);
            self.demand = self.plant.position();
            self.prev_target = cmd.target_position;
            return;
        }
        // The profile modes handle HALT themselves (605Dh, MR-J4-TM manual §5.4.6–§5.4.8).
        match self.mode_display {
            ModeOfOperation::ProfilePosition => return self.follow_profile_position(cmd, dt),
            ModeOfOperation::ProfileVelocity => return self.follow_profile_velocity(cmd, dt),
            ModeOfOperation::ProfileTorque => return self.follow_profile_torque(cmd, dt),
            _ => {}
        }
        if self.mode_display == ModeOfOperation::Homing && self.follow_homing_search(dt) {
            return;
        }
        if cmd.controlword.halt() && self.profile.cycle.halt_in_cyclic_modes {
            self.plant.hold(dt);
            self.demand = self.plant.position();
            self.prev_target = cmd.target_position;
            return;
        }
        if self.mode_display == ModeOfOperation::CyclicSyncTorque {
            let amax = self.params.plant.max_acceleration.abs();
            let a = f64::from(cmd.target_torque) / 3000.0 * amax;
            self.plant.step_torque(a, self.cst_velocity_limit(cmd), dt);
            self.demand = self.plant.position();
            self.prev_target = self.position_actual();
            return;
        }
        let manual_stop =
            self.mode_display == ModeOfOperation::CyclicSyncPosition && self.manual_stop(cmd, dt);
        let ff = match self.mode_display {
            ModeOfOperation::CyclicSyncPosition if manual_stop => 0.0,
            ModeOfOperation::CyclicSyncPosition => {
                // Work in the i32 domain relative to the actual position so 607Ah may wrap;
                // the command is 607Ah + 60B0h (§4.3 rule 2).
                let rel = cmd
                    .target_position
                    .wrapping_add(self.position_offset())
                    .wrapping_sub(self.position_actual());
                self.demand = self.plant.position() + f64::from(rel);
                let step = cmd.target_position.wrapping_sub(self.prev_target);
                self.prev_target = cmd.target_position;
                if dt > 0.0 && f64::from(step).abs() / dt > self.overspeed_limit() {
                    // A command implying more than the maximum speed (MR-J3-T04 AL.35).
                    self.raise(self.overspeed_code());
                    return;
                }
                if dt > 0.0 {
                    self.params.velocity_feedforward * f64::from(step) / dt
                } else {
                    0.0
                }
            }
            ModeOfOperation::CyclicSyncVelocity => {
                let lim = self.overspeed_limit();
                let v = self
                    .commanded_counts_per_s(i64::from(cmd.target_velocity))
                    .clamp(-lim, lim);
                let v = self.stroke_limited_velocity(v, dt);
                self.demand += v * dt;
                v
            }
            _ => 0.0,
        };
        self.plant.step(self.demand, ff, dt);
        // 60F4h = demand − 6064h in the wrapping i32 domain of the wire values (the demand in
        // 6064h's reference: shifted like it after a homing preset).
        let demand = self.position_demand();
        let demand = match self.mode_display {
            ModeOfOperation::CyclicSyncPosition => {
                cmd.target_position.wrapping_add(self.position_offset())
            }
            _ => demand,
        };
        self.following_error = demand.wrapping_sub(self.position_actual());
        let checked = matches!(
            self.mode_display,
            ModeOfOperation::CyclicSyncPosition | ModeOfOperation::ProfilePosition
        );
        if checked && self.following_error.unsigned_abs() > self.params.following_error_limit {
            self.raise(self.following_error_code());
        }
    }

    /// The cst speed limit: the velocity-limit object (2D20h) as received where the RxPDO maps
    /// it, else its SDO value or default (0 where none is given); a model without such an
    /// object (plain CiA 402: the speed in cst is bounded by 6080h Max motor speed, not by a
    /// cyclic object) runs up to the motor's maximum speed.
    pub(super) fn cst_velocity_limit(&self, cmd: &RxPdo) -> f64 {
        let index = cellrt_cia402::pdo::objects::VELOCITY_LIMIT;
        if self.profile.pdo.rx.maps(index) {
            return self.commanded_counts_per_s(i64::from(cmd.velocity_limit));
        }
        match self.object(index, 0) {
            Some(o) => {
                self.commanded_counts_per_s(self.sdo_value(index, 0).or(o.default).unwrap_or(0))
            }
            None => f64::INFINITY,
        }
    }

    /// The torque limits in effect for `cmd`, % of rated torque: (positive / CCW driving,
    /// negative / CW driving), per the profile's [`TorqueLimitSelection`].
    pub fn torque_limits_percent(&self, cmd: &RxPdo) -> (f64, f64) {
        let objects = (
            f64::from(cmd.torque_limit_positive) / 10.0,
            f64::from(cmd.torque_limit_negative) / 10.0,
        );
        match self.profile.limits.torque_limit_selection {
            TorqueLimitSelection::Objects => objects,
            TorqueLimitSelection::Controlword2 {
                c_tl_bit,
                c_tl1_bit,
            } => {
                // §9.4 table: each direction takes the lowest of the selected sources.
                let p = self.params.internal_torque_limits;
                let bit = |b: u8| cmd.controlword2 & (1 << b) != 0;
                let (mut fwd, mut rev) = (p.pa11_forward, p.pa12_reverse);
                if bit(c_tl1_bit) {
                    fwd = fwd.min(p.pc35_internal);
                    rev = rev.min(p.pc35_internal);
                }
                if bit(c_tl_bit) {
                    fwd = fwd.min(objects.0);
                    rev = rev.min(objects.1);
                }
                (fwd, rev)
            }
            TorqueLimitSelection::TorqueLimit2 { cptl_bit, cntl_bit } => {
                let t2 = self.params.torque_limit_2;
                let bit = |b: u8| t2.select && cmd.controlword.0 & (1 << b) != 0;
                (
                    if bit(cptl_bit) {
                        f64::from(t2.positive) / 10.0
                    } else {
                        objects.0
                    },
                    if bit(cntl_bit) {
                        f64::from(t2.negative) / 10.0
                    } else {
                        objects.1
                    },
                )
            }
        }
    }

    pub(super) fn apply_torque_limits(&mut self, cmd: &RxPdo) {
        let (pos, neg) = self.homing_torque_limits(self.torque_limits_percent(cmd));
        let max = InternalTorqueLimits::MOTOR_MAXIMUM_PERCENT;
        self.plant.set_torque_limits(pos / max, neg / max);
    }
}
