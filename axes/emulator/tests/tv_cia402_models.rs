//! Test vectors of MR-J4-TM manual, MR-JET-G-N1 manual and MR-J5-G-N1 manual against the
//! simulated drives and the master. Vectors the Review logs mark "do not rely on" are tested
//! only as the documented simulator default (named `*_configured_default`).

mod common;

use cellrt_cia402::profiles::{generic_cia402, mr_j4_tm, mr_j5_g_n1, mr_jet_g_n1};
use cellrt_cia402::{
    profile, AxisMaster, Controlword, CycleTime, Cycles, CyclicBus, DriveModel, FsaState,
    MasterRequest, ModeOfOperation, RxPdo,
};
use cellrt_emulator::sim::drive::TorqueLimit2;
use cellrt_emulator::{SimBus, SimDrive, SimDriveParams};
use common::{boot, csp, drive, enabled, exchange, lost, masked, move_csp, send};

const CYCLIC_1601: [DriveModel; 3] = [
    DriveModel::MrJ4TM,
    DriveModel::MrJetGN1,
    DriveModel::MrJ5GN1,
];

fn d(model: DriveModel) -> SimDrive {
    drive(model, 1000, SimDriveParams::default())
}

/// TV-1 of every model: SOD → RTSO → SO → OE (and back on MR-JET).
fn tv_1(model: DriveModel) {
    let mut d = d(model);
    boot(&mut d);
    assert!(masked(send(&mut d, 0x0000), 0x414F, 0x0040));
    assert!(masked(send(&mut d, 0x0006), 0x416F, 0x0021));
    assert!(masked(send(&mut d, 0x0007), 0x416F, 0x0023));
    assert!(masked(send(&mut d, 0x000F), 0x416F, 0x0027));
    assert!(masked(send(&mut d, 0x0007), 0x416F, 0x0023));
    assert!(masked(send(&mut d, 0x0006), 0x416F, 0x0021));
    assert!(masked(send(&mut d, 0x0000), 0x414F, 0x0040));
}

#[test]
fn tv_1_normal_enable_mr_j4_tm() {
    tv_1(DriveModel::MrJ4TM);
}

#[test]
fn tv_1_normal_enable_mr_jet_g_n1() {
    tv_1(DriveModel::MrJetGN1);
}

#[test]
fn tv_1_enable_axis_a_mr_j5_g_n1() {
    tv_1(DriveModel::MrJ5GN1);
    tv_1(DriveModel::MrJ5W2GN1);
    tv_1(DriveModel::MrJ5W3GN1);
}

#[test]
fn tv_2_skipped_enable_and_tv_3_shortcuts() {
    // J4-TM TV-2, JET TV-2, J5 TV-3.
    for model in CYCLIC_1601 {
        for (path, cw, want) in [
            (&[][..], 0x0007u16, 0x0023u16),
            (&[][..], 0x000F, 0x0027),
            (&[0x06u16][..], 0x000F, 0x0027),
        ] {
            let mut d = d(model);
            boot(&mut d);
            for &w in path {
                send(&mut d, w);
            }
            assert!(masked(send(&mut d, cw), 0x006F, want), "{model}");
        }
    }
}

#[test]
fn tv_3_disable_paths_mr_j4_tm() {
    let cases: [(&[u16], u16, u16, u16); 7] = [
        (&[0x0F], 0x0007, 0x6F, 0x23),
        (&[0x0F], 0x0006, 0x6F, 0x21),
        (&[0x0F], 0x0000, 0x4F, 0x40),
        (&[0x06, 0x07], 0x0006, 0x6F, 0x21),
        (&[0x06, 0x07], 0x0000, 0x4F, 0x40),
        (&[0x06, 0x07], 0x0002, 0x4F, 0x40),
        (&[0x06], 0x0002, 0x4F, 0x40),
    ];
    for (path, cw, mask, want) in cases {
        let mut d = d(DriveModel::MrJ4TM);
        boot(&mut d);
        for &w in path {
            send(&mut d, w);
        }
        assert!(masked(send(&mut d, cw), mask, want), "{path:?} + {cw:#06x}");
    }
}

#[test]
fn tv_5_disable_voltage_from_oe_mr_jet_g_n1() {
    let mut d = d(DriveModel::MrJetGN1);
    enabled(&mut d);
    assert!(masked(send(&mut d, 0x0000), 0x414F, 0x0040));
}

/// Quick stop from a moving OE: QSA with bit 5 = 0, 0x000F does not return to OE, SOD by itself.
fn tv_quick_stop(model: DriveModel) {
    let mut d = d(model);
    enabled(&mut d);
    move_csp(&mut d, 2_000, 200);
    assert!(d.tx_pdo().statusword.quick_stop());
    let sw = send(&mut d, 0x000B);
    assert!(
        masked(sw, 0x416F, 0x0007) && !sw.quick_stop(),
        "{model}: {sw}"
    );
    let mut states = Vec::new();
    for _ in 0..1000 {
        let sw = send(&mut d, 0x000F);
        states.push(sw.state());
        if d.state() == FsaState::SwitchOnDisabled {
            break;
        }
    }
    assert!(
        !states.contains(&Some(FsaState::OperationEnabled)),
        "{model}: no (16)"
    );
    assert_eq!(
        d.state(),
        FsaState::SwitchOnDisabled,
        "{model}: (12) by itself"
    );
    assert_eq!(d.plant().velocity(), 0.0);
    // (12b): Disable Voltage during QSA.
    let mut d2 = drive(model, 1000, SimDriveParams::default());
    enabled(&mut d2);
    move_csp(&mut d2, 2_000, 200);
    send(&mut d2, 0x000B);
    assert!(masked(send(&mut d2, 0x0000), 0x414F, 0x0040));
}

