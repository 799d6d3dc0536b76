//! Rule 1 of the RT thread for a homing with switches (issue 19): an MR-J4-TM homed with the
//! dog method −1 on the simulated switches, its 6098h, 6099h:1/2 and 609Ah written by SDO from
//! the RT loop's acyclic slot at the homing start, allocates nothing in steady state.

mod common;
#[allow(dead_code)] // the shared support: this test uses the RT-allocation rig
mod support;

use support::alloc_rig::{self, Counting};

use std::path::Path;
use std::time::{Duration, Instant};

use cellrt_cia402::homing::HomeProcedure;
use cellrt_config::CellConfig;
use cellrt_runtime::handoff::{EventKind, HomeRequest};

#[test]
fn a_homing_with_switches_runs_without_allocating_on_the_rt_thread() {
    let text = format!(
        r#"
[cell]
name = "na-home-{}"
cycle_time_us = 1000
[watchdogs]
max_consecutive_overruns = 0
[[axes]]
name = "x"
drive = "mr-j4-tm"
motor = {{ rated_speed = 3000 }}
unit = "mm"
counts_per_unit = 419430.4
limits = {{ position = [0.0, 500.0], velocity = 200.0, acceleration = 1000.0, jerk = 10000.0 }}
sim = {{ initial_position = 100.0, home_dog = [120.0, 130.0], positive_limit = 300.0, negative_limit = 10.0, z_phase_position = 2.5 }}
homing = {{ method = -1, switch_speed = 100.0, creep_speed = 20.0, acceleration_ms = 500 }}
"#,
        std::process::id()
    );
    let cell = CellConfig::parse(Path::new("na-homing.toml"), &text).unwrap();
    let counting = Counting::new(
        common::hook,
        common::marked_heap_calls,
        &common::LOOPS_EXITED,
    );
    let steady = alloc_rig::start_steady(&cell, counting);
    let h = &steady.h;
    h.request_homing(HomeRequest {
        axis: 0,
        procedure: HomeProcedure::HomingMode(-1),
    });
    let end = Instant::now() + Duration::from_secs(20);
    let mut finished = None;
    while finished.is_none() {
        assert!(Instant::now() < end, "the homing never finished");
        while let Some(e) = h.pop_event() {
            if e.kind == EventKind::HomingFinished {
                finished = Some(e.value);
            }
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    assert_eq!(finished, Some(0), "homing attained");
    alloc_rig::power_off_and_check(steady);
}
