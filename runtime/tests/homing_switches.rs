//! Homing with switches on the emulated drives of an in-process cell: each homing method the
//! MR-J4-TM manual lists and cellrt emulates (MR-J4-TM manual §5.4.9(4)) runs against a home
//! dog, limit switches and the Z phase placed by `[axes.sim]`, with the speeds (6099h),
//! acceleration (609Ah) of `[axes.homing]` written by SDO at the homing start.
//! Judged on the recorded cycles (the emulated clock): the motor comes to rest on the switch or
//! Z position within the in-position range (100 pulses, [Pr. PA10]'s default), 606Ch stays
//! within 6099h:1 and its change within the 609Ah rate, statusword bits 13/12/10 read
//! "in progress" (0/0/0) until the cycle the home is reached, then "completed" (0/1/1); a
//! stroke end in a method that fails on it gives "error" (1/0/0 moving, 1/0/1 at rest) and a
//! warning (statusword bit 7: AL. 90, asserted by code in the simulator's tests). A cell on
//! the in-process emulated EtherCAT segment homes by a program step with the configured method,
//! its 6099h/609Ah going through the mailbox worker.

#[allow(dead_code)] // the shared support: this test uses the event log and the cell rig
mod support;
use support::cell_rig::Rig;
use support::event_log::cycle_of;

use std::path::Path;

use cellrt_cia402::homing::{HomeProcedure, HomingFailure};
use cellrt_config::CellConfig;
use cellrt_runtime::handoff::{AxisRecord, EventKind, HomeRequest};

/// The in-position range of the emulated drives, counts ([Pr. PA10] default 100 pulses).
const IN_POSITION: f64 = 100.0;
/// MR-J4-TM 22-bit encoder on a 10 mm/rev axis.
const COUNTS_PER_MM: f64 = 419_430.4;
/// `[axes.homing]`: 6099h:1 and 6099h:2 in mm/s, 609Ah in ms (from 0 to the rated speed,
/// 3000 r/min = 500 mm/s: 1000 mm/s²).
const SWITCH_SPEED: f64 = 100.0;
const CREEP_SPEED: f64 = 10.0;
const ACCELERATION_MS: u32 = 500;
const ACCELERATION: f64 = 500.0 / (ACCELERATION_MS as f64 / 1000.0);
/// The simulated servo loop's overshoot of 606Ch over the drive's generator (within 3 %).
const VELOCITY_OVERSHOOT: f64 = 1.03;
/// The same for the change of 606Ch: about 6 % at the reversals of the searches, more after a
/// late exchange of a loaded machine; without 609Ah the plant's 3000 mm/s² would show.
const ACCELERATION_OVERSHOOT: f64 = 1.15;

/// Statusword bits in hm (MR-J4-TM manual §5.4.9).
const TARGET_REACHED: u16 = 1 << 10;
const HOMING_ATTAINED: u16 = 1 << 12;
const HOMING_ERROR: u16 = 1 << 13;
const WARNING: u16 = 1 << 7;
const HOS: u16 = 1 << 4;

/// The dog [150, 160] mm, limits at 20 and 250 mm, the Z phase every 10 mm from 2.5 mm, the
/// drive's travel distance after proximity dog 8 mm (from 100 to 10 mm/s at 1000 mm/s² takes
/// 4.95 mm: less would be −2's AL. 90).
fn cell(tag: &str, start_mm: f64) -> CellConfig {
    CellConfig::parse(Path::new("homing.toml"), &cell_text(tag, start_mm)).unwrap()
}

/// The text of [`cell`].
fn cell_text(tag: &str, start_mm: f64) -> String {
    format!(
        r#"
[cell]
name = "home-{tag}-{}"
cycle_time_us = 1000
[watchdogs]
max_consecutive_overruns = 0
[[axes]]
name = "x"
drive = "mr-j4-tm"
motor = {{ rated_speed = 3000 }}
unit = "mm"
counts_per_unit = {COUNTS_PER_MM}
limits = {{ position = [0.0, 500.0], velocity = 200.0, acceleration = 1000.0, jerk = 10000.0 }}
sim = {{ initial_position = {start_mm}, home_dog = [150.0, 160.0], positive_limit = 250.0, negative_limit = 20.0, z_phase_position = 2.5, travel_after_dog = 8.0 }}
homing = {{ switch_speed = {SWITCH_SPEED}, creep_speed = {CREEP_SPEED}, acceleration_ms = {ACCELERATION_MS} }}
"#,
        std::process::id()
    )
}

