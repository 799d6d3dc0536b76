//! MR-J3-T04 manual test vectors against the simulated MR-J3-T04 (and the master where it
//! applies), including the dog-type homing on simulated switches (§8.11.4.1).

mod common;

use cellrt_cia402::mode_switch::{
    ModeSwitch, ModeSwitchError, ModeSwitchParams, ModeSwitchProgress,
};
use cellrt_cia402::profiles::mr_j3_t04::{
    AL_34, AL_35, AL_36, AL_37, AL_61, AL_90, AL_99, AL_E6, AL_E9, MASTER_COUNTER_CHECK,
};
use cellrt_cia402::ModeOfOperation;
use cellrt_cia402::SharedSlice;
use cellrt_cia402::{
    profile, AxisMaster, Controlword, CounterParams, CounterVerdict, Cycles, CyclicBus, DriveModel,
    FaultInjection, FsaState, IncrementalCounter, MasterRequest, MasterState, PdoEntry, PdoMap,
    RxPdo,
};
use cellrt_emulator::sim::drive::InternalTorqueLimits;
use cellrt_emulator::{CommParams, SimBus, SimDrive, SimDriveParams};
use common::{
    boot, csp, drive, enabled, exchange, lost, masked, move_csp, next_counter, send, VendorObjects,
};

fn j3(params: SimDriveParams) -> SimDrive {
    drive(DriveModel::MrJ3T04, 1000, params)
}

fn po03(v: u16) -> SimDriveParams {
    SimDriveParams {
        comm: CommParams {
            po03: v,
            ..CommParams::default()
        },
        ..SimDriveParams::default()
    }
}

/// One exchange carrying counter `c` with the target at the actual position.
fn xc(d: &mut SimDrive, cw: u16, c: u8) -> cellrt_cia402::TxPdo {
    let rx = with_counter(d, cw, c);
    exchange(d, &rx)
}

/// An RxPDO carrying counter `c` and a target at the actual position.
fn with_counter(d: &SimDrive, cw: u16, c: u8) -> RxPdo {
    RxPdo {
        counter: c,
        ..csp(Controlword(cw), d.tx_pdo().position_actual)
    }
}

#[test]
fn tv_fsa_1_power_up_to_operation_enabled_and_back() {
    let mut d = j3(SimDriveParams::default());
    boot(&mut d);
    let steps: [(u16, u16); 7] = [
        (0x0000, 0x0060),
        (0x0006, 0x0021),
        (0x0007, 0x0023),
        (0x000F, 0x0027),
        (0x0007, 0x0023),
        (0x0006, 0x0021),
        (0x0000, 0x0060),
    ];
    for (cw, want) in steps {
        let sw = send(&mut d, cw);
        assert_eq!(sw.0 & 0x006F, want, "cw {cw:#06x}: sw {sw}");
        if cw == 0x000F {
            assert!(
                sw.drive_follows_command(),
                "csp bit 12 once targets are accepted"
            );
        }
    }
}

#[test]
fn tv_fsa_2_shortcuts_and_quick_stop_substitutes() {
    let cases: [(&[u16], u16, u16); 8] = [
        (&[], 0x000F, 0x0027),
        (&[], 0x0007, 0x0023),
        (&[0x06], 0x000F, 0x0027),
        (&[0x06, 0x07, 0x0F], 0x0006, 0x0021),
        (&[0x06, 0x07, 0x0F], 0x0000, 0x0060),
        // ⚠ the simulator defaults of §3.3: (10), (7), and Quick Stop in OE as Disable Voltage.
        (&[0x06, 0x07], 0x0002, 0x0060),
        (&[0x06], 0x0002, 0x0060),
        (&[0x06, 0x07, 0x0F], 0x0002, 0x0060),
    ];
    for (path, cw, want) in cases {
        let mut d = j3(SimDriveParams::default());
        boot(&mut d);
        for &w in path {
            send(&mut d, w);
        }
        let sw = send(&mut d, cw);
        assert_eq!(sw.0 & 0x006F, want, "after {path:?} + {cw:#06x}");
        assert!(sw.quick_stop(), "bit 5 always 1");
    }
}

#[test]
fn tv_fsa_3_fault_handling() {
    // 1. AL.35 from a csp step implying more than the maximum speed.
    let mut d = j3(SimDriveParams::default());
    enabled(&mut d);
    let pos = d.tx_pdo().position_actual;
    let sw = exchange(&mut d, &csp(Controlword::ENABLE_OPERATION, pos + 1_000_000)).statusword;
    assert!(sw.fault());
    let mut sw = sw;
    for _ in 0..200 {
        sw = send(&mut d, 0x0000);
    }
    assert!(
        masked(sw, 0x004F, 0x0008) && masked(sw, 0x006F, 0x0028),
        "{sw}"
    );
    assert_eq!(d.tx_pdo().error_code, 0x0035);
    assert_eq!(d.plant().velocity(), 0.0);
    // 2. 0x0080 held for 10 ms (10 cycles) resets; then TV-FSA-1 enables.
    let hold = profile(DriveModel::MrJ3T04).fault_reset_hold(d.cycle_time());
    assert_eq!(hold, Cycles(10));
    for _ in 0..hold.0 {
        sw = send(&mut d, 0x0080);
    }
    assert!(masked(sw, 0x004F, 0x0040));
    for cw in [0x06, 0x07, 0x0F] {
        sw = send(&mut d, cw);
    }
    assert!(masked(sw, 0x006F, 0x0027));
    // 3. AL.34 is not cleared by fault reset, only by a power cycle.
    d.inject_alarm(AL_34);
    for _ in 0..200 {
        send(&mut d, 0x0000);
    }
    for _ in 0..10 {
        sw = send(&mut d, 0x0080);
    }
    assert!(masked(sw, 0x004F, 0x0008), "AL.34 stays");
    d.power_cycle();
    boot(&mut d);
    assert_eq!(d.alarm(), None);
    // 4. Holding 0x0080 resets once; a second reset needs 0x0000 then 0x0080.
    d.inject_alarm(AL_35);
    send(&mut d, 0x0000);
    send(&mut d, 0x0080);
    assert_eq!(d.state(), FsaState::SwitchOnDisabled);
    d.inject_alarm(AL_35);
    send(&mut d, 0x0080);
    send(&mut d, 0x0080);
    assert_eq!(d.state(), FsaState::Fault, "no new edge");
    send(&mut d, 0x0000);
    send(&mut d, 0x0080);
    assert_eq!(d.state(), FsaState::SwitchOnDisabled);
}

