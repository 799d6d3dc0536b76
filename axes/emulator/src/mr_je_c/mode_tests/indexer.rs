//! Tests of the simulated MR-JE-C's indexer mode, run through the motor as a whole.

use super::super::fixture::{cw, pp, run, run_halted};
use super::super::indexer::*;
use super::super::motion::Motion;
use super::super::profile::*;

fn idx() -> Profile {
    Profile {
        mode: INDEXER,
        units_per_rev: 8,
        profile_velocity: 60_000, // 600 r/min = 10 rev/s = 80 stations/s
        indexer_station: 3,
        indexer_ramp: Ramp::default(),
        ..pp()
    }
}

#[test]
fn the_route_is_the_shorter_way_round() {
    assert_eq!(shortest_route(0.0, 3, 8), 3);
    assert_eq!(shortest_route(0.0, 5, 8), -3);
    assert_eq!(
        shortest_route(0.0, 4, 8),
        4,
        "a tie goes address-increasing"
    );
    assert_eq!(shortest_route(7.0, 1, 8), 9);
    assert_eq!(shortest_route(-1.0, 6, 8), -2);
}

#[test]
fn a_start_turns_to_the_station_and_halt_is_disabled() {
    let p = idx();
    let mut m = Motion::default();
    m.controlword(cw(0x1F), cw(0x0F), &p);
    assert_eq!(m.point_table().demand(0), 3);
    run_halted(&mut m, &p, 10, true);
    assert_eq!(m.velocity(&p), 60_000, "halt has no effect in idx");
    run(&mut m, &p, 100);
    assert_eq!(m.position(), 3);
    assert_eq!(m.point_table().actual(), 3);
    assert_eq!(m.point_table().m_code(), 0);
    assert_eq!(m.status_bits(&p, false), 1 << 10);
    let mut back = idx();
    back.indexer_station = 1;
    m.controlword(cw(0x0F), cw(0x1F), &back);
    m.controlword(cw(0x1F), cw(0x0F), &back);
    run(&mut m, &back, 10);
    assert_eq!(
        m.velocity(&back),
        -60_000,
        "3 → 1 the short way is backwards"
    );
    assert_eq!(
        m.point_table().actual(),
        3,
        "the previous station until completion"
    );
    run(&mut m, &back, 100);
    assert_eq!(m.position(), 1);
    back.indexer_station = 7;
    m.controlword(cw(0x0F), cw(0x1F), &back);
    m.controlword(cw(0x1F), cw(0x0F), &back);
    run(&mut m, &back, 100);
    assert_eq!(m.position(), 7, "1 → 7 backwards past 0 reads 0 … PT28 − 1");
    assert_eq!(m.point_table().actual(), 7);
}

#[test]
fn a_station_outside_the_revolution_does_not_start() {
    let mut p = idx();
    p.indexer_station = 8;
    let mut m = Motion::default();
    m.controlword(cw(0x1F), cw(0x0F), &p);
    run(&mut m, &p, 10);
    assert_eq!(m.velocity(&p), 0);
    assert_eq!(m.point_table().actual(), 0);
}

/// With [Pr. PC03] the turn to station 5 the short way (−3 stations) ends at 5 within the
/// revolution once the filtered command has arrived: the position goes back into 0 … 7 at the
/// trapezoid's arrival with the filter's samples, so the motor neither jumps nor turns back.
#[test]
fn the_s_pattern_turn_ends_at_the_station_within_the_revolution() {
    let p = Profile {
        indexer_station: 5,
        s_pattern_ms: 30,
        ..idx()
    };
    let mut m = Motion::default();
    m.controlword(cw(0x1F), cw(0x0F), &p);
    let mut last = m.position_in(&p);
    for _ in 0..200 {
        run(&mut m, &p, 1);
        let now = m.position_in(&p);
        // The step on the circle, −4 … 3 stations: never forward.
        let step = (now - last + 4).rem_euclid(8) - 4;
        assert!((-1..=0).contains(&step), "{last} -> {now}");
        last = now;
    }
    assert_eq!((m.position(), m.velocity(&p)), (5, 0));
    assert_eq!(m.status_bits(&p, false), 1 << 10);
}