#[test]
fn tv_4_quick_stop_mr_j4_tm() {
    tv_quick_stop(DriveModel::MrJ4TM);
}

#[test]
fn tv_3_quick_stop_mr_jet_g_n1() {
    tv_quick_stop(DriveModel::MrJetGN1);
}

/// MR-JET-G-N1 TV-3 with 605Ah ∈ 5–8 (FW D0 or later, §7.1): the drive stays in Quick stop
/// active after the stop; Enable Operation returns it to Operation enabled (16), and Disable
/// Voltage after the stop gives Switch on disabled (12B).
#[test]
fn tv_3_quick_stop_options_5_to_8_stay_in_qsa_mr_jet_g_n1() {
    for code in 5i16..=8 {
        for (cw, want_mask, want) in [(0x000Fu16, 0x416F, 0x0027), (0x0000, 0x414F, 0x0040)] {
            let mut d = d(DriveModel::MrJetGN1);
            d.sdo_download(0x605A, 0, &code.to_le_bytes()).unwrap();
            enabled(&mut d);
            move_csp(&mut d, 2_000, 200);
            let sw = send(&mut d, 0x000B);
            assert!(masked(sw, 0x416F, 0x0007), "{code}: QSA {sw}");
            // The stop ends and the drive stays in QSA (0x0007), not SOD.
            for _ in 0..1000 {
                send(&mut d, 0x000B);
            }
            assert_eq!(d.plant().velocity(), 0.0, "{code}: stopped");
            assert_eq!(d.state(), FsaState::QuickStopActive, "{code}");
            let sw = send(&mut d, cw);
            assert!(masked(sw, want_mask, want), "{code}: {cw:#06x} gives {sw}");
        }
    }
    // MR-J5 does not support (16) and 605Ah 5–8 is outside its documented 1–4.
    let mut j5 = d(DriveModel::MrJ5GN1);
    assert!(j5.sdo_download(0x605A, 0, &6i16.to_le_bytes()).is_err());
}

#[test]
fn tv_4_quick_stop_mr_j5_g_n1() {
    tv_quick_stop(DriveModel::MrJ5GN1);
    tv_quick_stop(DriveModel::MrJ5W3GN1);
}

/// Fault → 0x0000 → 0x0080 held for the model's hold → SOD → enable; the master holds exactly
/// the hold at every cycle time the model supports.
fn tv_fault_reset(model: DriveModel, expect: &[(u32, u32)]) {
    let p = profile(model);
    for &(us, n) in expect {
        let ct = CycleTime::from_micros(us).unwrap();
        assert_eq!(p.fault_reset_hold(ct), Cycles(n), "{model} {us} µs");
        let mut d = SimDrive::new(p, SimDriveParams::default(), ct);
        enabled(&mut d);
        d.inject_alarm(0x0321);
        let sw = send(&mut d, 0x000F);
        assert!(masked(sw, 0x414F, 0x0008) && sw.fault());
        let mut m = AxisMaster::for_profile(p, ct, Cycles(200));
        m.request(MasterRequest::Enable);
        let mut cws = Vec::new();
        for _ in 0..400 {
            let cw = m.update(d.tx_pdo().statusword);
            cws.push(cw);
            send(&mut d, cw.0);
            if m.is_enabled() {
                break;
            }
        }
        let first = cws.iter().position(|c| c.fault_reset()).unwrap();
        assert!(first == 0 || !cws[first - 1].fault_reset());
        let held = cws[first..].iter().take_while(|c| c.fault_reset()).count() as u32;
        assert_eq!(held, n, "{model} {us} µs");
        assert!(m.is_enabled(), "{model} {us} µs");
    }
    // A non-resettable alarm stays in Fault.
    if let Some(a) = p.faults.alarms.iter().find(|a| !a.resettable()) {
        let mut d = d(model);
        enabled(&mut d);
        d.inject_alarm(a.code);
        send(&mut d, 0);
        for _ in 0..20 {
            send(&mut d, 0x80);
        }
        assert!(
            masked(d.tx_pdo().statusword, 0x414F, 0x0008),
            "{model} {}",
            a.display
        );
    }
}

#[test]
fn tv_5_fault_and_reset_mr_j4_tm() {
    tv_fault_reset(
        DriveModel::MrJ4TM,
        &[(250, 40), (500, 20), (1000, 10), (2000, 5)],
    );
}

#[test]
fn tv_4_fault_and_reset_mr_jet_g_n1() {
    tv_fault_reset(
        DriveModel::MrJetGN1,
        &[
            (125, 80),
            (250, 40),
            (500, 20),
            (1000, 10),
            (2000, 5),
            (4000, 3),
            (8000, 3),
        ],
    );
}

#[test]
fn tv_5_fault_reset_hold_8ms_mr_j5_g_n1() {
    tv_fault_reset(
        DriveModel::MrJ5GN1,
        &[
            (125, 80),
            (250, 40),
            (500, 20),
            (1000, 10),
            (2000, 5),
            (4000, 3),
            (8000, 3),
        ],
    );
    tv_fault_reset(DriveModel::MrJ5W2GN1, &[(250, 40), (8000, 3)]);
}