#[test]
fn tv_al_1_al61_and_the_clean_shutdown() {
    // Operation enabled, master requests SafeOp → AL.61 (power cycle needed).
    let mut d = j3(SimDriveParams::default());
    enabled(&mut d);
    assert_eq!(d.leave_op(), Some(AL_61));
    for _ in 0..200 {
        lost(&mut d);
    }
    assert_eq!(d.state(), FsaState::Fault);
    assert_eq!(d.alarm(), Some(AL_61));
    // Clean: motor stopped, Shutdown → RTSO, then SafeOp: no alarm; frames stop: no AL.34/36.
    let mut d = j3(po03(0x0001));
    enabled(&mut d);
    let mut m = AxisMaster::for_profile(d.profile(), d.cycle_time(), Cycles(100));
    m.request(MasterRequest::Enable);
    m.request(MasterRequest::Disable);
    for _ in 0..10 {
        let cw = m.update(d.tx_pdo().statusword);
        send(&mut d, cw.0);
    }
    assert!(m.ready_to_leave_op());
    assert_eq!(d.state(), FsaState::ReadyToSwitchOn);
    assert_eq!(d.leave_op(), None);
    for _ in 0..100 {
        lost(&mut d);
    }
    assert_eq!(d.alarm(), None);
    assert_eq!(d.state(), FsaState::ReadyToSwitchOn);
    // OP, frames stop arriving → AL.36 after about 7 ms (TV-IC-4).
    let mut d = j3(SimDriveParams::default());
    enabled(&mut d);
    for _ in 0..7 {
        lost(&mut d);
    }
    assert_eq!(d.alarm(), Some(AL_36));
}

#[test]
fn tv_ic_1_normal_echo_and_wrap() {
    // Drive side, L = 1: Tx(k+1) = Rx(k) + 1.
    let mut d = j3(SimDriveParams::default());
    enabled(&mut d);
    let sent = [253u8, 254, 255, 0, 1, 2];
    let mut echoes = Vec::new();
    for c in sent {
        echoes.push(xc(&mut d, 0x0F, c).echo());
    }
    assert_eq!(&echoes[1..], &[254, 255, 0, 1, 2]);
    // With L = 0 the echo answers the same exchange.
    let mut d0 = j3(SimDriveParams {
        comm: CommParams {
            echo_lag: 0,
            ..CommParams::default()
        },
        ..SimDriveParams::default()
    });
    enabled(&mut d0);
    let e: Vec<u8> = sent.iter().map(|&c| xc(&mut d0, 0x0F, c).echo()).collect();
    assert_eq!(e, [254, 255, 0, 1, 2, 3]);
    // Master and drive together through the bus: never an error, across the wrap.
    let mut bus = SimBus::new(vec![j3(po03(0x0001))]);
    let p = bus.drive(0).profile().clone();
    let mut ctr = IncrementalCounter::new(MASTER_COUNTER_CHECK, 250);
    for k in 0..600 {
        let tx = p.pdo.tx.decode_tx(bus.tx_image(0)).unwrap();
        let v = ctr.check_rx(tx.echo());
        assert!(
            matches!(v, CounterVerdict::Ok | CounterVerdict::Warmup),
            "{k}: {v:?}"
        );
        let rx = RxPdo {
            counter: ctr.next_tx(),
            ..csp(Controlword(0), tx.position_actual)
        };
        p.pdo.rx.encode_rx(&rx, bus.rx_image_mut(0)).unwrap();
        bus.exchange(Cycles(1)).unwrap();
    }
    assert_eq!(bus.drive(0).alarm(), None);
}

#[test]
fn tv_ic_2_one_lost_rx_frame() {
    for (po, expect_alarm) in [(0x0000, None), (0x0001, None)] {
        let mut d = j3(po03(po));
        enabled(&mut d);
        // Continue the enable sequence's counter up to 9 without a jump.
        while next_counter() != 8 {}
        xc(&mut d, 0x0F, 9);
        // Drive cycles 1..4 of the table (L = 0 columns are one cycle earlier with L = 1).
        let t1 = xc(&mut d, 0x0F, 10).echo();
        let t2 = lost(&mut d).echo();
        let t3 = xc(&mut d, 0x0F, 12).echo();
        let t4 = xc(&mut d, 0x0F, 13).echo();
        let t5 = xc(&mut d, 0x0F, 14).echo();
        // L = 1: each echo is the previous cycle's last good + 1.
        assert_eq!([t1, t2, t3, t4, t5], [10, 11, 11, 13, 14], "PO03 {po:#06x}");
        // One counter error and one lost frame stay below every (placeholder) threshold.
        assert_eq!(d.alarm(), expect_alarm);
    }
    // The master sees 11 twice: one mismatch.
    let mut c = IncrementalCounter::new(
        CounterParams {
            echo_lag: 0,
            ..MASTER_COUNTER_CHECK
        },
        9,
    );
    assert_eq!(c.next_tx(), 10);
    assert_eq!(c.check_rx(11), CounterVerdict::Ok);
    assert_eq!(c.next_tx(), 11); // lost on the way
    assert!(matches!(
        c.check_rx(11),
        CounterVerdict::Mismatch {
            expected: 12,
            received: 11
        }
    ));
    assert_eq!(c.next_tx(), 12);
    assert_eq!(c.check_rx(13), CounterVerdict::Ok);
}

#[test]
fn tv_ic_3_master_stops_incrementing() {
    // Stale frames 20, 20, 20, …: the first initialises, every later one is an update error.
    for (po, alarm_at) in [(0x0001, Some(4)), (0x0002, Some(4)), (0x0000, None)] {
        let mut d = j3(po03(po));
        enabled(&mut d);
        let stale = next_counter();
        let mut at = None;
        for k in 1..=50 {
            let tx = xc(&mut d, 0x0F, stale);
            if at.is_none() && d.alarm().is_some() {
                at = Some(k);
            }
            if k > 1 && at.is_none() {
                assert_eq!(tx.echo(), stale.wrapping_add(1), "constant echo");
            }
        }
        assert_eq!(at, alarm_at, "PO03 {po:#06x}");
        if alarm_at.is_some() {
            assert_eq!(d.alarm(), Some(AL_34));
            assert_eq!(d.state(), FsaState::Fault);
        }
    }
    // The master sees a constant echo and must stop the axis itself: continuous error.
    let mut c = IncrementalCounter::new(MASTER_COUNTER_CHECK, 19);
    let mut verdicts = Vec::new();
    for _ in 0..6 {
        verdicts.push(c.check_rx(21));
        c.next_tx();
    }
    assert!(verdicts.iter().any(|v| v.is_fault()), "{verdicts:?}");
    assert!(c.faulted());
}

