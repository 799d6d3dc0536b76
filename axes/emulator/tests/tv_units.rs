//! The simulated drives read their velocity and torque objects by the manuals' units (their
//! own code path, `sim::drive::units`): literal numbers from the manuals, TV-UNITS-1
//! (MR-J3-T04) and TV-4's 6085h (MR-J4-TM), see docs/test-vectors.md.

mod common;

use cellrt_cia402::profiles::TorqueLimitSelection;
use cellrt_cia402::{profile, Controlword, DriveModel, FsaState, ModeOfOperation, RxPdo};
use cellrt_emulator::{PlantParams, SimDrive, SimDriveParams};
use common::{drive, enabled, exchange, next_counter};

/// A drive in csv whose plant can reach `max_counts_per_s`.
fn csv_drive(model: DriveModel, max_counts_per_s: f64) -> SimDrive {
    let mut d = drive(
        model,
        1000,
        SimDriveParams {
            initial_mode: ModeOfOperation::CyclicSyncVelocity,
            plant: PlantParams {
                max_velocity: max_counts_per_s,
                max_acceleration: 20.0 * max_counts_per_s,
                ..PlantParams::default()
            },
            ..SimDriveParams::default()
        },
    );
    enabled(&mut d);
    d
}

/// Runs `n` csv cycles at 60FFh = `v`.
fn run_csv(d: &mut SimDrive, v: i32, n: usize) {
    for _ in 0..n {
        let rx = RxPdo {
            mode: 9,
            controlword: Controlword(0x000F),
            target_velocity: v,
            target_position: d.tx_pdo().position_actual,
            counter: next_counter(),
            ..RxPdo::default()
        };
        exchange(d, &rx);
    }
}

#[test]
fn tv_units_1_velocity_truncation_clamp_and_torque_mr_j3_t04() {
    // 262 144 counts/rev (§1.5); plant up to 2400 r/min = 10 485 760 counts/s.
    let mut d = csv_drive(DriveModel::MrJ3T04, 10_485_760.0);
    // 60FFh = 1 500 000 → 1500.000 r/min; 606Ch reports it in 0.001 r/min.
    run_csv(&mut d, 1_500_000, 500);
    assert!(
        (d.motor_speed() - 1500.0).abs() < 1e-6,
        "{}",
        d.motor_speed()
    );
    assert!((d.plant().velocity() - 6_553_600.0).abs() < 1e-3);
    assert_eq!(d.tx_pdo().velocity_actual, 1_500_000);
    // 60FFh = 123 456 → applied as 123.45 r/min (truncated to 0.01 r/min).
    run_csv(&mut d, 123_456, 500);
    assert!(
        (d.motor_speed() - 123.45).abs() < 1e-6,
        "{}",
        d.motor_speed()
    );
    assert_eq!(d.tx_pdo().velocity_actual, 123_450);
    // Above 1.2 × the maximum speed: clamped to 1.2 × max (no alarm); the motor runs at its
    // maximum. The clamp shows in the position demand 6062h, which the command advances: 1.2 ×
    // 10 485 760 counts/s = 12 582 912 counts/s, 1 258 291 counts in 100 cycles of 1 ms (the
    // unclamped 60FFh would advance it by 2^31 × 262 144 / 60 000 counts/s).
    run_csv(&mut d, 2_147_483_647, 500);
    assert_eq!(d.alarm(), None);
    assert_eq!(d.state(), FsaState::OperationEnabled);
    assert!(
        (d.motor_speed() - 2400.0).abs() < 1e-6,
        "{}",
        d.motor_speed()
    );
    let before = d.position_demand();
    run_csv(&mut d, 2_147_483_647, 100);
    let advanced = d.position_demand().wrapping_sub(before);
    assert!(
        (advanced - 1_258_291).abs() <= 1,
        "6062h advanced {advanced} counts in 100 ms, not 1.2 × the maximum speed"
    );
    // 60E0h = 1000 → 100.0 % of rated torque (selected by C_TL, §9.4).
    let TorqueLimitSelection::Controlword2 { c_tl_bit, .. } =
        profile(DriveModel::MrJ3T04).limits.torque_limit_selection
    else {
        panic!("MR-J3-T04 selects its torque limits by Controlword2");
    };
    let rx = RxPdo {
        torque_limit_positive: 1000,
        torque_limit_negative: 2500,
        controlword2: 1 << c_tl_bit,
        ..RxPdo::default()
    };
    assert_eq!(d.torque_limits_percent(&rx), (100.0, 250.0));
}

