//! What the CiA 402 sequencers (`cia402::{master, mode_switch, homing}`) take from a drive
//! profile: each is given only the facts it needs, so `cia402` knows no profile.

use super::DriveProfile;
use crate::cycles::{CycleTime, Cycles};
use crate::homing::HomingFacts;
use crate::master::{AxisMaster, MasterParams};
use crate::mode::ModeOfOperation;
use crate::mode_switch::{ModeSwitch, ModeSwitchError, ModeSwitchParams};
use crate::pdo::objects::{CONTROLWORD2, MODES_OF_OPERATION_DISPLAY, STATUSWORD2};

impl DriveProfile {
    /// The homing facts of the model: its 6098h methods, home setting by Controlword2 and
    /// whether its default PDOs carry 6061h and 2001h/2011h.
    pub fn homing_facts(&self) -> HomingFacts {
        HomingFacts {
            name: self.name,
            methods: self.homing.methods,
            data_set_methods: self.homing.data_set_methods,
            home_setting: self.homing.setting,
            shows_mode: self.pdo.tx.maps(MODES_OF_OPERATION_DISPLAY),
            carries_controlword2: self.pdo.rx.maps(CONTROLWORD2) && self.pdo.tx.maps(STATUSWORD2),
            no_methods_statement: super::homing_methods::no_methods_statement(self.model),
        }
    }
}

impl From<&DriveProfile> for HomingFacts {
    fn from(profile: &DriveProfile) -> Self {
        profile.homing_facts()
    }
}

impl AxisMaster {
    /// A master for a drive of `profile` at `cycle`: the model's fault-reset hold
    /// ([`DriveProfile::fault_reset_hold`]) and, on a drive without quick stop, the
    /// [`crate::master::QuickStopSubstitute::Shutdown`] substitute.
    pub fn for_profile(
        profile: &DriveProfile,
        cycle: CycleTime,
        transition_timeout: Cycles,
    ) -> Self {
        let params = MasterParams {
            fault_reset_hold: profile.fault_reset_hold(cycle),
            transition_timeout,
        };
        AxisMaster::for_drive(params, profile.quirks)
    }
}

impl ModeSwitch {
    /// [`ModeSwitch::new`] with the drive's csp entry, refusing a mode `profile` does not list.
    pub fn for_profile(
        profile: &DriveProfile,
        to: ModeOfOperation,
        position_offset: i32,
        params: ModeSwitchParams,
    ) -> Result<Self, ModeSwitchError> {
        ModeSwitch::for_modes(&profile.cycle.modes, to, position_offset, params)
            .map(|s| s.with_csp_entry(profile.cycle.csp_entry))
    }
}

#[cfg(test)]
mod tests {
    use crate::homing::tests::{sw, P};
    use crate::homing::{
        choose_method, choose_procedure, HomeProcedure, HomeSettingEdge, HomingFailure,
        HomingPhase, HomingSequencer,
    };
    use crate::mode::ModeOfOperation;
    use crate::profiles::{profile, DriveModel};

    #[test]
    fn the_method_is_one_the_manual_lists_on_a_drive_that_shows_6061h() {
        let j4 = profile(DriveModel::MrJ4TM);
        assert_eq!(choose_method(j4, None), Ok(-3));
        assert_eq!(choose_method(j4, Some(35)), Ok(35));
        assert!(choose_method(j4, Some(99))
            .unwrap_err()
            .to_string()
            .contains("no homing method 99"));
        let j5 = profile(DriveModel::MrJ5GN1);
        assert!(choose_method(j5, None)
            .unwrap_err()
            .to_string()
            .contains("lists no homing methods"));
        let j3 = profile(DriveModel::MrJ3T04);
        assert!(choose_method(j3, Some(35))
            .unwrap_err()
            .to_string()
            .contains("6061h"));
    }

