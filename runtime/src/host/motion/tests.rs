//! The engine's timeline checks against a late or refused motion start.

use super::*;
use crate::handoff::HomingStatus;
use crate::services::LiveAxis;
use crate::setpoints::MAX_AXES;

fn idle_at(cycle: u64, motion_id: u32, motion_done: u32, motion_refused: u32) -> StatusSnapshot {
    StatusSnapshot {
        cycle,
        state: CellState::Idle,
        stop_reason: None,
        motion_id,
        motion_done,
        motion_refused,
        motion_slip: 0,
        hold: [0.0; MAX_AXES],
        live: [LiveAxis::default(); MAX_AXES],
        homing: HomingStatus::default(),
    }
}

const SLIP: Cycles = Cycles(100);

#[test]
fn a_motion_whose_first_block_was_refused_fails_at_once() {
    // Motion 7 is refused at its start cycle 100: the planner knows in the next status.
    let s = idle_at(101, 6, 6, 7);
    assert!(matches!(
        check_running(&s, 7, 500, SLIP),
        Err(MotionError::NotStarted(7))
    ));
    // A motion not yet started and not refused keeps waiting for its start cycle.
    let s = idle_at(101, 6, 6, 5);
    assert!(check_running(&s, 7, 500, SLIP).is_ok());
    // Started, then idle past its end without a report: an error, not a wait.
    let s = idle_at(500 + 2 * BLOCK_CYCLES as u64 + 1, 7, 6, 5);
    assert!(matches!(
        check_running(&s, 7, 500, SLIP),
        Err(MotionError::EndNotReported(7))
    ));
    assert!(check_running(&idle_at(501, 7, 6, 5), 7, 500, SLIP).is_ok());
    // Without a word from the RT thread it fails once its blocks are long past, the
    // start slip the RT thread allows included.
    let s = idle_at(500 + 2 * BLOCK_CYCLES as u64 + 100, 6, 6, 5);
    assert!(check_running(&s, 7, 500, SLIP).is_ok());
    let s = idle_at(500 + 2 * BLOCK_CYCLES as u64 + 101, 6, 6, 5);
    assert!(matches!(
        check_running(&s, 7, 500, SLIP),
        Err(MotionError::NotStarted(7))
    ));
}

#[test]
fn a_late_started_motion_is_judged_on_its_own_timeline() {
    // Motion 7 started 40 cycles late: its blocks are due 40 cycles after the cycle they
    // name, so it has not yet outlived its last published block at cycle 500.
    let mut s = idle_at(500 + 2 * BLOCK_CYCLES as u64 + 40, 7, 6, 5);
    s.motion_slip = 40;
    assert_eq!(motion_cycle(&s, 7), 500 + 2 * BLOCK_CYCLES as u64);
    assert!(check_running(&s, 7, 500, SLIP).is_ok());
    s.cycle += 1;
    assert!(matches!(
        check_running(&s, 7, 500, SLIP),
        Err(MotionError::EndNotReported(7))
    ));
    // The slip belongs to the motion the status names, not to the next one.
    assert_eq!(motion_cycle(&s, 8), s.cycle);
}
