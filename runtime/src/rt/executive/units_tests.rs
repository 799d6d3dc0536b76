//! End to end, in emulated cycles: the master's csv command (60FFh in the drive's unit, from
//! `AxisChannel`) into each model's simulated drive, which decodes it by its manual's unit on its
//! own; the plant's speed in r/min equals the commanded axis speed converted by hand.

use std::path::Path;

use cellrt_cia402::master::MasterRequest;
use cellrt_cia402::{Cycles, DriveModel, RxPdo};
use cellrt_emulator::SimDrive;

use super::axis::AxisChannel;
use crate::host::cell_bus::sim_drives;
use cellrt_config::CellConfig;

/// One csv axis on `model`: a 10 mm/rev screw, `counts_per_rev` encoder counts per revolution.
fn cell(model: DriveModel, counts_per_rev: u32) -> CellConfig {
    let text = format!(
        "[cell]\nname = \"units\"\ncycle_time_us = 1000\n\n[[axes]]\nname = \"x\"\n\
         drive = \"{model}\"\nmode = \"csv\"\nunit = \"mm\"\ncounts_per_unit = {}\n\
         motor = {{ counts_per_rev = {counts_per_rev} }}\n\
         limits = {{ position = [-300.0, 300.0], velocity = 200.0, acceleration = 2000.0, \
         jerk = 20000.0 }}\n",
        f64::from(counts_per_rev) / 10.0
    );
    CellConfig::parse(Path::new("units.toml"), &text).expect("valid cell")
}

/// One cycle: the master's controlword and command, encoded by the axis' maps, through the
/// simulated drive, and its TxPDO decoded back. Returns the 60FFh sent.
fn cycle(ch: &mut AxisChannel, d: &mut SimDrive) -> i32 {
    let controlword = ch.master.update(ch.feedback.statusword);
    let cmd = ch.drive_command().expect("representable");
    let rx = RxPdo {
        mode: cmd.mode.as_i8(),
        controlword,
        target_position: ch.setpoint.round() as i32,
        target_velocity: cmd.target_velocity,
        velocity_limit: ch.velocity_limit(),
        torque_limit_positive: ch.torque_limit_objects.0,
        torque_limit_negative: ch.torque_limit_objects.1,
        counter: ch.counter.as_mut().map_or(0, |c| c.next_tx()),
        ..RxPdo::default()
    };
    let (mut rxb, mut txb) = ([0u8; 64], [0u8; 64]);
    let (rn, tn) = (ch.rx_map.byte_len(), ch.tx_map.byte_len());
    ch.rx_map.encode_rx(&rx, &mut rxb[..rn]).unwrap();
    d.cycle(&rxb[..rn], &mut txb[..tn], Cycles(1)).unwrap();
    ch.feedback = ch.tx_map.decode_tx(&txb[..tn]).unwrap();
    cmd.target_velocity
}

/// Runs `model` at 100 mm/s for 1.5 s; returns (plant speed in r/min, last 60FFh).
fn run_at_100_mm_per_s(model: DriveModel, counts_per_rev: u32) -> (f64, i32) {
    let cell = cell(model, counts_per_rev);
    let axis = &cell.axes.on_loop()[0];
    let mut ch = AxisChannel::new(&cell, axis);
    let mut d = sim_drives(&cell).remove(0);
    ch.master.request(MasterRequest::Enable);
    for _ in 0..200 {
        cycle(&mut ch, &mut d);
        ch.track_actual();
    }
    assert!(ch.master.is_enabled(), "{model} enabled");
    let dt = cell.period();
    let v = 100.0 * axis.scaling.counts_per_unit();
    let mut sent = 0;
    for _ in 0..1500 {
        ch.apply(ch.setpoint + v * dt, v, dt);
        sent = cycle(&mut ch, &mut d);
    }
    (d.motor_speed(), sent)
}

