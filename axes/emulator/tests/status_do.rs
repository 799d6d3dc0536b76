//! Status DO 1–3 (2D11h–2D13h) of the simulated MR-J4-TM, MR-J5-G-N1 and MR-JET-G-N1, read
//! from the TxPDO bytes (MR-J4-TM manual §5.3.2, MR-J5-G-N1 manual §7.3, MR-JET-G-N1 manual
//! §7.3): servo-on signals, zero speed, in-position, speed reached, the brake interlock on an
//! alarm.

mod common;

use cellrt_cia402::profiles::status_do::{StatusDo, StatusDoSignal as S};
use cellrt_cia402::{Controlword, DriveModel, RxPdo};
use cellrt_emulator::{SimDrive, SimDriveParams};
use common::{csp, drive, enabled, exchange, next_counter, send, VendorObjects};

const MODELS: [DriveModel; 3] = [
    DriveModel::MrJ4TM,
    DriveModel::MrJ5GN1,
    DriveModel::MrJetGN1,
];

fn on(s: StatusDo) -> Vec<&'static str> {
    s.symbols_on().collect()
}

fn csp_cycle(d: &mut SimDrive, target: i32) -> StatusDo {
    let rx = RxPdo {
        counter: next_counter(),
        ..csp(Controlword(0x000F), target)
    };
    exchange(d, &rx).status_do()
}

#[test]
fn servo_on_at_rest_moving_and_off() {
    for model in MODELS {
        let mut d = drive(model, 1000, SimDriveParams::default());
        send(&mut d, 0);
        send(&mut d, 0);
        send(&mut d, 0);
        let off = exchange(&mut d, &csp(Controlword(0), 0)).status_do();
        assert_eq!(on(off), ["S_ZSP"], "{model}: servo off at rest");
        enabled(&mut d);
        let pos = d.tx_pdo().position_actual;
        let rest = csp_cycle(&mut d, pos);
        assert_eq!(
            on(rest),
            ["S_SA", "S_MBR", "S_INP", "S_ZSP", "S_DB"],
            "{model}: servo on at rest, wire words {:#06x?}",
            rest.0
        );
        // 2 000 counts per 1 ms cycle: moving, soon at the set speed, droop beyond 100 counts.
        let mut target = pos;
        let mut s = rest;
        for _ in 0..300 {
            target += 2_000;
            s = csp_cycle(&mut d, target);
        }
        assert!(!s.get(S::ZeroSpeed), "{model}: moving");
        assert!(s.get(S::SpeedReached), "{model}: at 2 000 000 counts/s");
        assert!(
            !s.get(S::InPosition),
            "{model}: droop {}",
            d.tx_pdo().following_error
        );
        assert!(s.get(S::BrakeInterlock) && s.get(S::DynamicBrakeOutput));
        // An alarm: S_MBR off at once (the brake must hold), the servo goes off.
        d.inject_alarm(0x0321);
        let s = csp_cycle(&mut d, target);
        assert!(!s.get(S::BrakeInterlock), "{model}: S_MBR off on an alarm");
        assert!(
            !s.get(S::DynamicBrakeOutput),
            "{model}: S_DB off: the brake acts"
        );
    }
}

#[test]
fn a_model_without_status_do_in_its_txpdo_sends_none() {
    let mut d = drive(DriveModel::MrJ3T04, 1000, SimDriveParams::default());
    enabled(&mut d);
    assert_eq!(d.tx_pdo().status_do(), StatusDo::default());
}

/// Statusword bit 13 in csp: set once the droop has stayed at or above the window for the time
/// out (MR-J3-T04 manual §8.5.2, MR-J4-TM manual §5.4.4), cleared when it falls below.
#[test]
fn statusword_bit_13_after_the_following_error_time_out() {
    for model in [DriveModel::MrJ3T04, DriveModel::MrJ4TM] {
        let params = SimDriveParams {
            following_error_window: 500,
            following_error_time_out_ms: 10,
            ..SimDriveParams::default()
        };
        let mut d = drive(model, 1000, params);
        enabled(&mut d);
        let mut target = d.tx_pdo().position_actual;
        let mut over = 0;
        let mut bit_at = None;
        for k in 0..200 {
            target += 2_000;
            let rx = RxPdo {
                counter: next_counter(),
                ..csp(Controlword(0x000F), target)
            };
            let tx = exchange(&mut d, &rx);
            let bit = tx.statusword.0 & (1 << 13) != 0;
            if tx.following_error.unsigned_abs() >= 500 {
                over += 1;
            } else {
                over = 0;
            }
            // Set exactly from the 10th cycle (10 ms) in a row over the window.
            assert_eq!(bit, over >= 10, "{model}: cycle {k}, {over} cycles over");
            if bit {
                bit_at.get_or_insert(k);
            }
        }
        assert!(bit_at.is_some(), "{model}: bit 13 never set");
        // At rest the droop settles inside the window and the bit clears.
        for _ in 0..300 {
            let rx = RxPdo {
                counter: next_counter(),
                ..csp(Controlword(0x000F), target)
            };
            exchange(&mut d, &rx);
        }
        assert_eq!(d.tx_pdo().statusword.0 & (1 << 13), 0, "{model}");
    }
}
