//! Profile velocity (pv) and profile torque (tq) of the simulated drives, with the 605Ah quick
//! stop, the 605Dh halt and the 607Dh software limits of pp: MR-J4-TM (PA01 `___2`, 1601h,
//! MR-J4-TM manual §5.4.6–§5.4.8, §8.1), MR-JET-G-N1 and MR-J5-G-N1 (objects by SDO).
//!
//! Units: the motor has 6000 counts/rev, so one 0.01 r/min LSB (MR-J4-TM manual §4.2 "Vel
//! unit") is one count/s; the rated speed the 6083h/6084h/6085h time constants refer to is
//! 3000 r/min = 300 000 counts/s.

mod common;

use cellrt_cia402::profiles::mr_j4_tm;
use cellrt_cia402::{Controlword, CycleTime, DriveModel, FsaState, ModeOfOperation, RxPdo, TxPdo};
use cellrt_emulator::motion::profile_position::{PpParams, INTERNAL_LIMIT_ACTIVE};
use cellrt_emulator::motion::profile_velocity::{SPEED_ZERO, TARGET_REACHED};
use cellrt_emulator::sim::drive::SimMotor;
use cellrt_emulator::{SimDrive, SimDriveParams};
use common::{drive, enabled, exchange};

/// Rated speed, counts/s (3000 r/min at 6000 counts/rev).
const RATED: f64 = 300_000.0;

fn params() -> SimDriveParams {
    SimDriveParams {
        zero_speed: 10.0,
        motor: SimMotor {
            counts_per: Some(6_000.0),
            ..SimMotor::default()
        },
        pp: PpParams {
            time_constant_speed: Some(RATED),
            ..PpParams::default()
        },
        ..SimDriveParams::default()
    }
}

/// An RxPDO in `mode` with controlword `cw`.
fn rx(mode: ModeOfOperation, cw: u16) -> RxPdo {
    RxPdo {
        mode: mode.as_i8(),
        controlword: Controlword(cw),
        ..RxPdo::default()
    }
}

fn with_cw(base: RxPdo, cw: u16) -> RxPdo {
    RxPdo {
        controlword: Controlword(cw),
        ..base
    }
}

/// A drive of `model` enabled in `mode`: the MR-J4-TM in PA01 `___2` with its 1601h objects in
/// `base`; the MR-JET / MR-J5 enabled in csp, 6083h/6084h/6087h written by SDO from `base`,
/// then switched at standstill.
fn drive_in(model: DriveModel, base: RxPdo) -> SimDrive {
    if model == DriveModel::MrJ4TM {
        let mut d = SimDrive::new(
            mr_j4_tm::ModeGroup::Profile.profile(),
            params(),
            CycleTime::from_micros(1000).unwrap(),
        );
        for cw in [0u16, 0, 0, 0x06, 0x07, 0x0F] {
            exchange(&mut d, &with_cw(at_rest(base), cw));
        }
        assert_eq!(d.state(), FsaState::OperationEnabled);
        return d;
    }
    let mut d = drive(model, 1000, params());
    enabled(&mut d);
    for (index, v) in [
        (0x6083u16, base.profile_acceleration),
        (0x6084, base.profile_deceleration),
        (0x6087, base.torque_slope),
    ] {
        d.sdo_download(index, 0, &v.to_le_bytes()).unwrap();
    }
    let pos = d.tx_pdo().position_actual;
    exchange(
        &mut d,
        &RxPdo {
            target_position: pos,
            ..with_cw(at_rest(base), 0x0F)
        },
    );
    d
}

/// `base` with no velocity or torque target (the cycles that enable or switch the mode).
fn at_rest(base: RxPdo) -> RxPdo {
    RxPdo {
        target_velocity: 0,
        target_torque: 0,
        ..base
    }
}

fn sw(tx: &TxPdo, bit: u16) -> bool {
    tx.statusword.0 & bit != 0
}

const PV_MODELS: [DriveModel; 3] = [
    DriveModel::MrJ4TM,
    DriveModel::MrJetGN1,
    DriveModel::MrJ5GN1,
];

/// pv with 60FFh = 150000 (1500.00 r/min), 6083h = 200 ms, 6084h = 100 ms.
fn pv_base() -> RxPdo {
    RxPdo {
        target_velocity: 150_000,
        profile_acceleration: 200,
        profile_deceleration: 100,
        ..rx(ModeOfOperation::ProfileVelocity, 0x0F)
    }
}

