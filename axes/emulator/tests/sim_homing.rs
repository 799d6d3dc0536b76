//! The simulated MR-J4-TM's homing searches seen through its PDO images and SDOs: the manual's
//! default speeds 6099h:1 = 10000 and 6099h:2 = 1000 (0.01 r/min, MR-J4-TM manual §5.4.9) when
//! the master writes none, an interrupted search (HOS dropped), 60FDh on the switches, and the
//! methods with the travel distance after proximity dog and the stopper type (§5.4.9(6)).

mod common;

use cellrt_cia402::profiles::mr_j4_tm::AL_90;
use cellrt_cia402::{Controlword, DriveModel, FsaState, RxPdo, TxPdo};
use cellrt_emulator::sim::homing_switches::HomingSwitches;
use cellrt_emulator::sim::plant::Stoppers;
use cellrt_emulator::{HomingParams, PlantParams, SimDrive, SimDriveParams};
use common::{drive, exchange};

fn j4(start: i32) -> SimDrive {
    j4_with(start, |_| {})
}

/// [`j4`] with `edit` applied to its parameters.
fn j4_with(start: i32, edit: impl FnOnce(&mut SimDriveParams)) -> SimDrive {
    let mut params = SimDriveParams {
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
    };
    edit(&mut params);
    let mut d = drive(DriveModel::MrJ4TM, 1000, params);
    for cw in [0x0000, 0x0000, 0x0006, 0x0007, 0x000F] {
        hm(&mut d, cw);
    }
    assert_eq!(d.state(), FsaState::OperationEnabled);
    d
}

/// One exchange in hm (6060h = 6 in the RxPDO) with controlword `cw`.
fn hm(d: &mut SimDrive, cw: u16) -> TxPdo {
    hm_limited(d, cw, RxPdo::default().torque_limit_negative)
}

/// [`hm`] with 60E1h Negative torque limit value `negative` (0.1 %).
fn hm_limited(d: &mut SimDrive, cw: u16, negative: u16) -> TxPdo {
    let rx = RxPdo {
        mode: 6,
        controlword: Controlword(cw),
        target_position: d.tx_pdo().position_actual,
        torque_limit_negative: negative,
        ..RxPdo::default()
    };
    exchange(d, &rx)
}