#[test]
fn every_model_runs_csv_at_the_commanded_speed_in_r_per_min() {
    // By hand: 100 mm/s on a 10 mm/rev screw is 10 rev/s = 600 r/min. 60FFh for 600 r/min:
    // MR-J3-T04 0.001 r/min (manual §9.6) = 600 000; MR-J4-TM 0.01 r/min (manual §4.2) =
    // 60 000; MR-JET / MR-J5 0.01 r/min (default, manuals silent) = 60 000; generic CiA 402
    // counts/s = 10 rev/s × 2^20 = 10 485 760.
    let cases = [
        (DriveModel::MrJ3T04, 262_144, 600_000),
        (DriveModel::MrJ3T04, 131_072, 600_000),
        (DriveModel::MrJ4TM, 4_194_304, 60_000),
        (DriveModel::MrJetGN1, 67_108_864, 60_000),
        (DriveModel::MrJ5GN1, 67_108_864, 60_000),
        (DriveModel::MrJ5W2GN1, 67_108_864, 60_000),
        (DriveModel::MrJ5W3GN1, 67_108_864, 60_000),
        (DriveModel::GenericCia402, 1_048_576, 10_485_760),
    ];
    for (model, cpr, literal) in cases {
        let (rpm, sent) = run_at_100_mm_per_s(model, cpr);
        assert!((rpm - 600.0).abs() < 0.01, "{model} ({cpr}): {rpm} r/min");
        let off = (f64::from(sent) - f64::from(literal)).abs();
        assert!(
            off <= f64::from(literal) * 1e-3,
            "{model}: 60FFh {sent}, manual {literal}"
        );
    }
}

/// The config error key of the one-axis cell on `model` with `motor` and `velocity` (mm/s).
fn refused_key(model: &str, motor: &str, velocity: f64) -> String {
    let text = format!(
        "[cell]\nname = \"units\"\ncycle_time_us = 1000\n\n[[axes]]\nname = \"x\"\n\
         drive = \"{model}\"\nmode = \"csv\"\nunit = \"mm\"\ncounts_per_unit = 1000\n{motor}\n\
         limits = {{ position = [-300.0, 300.0], velocity = {velocity}, acceleration = 2000.0, \
         jerk = 20000.0 }}\n"
    );
    match CellConfig::parse(Path::new("units.toml"), &text) {
        Ok(_) => String::new(),
        Err(e) => e.key,
    }
}

#[test]
fn limits_the_drive_cannot_represent_are_refused_at_load_naming_the_key() {
    // MR-J5 / MR-JET: no resolution in the manual, none configured.
    assert_eq!(
        refused_key("mr-j5-g-n1", "", 100.0),
        "axes[0].motor.counts_per_rev"
    );
    assert_eq!(
        refused_key("mr-jet-g-n1", "", 100.0),
        "axes[0].motor.counts_per_rev"
    );
    // MR-J3-T04: 0.001 r/min is the manual's, not a choice; no linear motors.
    let j3_unit = "motor = { velocity_unit = \"0.01 r/min\" }";
    assert_eq!(
        refused_key("mr-j3-t04", j3_unit, 100.0),
        "axes[0].motor.velocity_unit"
    );
    let j3_linear = "motor = { counts_per_mm = 1000 }";
    assert_eq!(
        refused_key("mr-j3-t04", j3_linear, 100.0),
        "axes[0].motor.counts_per_mm"
    );
    // Where the manual is silent the unit is the config's.
    let j5 = "motor = { counts_per_rev = 65536, velocity_unit = \"0.001 r/min\" }";
    assert_eq!(refused_key("mr-j5-g-n1", j5, 100.0), "");
    assert_eq!(
        refused_key(
            "mr-j5-g-n1",
            "motor = { counts_per_rev = 65536, velocity_unit = \"0.5 r/min\" }",
            100.0
        ),
        "axes[0].motor.velocity_unit"
    );
    // Velocity × scaling beyond I32: generic counts/s, 800 000 mm/s × 1000 × 3 (csv correction).
    assert_eq!(
        refused_key("cia402", "", 800_000.0),
        "axes[0].limits.velocity"
    );
    assert_eq!(refused_key("cia402", "", 700_000.0), "");
    // Beyond the motor's maximum speed: 100 mm/s = 100 000 counts/s = 3000 r/min at 2000
    // counts/rev.
    let max = "motor = { counts_per_rev = 2000, max_speed = 2999.0 }";
    assert_eq!(
        refused_key("mr-j5-g-n1", max, 100.0),
        "axes[0].limits.velocity"
    );
    let max = "motor = { counts_per_rev = 2000, max_speed = 3000.0 }";
    assert_eq!(refused_key("mr-j5-g-n1", max, 100.0), "");
}