#[test]
fn tv_6_csp_start_mr_j4_tm() {
    let mut d = d(DriveModel::MrJ4TM);
    boot(&mut d);
    let p = d.profile();
    let pos = d.tx_pdo().position_actual;
    let rx = RxPdo {
        mode: 8,
        controlword: Controlword(0),
        target_position: pos,
        velocity_limit: 50_000,
        torque_limit_positive: 0x2710,
        torque_limit_negative: 0x2710,
        ..RxPdo::default()
    };
    let mut b = [0u8; 29];
    p.pdo.rx.encode_rx(&rx, &mut b).unwrap();
    assert_eq!(b[0], 0x08);
    assert_eq!(&b[1..3], &[0, 0]);
    assert_eq!(&b[9..13], &pos.to_le_bytes());
    assert_eq!(&b[17..21], &50_000u32.to_le_bytes());
    assert_eq!(&b[23..25], &[0x10, 0x27]);
    assert_eq!(&b[25..27], &[0x10, 0x27]);
    assert_eq!(exchange(&mut d, &rx).mode_display, 8);
    for cw in [0x06, 0x07, 0x0F] {
        send(&mut d, cw);
    }
    let tx = exchange(
        &mut d,
        &RxPdo {
            controlword: Controlword(0x0F),
            ..rx
        },
    );
    assert!(tx.statusword.drive_follows_command() && !tx.statusword.following_error());
    move_csp(&mut d, 500, 200);
    let tx = *d.tx_pdo();
    assert!(tx.position_actual > pos + 50_000 && tx.following_error > 0);
    // §5.2 warning: 60E0h/60E1h = 0 give no torque: the motor cannot follow.
    let mut z = drive(DriveModel::MrJ4TM, 1000, SimDriveParams::default());
    enabled(&mut z);
    let start = z.tx_pdo().position_actual;
    for k in 1..=50 {
        exchange(
            &mut z,
            &RxPdo {
                torque_limit_positive: 0,
                torque_limit_negative: 0,
                ..csp(Controlword(0x0F), start + 500 * k)
            },
        );
    }
    assert!(
        (z.tx_pdo().position_actual - start).abs() <= 1,
        "no torque, no motion"
    );
}

/// Mode switch to/from a position mode waits for zero speed while 6060h keeps being sent.
fn mode_gate(model: DriveModel, from: i8, to: i8) {
    let mut d = drive(
        model,
        1000,
        SimDriveParams {
            zero_speed: 10.0,
            ..SimDriveParams::default()
        },
    );
    enabled(&mut d);
    let mut rx = RxPdo {
        mode: from,
        controlword: Controlword(0x0F),
        target_velocity: 50_000,
        target_position: d.tx_pdo().position_actual,
        ..RxPdo::default()
    };
    exchange(&mut d, &rx);
    assert_eq!(d.tx_pdo().mode_display, from);
    if from == 8 {
        move_csp(&mut d, 1_000, 100);
    } else {
        for _ in 0..100 {
            exchange(&mut d, &rx);
        }
    }
    rx.mode = to;
    rx.target_position = d.tx_pdo().position_actual + 1_000;
    assert_eq!(
        exchange(&mut d, &rx).mode_display,
        from,
        "{model}: moving, stays"
    );
    rx.target_velocity = 0;
    let mut n = 0;
    while d.tx_pdo().mode_display != to && n < 3000 {
        rx.target_position = d.tx_pdo().position_actual;
        exchange(&mut d, &rx);
        n += 1;
    }
    assert_eq!(d.tx_pdo().mode_display, to, "{model}");
}

#[test]
fn tv_7_mode_switch_gate_mr_j4_tm() {
    mode_gate(DriveModel::MrJ4TM, 9, 8);
}

#[test]
fn tv_6_mode_switch_blocked_by_motion_mr_jet_g_n1() {
    mode_gate(DriveModel::MrJetGN1, 8, 9);
}

#[test]
fn tv_9_mode_switch_gate_mr_j5_g_n1() {
    mode_gate(DriveModel::MrJ5GN1, 8, 1);
}

#[test]
fn tv_8_modes_on_multi_axis_mr_j5w2() {
    let mut d = d(DriveModel::MrJ5W2GN1);
    enabled(&mut d);
    let rx = RxPdo {
        mode: 3,
        ..csp(Controlword(0x0F), d.tx_pdo().position_actual)
    };
    assert_eq!(
        exchange(&mut d, &rx).mode_display,
        8,
        "pv refused: 6061h keeps 8"
    );
    let p = profile(DriveModel::MrJ5W2GN1);
    assert!(!p.supports_mode(ModeOfOperation::ProfileTorque));
    assert!(p.supports_mode(ModeOfOperation::ProfilePosition));
}

#[test]
fn tv_2_enable_axis_b_on_mr_j5w2() {
    let p = profile(DriveModel::MrJ5W2GN1);
    assert_eq!(mr_j5_g_n1::axis_index(0x6040, 1), Some(0x6840));
    assert_eq!(mr_j5_g_n1::axis_index(0x6041, 2), Some(0x7041));
    assert_eq!(mr_j5_g_n1::axis_index(0x2D01, 1), Some(0x3D01));
    assert_eq!(mr_j5_g_n1::axis_index(0x1600, 2), Some(0x1620));
    assert_eq!(mr_j5_g_n1::axis_index(0x1C12, 1), Some(0x1C12));
    let ct = CycleTime::from_micros(1000).unwrap();
    let mut bus = SimBus::new(vec![
        SimDrive::new(p, SimDriveParams::default(), ct),
        SimDrive::new(p, SimDriveParams::default(), ct),
    ]);
    for k in 0..8 {
        for axis in 0..2 {
            let cw = if axis == 1 && k >= 3 {
                [0x06, 0x07, 0x0F, 0x0F, 0x0F][k - 3]
            } else {
                0
            };
            p.pdo
                .rx
                .encode_rx(&csp(Controlword(cw), 0), bus.rx_image_mut(axis))
                .unwrap();
        }
        bus.exchange(Cycles(1)).unwrap();
    }
    assert_eq!(bus.drive(0).state(), FsaState::SwitchOnDisabled);
    assert_eq!(bus.drive(1).state(), FsaState::OperationEnabled);
    // Leaving OP resets the station: axis B (enabled) alarms, axis A re-initialises.
    assert_eq!(bus.leave_op(), 1);
    assert_eq!(bus.drive(0).state(), FsaState::SwitchOnDisabled);
    assert_eq!(bus.drive(1).alarm(), Some(mr_j5_g_n1::AL_086_1));
}