#[test]
fn pv_ramps_on_the_time_constants_and_sets_bits_10_and_12() {
    for model in PV_MODELS {
        let base = pv_base();
        let mut d = drive_in(model, base);
        assert_eq!(d.tx_pdo().mode_display, 3, "{model}");
        // Half the rated speed at 6083h = 200 ms to 3000 r/min: 100 cycles, 606Bh exact.
        let mut demand = Vec::new();
        let mut first_moving = None;
        let mut first_reached = None;
        let mut peak = 0;
        for k in 1..=400u32 {
            let tx = exchange(&mut d, &base);
            demand.push(d.velocity_demand());
            if !sw(&tx, SPEED_ZERO) && first_moving.is_none() {
                first_moving = Some(k);
            }
            if sw(&tx, TARGET_REACHED) && first_reached.is_none() {
                first_reached = Some((k, tx.velocity_actual));
            }
            peak = peak.max(tx.velocity_actual);
        }
        assert_eq!(demand[0], 1_500, "{model}: 1500 counts/s per 1 ms cycle");
        assert_eq!(demand[49], 75_000, "{model}");
        assert_eq!(demand[98], 148_500, "{model}");
        assert_eq!(demand[99], 150_000, "{model}: the ramp ends in cycle 100");
        // Bit 12 = 0 once 606Ch has stayed above 606Fh = 5000 (50 r/min) for 6070h = 10 ms.
        let moving = first_moving.unwrap();
        // The motor passes 5000 counts/s in cycle 4 (the servo loop's lag): 14.
        assert!((13..=16).contains(&moving), "{model}: {moving}");
        // Bit 10 once |606Ch − 60FFh| ≤ 606Dh = 2000 (606Eh = 0): near the ramp's end.
        let (reached, v) = first_reached.unwrap();
        assert!((95..=110).contains(&reached), "{model}: {reached}");
        assert!((150_000 - v).abs() <= 2_000, "{model}: {v}");
        // The recorded speed stays within 606Dh of 60FFh (the loop overshoots by < 1 %).
        assert!(peak <= 150_000 + 2_000, "{model}: {peak}");
        assert!(d.alarm().is_none(), "{model}");

        // 60FFh = 0: down at 6084h = 100 ms to rated → 50 cycles; bit 12 back to 1 at rest.
        let stop = RxPdo {
            target_velocity: 0,
            ..base
        };
        let mut k_zero = None;
        for k in 1..=300u32 {
            let tx = exchange(&mut d, &stop);
            if d.velocity_demand() == 0 && k_zero.is_none() {
                k_zero = Some(k);
            }
            if k == 300 {
                assert!(sw(&tx, SPEED_ZERO) && sw(&tx, TARGET_REACHED), "{model}");
            }
        }
        assert_eq!(k_zero, Some(50), "{model}");
    }
}

#[test]
fn pv_speed_is_capped_by_607fh_and_6080h() {
    for model in [DriveModel::MrJ4TM] {
        let base = pv_base();
        let mut d = drive_in(model, base);
        // 607Fh = 100000 (1000.00 r/min): 60FFh is capped, bit 10 stays 0 (|606Ch − 60FFh| =
        // 50000 > 606Dh).
        d.sdo_download(0x607F, 0, &100_000u32.to_le_bytes())
            .unwrap();
        let mut last = TxPdo::default();
        for _ in 0..400 {
            last = exchange(&mut d, &base);
            assert!(!sw(&last, TARGET_REACHED));
        }
        assert_eq!(d.velocity_demand(), 100_000);
        assert!((last.velocity_actual - 100_000).abs() <= 100, "{last:?}");
        // 6080h = 500 r/min: 50000 counts/s.
        d.sdo_download(0x6080, 0, &500u32.to_le_bytes()).unwrap();
        for _ in 0..400 {
            exchange(&mut d, &base);
        }
        assert_eq!(d.velocity_demand(), 50_000);
    }
}

#[test]
fn pv_halt_uses_605dh_and_reports_zero_velocity_in_bit_10() {
    for model in PV_MODELS {
        let base = pv_base();
        let mut d = drive_in(model, base);
        for _ in 0..300 {
            exchange(&mut d, &base);
        }
        // HALT with no 605Dh value: the profile deceleration 6084h, 100 ms → 50 cycles.
        let halt = with_cw(base, 0x010F);
        let mut k_zero = 0;
        for k in 1..=400u32 {
            let tx = exchange(&mut d, &halt);
            if d.velocity_demand() != 0 {
                assert!(!sw(&tx, TARGET_REACHED), "{model}: decelerating");
            } else if k_zero == 0 {
                k_zero = k;
            }
        }
        assert_eq!(k_zero, 50, "{model}");
        assert!(
            sw(d.tx_pdo(), TARGET_REACHED),
            "{model}: halted, velocity 0"
        );
        // Released: back to 60FFh at 6083h.
        for _ in 0..300 {
            exchange(&mut d, &base);
        }
        assert_eq!(d.velocity_demand(), 150_000, "{model}");
        // 605Dh = 3 (current limit, CiA 402) where the model takes a value: a sharper stop.
        if d.sdo_download(0x605D, 0, &3u16.to_le_bytes()).is_ok() {
            let mut k = 0;
            while d.velocity_demand() != 0 {
                exchange(&mut d, &halt);
                k += 1;
            }
            assert!(k <= 5, "{model}: {k} cycles at the maximum deceleration");
        }
    }
}

