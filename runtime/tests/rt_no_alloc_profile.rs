//! Rule 1 of the RT thread for a cell of profile axes (issue 19): pp, pv and tq axes on the
//! MR-J5-G-N1 (profile objects written by SDO) and a pp axis on the MR-J4-TM in PA01 `___2`
//! (objects in its 1601h RxPDO) run drive-side motions, halts and a cell stop, a csp axis switches
//! to pp, moves and switches back, and the RT loop allocates nothing in steady state.

mod common;
#[allow(dead_code)] // the shared support: this test uses the RT-allocation rig
mod support;

use support::alloc_rig::{self, Counting};

use std::path::Path;
use std::time::{Duration, Instant};

use cellrt_config::CellConfig;
use cellrt_runtime::handoff::{
    CellCommand, EventKind, HostEnd, ProfileCommand, ProfileMotion, SwitchableMode,
};

fn axis(name: &str, drive: &str, mode: &str, extra: &str) -> String {
    format!(
        r#"
[[axes]]
name = "{name}"
drive = "{drive}"
mode = "{mode}"
{extra}
unit = "mm"
counts_per_unit = 1000
limits = {{ position = [0.0, 500.0], velocity = 100.0, acceleration = 1000.0, jerk = 10000.0 }}
sim = {{ initial_position = 100.0 }}
"#
    )
}

#[test]
fn profile_axes_run_without_allocating_on_the_rt_thread() {
    let j5 = "motor = { counts_per_rev = 10000, rated_speed = 3000 }";
    let j4 = "mode_group = \"profile\"\nmotor = { counts_per_rev = 10000, rated_speed = 3000 }";
    let text = format!(
        "[cell]\nname = \"na-prof-{}\"\ncycle_time_us = 1000\n[watchdogs]\nmax_consecutive_overruns = 0\n{}{}{}{}{}",
        std::process::id(),
        axis("p", "mr-j5-g-n1", "pp", j5),
        axis("v", "mr-j5-g-n1", "pv", j5),
        axis("t", "mr-j5-g-n1", "tq", j5),
        axis("q", "mr-j4-tm", "pp", j4),
        axis("c", "mr-j5-g-n1", "csp", j5),
    );
    let cell = CellConfig::parse(Path::new("na-profile.toml"), &text).unwrap();
    let counting = Counting::new(
        common::hook,
        common::marked_heap_calls,
        &common::LOOPS_EXITED,
    );
    let steady = alloc_rig::start_steady(&cell, counting);
    let h = &steady.h;
    let mut finished = 0;
    let mut count_finished = |h: &HostEnd| {
        while let Some(e) = h.pop_event() {
            if e.kind == EventKind::ProfileFinished {
                assert_eq!(e.value, 0, "{e:?}");
                finished += 1;
            }
        }
        finished
    };
    let send = |axis: u16, motion: ProfileMotion| {
        h.send_profile_command(ProfileCommand {
            axis,
            motion,
            start_cycle: 0,
        })
        .unwrap();
    };
    let profile = |target: i32| ProfileMotion::Move {
        target,
        velocity: 50_000.0,
        acceleration: 500_000.0,
        deceleration: 500_000.0,
        immediate: true,
    };
    send(0, profile(120_000));
    send(
        1,
        ProfileMotion::Jog {
            velocity: 20_000.0,
            acceleration: 400_000.0,
            deceleration: 400_000.0,
        },
    );
    send(
        2,
        ProfileMotion::Torque {
            torque: 5.0,
            slope: 100.0,
        },
    );
    send(3, profile(80_000));
    let end = Instant::now() + Duration::from_secs(20);
    while count_finished(h) < 4 {
        assert!(Instant::now() < end, "motions never finished");
        std::thread::sleep(Duration::from_millis(1));
    }
    send(2, ProfileMotion::Halt(true));
    while count_finished(h) < 5 {
        assert!(Instant::now() < end, "halt never finished");
        std::thread::sleep(Duration::from_millis(1));
    }
    // The csp axis switches to pp, is moved by its drive, and switches back.
    for (n, motion) in [
        ProfileMotion::SwitchMode(SwitchableMode::Pp),
        profile(110_000),
        ProfileMotion::SwitchMode(SwitchableMode::Csp),
    ]
    .into_iter()
    .enumerate()
    {
        send(4, motion);
        while count_finished(h) < 6 + n {
            assert!(Instant::now() < end, "{motion:?} never finished");
            std::thread::sleep(Duration::from_millis(1));
        }
    }
    // The pv axis still runs: a cell stop halts it, the cell is idle again.
    h.send_command(CellCommand::Stop).unwrap();
    let mut stop_finished = false;
    while !stop_finished {
        assert!(Instant::now() < end, "stop never finished");
        while let Some(e) = h.pop_event() {
            stop_finished |= e.kind == EventKind::StopFinished;
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    alloc_rig::power_off_and_check(steady);
}