#[test]
fn tv_6_cycle_time_limits_mr_j5() {
    let c = |us| CycleTime::from_micros(us).unwrap();
    assert!(profile(DriveModel::MrJ5GN1).supports_cycle_time(c(125)));
    for m in [DriveModel::MrJ5W2GN1, DriveModel::MrJ5W3GN1] {
        assert!(!profile(m).supports_cycle_time(c(125)), "{m}");
        assert!(profile(m).supports_cycle_time(c(250)), "{m}");
    }
}

#[test]
fn tv_7_pdo_size_mr_j5w3() {
    // 1600h + 1610h + 1620h = 72 bytes ≤ 120 at 0.25 ms.
    let p = profile(DriveModel::MrJ5W3GN1);
    assert_eq!(p.pdo.rx.byte_len() * usize::from(p.axes_per_unit), 72);
    assert_eq!(p.pdo.tx.byte_len() * usize::from(p.axes_per_unit), 72);
}

#[test]
fn tv_10_cycle_time_mr_jet_g_n1() {
    let p = profile(DriveModel::MrJetGN1);
    assert!(p.supports_cycle_time(CycleTime::from_micros(125).unwrap()));
    assert!(p.supports_cycle_time(CycleTime::from_micros(8000).unwrap()));
    assert!(CycleTime::from_micros(3000).is_err());
    assert_eq!(p.object(0x1C32, 2).and_then(|o| o.default), Some(250_000));
}

/// Clean disconnect (stop, Shutdown, PreOp) raises nothing; lost frames raise the model's alarm
/// under the configured sync-error counter model (+3 per lost, −1 per good, limit 4).
fn disconnect(model: DriveModel, alarm: u16) {
    let mut d = d(model);
    enabled(&mut d);
    let mut m = AxisMaster::for_profile(d.profile(), d.cycle_time(), Cycles(100));
    m.request(MasterRequest::Disable);
    for _ in 0..5 {
        let cw = m.update(d.tx_pdo().statusword);
        send(&mut d, cw.0);
    }
    assert!(m.ready_to_leave_op());
    assert_eq!(d.leave_op(), None, "{model}");
    for _ in 0..50 {
        lost(&mut d);
    }
    assert_eq!(d.alarm(), None);
    // Straight out of OP while enabled.
    let mut d = drive(model, 1000, SimDriveParams::default());
    enabled(&mut d);
    assert_eq!(d.leave_op(), Some(alarm), "{model}");
    // Frames lost in OE: configured counter model.
    let mut d = drive(model, 1000, SimDriveParams::default());
    enabled(&mut d);
    lost(&mut d);
    assert_eq!(d.alarm(), None, "{model}: 3 ≤ 4");
    send(&mut d, 0x0F);
    assert_eq!(d.sync_errors(), 2);
    lost(&mut d);
    assert_eq!(d.alarm(), Some(alarm), "{model}: 5 > 4");
}

#[test]
fn tv_11_disconnect_configured_default_mr_jet_g_n1() {
    disconnect(DriveModel::MrJetGN1, mr_jet_g_n1::AL_086_1);
}

#[test]
fn tv_13_disconnect_configured_default_mr_j5_g_n1() {
    disconnect(DriveModel::MrJ5GN1, mr_j5_g_n1::AL_086_1);
}

#[test]
fn watchdog_counter_provisional_default_mr_j4_tm() {
    // §8.3: 2D23h/2D24h are not in the default maps; the sim counts lost frames like the
    // sync-error counter and raises AL. 86.1 (provisional, configurable).
    disconnect(DriveModel::MrJ4TM, mr_j4_tm::AL_86_1);
    assert!(!profile(DriveModel::MrJ4TM).pdo.rx.has_counter());
}

#[test]
fn halt_stops_in_cyclic_modes_only_where_the_model_honours_it() {
    for (model, honoured) in [
        (DriveModel::MrJ5GN1, true),
        (DriveModel::MrJetGN1, true),
        (DriveModel::MrJ4TM, false),
        (DriveModel::MrJ3T04, false),
        (DriveModel::GenericCia402, false),
    ] {
        let mut d = d(model);
        enabled(&mut d);
        let mut m = AxisMaster::for_profile(d.profile(), d.cycle_time(), Cycles(100));
        m.request(MasterRequest::Enable);
        m.set_halt(true);
        let cw = m.update(d.tx_pdo().statusword);
        assert_eq!(cw.0, 0x010F, "{model}");
        let start = d.tx_pdo().position_actual;
        for k in 1..=100 {
            exchange(&mut d, &csp(cw, start + 200 * k));
        }
        let moved = d.tx_pdo().position_actual - start;
        assert_eq!(moved.abs() < 100, honoured, "{model}: moved {moved}");
        assert_eq!(d.state(), FsaState::OperationEnabled);
    }
}

#[test]
fn cst_torque_within_limits_mr_jet_g_n1() {
    let mut d = d(DriveModel::MrJetGN1);
    enabled(&mut d);
    let rx = RxPdo {
        mode: 10,
        controlword: Controlword(0x0F),
        target_torque: 1000, // 100.0 % rated = max_acceleration / 3
        // 2D20h = 300 × 0.01 r/min (the MR-JET default unit) = 3 r/min = 3 355 443.2 counts/s
        // of the simulated 2^26 counts/rev motor.
        velocity_limit: 300,
        ..RxPdo::default()
    };
    for _ in 0..3 {
        exchange(&mut d, &rx);
    }
    assert_eq!(d.tx_pdo().mode_display, 10);
    let tq = d.tx_pdo().torque_actual;
    assert!((990..=1010).contains(&tq), "{tq}");
    for _ in 0..400 {
        exchange(&mut d, &rx);
    }
    assert!(
        (d.plant().velocity() - 3_355_443.2).abs() < 1.0,
        "speed limit 2D20h: {}",
        d.plant().velocity()
    );
    // Torque limit 60E0h (not mapped on the JET default map: the RxPdo default applies) and
    // the limit through the plant: 50.0 % caps 100 %.
    let mut p = SimDrive::new(
        profile(DriveModel::MrJ4TM),
        SimDriveParams::default(),
        CycleTime::from_micros(1000).unwrap(),
    );
    enabled(&mut p);
    let rx = RxPdo {
        torque_limit_positive: 500,
        ..rx
    };
    for _ in 0..3 {
        exchange(&mut p, &rx);
    }
    let tq = p.tx_pdo().torque_actual;
    assert!((490..=510).contains(&tq), "{tq}");
}

