//! The simulated drive seen through its PDO images.

mod common;

use cellrt_cia402::{Controlword, Cycles, CyclicBus, FsaState, RxPdo, Statusword};
use cellrt_emulator::sim::drive::FOLLOWING_ERROR_ALARM;
use cellrt_emulator::{PlantParams, SimBus, SimDriveParams};
use common::{csp, exchange, j5};

const CW_EO: Controlword = Controlword::ENABLE_OPERATION;

/// Runs until the drive is enabled via the TV-1 sequence; returns the last position.
fn enable(d: &mut cellrt_emulator::SimDrive) -> i32 {
    let mut tx = exchange(d, &csp(Controlword(0), 0));
    for cw in [0x0000, 0x0000, 0x0006, 0x0007, 0x000F] {
        tx = exchange(d, &csp(Controlword(cw), tx.position_actual));
    }
    assert_eq!(d.state(), FsaState::OperationEnabled);
    tx.position_actual
}

#[test]
fn starts_in_nrtso_without_statusword_then_sod() {
    let mut d = j5(SimDriveParams::default());
    assert_eq!(d.state(), FsaState::NotReadyToSwitchOn);
    let tx = exchange(&mut d, &RxPdo::default());
    assert_eq!(tx.statusword, Statusword(0));
    let tx = exchange(&mut d, &RxPdo::default());
    assert_eq!(
        tx.statusword.state_strict(),
        Some(FsaState::SwitchOnDisabled)
    );
    assert_eq!(tx.statusword, Statusword(0x0270));
    assert_eq!(tx.mode_display, 8);
}

#[test]
fn tv1_enable_sequence_and_tv3_shortcut() {
    let mut d = j5(SimDriveParams::default());
    enable(&mut d);
    let mut d = j5(SimDriveParams::default());
    exchange(&mut d, &csp(Controlword(0), 0));
    exchange(&mut d, &csp(Controlword(0), 0));
    let tx = exchange(&mut d, &csp(CW_EO, 0));
    assert_eq!(
        tx.statusword.state_strict(),
        Some(FsaState::OperationEnabled)
    );
    assert!(tx.statusword.drive_follows_command());
}

#[test]
fn ramp_following_error_is_nonzero_but_bounded() {
    let p = SimDriveParams::default();
    let mut d = j5(p);
    let start = enable(&mut d);
    let v = 1_000; // counts per 1 ms cycle = 1e6 counts/s
    let mut max_fe = 0i32;
    let mut last = 0;
    for k in 1..=3000 {
        let tx = exchange(&mut d, &csp(CW_EO, start + v * k));
        max_fe = max_fe.max(tx.following_error.abs());
        last = tx.following_error;
        assert_eq!(
            tx.following_error,
            start + v * k - tx.position_actual,
            "60F4h = 607Ah - 6064h"
        );
    }
    let kp = std::f64::consts::TAU * p.plant.position_bandwidth_hz;
    let expect = 1.0e6 / kp;
    assert!(last > 0, "lags behind");
    assert!(
        (f64::from(last) - expect).abs() < 0.05 * expect,
        "{last} vs {expect}"
    );
    assert!(f64::from(max_fe) < 1.5 * expect);
    assert_eq!(d.state(), FsaState::OperationEnabled);
}

#[test]
fn velocity_saturation_is_respected() {
    // Commands far beyond the motor's speed: overspeed detection off to see the saturation.
    let params = SimDriveParams {
        following_error_limit: u32::MAX,
        overspeed_limit: Some(f64::INFINITY),
        ..SimDriveParams::default()
    };
    let vmax = params.plant.max_velocity;
    let mut d = j5(params);
    enable(&mut d);
    let mut saw_max = false;
    for k in 1..=2000 {
        let tx = exchange(&mut d, &csp(CW_EO, 20_000 * k));
        let _ = tx;
        let v = d.plant().velocity().round();
        assert!(v.abs() <= vmax);
        saw_max |= v == vmax;
    }
    assert!(saw_max);
}