    #[test]
    fn the_procedure_is_hm_where_it_can_be_used_else_the_c_cr_clear_method() {
        let j3 = profile(DriveModel::MrJ3T04);
        assert_eq!(
            choose_procedure(j3, None, None),
            Ok(HomeProcedure::Controlword2(HomeSettingEdge::Clear))
        );
        assert_eq!(
            choose_procedure(j3, None, Some(HomeSettingEdge::ClearZ)),
            Ok(HomeProcedure::Controlword2(HomeSettingEdge::ClearZ))
        );
        assert!(choose_procedure(j3, Some(35), None)
            .unwrap_err()
            .to_string()
            .contains("6061h"));
        assert!(choose_procedure(j3, Some(35), Some(HomeSettingEdge::Clear))
            .unwrap_err()
            .to_string()
            .contains("not both"));
        let j4 = profile(DriveModel::MrJ4TM);
        assert_eq!(
            choose_procedure(j4, None, None),
            Ok(HomeProcedure::HomingMode(-3))
        );
        assert!(choose_procedure(j4, None, Some(HomeSettingEdge::Clear))
            .unwrap_err()
            .to_string()
            .contains("no home setting by Controlword2"));
        let j5 = profile(DriveModel::MrJ5GN1);
        assert!(choose_procedure(j5, None, None)
            .unwrap_err()
            .to_string()
            .contains("lists no homing methods"));
    }

    #[test]
    fn a_controlword2_setting_raises_the_edge_until_s_oset_then_drops_it() {
        let bits = profile(DriveModel::MrJ3T04).homing.setting.unwrap();
        let mut h = HomingSequencer::new(P, ModeOfOperation::CyclicSyncPosition);
        h.start_setting(HomeSettingEdge::Clear, &bits, sw(0));
        let c = h.update(sw(0), 0, true, None, true).unwrap();
        assert_eq!(
            c.mode,
            ModeOfOperation::CyclicSyncPosition,
            "no mode change"
        );
        assert_eq!((c.start_bit, c.controlword2), (0, 1 << 7));
        let c = h.update(sw(0), 0, true, None, true).unwrap();
        assert_eq!(c.controlword2, 1 << 7);
        // S_OSET: drop the bit, wait for S_OSET to drop.
        let c = h.update(sw(0), 1 << 8, true, None, true).unwrap();
        assert_eq!(c.controlword2, 0);
        assert_eq!(h.phase(), HomingPhase::SettingRelease(None));
        h.update(sw(0), 1 << 8, true, None, true);
        assert!(h.is_active());
        h.update(sw(0), 0, true, None, true);
        assert_eq!(h.phase(), HomingPhase::Done(None));

        // C_CR2 answered by a new warning (AL.96): refused; an older warning is not its answer.
        h.start_setting(HomeSettingEdge::ClearZ, &bits, sw(0));
        let c = h.update(sw(0), 0, true, None, true).unwrap();
        assert_eq!(c.controlword2, 1 << 6);
        let c = h.update(sw(1 << 7), 0, true, None, true).unwrap();
        assert_eq!(
            h.phase(),
            HomingPhase::SettingRelease(Some(HomingFailure::SettingRefused))
        );
        assert_eq!(c.controlword2, 0);
        h.update(sw(1 << 7), 0, true, None, true);
        assert_eq!(
            h.phase(),
            HomingPhase::Done(Some(HomingFailure::SettingRefused))
        );
        h.start_setting(HomeSettingEdge::Clear, &bits, sw(1 << 7));
        for _ in 0..5 {
            h.update(sw(1 << 7), 0, true, None, true);
        }
        assert_eq!(h.phase(), HomingPhase::Setting);
        // Never answered: times out (timeout 100 cycles), the bit is dropped.
        let mut raised = 0;
        while let Some(c) = h.update(sw(1 << 7), 0, true, None, true) {
            raised += usize::from(c.controlword2 != 0);
            assert!(raised < 200, "never times out");
        }
        assert_eq!(h.phase(), HomingPhase::Done(Some(HomingFailure::Timeout)));
        assert!((100..=101).contains(&(raised + 5)), "5 above + {raised}");
    }
}