fn with_limit_2(model: DriveModel, t2: TorqueLimit2) -> SimDrive {
    drive(
        model,
        1000,
        SimDriveParams {
            torque_limit_2: t2,
            ..SimDriveParams::default()
        },
    )
}

fn limits(d: &SimDrive, cw: u16, p: u16, n: u16) -> (f64, f64) {
    d.torque_limits_percent(&RxPdo {
        torque_limit_positive: p,
        torque_limit_negative: n,
        ..csp(Controlword(cw), 0)
    })
}

#[test]
fn tv_8_torque_limit_2_mr_jet_g_n1() {
    let t2 = TorqueLimit2 {
        select: true,
        positive: 500,
        ..TorqueLimit2::default()
    };
    let d = with_limit_2(DriveModel::MrJetGN1, t2);
    assert_eq!(limits(&d, 0x000F, 3000, 3000).0, 300.0, "bit 11 = 0: 60E0h");
    assert_eq!(
        limits(&d, 0x080F, 3000, 3000).0,
        50.0,
        "bit 11 = 1: 2D6Dh:02"
    );
    let off = with_limit_2(
        DriveModel::MrJetGN1,
        TorqueLimit2 {
            select: false,
            ..t2
        },
    );
    assert_eq!(
        limits(&off, 0x080F, 3000, 3000).0,
        300.0,
        "2D6Dh:01 = 0: no effect"
    );
}

#[test]
fn tv_11_torque_limit_2_mr_j5_g_n1() {
    let d = with_limit_2(
        DriveModel::MrJ5GN1,
        TorqueLimit2 {
            select: true,
            negative: 300,
            ..TorqueLimit2::default()
        },
    );
    assert_eq!(
        limits(&d, 0x100F, 2000, 2000),
        (200.0, 30.0),
        "bit 12: reverse 30.0 %"
    );
    assert_eq!(
        limits(&d, 0x000F, 2000, 1500),
        (200.0, 150.0),
        "no bit: 60E1h"
    );
    // The bits do not disturb the PDS: the drive still enables with them set.
    let mut e = with_limit_2(DriveModel::MrJ5GN1, TorqueLimit2::default());
    boot(&mut e);
    for cw in [0x1806, 0x1807, 0x180F] {
        send(&mut e, cw);
    }
    assert_eq!(e.state(), FsaState::OperationEnabled);
}

#[test]
fn tv_10_sdo_negative_cases_mr_j4_tm() {
    use cellrt_emulator::sim::sdo::SdoAbort;
    let mut d = d(DriveModel::MrJ4TM);
    boot(&mut d);
    // Write 1C32h:3 (any value) → 0609 0030h.
    assert_eq!(
        d.sdo_download(0x1C32, 3, &[0; 4]),
        Err(SdoAbort(0x0609_0030))
    );
    // 6040h is in the RxPDO → 0601 0006h.
    assert_eq!(
        d.sdo_download(0x6040, 0, &[0x0F, 0]),
        Err(SdoAbort(0x0601_0006))
    );
    // A non-existent index → 0602 0000h.
    assert_eq!(d.sdo_upload(0x5FFE, 0), Err(SdoAbort(0x0602_0000)));
    // A sub-index that does not exist → 0609 0011h.
    assert_eq!(
        d.sdo_download(0x6085, 7, &[0; 4]),
        Err(SdoAbort(0x0609_0011))
    );
    // 6041h (read only) → 0601 0002h.
    assert_eq!(
        d.sdo_download(0x6041, 0, &[0, 0]),
        Err(SdoAbort(0x0601_0002))
    );
    // A U32 object written with 2 bytes → 0607 0013h.
    assert_eq!(
        d.sdo_download(0x6085, 0, &[100, 0]),
        Err(SdoAbort(0x0607_0013))
    );
    // A good write reads back; PDO-mapped objects read their live value.
    d.sdo_download(0x6085, 0, &250u32.to_le_bytes()).unwrap();
    assert_eq!(d.sdo_upload(0x6085, 0), Ok(250));
    assert_eq!(
        d.sdo_upload(0x6041, 0),
        Ok(i64::from(d.tx_pdo().statusword.0))
    );
    // Out of range (1C32h:02 allows 250 000…2 000 000 ns) → 0609 0030h, nothing stored.
    assert_eq!(
        d.sdo_download(0x1C32, 2, &100u32.to_le_bytes()),
        Err(SdoAbort(0x0609_0030))
    );
    assert_eq!(d.sdo_upload(0x1C32, 2), Ok(250_000));
}

#[test]
fn tv_12_sdo_write_to_a_mapped_controlword_mr_j5_g_n1() {
    use cellrt_emulator::sim::sdo::SdoAbort;
    let mut d = d(DriveModel::MrJ5GN1);
    assert_eq!(
        d.sdo_download(0x6040, 0, &[0x06, 0]),
        Err(SdoAbort(0x0601_0006))
    );
    assert_eq!(d.sdo_download(0x6060, 0, &[9]), Err(SdoAbort(0x0601_0006)));
}