/// Cycles in Quick stop active until the drive leaves it (to Switch on disabled).
fn quick_stop_cycles(d: &mut SimDrive, base: RxPdo) -> u32 {
    let qs = with_cw(base, 0x0B);
    for k in 1..=2_000 {
        exchange(d, &qs);
        if d.state() == FsaState::SwitchOnDisabled {
            return k;
        }
    }
    panic!("quick stop never ended");
}

#[test]
fn quick_stop_follows_605ah_on_the_mr_j4_tm() {
    // From 1500 r/min (half the rated speed): 605Ah = 2 (default) → 6085h = 100 ms: 50 ms;
    // 605Ah = 1 → 6084h = 300 ms: 150 ms; 605Ah = 3 → current limit: a few ms. The motor lags
    // the ramp by the servo loop, so the state changes a little later.
    let run = |code: Option<i16>| {
        let base = RxPdo {
            profile_deceleration: 300,
            ..pv_base()
        };
        let mut d = drive_in(DriveModel::MrJ4TM, base);
        if let Some(c) = code {
            d.sdo_download(0x605A, 0, &c.to_le_bytes()).unwrap();
        }
        for _ in 0..400 {
            exchange(&mut d, &base);
        }
        quick_stop_cycles(&mut d, base)
    };
    let default = run(None);
    assert!((50..=90).contains(&default), "605Ah = 2: {default}");
    let profile = run(Some(1));
    assert!((150..=190).contains(&profile), "605Ah = 1: {profile}");
    let current = run(Some(3));
    assert!(current <= 40, "605Ah = 3: {current}");
}

/// tq with 6071h = 500 (50.0 %), 6087h = 10000 (1000.0 %/s), 2D20h = 30000 (300.00 r/min).
fn tq_base() -> RxPdo {
    RxPdo {
        target_torque: 500,
        torque_slope: 10_000,
        velocity_limit: 30_000,
        ..rx(ModeOfOperation::ProfileTorque, 0x0F)
    }
}

#[test]
fn tq_ramps_6074h_at_6087h_within_the_speed_limit() {
    for model in PV_MODELS {
        let base = tq_base();
        let mut d = drive_in(model, base);
        assert_eq!(d.tx_pdo().mode_display, 4, "{model}");
        let mut peak = 0;
        for k in 1..=200u32 {
            let tx = exchange(&mut d, &base);
            match k {
                1 => assert_eq!(d.torque_demand(), 10, "{model}"),
                25 => assert_eq!(d.torque_demand(), 250, "{model}"),
                50.. => assert_eq!(d.torque_demand(), 500, "{model}"),
                _ => {}
            }
            // tq: bit 10 not supported, bits 12/13 reserved (MR-J4-TM manual §5.4.8).
            assert_eq!(tx.statusword.0 & 0x3400, 0, "{model}: cycle {k}");
            peak = peak.max(tx.velocity_actual);
        }
        assert!((29_000..=30_300).contains(&peak), "{model}: {peak}");
        // HALT: 6074h back to 0 at 6087h, 50 cycles.
        for _ in 0..49 {
            exchange(&mut d, &with_cw(base, 0x010F));
        }
        assert_eq!(d.torque_demand(), 10, "{model}");
        exchange(&mut d, &with_cw(base, 0x010F));
        assert_eq!(d.torque_demand(), 0, "{model}");
        assert!(d.alarm().is_none(), "{model}");
    }
}

#[test]
fn pp_set_point_beyond_607dh_stops_at_the_limit_with_bit_11() {
    let base = RxPdo {
        profile_velocity: 100_000,
        profile_acceleration: 100,
        profile_deceleration: 100,
        target_position: 200_000,
        ..rx(ModeOfOperation::ProfilePosition, 0x0F)
    };
    let mut d = drive_in(DriveModel::MrJ4TM, base);
    d.sdo_download(0x607D, 1, &(-1_000i32).to_le_bytes())
        .unwrap();
    d.sdo_download(0x607D, 2, &50_000i32.to_le_bytes()).unwrap();
    exchange(&mut d, &with_cw(base, 0x3F));
    let mut last = TxPdo::default();
    for _ in 0..3_000 {
        last = exchange(&mut d, &with_cw(base, 0x2F));
        if sw(&last, TARGET_REACHED) {
            break;
        }
    }
    assert!(sw(&last, TARGET_REACHED), "{last:?}");
    assert!((last.position_actual - 50_000).abs() <= 100, "{last:?}");
    assert!(sw(&last, INTERNAL_LIMIT_ACTIVE), "ILA at the limit");
    // A set-point inside the limits clears bit 11.
    exchange(
        &mut d,
        &RxPdo {
            target_position: 10_000,
            ..with_cw(base, 0x2F)
        },
    );
    let tx = exchange(
        &mut d,
        &RxPdo {
            target_position: 10_000,
            ..with_cw(base, 0x3F)
        },
    );
    assert!(!sw(&tx, INTERNAL_LIMIT_ACTIVE));
}