#[test]
fn the_travel_after_dog_reaches_the_drive_in_counts_and_is_a_length() {
    // 8 mm × 419 430.4 counts/mm = 3 355 443.2 counts.
    assert_eq!(
        cell("travel", 100.0).axes.on_loop()[0]
            .sim
            .homing
            .travel_after_dog,
        3_355_443
    );
    let text =
        cell_text("travel", 100.0).replace("travel_after_dog = 8.0", "travel_after_dog = -1.0");
    let err = CellConfig::parse(Path::new("homing.toml"), &text).unwrap_err();
    assert!(err.to_string().contains("sim.travel_after_dog"), "{err}");
}

/// Homes `rig`'s axis with `method`; returns the records of the homing and its failure code.
fn run_homing(rig: &mut Rig, method: i8) -> (Vec<AxisRecord>, i64) {
    let seen = rig.events.len();
    rig.handoff.request_homing(HomeRequest {
        axis: 0,
        procedure: HomeProcedure::HomingMode(method),
    });
    let kinds = (EventKind::HomingStarted, EventKind::HomingFinished);
    let (started, finished, _) = rig.until(seen, kinds, 1);
    let span = rig.span(started.unwrap_or(0), finished.cycle);
    (span, finished.value)
}

/// The hm records from the first with homing operation start (controlword bit 4) on.
fn running(span: &[AxisRecord]) -> Vec<AxisRecord> {
    span.iter()
        .skip_while(|r| r.controlword & HOS == 0)
        .take_while(|r| r.mode_display == 6)
        .copied()
        .collect()
}

/// (method, start mm, home mm): every searching method MR-J4-TM lists and cellrt emulates.
const SEARCHES: [(i8, f64, f64); 28] = [
    // Dog type (rear-end detection, Z reference): the first Z after the rear end.
    (-1, 100.0, 162.5),
    (-33, 200.0, 142.5),
    // Dog cradle type: the first Z after the front end.
    (-8, 100.0, 152.5),
    (-40, 200.0, 152.5),
    (4, 100.0, 152.5),
    (6, 200.0, 152.5),
    // Last Z-phase reference: back off the dog, the first Z.
    (-9, 100.0, 142.5),
    (-41, 200.0, 162.5),
    (3, 100.0, 142.5),
    (5, 200.0, 162.5),
    // Dogless: the first Z (33/34 at the creep speed from the start).
    (-11, 95.0, 102.5),
    (-43, 100.0, 92.5),
    (33, 100.0, 92.5),
    (34, 100.0, 102.5),
    // The stroke end reverses the search: forward from above the dog to the 250 mm limit,
    // back over the dog, forward again.
    (7, 200.0, 142.5),
    (8, 200.0, 152.5),
    (-1, 200.0, 162.5),
    // Mirrored, reverse from below the dog to the 20 mm limit.
    (11, 100.0, 162.5),
    (12, 100.0, 152.5),
    (-33, 100.0, 142.5),
    // Count type (−2/−34): the front end ± the 8 mm travel (158, 152), then the next Z.
    (-2, 100.0, 162.5),
    (-34, 200.0, 142.5),
    // Rear-end reference (−6): the rear end 160 + 8.
    (-6, 100.0, 168.0),
    // Front-end reference (−7, −10, 19–24, 27, 28): the front end 150 + 8 or 160 − 8.
    (-7, 100.0, 158.0),
    (-42, 200.0, 152.0),
    (20, 100.0, 158.0),
    // 23 from above the dog: the 250 mm limit reverses it; 28 reverse from above.
    (23, 200.0, 158.0),
    (28, 200.0, 152.0),
];