/// MR-J5-G-N1 TV-12, the rest: 1010h:01 ← "save" takes bit 0 from 0 back to 1 within about
/// 25 s (the simulator's `store_parameters_ms`, 25 000 by default), 1011h:01 takes only "load",
/// and 1C32h:0B answers 0609 0011h (the spec's [inferred] case: not relied on by the master).
#[test]
fn tv_12_store_restore_and_1c32h_0b_mr_j5_g_n1() {
    use cellrt_emulator::sim::sdo::{SdoAbort, LOAD_SIGNATURE, SAVE_SIGNATURE};
    let mut d = d(DriveModel::MrJ5GN1);
    boot(&mut d);
    assert_eq!(d.sdo_upload(0x1C32, 0x0B), Err(SdoAbort(0x0609_0011)));
    assert_eq!(d.sdo_upload(0x1010, 1), Ok(1));
    d.sdo_download(0x1010, 1, &SAVE_SIGNATURE.to_le_bytes())
        .unwrap();
    let mut saving = 0u32;
    while d.sdo_upload(0x1010, 1) == Ok(0) {
        saving += 1;
        assert!(saving <= 25_000, "bit 0 still 0 after 25 s");
        send(&mut d, 0);
    }
    assert_eq!(d.sdo_upload(0x1010, 1), Ok(1));
    assert!(
        saving >= 24_000,
        "the save took {saving} ms, not about 25 s"
    );
    assert_eq!(
        d.sdo_download(0x1011, 1, &0x6461_6F6Du32.to_le_bytes()),
        Err(SdoAbort::CANNOT_STORE),
        "anything other than 64616F6Ch is refused"
    );
    d.sdo_download(0x1011, 1, &LOAD_SIGNATURE.to_le_bytes())
        .unwrap();
    assert_eq!(d.sdo_upload(0x1011, 1), Ok(1));
}

#[test]
fn tv_8_homing_handshake_mr_j4_tm() {
    let mut d = drive(
        DriveModel::MrJ4TM,
        1000,
        SimDriveParams {
            initial_position: 777_000,
            home_position_address: 5000,
            ..SimDriveParams::default()
        },
    );
    enabled(&mut d);
    d.sdo_download(0x6098, 0, &[35]).unwrap();
    // 6060h = 6 through the RxPDO (mapped in 1600h).
    let tx = hm_cycle(&mut d, 0x000F);
    assert_eq!(tx.mode_display, 6);
    assert_eq!(tx.statusword.0 & 0x3400, 0x0400, "not started: 0/0/1");
    // HOS: completed successfully within 50 ms.
    let mut done_at = None;
    for k in 0..50 {
        let tx = hm_cycle(&mut d, 0x001F);
        if tx.statusword.0 & 0x3400 == 0x1400 {
            done_at = Some(k);
            break;
        }
    }
    assert!(done_at.is_some(), "bits 13/12/10 never 0/1/1");
    // ≥ 8 ms later 6064h is the home position address and stays there (no motion).
    for _ in 0..10 {
        hm_cycle(&mut d, 0x001F);
    }
    let p = d.tx_pdo().position_actual;
    assert_eq!(p, 5000);
    for _ in 0..20 {
        assert_eq!(hm_cycle(&mut d, 0x000F).position_actual, 5000);
    }
    assert_eq!(d.sdo_upload(0x607C, 0), Ok(0), "607Ch stays 0 without ABS");
}

#[test]
fn homing_on_a_drive_whose_manual_lists_no_method_is_an_error() {
    let mut d = d(DriveModel::MrJetGN1);
    enabled(&mut d);
    hm_cycle(&mut d, 0x000F);
    let tx = hm_cycle(&mut d, 0x001F);
    assert_eq!(tx.mode_display, 6);
    assert_eq!(tx.statusword.0 & 0x3400, 0x2400);
}

/// One hm cycle (6060h = 6 in the RxPDO, target at the actual position) with controlword `cw`.
fn hm_cycle(d: &mut SimDrive, cw: u16) -> cellrt_cia402::TxPdo {
    let rx = RxPdo {
        mode: 6,
        ..csp(Controlword(cw), d.tx_pdo().position_actual)
    };
    exchange(d, &rx)
}

#[test]
fn tv_13_infinite_feed_check_mr_jet_g_n1() {
    use cellrt_cia402::profiles::mr_jet_g_n1::{infinite_feed_gear, AL_037};
    assert_eq!(infinite_feed_gear(48, 1, 1 << 26), Ok((3072, 1)));
    assert_eq!(infinite_feed_gear(1, 1, 1 << 17), Err(AL_037), "m = 32768");
    // Just below and at the bound: 2^32 / 2^18 = 16384 is refused, 2^32 × 3 / (2^20 × 1) =
    // 12288 accepted.
    assert_eq!(infinite_feed_gear(1, 1, 1 << 18), Err(AL_037));
    assert_eq!(infinite_feed_gear(3, 1, 1 << 20), Ok((12288, 1)));
    assert_eq!(infinite_feed_gear(0, 1, 1 << 26), Err(AL_037));
}

