//! Homing (hm) with the data-set methods and the Controlword2 home setting with the Z phase.

use super::SimDrive;
use crate::cia402::controlword::Controlword;
use crate::cia402::fsa::FsaState;
use crate::cia402::mode::ModeOfOperation;
use crate::pdo::RxPdo;
use crate::profiles::HomeReference;
use crate::sim::home_setting::{HomeSettingOutcome, ZPhase};

/// What homing has done to this drive.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(super) struct HomingState {
    /// 607Ch Home offset.
    pub(super) home_offset: i32,
    /// Added to the motor position to give 6064h ([`HomeReference::PositionPreset`]).
    pub(super) position_shift: i64,
    /// Statusword bit 12 in hm: homing attained (cleared at power-on and at homing start).
    pub(super) attained: bool,
    /// Statusword bit 13 in hm: homing error.
    pub(super) error: bool,
    /// Controlword bit 4 (HOS) of the previous cycle.
    pub(super) hos: bool,
}

impl SimDrive {
    /// hm (6060h = 6): a rising controlword bit 4 (HOS) starts the method in 6098h. The
    /// data-set methods set home at the current position at once, without motion (also outside
    /// Operation enabled, MR-J3-T04 manual §8.11.3, §8.11.6); a method the manual does not list, or 0, ends in
    /// a homing error (bit 13). Methods that search a dog, a stroke end or the Z phase are not
    /// simulated (no dog or Z-phase model) and also end in a homing error.
    pub(super) fn run_homing(&mut self, cw: Controlword) {
        let hos = cw.0 & (1 << 4) != 0;
        let start = hos && !self.homing.hos;
        self.homing.hos = hos;
        if self.mode_display != ModeOfOperation::Homing || !start {
            return;
        }
        if matches!(self.state, FsaState::Fault | FsaState::FaultReactionActive) {
            return;
        }
        let method = self
            .sdo_value(0x6098, 0)
            .or_else(|| self.profile.object(0x6098, 0).and_then(|o| o.default))
            .unwrap_or(0) as i8;
        // Homing start clears bit 12 (MR-J4-TM manual §5.4.9 retention rules).
        self.homing.attained = false;
        self.homing.error = false;
        if !self.profile.data_set_homing_methods.contains(&method) {
            self.homing.error = true;
            return;
        }
        let raw = (self.plant.position().round() as i64) as i32;
        match self.profile.home_reference {
            HomeReference::OffsetObject => self.homing.home_offset = raw.wrapping_neg(),
            HomeReference::PositionPreset => {
                self.homing.position_shift =
                    i64::from(self.params.home_position_address) - i64::from(raw);
                // Re-reference the held command so the motor does not move.
                self.demand = self.plant.position();
                self.plant.set_last_command(self.demand);
                self.prev_target = self.position_actual();
            }
        }
        self.homing.attained = true;
    }

    /// Controlword2 home setting and the Z phase, on models that have them (MR-J3-T04 §8.3).
    pub(super) fn run_home_setting(&mut self, cmd: &RxPdo) {
        let Some(bits) = self.profile.home_setting else {
            return;
        };
        let raw = self.plant.position().round() as i64;
        if let Some(cpr) = self.profile.units.counts_per_rev {
            let z = ZPhase {
                counts_per_rev: i64::from(cpr),
                position: i64::from(self.params.z_phase_position),
            };
            self.home_set.track_encoder(raw, z);
        }
        let cyclic_position_or_velocity = matches!(
            self.mode_display,
            ModeOfOperation::CyclicSyncPosition | ModeOfOperation::CyclicSyncVelocity
        );
        if !(self.op && cyclic_position_or_velocity) {
            self.home_set.ignore(cmd.controlword2, &bits);
            return;
        }
        let position = self.position_actual();
        match self.home_set.controlword2(
            cmd.controlword2,
            &bits,
            position,
            self.params.before_z_reaction,
        ) {
            Some(HomeSettingOutcome::HomeOffset(v)) => {
                self.homing.home_offset = v;
                // PD22 note: the CR rising edge also clears the droop pulses.
                self.demand = self.plant.position();
            }
            Some(HomeSettingOutcome::Alarm(code)) => self.raise(code),
            None => {}
        }
    }

    /// 607Ch Home offset.
    pub fn home_offset(&self) -> i32 {
        self.homing.home_offset
    }
}