#[test]
fn tv_ic_4_continuous_rx_loss() {
    // About 7 ms: 14 cycles at 0.5 ms, 7 at 1 ms, 4 at 2 ms (±1 allowed; the model is exact).
    for (us, n) in [(500u32, 14u32), (1000, 7), (2000, 4)] {
        let mut d = drive(DriveModel::MrJ3T04, us, po03(0x0200));
        enabled(&mut d);
        xc(&mut d, 0x0F, 41);
        let mut echoes = Vec::new();
        for k in 1..=n {
            echoes.push(lost(&mut d).echo());
            if k < n {
                assert_eq!(d.alarm(), None, "{us} µs: cycle {k}");
            }
        }
        assert_eq!(d.alarm(), Some(AL_36), "{us} µs");
        assert!(
            echoes.iter().all(|&e| e == 42),
            "repeats last good + 1: {echoes:?}"
        );
        for _ in 0..300 {
            lost(&mut d);
        }
        assert_eq!(d.state(), FsaState::Fault);
        assert_eq!(d.plant().velocity(), 0.0, "the motor stops");
    }
}

#[test]
fn tv_ic_5_only_the_three_cycle_times() {
    let p = profile(DriveModel::MrJ3T04);
    assert_eq!(p.cycle.cycle_times_us, &[500, 1000, 2000]);
    assert_eq!(
        p.object(0x1C32, 2).and_then(|o| o.range.bounds()),
        Some((500_000, 2_000_000))
    );
}

/// TV-IC-5 row 1 (§2.4): free-run (PO02 = 0001h) with the incremental-counter check on (PO03 =
/// 0001h) → AL.37 at power-on; free-run with PO03 = 0200h (the manual's setting) and DC mode
/// with PO03 = 0001h start cleanly.
#[test]
fn tv_ic_5_free_run_with_the_counter_check_raises_al_37_at_power_on() {
    let with = |po02: u16, po03: u16| {
        j3(SimDriveParams {
            comm: CommParams {
                po02,
                po03,
                ..CommParams::default()
            },
            ..SimDriveParams::default()
        })
    };
    let mut bad = with(0x0001, 0x0001);
    assert_eq!(bad.tx_pdo().error_code, AL_37);
    assert!(bad.tx_pdo().statusword.fault());
    bad.power_cycle();
    assert_eq!(
        bad.tx_pdo().error_code,
        AL_37,
        "raised again at every power-on"
    );
    for (po02, po03) in [(0x0001, 0x0200), (0x0000, 0x0001)] {
        let d = with(po02, po03);
        assert_eq!(
            d.tx_pdo().error_code,
            0,
            "PO02 {po02:04X}h PO03 {po03:04X}h"
        );
    }
}

/// TV-IC-5 row 2: SYNC0 at 1 ms while 1C32h:02 = 500000 raises AL.76 by default, AL.74 where
/// configured (the manual does not settle which, §8.2.3(1)); a matching SYNC0 raises nothing.
#[test]
fn tv_ic_5_sync0_other_than_the_pdo_cycle_raises_al_76_or_al_74() {
    for (choice, expected) in [
        (None, 0x0076),
        (Some(0x0074), 0x0074),
        (Some(0x0052), 0x0076),
    ] {
        let mut d = j3(SimDriveParams {
            sync_mismatch_alarm: choice,
            ..SimDriveParams::default()
        });
        d.sdo_download(0x1C32, 2, &500_000u32.to_le_bytes())
            .unwrap();
        assert_eq!(d.start_sync(1_000_000), Some(expected), "{choice:?}");
        assert_eq!(d.tx_pdo().error_code, expected);
        assert!(d.tx_pdo().statusword.fault(), "{choice:?}");
    }
    let mut d = j3(SimDriveParams::default());
    d.sdo_download(0x1C32, 2, &1_000_000u32.to_le_bytes())
        .unwrap();
    assert_eq!(d.start_sync(1_000_000), None);
    assert_eq!(d.tx_pdo().error_code, 0);
    // Models whose manuals name no such alarm run on SYNC0.
    let mut j5 = drive(DriveModel::MrJ5GN1, 1000, SimDriveParams::default());
    assert_eq!(j5.start_sync(2_000_000), None);
}

#[test]
fn tv_pdo_1_csv_only_remap_layout() {
    // 1614h := 20200008h, 00000008h (gap), 60400010h, 20010010h, 60FF0020h → 10 bytes.
    const CSV: PdoMap = PdoMap {
        index: 0x1614,
        entries: SharedSlice::Static(&[
            PdoEntry::object(0x2020, 0, 8),
            PdoEntry::padding(8),
            PdoEntry::object(0x6040, 0, 16),
            PdoEntry::object(0x2001, 0, 16),
            PdoEntry::object(0x60FF, 0, 32),
        ]),
    };
    let words: Vec<u32> = CSV.entries.iter().map(|e| e.mapping_word()).collect();
    assert_eq!(
        words,
        [
            0x2020_0008,
            0x0000_0008,
            0x6040_0010,
            0x2001_0010,
            0x60FF_0020
        ]
    );
    assert_eq!(CSV.byte_len(), 10);
    let rx = RxPdo {
        counter: 0x12,
        controlword: Controlword(0x000F),
        target_velocity: -2,
        ..RxPdo::default()
    };
    let mut b = [0xEEu8; 10];
    CSV.encode_rx(&rx, &mut b).unwrap();
    assert_eq!(b, [0x12, 0, 0x0F, 0, 0, 0, 0xFE, 0xFF, 0xFF, 0xFF]);
}