#[test]
fn tv_9_sdo_mr_jet_g_n1() {
    use cellrt_emulator::sim::sdo::{SdoAbort, LOAD_SIGNATURE, SAVE_SIGNATURE};
    let mut d = drive(
        DriveModel::MrJetGN1,
        1000,
        SimDriveParams {
            store_parameters_ms: 50,
            ..SimDriveParams::default()
        },
    );
    boot(&mut d);
    assert_eq!(
        d.sdo_download(0x6040, 0, &[0x06, 0]),
        Err(SdoAbort(0x0601_0006))
    );
    assert_eq!(
        d.sdo_download(0x6041, 0, &[0, 0]),
        Err(SdoAbort(0x0601_0002))
    );
    assert_eq!(d.sdo_upload(0x5FFF, 0), Err(SdoAbort(0x0602_0000)));
    assert_eq!(d.sdo_upload(0x1C32, 3), Err(SdoAbort(0x0609_0011)));
    // Save: bit0 = 0 while saving, then 1.
    assert_eq!(d.sdo_upload(0x1010, 1), Ok(1));
    d.sdo_download(0x1010, 1, &SAVE_SIGNATURE.to_le_bytes())
        .unwrap();
    assert_eq!(d.sdo_upload(0x1010, 1), Ok(0));
    for _ in 0..60 {
        send(&mut d, 0);
    }
    assert_eq!(d.sdo_upload(0x1010, 1), Ok(1));
    assert_eq!(
        d.sdo_download(0x1010, 1, &0x1234_5678u32.to_le_bytes()),
        Err(SdoAbort::CANNOT_STORE)
    );
    // Restore: only "load" is accepted; reads back 1.
    assert_eq!(
        d.sdo_download(0x1011, 1, &0x1234_5678u32.to_le_bytes()),
        Err(SdoAbort::CANNOT_STORE)
    );
    d.sdo_download(0x1011, 1, &LOAD_SIGNATURE.to_le_bytes())
        .unwrap();
    assert_eq!(d.sdo_upload(0x1011, 1), Ok(1));
}

// The generic CiA 402 model (`drive = "cia402"`): plain CiA 402 / ETG.6010 behaviour.

#[test]
fn generic_cia402_normal_enable_and_no_shortcuts() {
    tv_1(DriveModel::GenericCia402);
    // Plain CiA 402: Switch On or Enable Operation from Switch on disabled is no transition;
    // the drive stays where it is (unlike the Mitsubishi shortcuts above).
    for cw in [0x0007u16, 0x000F] {
        let mut d = d(DriveModel::GenericCia402);
        boot(&mut d);
        assert!(
            masked(send(&mut d, cw), 0x004F, 0x0040),
            "{cw:#06x}: stays in Switch on disabled"
        );
    }
    let mut d = d(DriveModel::GenericCia402);
    boot(&mut d);
    send(&mut d, 0x0006);
    assert!(
        masked(send(&mut d, 0x000F), 0x006F, 0x0021),
        "RTSO + Enable Operation: no jump to OE"
    );
}

#[test]
fn generic_cia402_quick_stop_without_transition_16() {
    tv_quick_stop(DriveModel::GenericCia402);
}

#[test]
fn generic_cia402_fault_reset_hold_is_the_named_default_at_every_cycle() {
    // 10 ms (generic_cia402::FAULT_RESET_HOLD_MS), at least one cycle.
    assert_eq!(generic_cia402::FAULT_RESET_HOLD_MS, 10);
    tv_fault_reset(
        DriveModel::GenericCia402,
        &[
            (125, 80),
            (250, 40),
            (500, 20),
            (1000, 10),
            (2000, 5),
            (4000, 3),
            (8000, 2),
        ],
    );
}

#[test]
fn generic_cia402_lost_frames_and_leaving_op_raise_the_communication_code() {
    disconnect(DriveModel::GenericCia402, generic_cia402::COMMUNICATION);
    assert_eq!(generic_cia402::COMMUNICATION, 0x8100);
}

#[test]
fn generic_cia402_mode_switch_csp_csv_cst() {
    mode_gate(DriveModel::GenericCia402, 8, 9);
    mode_gate(DriveModel::GenericCia402, 9, 8);
    // cst: the torque follows 6071h, limited by 60E0h/60E1h as received (CiA 402).
    let mut d = d(DriveModel::GenericCia402);
    enabled(&mut d);
    let rx = RxPdo {
        mode: 10,
        controlword: Controlword(0x0F),
        target_torque: 300,
        ..RxPdo::default()
    };
    for _ in 0..3 {
        exchange(&mut d, &rx);
    }
    assert_eq!(d.tx_pdo().mode_display, 10);
    let tq = d.tx_pdo().torque_actual;
    assert!((290..=310).contains(&tq), "{tq}");
    // No velocity-limit object in CiA 402's cst: the motor accelerates up to its maximum speed.
    let v0 = d.plant().velocity();
    for _ in 0..50 {
        exchange(&mut d, &rx);
    }
    assert!(d.plant().velocity() > v0 && v0 > 0.0, "{v0}");
}

/// A `model` drive with a 5000-count following-error limit, enabled in csp and commanded
/// ahead by 1000 counts a cycle until it faults.
fn run_into_following_error(model: DriveModel) -> SimDrive {
    let mut d = drive(
        model,
        1000,
        SimDriveParams {
            following_error_limit: 5_000,
            ..SimDriveParams::default()
        },
    );
    enabled(&mut d);
    let start = d.tx_pdo().position_actual;
    for k in 1..=2000 {
        if exchange(&mut d, &csp(Controlword(0x0F), start + 1_000 * k))
            .statusword
            .fault()
        {
            break;
        }
    }
    d
}

#[test]
fn generic_cia402_following_error_and_overspeed_are_cia402_codes() {
    let p = profile(DriveModel::GenericCia402);
    assert_eq!(p.limits.following_error_alarm, 0x8611);
    assert_eq!(p.limits.overspeed_alarm, 0x8400);
    let d = run_into_following_error(DriveModel::GenericCia402);
    assert_eq!(d.alarm(), Some(0x8611));
    assert_eq!(d.tx_pdo().error_code, 0x8611, "603Fh in the default TxPDO");
}

