//! Tests of the simulated MR-JE-C's torque mode, run through the motor as a whole.

use super::super::fixture::{pp, run, run_halted};
use super::super::motion::Motion;
use super::super::profile::*;

fn tq() -> Profile {
    Profile {
        mode: PROFILE_TORQUE,
        target_torque: 1000,    // 100.0 %
        torque_slope: 10_000,   // 1000.0 %/s
        velocity_limit: 50_000, // 500.00 r/min, the 2D20h default
        ..pp()
    }
}

#[test]
fn the_demand_ramps_with_6087h_and_the_speed_stops_at_2d20h() {
    let p = tq();
    let mut m = Motion::default();
    run(&mut m, &p, 50);
    assert_eq!(m.torque().demand(), 500, "1000.0 %/s for 50 ms");
    run(&mut m, &p, 50);
    assert_eq!(m.torque().demand(), 1000);
    assert_eq!(m.status_bits(&p, false), 1 << 10);
    run(&mut m, &p, 100);
    assert_eq!(m.velocity(&p), 50_000, "held at the speed limit");
    assert_eq!(
        m.torque().actual(),
        30,
        "the friction torque holds the speed"
    );
}

#[test]
fn a_step_without_slope_and_torque_within_friction_leaves_the_motor_standing() {
    let mut p = tq();
    p.torque_slope = 0;
    p.target_torque = -30;
    let mut m = Motion::default();
    run(&mut m, &p, 1);
    assert_eq!(m.torque().demand(), -30);
    run(&mut m, &p, 100);
    assert_eq!(m.velocity(&p), 0);
    p.target_torque = -5000;
    run(&mut m, &p, 1);
    assert_eq!(m.torque().demand(), -3000, "6072h limits the demand");
}

#[test]
fn the_plant_accelerates_with_the_torque_over_friction() {
    let mut p = tq();
    p.torque_slope = 0;
    p.target_torque = 530; // 53.0 %: 50 % over the 3 % friction
    p.velocity_limit = 600_000;
    let mut m = Motion::default();
    run(&mut m, &p, 10);
    // 100 % takes 50 ms to 3000 r/min: 50 % gives 300 r/min in 10 ms.
    assert_eq!(m.velocity(&p), 30_000);
}

#[test]
fn halt_ramps_the_demand_to_0_and_restarts_after() {
    let p = tq();
    let mut m = Motion::default();
    run(&mut m, &p, 100);
    run_halted(&mut m, &p, 50, true);
    assert_eq!(m.torque().demand(), 500);
    run_halted(&mut m, &p, 50, true);
    assert_eq!(m.torque().demand(), 0);
    assert_eq!(m.status_bits(&p, true), 1 << 10);
    run(&mut m, &p, 10);
    assert_eq!(m.torque().demand(), 100);
}