#[test]
fn each_searching_method_homes_on_its_switch_or_z_phase_within_its_speeds() {
    for (method, start, home) in SEARCHES {
        let mut rig = Rig::start(cell(&format!("m{}", method as u8), start));
        let (span, failure) = run_homing(&mut rig, method);
        assert_eq!(failure, 0, "method {method}: attained");
        let run = running(&span);
        let done = run
            .iter()
            .position(|r| r.statusword & HOMING_ATTAINED != 0)
            .unwrap_or_else(|| panic!("method {method}: no bit 12"));
        // In progress until the home is reached: bits 13/12/10 = 0/0/0.
        assert!(done > 1, "method {method}: it moved");
        for r in &run[1..done] {
            let bits = r.statusword & (HOMING_ERROR | HOMING_ATTAINED | TARGET_REACHED);
            assert_eq!(bits, 0, "method {method}: in progress at cycle {}", r.cycle);
        }
        let end = run[done];
        assert_eq!(
            end.statusword & (HOMING_ERROR | HOMING_ATTAINED | TARGET_REACHED),
            HOMING_ATTAINED | TARGET_REACHED,
            "method {method}: completed"
        );
        // The cycle before: at rest on the home (raw 6064h, before the drive's preset).
        let at = f64::from(run[done - 1].position_actual);
        assert!(
            (at - home * COUNTS_PER_MM).abs() <= IN_POSITION,
            "method {method}: rests at {} mm, home {home} mm",
            at / COUNTS_PER_MM
        );
        // MR-J4-TM: 6064h = the home position address (0) from then on.
        assert!(
            f64::from(end.position_actual).abs() <= IN_POSITION,
            "method {method}: 6064h {} after the preset",
            end.position_actual
        );
        let (v, a) = rig.peaks(&span);
        let fast = if matches!(method, 33 | 34) {
            CREEP_SPEED
        } else {
            SWITCH_SPEED
        };
        assert!(
            v <= fast * VELOCITY_OVERSHOOT && v >= fast * 0.9,
            "method {method}: peak {v} mm/s"
        );
        assert!(
            a <= ACCELERATION * ACCELERATION_OVERSHOOT,
            "method {method}: peak {a} mm/s²"
        );
        rig.stop();
    }
}

#[test]
fn the_data_set_methods_home_where_the_axis_stands_without_moving() {
    for method in [-3, 35, 37] {
        let mut rig = Rig::start(cell(&format!("d{}", method as u8), 123.0));
        let (span, failure) = run_homing(&mut rig, method);
        assert_eq!(failure, 0, "method {method}");
        let (v, _) = rig.peaks(&span);
        assert!(v < 0.01, "method {method}: moved at {v} mm/s");
        let run = running(&span);
        let done = run
            .iter()
            .position(|r| r.statusword & HOMING_ATTAINED != 0)
            .unwrap();
        assert!(f64::from(run[done].position_actual).abs() <= IN_POSITION);
        assert!(
            (f64::from(run[done - 1].position_actual) - 123.0 * COUNTS_PER_MM).abs() <= 1.0,
            "method {method}"
        );
        rig.stop();
    }
}

#[test]
fn a_stroke_end_in_a_method_that_fails_on_it_is_a_homing_error_with_al_90() {
    // Method 3 forward from above the dog: the 250 mm limit, "stroke end → AL. 90".
    let mut rig = Rig::start(cell("err", 200.0));
    let (span, failure) = run_homing(&mut rig, 3);
    assert_eq!(failure, HomingFailure::DriveError as i64);
    let run = running(&span);
    let first = run
        .iter()
        .position(|r| r.statusword & HOMING_ERROR != 0)
        .expect("bit 13");
    assert!(
        f64::from(run[first].position_actual) >= 250.0 * COUNTS_PER_MM - IN_POSITION,
        "at the limit"
    );
    // Error while moving: 1/0/0; the sudden stop ends at rest: 1/0/1 with the warning.
    assert_eq!(
        run[first].statusword & (HOMING_ATTAINED | TARGET_REACHED),
        0,
        "velocity ≠ 0"
    );
    assert!(rig.speed(&run[first]).abs() > 1.0);
    let rest = run[first..]
        .iter()
        .find(|r| r.statusword & TARGET_REACHED != 0)
        .expect("comes to rest");
    assert_eq!(
        rest.statusword & (HOMING_ERROR | HOMING_ATTAINED),
        HOMING_ERROR
    );
    assert_eq!(rest.statusword & WARNING, WARNING);
    assert!(
        span.iter()
            .all(|r| r.statusword & HOMING_ATTAINED == 0 || r.mode_display != 6),
        "never attained"
    );
    rig.stop();
}