#[test]
fn following_error_alarm_trips_to_fault() {
    let params = SimDriveParams {
        following_error_limit: 5_000,
        ..SimDriveParams::default()
    };
    let mut d = j5(params);
    let start = enable(&mut d);
    let mut tripped_at = None;
    for k in 1..=2000 {
        let tx = exchange(&mut d, &csp(CW_EO, start + 1_000 * k));
        if tx.statusword.fault() {
            tripped_at = Some(k);
            break;
        }
        assert!(tx.following_error <= 5_000);
    }
    assert!(tripped_at.is_some());
    for _ in 0..500 {
        exchange(&mut d, &csp(CW_EO, 0));
    }
    assert_eq!(d.state(), FsaState::Fault);
    assert_eq!(d.alarm(), Some(FOLLOWING_ERROR_ALARM));
    assert_eq!(d.tx_pdo().error_code, FOLLOWING_ERROR_ALARM);
    assert_eq!(d.plant().velocity(), 0.0, "fault reaction stops the motor");
}

#[test]
fn inject_alarm_goes_through_fra_to_fault_and_resets_on_edge() {
    let mut d = j5(SimDriveParams::default());
    enable(&mut d);
    d.inject_alarm(0x0321);
    assert_eq!(d.state(), FsaState::FaultReactionActive);
    let tx = exchange(&mut d, &csp(Controlword(0), 0));
    assert_eq!(tx.statusword.state_strict(), Some(FsaState::Fault));
    assert!(tx.statusword.fault());
    assert_eq!(d.alarm(), Some(0x0321));
    // 0x0000 then 0x0080: a rising edge of bit 7 (15).
    exchange(&mut d, &csp(Controlword(0x80), 0));
    assert_eq!(d.state(), FsaState::SwitchOnDisabled, "0->1 edge resets");
    assert_eq!(d.alarm(), None);
    let mut d2 = j5(SimDriveParams::default());
    enable(&mut d2);
    exchange(&mut d2, &csp(Controlword(0x8F), 0));
    d2.inject_alarm(1);
    exchange(&mut d2, &csp(Controlword(0x80), 0));
    exchange(&mut d2, &csp(Controlword(0x80), 0));
    assert_eq!(d2.state(), FsaState::Fault, "bit 7 already high: no edge");
}

#[test]
fn quick_stop_ends_in_sod_and_does_not_return_to_oe() {
    // TV-4.
    let mut d = j5(SimDriveParams::default());
    let start = enable(&mut d);
    for k in 1..=200 {
        exchange(&mut d, &csp(CW_EO, start + 1_000 * k));
    }
    let tx = exchange(&mut d, &csp(Controlword(0x000B), 0));
    assert_eq!(
        tx.statusword.state_strict(),
        Some(FsaState::QuickStopActive)
    );
    let tx = exchange(&mut d, &csp(CW_EO, 0));
    assert_eq!(tx.statusword.state(), Some(FsaState::QuickStopActive));
    let mut n = 0;
    while d.state() == FsaState::QuickStopActive && n < 1000 {
        exchange(&mut d, &csp(CW_EO, 0));
        n += 1;
    }
    assert_eq!(d.state(), FsaState::SwitchOnDisabled);
    assert_eq!(d.plant().velocity(), 0.0);
}

#[test]
fn mode_display_echoes_supported_modes_only() {
    let mut d = j5(SimDriveParams::default());
    let mut rx = RxPdo {
        mode: 9,
        ..RxPdo::default()
    };
    assert_eq!(exchange(&mut d, &rx).mode_display, 9);
    rx.mode = 0;
    assert_eq!(exchange(&mut d, &rx).mode_display, 9, "0 = no mode change");
    rx.mode = -101;
    assert_eq!(exchange(&mut d, &rx).mode_display, 9, "manufacturer mode");
    rx.mode = 42;
    assert_eq!(exchange(&mut d, &rx).mode_display, 9);
    rx.mode = 1;
    assert_eq!(exchange(&mut d, &rx).mode_display, 1);
}

#[test]
fn mode_switch_waits_for_zero_speed() {
    // §4.3 / TV-9.
    let mut d = j5(SimDriveParams::default());
    let start = enable(&mut d);
    for k in 1..=100 {
        exchange(&mut d, &csp(CW_EO, start + 1_000 * k));
    }
    let mut rx = csp(CW_EO, start + 100_000);
    rx.mode = 1;
    assert_eq!(exchange(&mut d, &rx).mode_display, 8, "moving: stays csp");
    let mut tx = exchange(&mut d, &rx);
    for _ in 0..3000 {
        if tx.mode_display == 1 {
            break;
        }
        rx.controlword = Controlword(0x0007);
        tx = exchange(&mut d, &rx);
    }
    assert_eq!(tx.mode_display, 1);
}

