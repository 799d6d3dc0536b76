//! Tests of the simulated MR-JE-C's point table mode, run through the motor as a whole.

use super::super::fixture::{cw, pp, run, run_halted};
use super::super::motion::Motion;
use super::super::profile::*;

fn table_3() -> PointTable {
    PointTable {
        number: 3,
        position: -65_536,
        speed: 30_000, // 300 r/min = 5 rev/s
        ramp: Ramp {
            acceleration_ms: 100,
            deceleration_ms: 200,
        },
        m_code: 0x42,
    }
}

fn pt() -> Profile {
    Profile {
        mode: POINT_TABLE,
        point: Target::Table(table_3()),
        ..pp()
    }
}

#[test]
fn a_start_runs_the_selected_table_and_reports_it_done() {
    let p = pt();
    let mut m = Motion::default();
    assert_eq!(m.point_table().demand(3), 3);
    m.controlword(cw(0x1F), cw(0x0F), &p);
    assert_eq!(m.status_bits(&p, false), 0);
    // 100 ms to 3000 r/min: 300 r/min after 10 ms.
    run(&mut m, &p, 10);
    assert_eq!(m.velocity(&p), -30_000);
    assert_eq!(m.point_table().demand(0), 3);
    run(&mut m, &p, 300);
    assert_eq!(m.position(), -65_536);
    assert_eq!(m.point_table().actual(), 3);
    assert_eq!(m.point_table().m_code(), 0x42);
    assert_eq!(m.point_table().demand(5), 5, "2D60h while stopped");
    assert_eq!(m.status_bits(&p, false), 1 << 10);
}

#[test]
fn halt_decelerates_with_the_table_and_restarts_at_once() {
    let p = pt();
    let mut m = Motion::default();
    m.controlword(cw(0x1F), cw(0x0F), &p);
    run(&mut m, &p, 20);
    run_halted(&mut m, &p, 10, true);
    // 200 ms from 3000 r/min: 300 r/min loses 150 r/min in 10 ms.
    assert_eq!(m.velocity(&p), -15_000);
    run_halted(&mut m, &p, 20, true);
    assert_eq!(m.velocity(&p), 0);
    assert_eq!(m.status_bits(&p, true), 1 << 10);
    run(&mut m, &p, 5);
    assert_eq!(
        m.velocity(&p),
        -15_000,
        "restarted with the table's acceleration"
    );
    run(&mut m, &p, 400);
    assert_eq!(m.position(), -65_536);
}

#[test]
fn high_speed_home_return_needs_a_home_and_ends_at_it() {
    let mut p = pt();
    p.point = Target::HomeReturn;
    p.home_offset = 1000;
    let mut m = Motion::default();
    m.controlword(cw(0x1F), cw(0x0F), &p);
    run(&mut m, &p, 10);
    assert_eq!(m.velocity(&p), 0, "no home yet: ignored");
    let hm = Profile { mode: HOMING, ..p };
    m.mode_changed();
    m.controlword(cw(0x0F), cw(0x1F), &hm);
    m.controlword(cw(0x1F), cw(0x0F), &hm);
    assert_eq!(m.position(), 1000);
    let mut go = pt();
    m.mode_changed();
    m.controlword(cw(0x0F), cw(0x1F), &go);
    m.controlword(cw(0x1F), cw(0x0F), &go);
    run(&mut m, &go, 400);
    assert_eq!(m.point_table().actual(), 3);
    go.point = Target::HomeReturn;
    go.home_offset = 1000;
    m.controlword(cw(0x0F), cw(0x1F), &go);
    m.controlword(cw(0x1F), cw(0x0F), &go);
    run(&mut m, &go, 2000);
    assert_eq!(m.position(), 1000);
    assert_eq!(m.point_table().actual(), 0);
}
