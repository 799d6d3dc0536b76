//! The simulated MR-J4-TM's homing searches seen through its PDO images and SDOs: the manual's
//! default speeds 6099h:1 = 10000 and 6099h:2 = 1000 (0.01 r/min, MR-J4-TM manual §5.4.9) when
//! the master writes none, an interrupted search (HOS dropped), and 60FDh on the switches.

mod common;

use cellrt_axes::sim::homing_switches::HomingSwitches;
use cellrt_axes::{
    Controlword, DriveModel, FsaState, PlantParams, RxPdo, SimDrive, SimDriveParams, TxPdo,
};
use common::{drive, exchange};

fn j4(start: i32) -> SimDrive {
    let mut d = drive(
        DriveModel::MrJ4TM,
        1000,
        SimDriveParams {
            initial_position: start,
            z_phase_position: 1000,
            // Fast enough for the 100 r/min default (7 M counts/s).
            plant: PlantParams {
                max_velocity: 2.0e7,
                max_acceleration: 5.0e7,
                ..PlantParams::default()
            },
            homing_switches: HomingSwitches {
                home_dog: Some([20.0e6, 30.0e6]),
                positive_limit: Some(60.0e6),
                negative_limit: Some(-60.0e6),
            },
            ..SimDriveParams::default()
        },
    );
    for cw in [0x0000, 0x0000, 0x0006, 0x0007, 0x000F] {
        hm(&mut d, cw);
    }
    assert_eq!(d.state(), FsaState::OperationEnabled);
    d
}

/// One exchange in hm (6060h = 6 in the RxPDO) with controlword `cw`.
fn hm(d: &mut SimDrive, cw: u16) -> TxPdo {
    let rx = RxPdo {
        mode: 6,
        controlword: Controlword(cw),
        target_position: d.tx_pdo().position_actual,
        ..RxPdo::default()
    };
    exchange(d, &rx)
}

/// Runs HOS until bit 10 comes with bit 12 or 13; returns (statusword, peak |606Ch|).
fn run(d: &mut SimDrive) -> (u16, i32) {
    let mut peak = 0;
    for _ in 0..20_000 {
        let tx = hm(d, 0x001F);
        peak = peak.max(tx.velocity_actual.abs());
        if tx.statusword.0 & 0x0400 != 0 && tx.statusword.0 & 0x3000 != 0 {
            return (tx.statusword.0, peak);
        }
    }
    let tx = d.tx_pdo();
    panic!(
        "the homing never ended: {:04x} at {} v {}",
        tx.statusword.0, tx.position_actual, tx.velocity_actual
    );
}

#[test]
fn without_6099h_written_the_search_runs_at_the_manuals_10000_and_1000() {
    // −11 dogless forward (2^22 counts/rev, Z from 1000): at 6099h:1 to the first Z above
    // 10 M counts.
    let mut d = j4(10_000_000);
    assert_eq!(d.sdo_upload(0x609A, 0), Ok(0), "609Ah default");
    d.sdo_download(0x6098, 0, &[(-11i8) as u8]).unwrap();
    // A gentle ramp (0.5 s to the plant's 2e7 counts/s) keeps the loop's overshoot small.
    d.sdo_download(0x609A, 0, &500u32.to_le_bytes()).unwrap();
    let (sw, peak) = run(&mut d);
    assert_eq!(sw & 0x3400, 0x1400, "completed");
    assert!((9_900..=10_300).contains(&peak), "606Ch {peak} vs 10000");
    // 34 at the creep speed from the start.
    let mut d = j4(10_000_000);
    d.sdo_download(0x6098, 0, &[34]).unwrap();
    d.sdo_download(0x609A, 0, &500u32.to_le_bytes()).unwrap();
    let (sw, peak) = run(&mut d);
    assert_eq!(sw & 0x3400, 0x1400);
    assert!((990..=1_030).contains(&peak), "606Ch {peak} vs 1000");
    assert_eq!(d.sdo_upload(0x6099, 1), Ok(10_000));
    assert_eq!(d.sdo_upload(0x6099, 2), Ok(1_000));
}

#[test]
fn dropping_hos_interrupts_the_search_without_an_error() {
    let mut d = j4(0);
    d.sdo_download(0x6098, 0, &[(-1i8) as u8]).unwrap();
    for _ in 0..200 {
        let sw = hm(&mut d, 0x001F).statusword.0;
        assert_eq!(sw & 0x3400, 0, "in progress");
    }
    assert!(d.tx_pdo().velocity_actual > 0);
    let mut sw = 0;
    for _ in 0..2000 {
        sw = hm(&mut d, 0x000F).statusword.0;
        if sw & 0x0400 != 0 {
            break;
        }
    }
    assert_eq!(sw & 0x3400, 0x0400, "interrupted: bits 13/12/10 = 0/0/1");
    assert_eq!(d.tx_pdo().velocity_actual, 0);
    assert_eq!(d.warning(), None);
}

#[test]
fn digital_inputs_60fdh_show_the_switches_where_the_motor_stands() {
    for (start, bits) in [
        (0, 0),
        (25_000_000, 0b100),
        (60_000_000, 0b010),
        (-61_000_000, 0b001),
    ] {
        let d = j4(start);
        assert_eq!(d.sdo_upload(0x60FD, 0), Ok(bits), "at {start}");
    }
    // Read-only.
    let mut d = j4(0);
    assert!(d.sdo_download(0x60FD, 0, &[0, 0, 0, 0]).is_err());
}