#[test]
fn tv_units_1_encoder_and_position_wrap() {
    let u = profile(DriveModel::MrJ3T04).units;
    assert_eq!(u.counts_per_rev, Some(262_144));
    // 6064h wraps from 2 147 483 647 to −2 147 483 648 after 8192 rev.
    assert_eq!((1u64 << 31) / u64::from(u.counts_per_rev.unwrap()), 8192);
    let mut d = j3(SimDriveParams {
        initial_position: i32::MAX - 500,
        ..SimDriveParams::default()
    });
    enabled(&mut d);
    move_csp(&mut d, 100, 30);
    for _ in 0..300 {
        let t = d.tx_pdo().position_actual.wrapping_add(0);
        exchange(
            &mut d,
            &csp(Controlword::ENABLE_OPERATION, t.wrapping_add(0)),
        );
    }
    assert!(
        d.tx_pdo().position_actual < 0,
        "wrapped like a 32-bit counter"
    );
    assert_eq!(d.state(), FsaState::OperationEnabled);
}

/// The J3's TxPDO with 6061h and 6062h in place of the reserved statuswords 3–5 (§4.5: both
/// mappable; 25 of the 30 bytes).
const TX_WITH_DEMAND: &[PdoEntry] = &[
    PdoEntry::object(0x2021, 0, 8),
    PdoEntry::object(0x2023, 0, 8),
    PdoEntry::object(0x6041, 0, 16),
    PdoEntry::object(0x2011, 0, 16),
    PdoEntry::object(0x6064, 0, 32),
    PdoEntry::object(0x606C, 0, 32),
    PdoEntry::object(0x60F4, 0, 32),
    PdoEntry::object(0x6077, 0, 16),
    PdoEntry::object(0x6061, 0, 8),
    PdoEntry::object(0x6062, 0, 32),
];

/// TV-MODE-1 (§8.4.2 ① and Note 1): from csv at 300 r/min, the master sends 60FFh = 0 and
/// 607Ah = 6062h every cycle, writes 6060h = 8 (by SDO: not in the default RxPDO) only after
/// 6062h has stopped changing and the motor has stopped, and the drive switches at zero speed
/// with no jump. The procedure is `ModeSwitch::for_profile` with the J3's
/// `CspEntry::PositionDemand`.
#[test]
fn tv_mode_1_csv_to_csp_sends_6062h_and_switches_once_it_stands() {
    let mut d = j3(SimDriveParams {
        zero_speed: 10.0,
        ..SimDriveParams::default()
    });
    let rx_map: Vec<PdoEntry> = d.profile().pdo.rx.entries.to_vec();
    d.remap(&rx_map, TX_WITH_DEMAND).unwrap();
    enabled(&mut d);
    d.sdo_write_mode(9).unwrap();
    // csv at 300 r/min (60FFh in 0.001 r/min).
    let mut rx = RxPdo {
        controlword: Controlword::ENABLE_OPERATION,
        target_velocity: 300_000,
        ..RxPdo::default()
    };
    let mut tx = exchange(&mut d, &rx);
    for _ in 0..300 {
        rx.counter = next_counter();
        tx = exchange(&mut d, &rx);
    }
    assert_eq!(tx.mode_display, 9);
    assert!(tx.velocity_actual > 290_000, "{}", tx.velocity_actual);
    let mut switch = ModeSwitch::for_profile(
        d.profile(),
        ModeOfOperation::CyclicSyncPosition,
        0,
        ModeSwitchParams {
            timeout: Cycles(5000),
            zero_speed: 100,
        },
    )
    .unwrap();
    let mut written = 9i8;
    let mut last_demand = None;
    let mut handed_over = None;
    for _ in 0..5000 {
        rx.target_velocity = 0;
        rx.counter = next_counter();
        let demand = tx.extra(0x6062).map(|v| v as u32 as i32);
        let progress = switch.update(&tx, &mut rx).unwrap();
        assert_eq!(
            Some(rx.target_position),
            demand,
            "607Ah is 6062h every cycle ({progress:?})"
        );
        if rx.mode != written {
            assert_eq!(rx.mode, 8);
            assert_eq!(
                demand, last_demand,
                "6060h = 8 only once 6062h stands still"
            );
            assert!(tx.velocity_actual.unsigned_abs() <= 100, "and the motor");
            d.sdo_write_mode(8).unwrap();
            written = 8;
        }
        if let ModeSwitchProgress::Done { csp_target } = progress {
            handed_over = csp_target;
            break;
        }
        last_demand = demand;
        tx = exchange(&mut d, &rx);
    }
    let target = handed_over.expect("6061h never showed csp");
    assert_eq!(tx.mode_display, 8);
    assert_eq!(Some(target), tx.extra(0x6062).map(|v| v as u32 as i32));
    // csp on the handed-over 607Ah: the motor does not move.
    let at = tx.position_actual;
    for _ in 0..300 {
        rx.counter = next_counter();
        rx.target_position = target;
        tx = exchange(&mut d, &rx);
    }
    assert!(
        (tx.position_actual - at).abs() <= 2,
        "jumped from {at} to {}",
        tx.position_actual
    );
    assert_eq!(d.alarm(), None);
    // SDO write of 6060h while it is PDO-mapped → 0x06010000 (J3) / 0x06010006 (J5).
    let mut j5 = common::j5(SimDriveParams::default());
    assert_eq!(j5.sdo_write_mode(9), Err(0x0601_0006));
}

/// TV-MODE-1 needs 6062h in the TxPDO: with the default 1A14h the switch is refused at once,
/// naming the object, and 6060h stays csv.
#[test]
fn tv_mode_1_without_6062h_in_the_txpdo_the_switch_is_refused() {
    let mut d = j3(SimDriveParams::default());
    enabled(&mut d);
    d.sdo_write_mode(9).unwrap();
    let mut rx = RxPdo {
        mode: 9,
        controlword: Controlword::ENABLE_OPERATION,
        ..RxPdo::default()
    };
    let mut tx = exchange(&mut d, &rx);
    tx.mode_display = 9;
    let mut switch = ModeSwitch::for_profile(
        d.profile(),
        ModeOfOperation::CyclicSyncPosition,
        0,
        ModeSwitchParams::default(),
    )
    .unwrap();
    let e = switch.update(&tx, &mut rx).unwrap_err();
    assert_eq!(e, ModeSwitchError::PositionDemandNotMapped);
    assert!(e.to_string().contains("6062h"), "{e}");
    assert_eq!(rx.mode, 9, "request withdrawn");
}

