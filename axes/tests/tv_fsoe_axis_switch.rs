//! Test vectors mr-jet-g-n1.md §11 TV-12 (FSoE: the safety process data of the MR-JET-G-N1
//! and the master's side of it) and mr-j5-g-n1.md §11 TV-14 (the axis-selection switch SW3),
//! against the simulated drives. Items the specs mark "not stated" / [inferred] are tested only
//! as the simulator's named, documented parameters.

mod common;

use cellrt_axes::profiles::mr_j5_g_n1::AL_011_2;
use cellrt_axes::sim::drive::AxisSwitch;
use cellrt_axes::{DriveModel, FsaState, SimDriveParams};
use common::{boot, drive, masked, send};

fn switch(sw3_1: bool, sw3_2: bool) -> SimDriveParams {
    SimDriveParams {
        axis_switch: AxisSwitch { sw3_1, sw3_2 },
        ..SimDriveParams::default()
    }
}

/// Runs a few cycles with Disable Voltage and returns the last statusword.
fn idle(d: &mut cellrt_axes::SimDrive) -> cellrt_axes::Statusword {
    let mut sw = d.tx_pdo().statusword;
    for _ in 0..5 {
        sw = send(d, 0x0000);
    }
    sw
}

#[test]
fn tv_14_sw3_1_off_sw3_2_on_raises_al_011_2_on_a_1_axis_mr_j5() {
    let mut d = drive(DriveModel::MrJ5GN1, 1000, switch(false, true));
    let sw = idle(&mut d);
    assert_eq!(d.alarm(), Some(AL_011_2));
    assert_eq!(d.tx_pdo().error_code, AL_011_2, "603Fh");
    assert_eq!(d.state(), FsaState::Fault);
    assert!(masked(sw, 0x414F, 0x0008), "Fault: {sw}");
    // The switch is read at power-on ([inferred]): a Fault Reset cannot remove the cause.
    send(&mut d, 0x0080);
    let sw = idle(&mut d);
    assert_eq!(d.state(), FsaState::Fault, "{sw}");
    assert_eq!(d.alarm(), Some(AL_011_2));
    // Enable commands are refused while the alarm stands.
    for cw in [0x06, 0x07, 0x0F] {
        send(&mut d, cw);
    }
    assert_eq!(d.state(), FsaState::Fault);
    // A valid setting takes effect at the next power-on.
    d.set_axis_switch(AxisSwitch::default());
    assert_eq!(d.alarm(), Some(AL_011_2), "not before the power cycle");
    d.power_cycle();
    boot(&mut d);
    assert_eq!(d.alarm(), None);
    assert_eq!(d.tx_pdo().error_code, 0);
}

#[test]
fn tv_14_every_other_sw3_setting_starts_cleanly_on_a_1_axis_mr_j5() {
    for (a, b) in [(false, false), (true, false), (true, true)] {
        let mut d = drive(DriveModel::MrJ5GN1, 1000, switch(a, b));
        boot(&mut d);
        assert_eq!(d.alarm(), None, "SW3-1 {a}, SW3-2 {b}");
    }
    // The default is a valid setting.
    let mut d = drive(DriveModel::MrJ5GN1, 1000, SimDriveParams::default());
    boot(&mut d);
    assert_eq!(d.alarm(), None);
}

#[test]
fn tv_14_setting_changed_at_run_time_raises_at_the_next_power_on() {
    let mut d = drive(DriveModel::MrJ5GN1, 1000, SimDriveParams::default());
    boot(&mut d);
    d.set_axis_switch(AxisSwitch {
        sw3_1: false,
        sw3_2: true,
    });
    idle(&mut d);
    assert_eq!(d.alarm(), None, "SW3 is read at power-on only");
    d.power_cycle();
    idle(&mut d);
    assert_eq!(d.alarm(), Some(AL_011_2));
    assert_eq!(d.state(), FsaState::Fault);
}

#[test]
fn tv_14_multi_axis_and_other_models_have_no_stated_sw3_rule() {
    // mr-j5-g-n1.md §1.5: "Multi-axis SW3 settings are not given"; the other models have no SW3
    // rule in their manuals.
    for model in [
        DriveModel::MrJ5W2GN1,
        DriveModel::MrJ5W3GN1,
        DriveModel::MrJetGN1,
        DriveModel::MrJ4TM,
    ] {
        let mut d = drive(model, 1000, switch(false, true));
        boot(&mut d);
        assert_eq!(d.alarm(), None, "{model}");
        assert!(cellrt_axes::profile(model).invalid_axis_switch.is_none());
    }
}