/// A cell of one MR-J4-TM on the in-process emulated EtherCAT segment whose program homes with
/// `[axes.homing] method = -1` (no method in the step) and then moves in the new coordinates.
const ETHERCAT_PROGRAM: &str = r#"
[[step]]
do = "power_on"
[[step]]
do = "home"
axis = "y"
[[step]]
do = "move"
target = { y = 20.0 }
[[step]]
do = "power_off"
"#;

#[test]
fn an_emulated_ethercat_drive_homes_on_its_switches_with_the_configured_method_and_speeds() {
    use cellrt_runtime::host::controller::{run, Outcome, RunOptions};
    use cellrt_runtime::host::program::Program;
    let text = format!(
        r#"
[cell]
name = "home-ecat-{}"
cycle_time_us = 1000
[setpoints]
lookahead_ms = 200
[watchdogs]
max_consecutive_overruns = 0
[ethercat]
interface = "in-process"
[[axes]]
name = "y"
drive = "mr-j4-tm"
transport = "ethercat"
motor = {{ rated_speed = 3000 }}
unit = "mm"
counts_per_unit = {COUNTS_PER_MM}
limits = {{ position = [0.0, 500.0], velocity = 200.0, acceleration = 1000.0, jerk = 10000.0 }}
sim = {{ initial_position = 50.0, home_dog = [100.0, 110.0], positive_limit = 300.0, negative_limit = 10.0, z_phase_position = 2.5 }}
homing = {{ method = -1, switch_speed = {SWITCH_SPEED}, creep_speed = {CREEP_SPEED}, acceleration_ms = {ACCELERATION_MS} }}
"#,
        std::process::id()
    );
    let cell = CellConfig::parse(Path::new("home-ecat.toml"), &text).unwrap();
    let program = Program::parse(Path::new("p.toml"), ETHERCAT_PROGRAM, &cell).unwrap();
    let summary = run(
        &cell,
        RunOptions {
            program: Some(program),
            ..RunOptions::default()
        },
    )
    .expect("cell runs");
    let log = &summary.recording.event_log;
    assert_eq!(summary.outcome, Outcome::ProgramCompleted, "{log:#?}");
    assert!(
        log.iter()
            .any(|l| l.contains("homing_started") && l.contains("method -1")),
        "{log:#?}"
    );
    let started = cycle_of(log, "homing_started").unwrap();
    let finished = cycle_of(log, "homing_finished").unwrap();
    assert!(
        log.iter()
            .any(|l| l.contains("homing_finished") && l.contains("attained")),
        "{log:#?}"
    );
    // 50 → 100 mm at 100 mm/s (0.55 s), through the dog slowing to 10 mm/s, 2.5 mm to the Z at
    // 10 mm/s: about 1.4 s (a data-set homing would take a few cycles). The
    // drive's own 6099h (100 r/min = 16.7 mm/s, creep 1.67 mm/s here) would take over 9 s: the
    // SDO writes of 6099h/609Ah reached it through the mailbox.
    let cycles = finished - started;
    assert!((1200..2500).contains(&cycles), "{cycles} cycles\n{log:#?}");
    // 6064h = 0 at the home (112.5 mm raw): the move to 20 mm ends at 132.5 mm raw.
    let y = &summary.axes[0];
    assert!(
        (y.final_position - 20.0).abs() < 0.05,
        "{}",
        y.final_position
    );
}