#[test]
fn master_quick_stop_substitute_never_sends_quick_stop() {
    let mut d = j3(SimDriveParams::default());
    boot(&mut d);
    let mut m = AxisMaster::for_profile(d.profile(), d.cycle_time(), Cycles(100));
    m.request(MasterRequest::Enable);
    for _ in 0..5 {
        let cw = m.update(d.tx_pdo().statusword);
        send(&mut d, cw.0);
    }
    assert!(m.is_enabled());
    m.request(MasterRequest::QuickStop);
    let mut cws = Vec::new();
    for _ in 0..5 {
        let cw = m.update(d.tx_pdo().statusword);
        cws.push(cw);
        send(&mut d, cw.0);
    }
    assert!(cws.iter().all(|c| c.quick_stop()), "bit 2 never 0: {cws:?}");
    assert_eq!(m.state(), MasterState::Disabled);
    assert_eq!(d.state(), FsaState::ReadyToSwitchOn);
    assert_eq!(d.alarm(), None);
}

#[test]
fn bus_injections_reach_the_drive() {
    let mut bus = SimBus::new(vec![j3(po03(0x0001))]);
    let p = bus.drive(0).profile().clone();
    assert!(bus.inject_counter_corruption(0, 3));
    assert!(!bus.inject_rx_loss(5, 1));
    let mut c = 0u8;
    for _ in 0..10 {
        let tx = p.pdo.tx.decode_tx(bus.tx_image(0)).unwrap();
        c = c.wrapping_add(1);
        let rx = RxPdo {
            counter: c,
            ..csp(Controlword(0), tx.position_actual)
        };
        p.pdo.rx.encode_rx(&rx, bus.rx_image_mut(0)).unwrap();
        bus.exchange(Cycles(1)).unwrap();
    }
    assert_eq!(bus.drive(0).alarm(), Some(AL_34));
    let mut bus = SimBus::new(vec![j3(SimDriveParams::default())]);
    assert!(bus.inject_rx_loss(0, 7));
    for _ in 0..7 {
        bus.exchange(Cycles(1)).unwrap();
    }
    assert_eq!(bus.drive(0).alarm(), Some(AL_36));
}

#[test]
fn tv_tl_1_torque_limit_selection() {
    let mut d = j3(SimDriveParams {
        internal_torque_limits: InternalTorqueLimits {
            pa11_forward: 200.0,
            pa12_reverse: 150.0,
            pc35_internal: 100.0,
        },
        ..SimDriveParams::default()
    });
    boot(&mut d);
    // (C_TL1, C_TL) → (CCW-drive limit, CW-drive limit), with 60E0h = 800, 60E1h = 3000.
    let rows = [
        (0, 0, 200.0, 150.0),
        (0, 1, 80.0, 150.0),
        (1, 0, 100.0, 100.0),
        (1, 1, 80.0, 100.0),
    ];
    for (tl1, tl, ccw, cw) in rows {
        let rx = RxPdo {
            controlword2: (tl1 << 4) | (tl << 3),
            torque_limit_positive: 800,
            torque_limit_negative: 3000,
            ..csp(Controlword(0x000F), 0)
        };
        assert_eq!(
            d.torque_limits_percent(&rx),
            (ccw, cw),
            "C_TL1 {tl1} C_TL {tl}"
        );
    }
}

#[test]
fn c_tl_limits_the_acceleration_the_motor_develops() {
    // 60E0h = 30 (3 %) selected by C_TL: an accelerating csp ramp may use at most 1 % of the
    // plant's 300 % maximum; without C_TL the same ramp accelerates much harder.
    let peak = |cw2: u16| {
        let mut d = j3(SimDriveParams::default());
        boot(&mut d);
        for cw in [0x0006, 0x0007, 0x000F] {
            send(&mut d, cw);
        }
        let amax = d.plant().params().max_acceleration;
        let mut peak: f64 = 0.0;
        for k in 1..=50i32 {
            let rx = RxPdo {
                controlword2: cw2,
                torque_limit_positive: 30,
                torque_limit_negative: 30,
                ..csp(Controlword(0x000F), k * k * 20)
            };
            exchange(&mut d, &rx);
            peak = peak.max(d.plant().acceleration() / amax);
        }
        peak
    };
    let limited = peak(1 << 3);
    assert!(limited <= 0.01 + 1e-12, "C_TL: {limited}");
    assert!(limited > 0.009, "the limit is reached: {limited}");
    assert!(peak(0) > 0.05, "without C_TL: {}", peak(0));
}

#[test]
fn tv_home_1_method_35_sets_the_home_offset_without_motion() {
    let mut d = j3(SimDriveParams {
        initial_position: -123_456,
        ..SimDriveParams::default()
    });
    boot(&mut d);
    d.sdo_download(0x6098, 0, &[35]).unwrap();
    d.sdo_write_mode(6).unwrap();
    send(&mut d, 0x0006);
    assert_eq!(d.mode_display(), cellrt_cia402::ModeOfOperation::Homing);
    // Outside Operation enabled (Ready to switch on), HOS rising: 607Ch := −(raw position).
    let sw = send(&mut d, 0x0016);
    assert_eq!(d.sdo_upload(0x607C, 0), Ok(123_456));
    assert_eq!(d.tx_pdo().position_actual, -123_456, "6064h stays raw");
    assert_eq!(sw.0 & 0x3400, 0x1400, "bits 13/12/10 = 0/1/1: completed");
    // The user arithmetic of §8.2: user target 5000 → 607Ah = 5000 − 607Ch.
    assert_eq!(5000 - d.home_offset(), 5000 - 123_456);
}

#[test]
fn tv_home_1_a_dog_method_outside_operation_enabled_is_a_homing_error() {
    let mut d = j3(SimDriveParams::default());
    boot(&mut d);
    d.sdo_write_mode(6).unwrap(); // 6098h stays at its default −1 (dog type)
    send(&mut d, 0x0006);
    let sw = send(&mut d, 0x0016);
    assert_eq!(sw.0 & 0x3400, 0x2400, "bit 13: homing error, velocity 0");
    assert_eq!(d.home_offset(), 0);
}