#[test]
fn determinism_over_10k_cycles() {
    let mut a = j5(SimDriveParams::default());
    let mut b = j5(SimDriveParams::default());
    let mut rxb = [0u8; 24];
    let (mut ta, mut tb) = ([0u8; 24], [0u8; 24]);
    let p = a.profile().clone();
    let mut seed = 0x1234_5678u32;
    for k in 0..10_000i32 {
        seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        let cw = match k {
            0..=3 => 0,
            4 => 6,
            5 => 7,
            k if k % 3000 == 2999 => 0x0B,
            k if k % 3000 < 5 => 0x80 * u16::from(k % 2 == 0),
            _ => 0x0F,
        };
        let target = (k % 2000) * 700 + (seed % 50) as i32;
        let rx = csp(Controlword(cw), target);
        p.pdo.rx.encode_rx(&rx, &mut rxb).unwrap();
        a.cycle(&rxb, &mut ta, Cycles(1)).unwrap();
        b.cycle(&rxb, &mut tb, Cycles(1)).unwrap();
        assert_eq!(ta, tb, "cycle {k}");
    }
    assert_eq!(
        a.plant().position().to_bits(),
        b.plant().position().to_bits()
    );
}

#[test]
fn bad_images_return_errors_and_change_nothing() {
    let mut d = j5(SimDriveParams::default());
    let mut tx = [0u8; 24];
    assert!(d.cycle(&[0u8; 3], &mut tx, Cycles(1)).is_err());
    assert!(d.cycle(&[0u8; 24], &mut [0u8; 10], Cycles(1)).is_err());
    assert_eq!(d.state(), FsaState::NotReadyToSwitchOn);
}

#[test]
fn sim_bus_exchanges_every_axis() {
    let params = SimDriveParams {
        plant: PlantParams::default(),
        ..SimDriveParams::default()
    };
    let mut bus = SimBus::new(vec![j5(params), j5(params)]);
    assert_eq!(bus.axis_count(), 2);
    assert_eq!(bus.rx_image_mut(0).len(), 24);
    assert_eq!(bus.tx_image(1).len(), 24);
    assert!(bus.rx_image_mut(7).is_empty());
    let map = bus.drive(0).profile().pdo.rx.clone();
    for _ in 0..3 {
        map.encode_rx(&csp(Controlword(0), 0), bus.rx_image_mut(0))
            .unwrap();
        map.encode_rx(&csp(Controlword(0), 0), bus.rx_image_mut(1))
            .unwrap();
        bus.exchange(Cycles(1)).unwrap();
    }
    map.encode_rx(&csp(Controlword(0x0F), 0), bus.rx_image_mut(1))
        .unwrap();
    bus.exchange(Cycles(1)).unwrap();
    assert_eq!(bus.drive(0).state(), FsaState::SwitchOnDisabled);
    assert_eq!(bus.drive(1).state(), FsaState::OperationEnabled);
    let tx = bus
        .drive(1)
        .profile()
        .pdo
        .tx
        .decode_tx(bus.tx_image(1))
        .unwrap();
    assert_eq!(tx.statusword.state(), Some(FsaState::OperationEnabled));
    bus.drive_mut(0).inject_alarm(7);
    bus.exchange(Cycles(1)).unwrap();
    assert_eq!(bus.drive(0).state(), FsaState::Fault);
    assert!(bus.get_drive(2).is_none());
}

#[test]
fn identical_axes_of_one_bus_read_one_cycle_map() {
    let params = SimDriveParams::default();
    let slow = SimDriveParams {
        plant: PlantParams {
            velocity_bandwidth_hz: 100.0,
            ..PlantParams::default()
        },
        ..SimDriveParams::default()
    };
    let (a, b) = (j5(params), j5(params));
    assert!(
        !a.plant().shares_cycle_map_with(b.plant()),
        "each drive builds its own"
    );
    let bus = SimBus::new(vec![a, b, j5(slow)]);
    assert!(bus
        .drive(0)
        .plant()
        .shares_cycle_map_with(bus.drive(1).plant()));
    assert!(!bus
        .drive(0)
        .plant()
        .shares_cycle_map_with(bus.drive(2).plant()));
}
