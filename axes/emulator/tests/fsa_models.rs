//! The FSA property test over every model's simulated drive: random controlword sequences only
//! take transitions the model's quirks allow, and the model-specific invariants hold.

mod common;

use cellrt_cia402::{Controlword, DriveModel, FsaState, RxPdo};
use cellrt_emulator::SimDriveParams;
use common::{drive, exchange};
use proptest::prelude::*;

fn any_cw() -> impl Strategy<Value = u16> {
    prop_oneof![
        prop::sample::select(vec![
            0x0000u16, 0x0002, 0x0006, 0x0007, 0x000B, 0x000F, 0x0080, 0x010F
        ]),
        any::<u16>(),
    ]
}

proptest! {
    #[test]
    fn every_model_only_takes_allowed_transitions(
        model in prop::sample::select(DriveModel::ALL.to_vec()),
        words in prop::collection::vec((any_cw(), any::<bool>()), 1..120),
    ) {
        let mut d = drive(model, 1000, SimDriveParams::default());
        let q = d.profile().quirks;
        let mut prev = 0u16;
        for (cw, alarm) in words {
            let before = d.state();
            if alarm && before == FsaState::OperationEnabled {
                d.inject_alarm(0x0999);
            }
            let from = d.state();
            let pos = d.tx_pdo().position_actual;
            let tx = exchange(&mut d, &RxPdo { mode: 8, controlword: Controlword(cw), target_position: pos, ..RxPdo::default() });
            let to = d.state();
            let ev = cw & 2 != 0;
            let qs = cw & 4 != 0;
            // Never (16) on any model; QSA only with a quick stop; bit 5 always 1 without one.
            prop_assert!(!(from == FsaState::QuickStopActive && to == FsaState::OperationEnabled), "{model}: (16)");
            if !q.has_quick_stop {
                prop_assert!(to != FsaState::QuickStopActive, "{model}");
                if to != FsaState::NotReadyToSwitchOn {
                    prop_assert!(tx.statusword.quick_stop(), "{model}: bit 5 must stay 1");
                }
            }
            // Shortcuts jump only where the model allows them.
            if from == FsaState::SwitchOnDisabled && matches!(to, FsaState::SwitchedOn | FsaState::OperationEnabled) {
                prop_assert!(q.shortcut_transitions);
            }
            // Leaving Fault needs a rising edge of bit 7.
            if from == FsaState::Fault && to != FsaState::Fault {
                prop_assert!(cw & 0x80 != 0 && prev & 0x80 == 0, "{model}");
            }
            // Quick Stop in OE: QSA with a quick stop, SOD without one.
            if from == FsaState::OperationEnabled && ev && !qs {
                // With a quick stop at standstill, (11) and the automatic (12) can fall into one
                // cycle: QSA or SOD. Without one: SOD (MR-J3-T04 §3.3 default).
                let ok = to == FsaState::SwitchOnDisabled
                    || (q.has_quick_stop && to == FsaState::QuickStopActive);
                prop_assert!(ok, "{}: {:?}", model, to);
            }
            // Bits 8 and 14 are 0 in what the simulator emits.
            prop_assert_eq!(tx.statusword.0 & 0x4100, 0);
            prev = cw;
        }
    }
}
