//! Tests of the simulated MR-JE-C's homing mode, run through the motor as a whole.

use super::super::fixture::{cw, pp, run, run_halted};
use super::super::motion::Motion;
use super::super::profile::*;

fn hm() -> Profile {
    Profile {
        mode: HOMING,
        ..pp()
    }
}

#[test]
fn method_37_makes_the_current_position_home_at_once() {
    let mut p = pp();
    let mut m = Motion::default();
    m.controlword(cw(0x1F), cw(0x0F), &p);
    run(&mut m, &p, 300);
    assert_eq!(m.position(), 131_072);
    p = hm();
    p.home_offset = 500;
    m.mode_changed();
    m.controlword(cw(0x0F), cw(0x1F), &p);
    assert_eq!(m.status_bits(&p, false), 1 << 10, "not started");
    m.controlword(cw(0x1F), cw(0x0F), &p);
    assert_eq!(m.position(), 500, "6064h reads the home position 607Ch");
    assert!(m.homed());
    assert_eq!(m.status_bits(&p, false), (1 << 10) | (1 << 12));
    run(&mut m, &p, 10);
    assert_eq!(m.position(), 500, "no motion");
}

#[test]
fn a_method_not_emulated_is_a_homing_error_without_motion() {
    let mut p = hm();
    p.homing_method = 35;
    let mut m = Motion::default();
    m.controlword(cw(0x1F), cw(0x0F), &p);
    assert!(!m.homed());
    assert_eq!(m.status_bits(&p, false), (1 << 10) | (1 << 13));
    run(&mut m, &p, 10);
    assert_eq!(m.position(), 0);
    p.homing_method = -1;
    m.controlword(cw(0x0F), cw(0x1F), &p);
    m.controlword(cw(0x1F), cw(0x0F), &p);
    assert_eq!(m.status_bits(&p, false) & (1 << 13), 1 << 13);
}

#[test]
fn halt_blocks_the_start_until_bit_4_rises_again_with_halt_off() {
    let p = hm();
    let mut m = Motion::default();
    m.controlword(cw(0x11F), cw(0x10F), &p);
    assert!(!m.homed(), "a start with the halt on does nothing");
    m.controlword(cw(0x1F), cw(0x11F), &p);
    assert!(!m.homed(), "halt off with bit 4 still on does not start");
    m.controlword(cw(0x0F), cw(0x1F), &p);
    m.controlword(cw(0x1F), cw(0x0F), &p);
    assert!(m.homed());
}

#[test]
fn the_motor_in_hm_decelerates_with_609ah() {
    let mut p = pp();
    p.mode = PROFILE_VELOCITY;
    p.target_velocity = 300_000; // the rated speed, 50 rev/s
    p.acceleration_ms = 0;
    p.deceleration_ms = 0;
    let mut m = Motion::default();
    run(&mut m, &p, 1);
    assert_eq!(m.velocity(&p), 300_000);
    p.mode = HOMING;
    p.homing_acceleration_ms = 200;
    m.mode_changed();
    run_halted(&mut m, &p, 100, true);
    // 200 ms from the rated speed to 0: half of it after 100 ms.
    assert_eq!(m.velocity(&p), 150_000);
    run_halted(&mut m, &p, 100, true);
    assert_eq!(m.velocity(&p), 0);
    assert_eq!(m.status_bits(&p, true), 1 << 10);
}