/// Runs HOS until bit 10 comes with bit 12 or 13 (at most 60 s of 1 ms cycles: a dog of 10 M
/// counts at the 699 051 counts/s creep speed takes 14 s); returns (statusword, peak |606Ch|).
fn run(d: &mut SimDrive) -> (u16, i32) {
    let mut peak = 0;
    for _ in 0..60_000 {
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

/// The travel distance after proximity dog of the tests below, counts. From 6099h:1's default
/// 100 r/min (6 990 506 counts/s at 2^22 counts/rev) to the creep speed's 10 r/min
/// (699 051 counts/s) at the plant's 5e7 counts/s² (609Ah = 0) takes
/// (6 990 506² − 699 051²) / (2 × 5e7) ≈ 483 843 counts.
const TRAVEL: u32 = 5_000_000;

/// Runs `method` from `start` with the travel distance `travel` and `switches`; returns the
/// final statusword and the raw position the drive took as home (the motor's raw position
/// less 6064h, which the MR-J4-TM presets to its home position address 0 there).
fn home_with(method: i8, start: i32, travel: u32, switches: Option<HomingSwitches>) -> (u16, f64) {
    let mut d = j4_with(start, |p| {
        p.homing.travel_after_dog = travel;
        if let Some(s) = switches {
            p.homing_switches = s;
        }
    });
    d.sdo_download(0x6098, 0, &[method as u8]).unwrap();
    let (sw, _) = run(&mut d);
    let warning = d.warning();
    assert_eq!(
        warning,
        (sw & 0x2000 != 0).then_some(AL_90),
        "{method}: AL. 90 with bit 13 only"
    );
    let raw = d.plant().position().round() - f64::from(d.tx_pdo().position_actual);
    (sw & 0x3400, raw)
}

#[test]
fn the_travel_methods_home_on_the_dog_edge_plus_the_travel_distance() {
    // Dog [20 M, 30 M], Z at 1 000 + k × 4 194 304, travel 5 M; the MR-J4-TM has no shift
    // object (shift 0).
    for (method, start, home) in [
        // −2 count type: front end 20 M + 5 M = 25 M, next Z k = 6: 1 000 + 25 165 824.
        (-2, 0, 25_166_824.0),
        // −34 from above: front end 30 M − 5 M = 25 M, next Z below, k = 5: 1 000 + 20 971 520.
        (-34, 50_000_000, 20_972_520.0),
        // −6 / −38 rear-end reference: 30 M + 5 M, 20 M − 5 M.
        (-6, 0, 35_000_000.0),
        (-38, 50_000_000, 15_000_000.0),
        // Front-end reference: 20 M + 5 M forward, 30 M − 5 M reverse.
        (-7, 0, 25_000_000.0),
        (-39, 50_000_000, 25_000_000.0),
        (-10, 0, 25_000_000.0),
        (-42, 50_000_000, 25_000_000.0),
        (19, 0, 25_000_000.0),
        (20, 0, 25_000_000.0),
        (21, 50_000_000, 25_000_000.0),
        (22, 50_000_000, 25_000_000.0),
        (23, 0, 25_000_000.0),
        (24, 0, 25_000_000.0),
        (27, 50_000_000, 25_000_000.0),
        (28, 50_000_000, 25_000_000.0),
        // Started on the dog: out backwards below 20 M first, then 20 M + 5 M.
        (-7, 22_000_000, 25_000_000.0),
        // Started above the dog: the stroke end at 60 M reverses the search (§5.4.9(6)
        // "when the movement is returned at the stroke end"), back below the dog, then
        // forward: the same homes.
        (23, 40_000_000, 25_000_000.0),
        (-6, 40_000_000, 35_000_000.0),
        (-2, 40_000_000, 25_166_824.0),
    ] {
        assert_eq!(
            home_with(method, start, TRAVEL, None),
            (0x1400, home),
            "{method} from {start}: bits 12/10 and the home"
        );
    }
}

#[test]
fn the_travel_methods_stop_with_al_90_where_the_manual_says() {
    // Stroke end in the search direction on 19–22 (§5.4.9(5)(b)5), 6)): from 40 M forward
    // the limit at 60 M comes before any dog.
    for method in [19, 20] {
        assert_eq!(
            home_with(method, 40_000_000, TRAVEL, None).0,
            0x2400,
            "{method}"
        );
    }
    // A dog of 200 000 counts, shorter than the ≈ 483 843 counts to the creep speed: its rear
    // end comes first, an AL. 90 for −6 and −10 (§5.4.9(6)(e), (i)); the count type −7 takes
    // any dog length: 20 M + 5 M.
    let short = HomingSwitches {
        home_dog: Some([20.0e6, 20.2e6]),
        positive_limit: Some(60.0e6),
        negative_limit: Some(-60.0e6),
    };
    for method in [-6, -10] {
        assert_eq!(
            home_with(method, 0, TRAVEL, Some(short)).0,
            0x2400,
            "{method}"
        );
    }
    assert_eq!(
        home_with(-7, 0, TRAVEL, Some(short)),
        (0x1400, 25_000_000.0)
    );
    // −2 with a 300 000-count travel, covered before the creep speed (§5.4.9(6)(b)).
    assert_eq!(home_with(-2, 0, 300_000, None).0, 0x2400);
}

/// An MR-J4-TM with stoppers at ±5 M counts, searching at 6099h:1 = 1000 (10 r/min,
/// 699 051 counts/s): the cycle the motor first stands on the stopper, the cycle bit 12 comes,
/// and 6077h while pressing.
fn stopper_homing(method: i8, negative_limit: u16) -> (u16, u32, u32, i16, f64) {
    let mut d = j4_with(0, |p| {
        p.stoppers = Stoppers {
            positive: Some(5.0e6),
            negative: Some(-5.0e6),
        };
    });
    assert_eq!(d.params().homing, HomingParams::default());
    d.sdo_download(0x6098, 0, &[method as u8]).unwrap();
    d.sdo_download(0x6099, 1, &1000u32.to_le_bytes()).unwrap();
    let (mut contact, mut torque) = (None, 0);
    for cycle in 0..20_000 {
        let tx = hm_limited(&mut d, 0x001F, negative_limit);
        let p = d.plant().position();
        if contact.is_none() && p.abs() == 5.0e6 && d.plant().velocity() == 0.0 {
            contact = Some(cycle);
            torque = tx.torque_actual;
        }
        let sw = tx.statusword.0;
        if sw & 0x0400 != 0 && sw & 0x3000 != 0 {
            let raw = p.round() - f64::from(tx.position_actual);
            return (sw & 0x3400, contact.unwrap(), cycle, torque, raw);
        }
    }
    panic!("the stopper homing never ended");
}

#[test]
fn the_stopper_type_homes_where_the_motor_stood_at_its_torque_limit_for_pt10() {
    // −4: toward +5 M with the forward torque limited to [Pr. PT11]'s default 15 % (6077h
    // 150 × 0.1 %) under 60E0h's 1000 %; home = the stopper, once the motor has stood at the
    // limit for [Pr. PT10]'s default 100 ms = 100 cycles of 1 ms.
    let (sw, contact, done, torque, home) = stopper_homing(-4, 10_000);
    assert_eq!((sw, home, torque), (0x1400, 5_000_000.0, 150));
    assert!(
        (contact + 100..=contact + 102).contains(&done),
        "pressed at cycle {contact}, attained at {done}"
    );
    // −36: toward −5 M with 60E1h = 100 (10 %), below PT11's 15 %: it limits.
    let (sw, contact, done, torque, home) = stopper_homing(-36, 100);
    assert_eq!((sw, home, torque), (0x1400, -5_000_000.0, -100));
    assert!((contact + 100..=contact + 102).contains(&done));
}

#[test]
fn the_stopper_type_stops_with_al_90_at_a_stroke_end() {
    // No stopper before the limit at 60 M (§5.4.9(6)(d) "when the stroke end is detected").
    let mut d = j4(0);
    d.sdo_download(0x6098, 0, &[(-4i8) as u8]).unwrap();
    let (sw, _) = run(&mut d);
    assert_eq!(sw & 0x3400, 0x2400);
    assert_eq!(d.warning(), Some(AL_90));
    assert!(d.plant().position() >= 60.0e6);
}