/// A J3 with the dog at [300 000, 500 000] counts, the limits at ±1 000 000, the Z phase every
/// revolution (2^18) from 1000, switched into hm with `method`, 6099h:1 100 r/min, 6099h:2
/// 10 r/min, 609Ah 1000 ms and the 2080h shift 5000 pulses (MR-J3-T04 manual §8.11.4.1).
fn j3_homing(method: i8, start: i32, dog: Option<[f64; 2]>) -> SimDrive {
    let mut d = j3(SimDriveParams {
        initial_position: start,
        z_phase_position: 1000,
        homing_switches: cellrt_emulator::sim::homing_switches::HomingSwitches {
            home_dog: dog,
            positive_limit: Some(1_000_000.0),
            negative_limit: Some(-1_000_000.0),
        },
        ..SimDriveParams::default()
    });
    enabled(&mut d);
    d.sdo_download(0x6098, 0, &[method as u8]).unwrap();
    d.sdo_download(0x6099, 1, &100_000u32.to_le_bytes())
        .unwrap();
    d.sdo_download(0x6099, 2, &10_000u32.to_le_bytes()).unwrap();
    d.sdo_download(0x609A, 0, &1000u32.to_le_bytes()).unwrap();
    d.sdo_download(0x2080, 0, &5000u32.to_le_bytes()).unwrap();
    d.sdo_write_mode(6).unwrap();
    send(&mut d, 0x000F);
    assert_eq!(d.mode_display(), cellrt_cia402::ModeOfOperation::Homing);
    d
}

/// Runs HOS until bits 12 or 13 show with bit 10 (at rest); returns that statusword and the
/// peak |606Ch| in 0.001 r/min. A successful search shows 0/0/0 until then.
fn run_hos(d: &mut SimDrive) -> (u16, i32) {
    let mut peak = 0;
    for _ in 0..30_000 {
        let sw = send(d, 0x001F).0;
        peak = peak.max(d.tx_pdo().velocity_actual.abs());
        if sw & 0x0400 != 0 && sw & 0x3000 != 0 {
            return (sw, peak);
        }
        // In progress 0/0/0, or an error while the motor still moves 1/0/0.
        assert_eq!(sw & 0x1400, 0, "moving: bits 12/10 = 0/0 ({sw:04x})");
    }
    panic!("the homing never ended");
}

#[test]
fn tv_home_1_dog_type_homes_on_the_z_phase_after_the_dog_plus_the_2080h_shift() {
    const Z: i32 = 1000;
    const REV: i32 = 262_144;
    // −1 forward: rear end at 500 000, the next Z 1000 + 2·2^18 = 525 288, + 5000.
    // −17 reverse from above: rear end at 300 000, the Z below 263 144, − 5000.
    // −1 started on the dog: out backwards first, then the same home.
    for (method, start, home) in [
        (-1, 0, Z + 2 * REV + 5000),
        (-17, 800_000, Z + REV - 5000),
        (-1, 400_000, Z + 2 * REV + 5000),
        // Beyond the dog forward: LSP reverses back over the dog, then forward again.
        (-1, 700_000, Z + 2 * REV + 5000),
    ] {
        let mut d = j3_homing(method, start, Some([300_000.0, 500_000.0]));
        let (sw, peak) = run_hos(&mut d);
        assert_eq!(sw & 0x3400, 0x1400, "{method}: bits 13/12/10 = 0/1/1");
        let at = d.tx_pdo().position_actual;
        assert!(
            (at - home).abs() <= 100,
            "{method} from {start}: {at} vs {home}"
        );
        assert_eq!(d.home_offset(), -home, "{method}: 607Ch = −(home)");
        assert!(
            peak <= 100_000 * 103 / 100,
            "{method}: 606Ch {peak} within 6099h:1"
        );
        assert_eq!(d.warning(), None);
    }
}

#[test]
fn tv_home_1_lsn_reached_or_a_dog_too_short_for_the_creep_speed_is_al_90() {
    // No dog: LSP reverses the search, LSN ends it (§8.11.4.1 "LSN reached → homing error").
    let mut d = j3_homing(-1, 0, None);
    let (sw, _) = run_hos(&mut d);
    assert_eq!(sw & 0x3400, 0x2400, "bits 13/12/10 = 1/0/1");
    assert!(d.tx_pdo().position_actual <= -1_000_000 + 100);
    assert_eq!(d.warning(), Some(AL_90));
    assert_eq!(sw & 0x0080, 0x0080, "statusword bit 7");
    assert_eq!(d.home_offset(), 0);
    // A 1000-count dog: 6099h:1 cannot slow to 6099h:2 before its end (§7.2 AL.90).
    let mut d = j3_homing(-1, 0, Some([300_000.0, 301_000.0]));
    let (sw, _) = run_hos(&mut d);
    assert_eq!(sw & 0x3400, 0x2400);
    assert_eq!(d.warning(), Some(AL_90));
    // The next start clears it.
    d.sdo_download(0x6098, 0, &[35]).unwrap();
    send(&mut d, 0x000F);
    assert_eq!(send(&mut d, 0x001F).0 & 0x3400, 0x1400);
    assert_eq!(d.warning(), None);
}

/// One csp cycle holding at `target` with Controlword2 = `cw2` (Enable operation).
fn cw2_cycle(d: &mut SimDrive, target: i32, cw2: u16) -> cellrt_cia402::TxPdo {
    let rx = RxPdo {
        controlword2: cw2,
        counter: next_counter(),
        ..csp(Controlword(0x000F), target)
    };
    exchange(d, &rx)
}

const C_CR: u16 = 1 << 7;
const C_CR2: u16 = 1 << 6;
const S_ZPAS: u16 = 1 << 7;
const S_OSET: u16 = 1 << 8;

#[test]
fn tv_home_1_c_cr_sets_home_at_the_current_position_in_csp() {
    let mut d = j3(SimDriveParams {
        initial_position: 10_000,
        ..SimDriveParams::default()
    });
    enabled(&mut d);
    let tx = cw2_cycle(&mut d, 10_000, 0);
    assert_eq!(tx.statusword2() & S_OSET, 0);
    // C_CR 0→1 at standstill: 607Ch = −10000, S_OSET = 1; 6064h stays raw.
    let tx = cw2_cycle(&mut d, 10_000, C_CR);
    assert_eq!(d.sdo_upload(0x607C, 0), Ok(-10_000));
    assert_eq!(tx.statusword2() & S_OSET, S_OSET);
    assert_eq!(tx.position_actual, 10_000);
    // Holding the bit changes nothing more; dropping it clears S_OSET (no edge, no change).
    cw2_cycle(&mut d, 10_000, C_CR);
    let tx = cw2_cycle(&mut d, 10_000, 0);
    assert_eq!(tx.statusword2() & S_OSET, 0);
    assert_eq!(d.home_offset(), -10_000);
    // User point B = 5000 is sent as 607Ah = 15000; 6064h then reads raw 15000.
    let target = 5000 - d.home_offset();
    assert_eq!(target, 15_000);
    move_csp(&mut d, 50, 100);
    for _ in 0..200 {
        cw2_cycle(&mut d, target, 0);
    }
    assert!((d.tx_pdo().position_actual - 15_000).abs() <= 1);
    assert_eq!(
        0 - d.home_offset(),
        10_000,
        "user point A = 0 is 607Ah = 10000"
    );
}