#[test]
fn mr_j3_t04_following_error_alarm_lands_in_its_alarm_history() {
    // MR-J3-T04 manual §8.9: the newest alarm in 2030h; AL.52 (standard MR-J3-A error
    // excessive) is the profile's following-error alarm.
    let d = run_into_following_error(DriveModel::MrJ3T04);
    assert_eq!(d.alarm(), Some(0x0052));
    assert_eq!(d.sdo_upload(0x2030, 1), Ok(0x0052));
    assert_eq!(d.sdo_upload(0x2031, 1), Ok(0));
    assert_eq!(d.alarm_history().entry(0).number, 0x0052);
}

#[test]
fn generic_cia402_homing_on_the_current_position() {
    // hm with 6098h = 37 (the profile's default) and 35: home = the current position, no
    // motion; any other method ends in a homing error (statusword bit 13).
    for (method, ok) in [(None, true), (Some(35i8), true), (Some(1), false)] {
        let mut d = d(DriveModel::GenericCia402);
        enabled(&mut d);
        let start = d.tx_pdo().position_actual;
        move_csp(&mut d, 1_000, 50);
        for _ in 0..300 {
            exchange(&mut d, &csp(Controlword(0x0F), start + 50_000));
        }
        assert_eq!(d.alarm(), None);
        if let Some(m) = method {
            d.sdo_download(0x6098, 0, &[m as u8]).unwrap();
        }
        let pos = d.tx_pdo().position_actual;
        let hm = |cw: u16| RxPdo {
            mode: 6,
            controlword: Controlword(cw),
            target_position: pos,
            ..RxPdo::default()
        };
        // The mode switch waits for the axis to stand still.
        for _ in 0..3000 {
            if exchange(&mut d, &hm(0x0F)).mode_display == 6 {
                break;
            }
        }
        assert_eq!(d.tx_pdo().mode_display, 6);
        let sw = exchange(&mut d, &hm(0x1F)).statusword;
        let attained = sw.0 & (1 << 12) != 0;
        let error = sw.0 & (1 << 13) != 0;
        assert_eq!(
            (attained, error),
            (ok, !ok),
            "{method:?}: {sw} alarm {:?}",
            d.alarm()
        );
        // No motion: the servo loop only settles out (the switch took it at S_ZSP, ≤ 1 count/s).
        assert!(
            d.plant().velocity().abs() <= 1.0,
            "{method:?}: {} counts/s",
            d.plant().velocity()
        );
    }
}

/// 10F1h:02 Sync Error Counter Limit acts (ETG.1020; MR-JET/MR-J5 manual §2.4 name it as the
/// AL.086.1 threshold): written in PRE-OP, it replaces the default 4 from the next OP.
fn sync_error_limit_written(model: DriveModel, alarm: u16) {
    let mut d = d(model);
    assert_eq!(
        d.sdo_upload(0x10F1, 2),
        Ok(4),
        "{model}: the default in force"
    );
    d.leave_op();
    d.sdo_download(0x10F1, 2, &100u16.to_le_bytes()).unwrap();
    d.enter_op();
    enabled(&mut d);
    // +3 per lost frame: 99 ≤ 100 after 33, 102 > 100 at the 34th.
    for _ in 0..33 {
        lost(&mut d);
    }
    assert_eq!(d.alarm(), None, "{model}: 99 ≤ 100");
    lost(&mut d);
    assert_eq!(d.alarm(), Some(alarm), "{model}: 102 > 100");
}

#[test]
fn sync_error_limit_written_to_10f1h_acts_mr_jet_g_n1() {
    sync_error_limit_written(DriveModel::MrJetGN1, mr_jet_g_n1::AL_086_1);
}

#[test]
fn sync_error_limit_written_to_10f1h_acts_mr_j5_g_n1() {
    sync_error_limit_written(DriveModel::MrJ5GN1, mr_j5_g_n1::AL_086_1);
}

/// MR-J4-TM [Pr. PA01] (object 2001h [INFER], §1.3 groups): written by SDO it selects the
/// control-mode group at once: `___2` the profile modes (6061h = 1, RxPDO 1601h), `___0`/`___1`
/// back to the cyclic group (6061h = 8); `___6`/`___8` (point table, indexer: not modelled)
/// are refused with 0609 0030h. A drive built in the profile group reads PA01 = 1002h.
#[test]
fn pa01_selects_the_mr_j4_tm_control_mode_group() {
    use cellrt_emulator::sim::sdo::SdoAbort;
    let mut d = d(DriveModel::MrJ4TM);
    assert_eq!(d.sdo_upload(0x2001, 0), Ok(0x1000));
    assert_eq!(d.mode_display(), ModeOfOperation::CyclicSyncPosition);
    d.sdo_download(0x2001, 0, &0x1002u32.to_le_bytes()).unwrap();
    assert_eq!(d.profile().name, mr_j4_tm::PROFILE_MODE_GROUP.name);
    assert_eq!(d.mode_display(), ModeOfOperation::ProfilePosition);
    assert_eq!(d.tx_pdo().mode_display, 1, "6061h at once");
    assert_eq!(d.profile().pdo.rx.index, 0x1601);
    assert_eq!(
        d.sdo_download(0x2001, 0, &0x1006u32.to_le_bytes()),
        Err(SdoAbort::VALUE_RANGE)
    );
    d.sdo_download(0x2001, 0, &0x1001u32.to_le_bytes()).unwrap();
    assert_eq!(d.profile().name, mr_j4_tm::PROFILE.name);
    assert_eq!(d.mode_display(), ModeOfOperation::CyclicSyncPosition);
    let group = SimDrive::new(
        mr_j4_tm::ModeGroup::Profile.profile(),
        SimDriveParams::default(),
        cellrt_cia402::CycleTime::from_micros(1000).unwrap(),
    );
    assert_eq!(group.sdo_upload(0x2001, 0), Ok(0x1002));
    assert_eq!(group.mode_display(), ModeOfOperation::ProfilePosition);
}