#[test]
fn velocity_objects_per_manual_on_every_model() {
    // (model, 60FFh for 30 r/min, the drive's counts/rev): MR-J4-TM 0.01 r/min with its
    // 22-bit encoder (§1.2, §4.2); MR-JET / MR-J5 0.01 r/min by default (manual silent) on the
    // simulated 2^26 motor; generic CiA 402 counts/s by default.
    let cases = [
        (DriveModel::MrJ3T04, 30_000, 262_144.0),
        (DriveModel::MrJ4TM, 3_000, 4_194_304.0),
        (DriveModel::MrJetGN1, 3_000, 67_108_864.0),
        (DriveModel::MrJ5GN1, 3_000, 67_108_864.0),
        (DriveModel::MrJ5W2GN1, 3_000, 67_108_864.0),
        (DriveModel::MrJ5W3GN1, 3_000, 67_108_864.0),
    ];
    for (model, raw, cpr) in cases {
        let counts_per_s = 30.0 * cpr / 60.0;
        let mut d = csv_drive(model, 2.0 * counts_per_s);
        assert_eq!(d.motor_resolution(), cpr, "{model}");
        run_csv(&mut d, raw, 600);
        assert!(
            (d.motor_speed() - 30.0).abs() < 1e-6,
            "{model}: {}",
            d.motor_speed()
        );
        assert_eq!(d.tx_pdo().velocity_actual, raw, "{model}");
    }
    let mut g = csv_drive(DriveModel::GenericCia402, 1.0e6);
    run_csv(&mut g, 250_000, 600);
    assert!((g.plant().velocity() - 250_000.0).abs() < 1e-3);
    assert_eq!(g.tx_pdo().velocity_actual, 250_000);
}

/// Cycles (1 ms) a quick stop from 60FFh = `raw` (0.01 r/min) takes on an MR-J4-TM.
fn quick_stop_cycles(six085: Option<u32>, raw: i32) -> usize {
    // Plant maximum ("rated") 60 r/min = 4 194 304 counts/s.
    let mut d = csv_drive(DriveModel::MrJ4TM, 4_194_304.0);
    if let Some(ms) = six085 {
        d.sdo_download(0x6085, 0, &ms.to_le_bytes()).unwrap();
    }
    run_csv(&mut d, raw, 600);
    let mut n = 0;
    while d.state() != FsaState::SwitchOnDisabled {
        let rx = RxPdo {
            mode: 9,
            controlword: Controlword(0x000B),
            target_velocity: raw,
            target_position: d.tx_pdo().position_actual,
            ..RxPdo::default()
        };
        exchange(&mut d, &rx);
        n += 1;
        assert!(n < 5_000, "quick stop ends");
    }
    n
}

#[test]
fn tv_4_quick_stop_decelerates_on_6085h_mr_j4_tm() {
    // 6085h default 100 ms from rated (60 r/min here) to 0 (MR-J4-TM manual §8.1, §4.2):
    // from 30.00 r/min (60FFh = 3000) half of it, 50 ms.
    let default = quick_stop_cycles(None, 3_000);
    assert!((50..=56).contains(&default), "{default}");
    // 6085h = 400 ms: 200 ms from 30 r/min.
    let slow = quick_stop_cycles(Some(400), 3_000);
    assert!((200..=206).contains(&slow), "{slow}");
}
