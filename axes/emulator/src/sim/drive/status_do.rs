//! The simulated Status DO words 2D11h–2D13h (MR-J4-TM manual §5.3.2, MR-J5-G-N1 manual §7.3,
//! MR-JET-G-N1 manual §7.3), from the drive's own state. Signals the simulator has no model
//! for (S_CDPS, S_ABSV, S_BWNG, S_IPF, S_PC, S_MTTR, S_ZPAS outside the MR-J3-T04 home
//! setting) stay 0.

use super::SimDrive;
use cellrt_cia402::fsa::FsaState;
use cellrt_cia402::mode::ModeOfOperation;
use cellrt_cia402::profiles::status_do::{StatusDo, StatusDoSignal as S};

impl SimDrive {
    /// The Status DO words of this cycle (all 0 on a model whose TxPDO does not map them).
    pub(super) fn status_do(&self) -> StatusDo {
        let mut s = StatusDo::default();
        if !self.status_do_mapped {
            return s;
        }
        let servo_on = self.state == FsaState::OperationEnabled;
        let sto = self.safe_torque_off();
        let v = self.plant.velocity();
        let position_mode = matches!(
            self.mode_display,
            ModeOfOperation::CyclicSyncPosition | ModeOfOperation::ProfilePosition
        );
        let torque_mode = matches!(
            self.mode_display,
            ModeOfOperation::CyclicSyncTorque | ModeOfOperation::ProfileTorque
        );
        s.set(S::SpeedReached, servo_on && self.speed_reached());
        s.set(S::BrakeInterlock, servo_on && self.alarm.is_none());
        s.set(
            S::InPosition,
            servo_on
                && position_mode
                && self.following_error.unsigned_abs() <= self.params.in_position_range,
        );
        s.set(
            S::TorqueLimiting,
            servo_on && !torque_mode && self.plant.at_torque_limit(),
        );
        s.set(S::ZeroSpeed, self.stopped());
        s.set(
            S::SpeedLimiting,
            servo_on && torque_mode && v.abs() >= self.cst_velocity_limit(&self.last_cmd) * 0.999,
        );
        s.set(S::DynamicBrakeOutput, servo_on && !sto);
        s.set(S::HomeCompleted2, self.homing.attained);
        s.set(S::SafeTorqueOff, sto);
        s
    }

    /// The speed the command asks for, counts/s: csv 60FFh (in the model's unit), csp the last
    /// 607Ah step per cycle.
    fn set_speed(&self) -> f64 {
        match self.mode_display {
            ModeOfOperation::CyclicSyncVelocity => {
                self.commanded_counts_per_s(i64::from(self.last_cmd.target_velocity))
            }
            ModeOfOperation::CyclicSyncPosition => {
                f64::from(self.last_step) / self.cycle_time.as_secs_f64()
            }
            _ => self.plant.velocity(),
        }
    }

    /// S_SA: the speed is within the set speed ± (set speed × 0.05 + the named band); always on
    /// at a set speed within the band (MR-J4-TM manual §5.3.2: the band is 20 r/min).
    fn speed_reached(&self) -> bool {
        let set = self.set_speed();
        let band = self.params.speed_reached_band;
        set.abs() <= band || (self.plant.velocity() - set).abs() <= set.abs() * 0.05 + band
    }
}