#[test]
fn tv_home_1_c_cr2_needs_the_z_phase_and_wins_over_c_cr() {
    let mut d = j3(SimDriveParams {
        initial_position: 261_000,
        z_phase_position: 262_100,
        ..SimDriveParams::default()
    });
    enabled(&mut d);
    // After power-up S_ZPAS = 0: C_CR2 0→1 → AL.96 warning, home not changed.
    let tx = cw2_cycle(&mut d, 261_000, C_CR2);
    assert_eq!(tx.statusword2() & (S_ZPAS | S_OSET), 0);
    assert_eq!(d.warning(), Some(0x0096));
    assert!(tx.statusword.0 & (1 << 7) != 0, "statusword bit 7: warning");
    assert_eq!(d.home_offset(), 0);
    assert_eq!(d.state(), FsaState::OperationEnabled, "operation continues");
    let tx = cw2_cycle(&mut d, 261_000, 0);
    assert_eq!(d.warning(), None, "clears with C_CR2 off");
    assert_eq!(tx.statusword.0 & (1 << 7), 0);
    // Travel past the Z phase at raw 262100 (S_ZPAS = 1), then stop further on.
    move_csp(&mut d, 20, 100); // to 263000
    for _ in 0..100 {
        cw2_cycle(&mut d, 263_000, 0);
    }
    let tx = cw2_cycle(&mut d, 263_000, 0);
    assert_eq!(tx.statusword2() & S_ZPAS, S_ZPAS);
    // C_CR and C_CR2 rise together: C_CR2 wins, 607Ch = −(last Z) = −262100.
    let tx = cw2_cycle(&mut d, 263_000, C_CR | C_CR2);
    assert_eq!(d.sdo_upload(0x607C, 0), Ok(-262_100));
    assert_eq!(tx.statusword2() & S_OSET, S_OSET);
    // At different times the later edge wins: C_CR now sets the current position.
    let tx = cw2_cycle(&mut d, 263_000, C_CR2);
    assert_eq!(d.home_offset(), -262_100);
    cw2_cycle(&mut d, 263_000, C_CR2 | C_CR);
    assert_eq!(d.home_offset(), -tx.position_actual);
}

#[test]
fn tv_home_1_c_cr2_before_the_z_phase_may_be_configured_as_al26() {
    let mut d = j3(SimDriveParams {
        before_z_reaction: cellrt_emulator::sim::home_setting::BeforeZReaction::Alarm,
        ..SimDriveParams::default()
    });
    enabled(&mut d);
    cw2_cycle(&mut d, 0, 0);
    cw2_cycle(&mut d, 0, C_CR2);
    for _ in 0..5 {
        cw2_cycle(&mut d, 0, C_CR2);
    }
    assert_eq!(d.alarm(), Some(0x0026));
    assert_eq!(d.state(), FsaState::Fault);
    assert_eq!(d.home_offset(), 0);
}

#[test]
fn c_cr_is_not_acted_on_in_hm() {
    let mut d = j3(SimDriveParams {
        initial_position: 5000,
        ..SimDriveParams::default()
    });
    boot(&mut d);
    d.sdo_write_mode(6).unwrap();
    send(&mut d, 0x0006);
    assert_eq!(d.mode_display(), cellrt_cia402::ModeOfOperation::Homing);
    let rx = RxPdo {
        controlword2: C_CR,
        counter: next_counter(),
        ..csp(Controlword(0x0006), 5000)
    };
    let tx = exchange(&mut d, &rx);
    assert_eq!(d.home_offset(), 0);
    assert_eq!(tx.statusword2() & S_OSET, 0);
}

/// One csv cycle with 60FFh = `v` (counter incrementing, controlword Enable operation).
fn csv_cycle(d: &mut SimDrive, v: i32) -> cellrt_cia402::TxPdo {
    let rx = RxPdo {
        mode: 9,
        target_velocity: v,
        counter: next_counter(),
        ..csp(Controlword(0x000F), d.tx_pdo().position_actual)
    };
    exchange(d, &rx)
}

#[test]
fn tv_stroke_1_csv_at_the_forward_limit() {
    let mut d = j3(SimDriveParams {
        initial_mode: cellrt_cia402::ModeOfOperation::CyclicSyncVelocity,
        slow_stop_time_ms: 1000,
        ..SimDriveParams::default()
    });
    enabled(&mut d);
    for _ in 0..300 {
        csv_cycle(&mut d, 500_000);
    }
    let v0 = d.tx_pdo().velocity_actual;
    assert!((v0 - 500_000).abs() < 5_000, "at speed: {v0}");
    // LSP OFF: AL.99 (bit 7), slow stop with PC02; 60FFh is ignored during the stop, even a
    // reversal.
    d.set_stroke_end_inputs(false, true);
    let tx = csv_cycle(&mut d, -100_000);
    assert_eq!(d.warning(), Some(AL_99));
    assert!(tx.statusword.0 & 0x80 != 0, "warning bit 7");
    let mut last = tx.velocity_actual;
    let mut stop_cycles = 0;
    while d.tx_pdo().velocity_actual.abs() > 1_000 {
        let tx = csv_cycle(&mut d, -100_000);
        assert!(tx.velocity_actual <= last + 2_000, "decelerating");
        assert!(tx.velocity_actual > -20_000, "no reversal during the stop");
        last = tx.velocity_actual;
        stop_cycles += 1;
        assert!(stop_cycles < 700, "stops within PC02 scaled to the speed");
    }
    // 60FFh = 500 000 is 500 r/min (0.001 r/min, §9.6) = 2 184 533 counts/s at 262 144
    // counts/rev; of 4 000 000 counts/s ("rated") at PC02 = 1000 ms: about 546 ms.
    assert!(
        (500..=600).contains(&stop_cycles),
        "stop took {stop_cycles} ms"
    );
    for _ in 0..50 {
        csv_cycle(&mut d, 0);
    }
    // At standstill: CCW (+) stays blocked, CW (−) is accepted.
    for _ in 0..100 {
        csv_cycle(&mut d, 100_000);
    }
    assert!(d.tx_pdo().velocity_actual.abs() < 1_000, "CCW blocked");
    for _ in 0..200 {
        csv_cycle(&mut d, -100_000);
    }
    assert!(d.tx_pdo().velocity_actual < -90_000, "CW accepted");
    // LSP back ON: both directions, AL.99 clears by itself.
    d.set_stroke_end_inputs(true, true);
    for _ in 0..300 {
        csv_cycle(&mut d, 100_000);
    }
    assert!(d.tx_pdo().velocity_actual > 90_000);
    assert_eq!(d.warning(), None);
    assert_eq!(d.tx_pdo().statusword.0 & 0x80, 0);
}

