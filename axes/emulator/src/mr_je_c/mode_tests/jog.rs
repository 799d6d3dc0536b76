//! Tests of the simulated MR-JE-C's jog mode, run through the motor as a whole.

use super::super::fixture::{cw, pp, run, run_halted};
use super::super::motion::Motion;
use super::super::profile::*;

fn jg() -> Profile {
    Profile {
        mode: JOG,
        profile_velocity: 60_000, // 600 r/min = 10 rev/s
        acceleration_ms: 100,
        deceleration_ms: 200,
        ..pp()
    }
}

#[test]
fn jog_runs_at_6081h_while_bit_4_is_on() {
    let p = jg();
    let mut m = Motion::default();
    assert_eq!(m.status_bits(&p, false), 1 << 10);
    m.controlword(cw(0x1F), cw(0x0F), &p);
    // 100 ms to 3000 r/min: 600 r/min after 20 ms.
    run(&mut m, &p, 10);
    assert_eq!(m.velocity(&p), 30_000);
    run(&mut m, &p, 10);
    assert_eq!(m.velocity(&p), 60_000);
    assert_eq!(m.status_bits(&p, false), 0);
    run(&mut m, &p, 100);
    m.controlword(cw(0x0F), cw(0x1F), &p);
    // 200 ms from 3000 r/min: 600 r/min stops in 40 ms.
    run(&mut m, &p, 20);
    assert_eq!(m.velocity(&p), 30_000);
    run(&mut m, &p, 21);
    assert_eq!(m.velocity(&p), 0);
    assert_eq!(m.status_bits(&p, false), 1 << 10);
    assert!(m.position() > 131_072, "more than one revolution in 140 ms");
}

#[test]
fn bit_6_jogs_in_reverse_and_6084h_is_taken_at_the_edge() {
    let mut p = jg();
    let mut m = Motion::default();
    m.controlword(cw(0x5F), cw(0x0F), &p);
    run(&mut m, &p, 30);
    assert_eq!(m.velocity(&p), -60_000);
    p.deceleration_ms = 0;
    run_halted(&mut m, &p, 20, true);
    assert_eq!(
        m.velocity(&p),
        -30_000,
        "halt decelerates with the 200 ms taken at the edge"
    );
    run_halted(&mut m, &p, 21, true);
    assert_eq!(m.velocity(&p), 0);
    assert_eq!(m.status_bits(&p, true), 1 << 10);
    run(&mut m, &p, 10);
    assert_eq!(m.velocity(&p), -30_000, "halt off restarts at once");
}