#[test]
fn tv_fsa_4_main_circuit_off_and_e9() {
    let mut d = j3(SimDriveParams::default());
    enabled(&mut d);
    d.set_main_circuit_power(false);
    let sw = send(&mut d, 0x000F);
    assert_eq!(sw.0 & 0x006F, 0x0021, "(8B) to Ready to switch on");
    let sw = send(&mut d, 0x000F);
    assert_eq!(sw.0 & 0x006F, 0x0021, "stays Ready to switch on");
    assert_eq!(d.warning(), Some(AL_E9));
    assert!(sw.0 & 0x80 != 0, "warning bit 7");
    d.set_main_circuit_power(true);
    let sw = send(&mut d, 0x000F);
    assert_eq!(sw.0 & 0x006F, 0x0027, "Operation enabled again");
    assert_eq!(d.warning(), None);
}

#[test]
fn tv_fsa_4_em1_stops_the_motor_and_it_resumes_on_release() {
    let mut d = j3(SimDriveParams {
        initial_mode: cellrt_cia402::ModeOfOperation::CyclicSyncVelocity,
        ..SimDriveParams::default()
    });
    enabled(&mut d);
    for _ in 0..300 {
        csv_cycle(&mut d, 100_000);
    }
    assert!((d.tx_pdo().velocity_actual - 100_000).abs() < 2_000);
    d.set_em1(false);
    let tx = csv_cycle(&mut d, 100_000);
    assert_eq!(d.warning(), Some(AL_E6));
    assert!(tx.statusword.0 & 0x80 != 0);
    for _ in 0..50 {
        csv_cycle(&mut d, 100_000);
    }
    assert_eq!(d.tx_pdo().velocity_actual, 0, "base off, dynamic brake");
    // Released with 60FFh still 100 000: the motor runs again without a new controlword.
    d.set_em1(true);
    for _ in 0..300 {
        csv_cycle(&mut d, 100_000);
    }
    assert!((d.tx_pdo().velocity_actual - 100_000).abs() < 2_000);
    assert_eq!(d.warning(), None);
}

#[test]
fn tv_stroke_2_csp_manual_stop_and_follow_up() {
    let mut d = j3(SimDriveParams {
        slow_stop_time_ms: 1000,
        ..SimDriveParams::default()
    });
    enabled(&mut d);
    // csp at 200 counts/ms = 200 000 counts/s.
    let mut target = d.tx_pdo().position_actual;
    let cycle = |d: &mut SimDrive, target: i32, cw2: u16| {
        let rx = RxPdo {
            controlword2: cw2,
            counter: next_counter(),
            ..csp(Controlword(0x000F), target)
        };
        exchange(d, &rx)
    };
    for _ in 0..300 {
        target += 200;
        cycle(&mut d, target, 0);
    }
    // C_MSTOP: targets keep running away, but the drive ramps down linearly and raises S_FLW.
    let mut flw_at = None;
    for k in 0..400 {
        target += 200;
        let tx = cycle(&mut d, target, 0x0100);
        assert_eq!(tx.statusword.0 & (1 << 12), 0, "bit 12 off during MSTOP");
        if tx.statusword.0 & (1 << 14) != 0 {
            flw_at = Some(k);
            break;
        }
    }
    // 200 000 of 4 000 000 counts/s at PC02 = 1000 ms: about 50 ms.
    let k = flw_at.expect("S_FLW never set");
    assert!((40..=60).contains(&k), "ramp took {k} cycles");
    for _ in 0..50 {
        cycle(&mut d, target, 0x0100);
    }
    let stop = d.position_demand();
    assert!(
        (d.tx_pdo().position_actual - stop).abs() < 50,
        "motor at the demand"
    );
    assert!(
        target - stop > 5_000,
        "stopped away from the runaway target"
    );
    // Negative case: clearing C_MSTOP while 607Ah is still a far-away target is a sudden
    // motion toward it, limited by the drive's acceleration (torque), and by AL.35 where the
    // step implies more than the maximum motor speed (§7.2; overspeed at 1.2 × 4 000 000
    // counts/s: 4 800 counts in one 1 ms cycle).
    let mut sudden = d.clone();
    let near = stop + 3_000;
    let mut peak_velocity = 0.0f64;
    for _ in 0..200 {
        cycle(&mut sudden, near, 0);
        peak_velocity = peak_velocity.max(sudden.plant().velocity().abs());
    }
    assert_eq!(
        sudden.state(),
        FsaState::OperationEnabled,
        "3 000 counts: no alarm"
    );
    assert!(
        (sudden.tx_pdo().position_actual - near).abs() < 50,
        "the motor jumped to the old target"
    );
    assert!(
        peak_velocity > 200_000.0,
        "faster than before the stop: {peak_velocity}"
    );
    let mut runaway = d.clone();
    assert!(
        target - stop > 4_800,
        "the runaway target is beyond one cycle at 1.2 × max"
    );
    let tx = cycle(&mut runaway, target, 0);
    assert!(
        tx.statusword.fault() || runaway.state().is_fault(),
        "AL.35: {}",
        tx.statusword
    );
    assert_eq!(runaway.alarm(), Some(AL_35));
    // Follow-up: 607Ah := 6062h, then clear C_MSTOP: bit 12 back, no jump.
    let tx = cycle(&mut d, stop, 0x0100);
    assert!(tx.statusword.0 & (1 << 14) != 0);
    for _ in 0..100 {
        let tx = cycle(&mut d, stop, 0);
        assert!(tx.statusword.0 & (1 << 12) != 0, "tracking again");
        assert!((tx.position_actual - stop).abs() < 50, "no jump");
    }
}
