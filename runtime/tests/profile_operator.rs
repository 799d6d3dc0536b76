//! Operator commands on profile axes of a running cell (issue 19): `move` of a pp axis together
//! with a csp axis, `velocity` and `halt` of a pv axis, `torque` of a tq axis, and the
//! refusals that name the axis' mode; a csp axis switched to pp at run time (`mode`) and back;
//! then a program whose move step mixes a csp and a pp axis. Judged on the positions and speeds the status reports;
//! the waits are timeouts only.

#[allow(dead_code)] // the shared support: this test asks the operator service through it
mod support;

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use cellrt_config::CellConfig;
use cellrt_runtime::host::controller::{run, RunOptions};
use cellrt_runtime::host::operator::client::{running_cells, OperatorClient};
use cellrt_runtime::host::operator::wire::{AxisStatus, Reply, Request, StatusReport};
use support::operator::{request, status};

fn axis(name: &str, mode: &str) -> String {
    axis_on(name, mode, "sim", J5)
}

/// The MR-J5-G-N1 (profile objects by SDO: not in its 1600h).
const J5: &str = "drive = \"mr-j5-g-n1\"";
/// The MR-J4-TM in PA01 `___2` (profile objects in its 1601h).
const J4_PROFILE: &str = "drive = \"mr-j4-tm\"\nmode_group = \"profile\"";

fn axis_on(name: &str, mode: &str, transport: &str, drive: &str) -> String {
    format!(
        r#"
[[axes]]
name = "{name}"
{drive}
transport = "{transport}"
mode = "{mode}"
motor = {{ counts_per_rev = 10000, rated_speed = 3000 }}
unit = "mm"
counts_per_unit = 1000
limits = {{ position = [0.0, 500.0], velocity = 100.0, acceleration = 1000.0, jerk = 10000.0, torque = 50.0 }}
sim = {{ initial_position = 100.0 }}
"#
    )
}

fn axis_of<'a>(s: &'a StatusReport, name: &str) -> &'a AxisStatus {
    s.axes.iter().find(|a| a.name == name).unwrap()
}

fn wait(c: &OperatorClient, what: &str, done: impl Fn(&StatusReport) -> bool) -> StatusReport {
    let end = Instant::now() + Duration::from_secs(30);
    loop {
        let s = status(c);
        if done(&s) {
            return s;
        }
        assert!(Instant::now() < end, "never {what}: {s:?}");
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// The cycle of an event-log line ("cycle N: …").
fn cycle_of(line: &str) -> u64 {
    line.trim_start_matches("cycle ")
        .split(':')
        .next()
        .and_then(|c| c.parse().ok())
        .unwrap_or(u64::MAX)
}

/// An absolute move of `targets` at `velocity` (the axes' limits where `None`).
fn move_to(targets: BTreeMap<String, f64>, velocity: Option<f64>) -> Request {
    Request::Move {
        targets,
        relative: false,
        velocity,
        acceleration: None,
        jerk: None,
        clamp: false,
        line: false,
    }
}

fn accepted(r: Reply) {
    assert!(matches!(r, Reply::Accepted { .. }), "{r:?}");
}

fn rejected(r: Reply) -> String {
    match r {
        Reply::Rejected { reason } => reason,
        r => panic!("{r:?}"),
    }
}

/// The running controller of a powered cell: its operator client, shutdown flag and thread.
type Controller = std::thread::JoinHandle<
    Result<cellrt_runtime::host::controller::Outcome, cellrt_runtime::host::controller::RunError>,
>;

/// Starts the cell `text` (named `name`) in this process and powers it on.
fn powered_cell(name: &str, text: &str) -> (OperatorClient, Arc<AtomicBool>, Controller) {
    let cell = CellConfig::parse(Path::new("profile-operator.toml"), text).unwrap();
    let shutdown = Arc::new(AtomicBool::new(false));
    let options = RunOptions {
        shutdown: shutdown.clone(),
        ..RunOptions::default()
    };
    let controller = std::thread::spawn(move || run(&cell, options).map(|s| s.outcome));
    let end = Instant::now() + Duration::from_secs(30);
    while !running_cells().contains(&name.to_string()) {
        assert!(Instant::now() < end, "the cell never came up");
        std::thread::sleep(Duration::from_millis(20));
    }
    let c = OperatorClient::connect(Some(name)).unwrap();
    accepted(request(
        &c,
        &Request::Power {
            on: true,
            axes: vec![],
        },
    ));
    wait(&c, "idle", |s| s.state == "idle");
    (c, shutdown, controller)
}

#[test]
fn operator_commands_and_program_steps_drive_profile_axes() {
    let name = format!("prof-op-{}", std::process::id());
    let text = format!(
        "[cell]\nname = \"{name}\"\ncycle_time_us = 1000\n[watchdogs]\nmax_consecutive_overruns = 0\n[setpoints]\nlookahead_ms = 1000\n{}{}{}{}",
        axis("p", "pp"),
        axis("y", "csp"),
        axis("v", "pv"),
        axis("t", "tq"),
    );
    let (c, shutdown, controller) = powered_cell(&name, &text);

    // One move: the pp axis by its drive, the csp axis streamed.
    let targets = BTreeMap::from([("p".to_string(), 130.0), ("y".to_string(), 80.0)]);
    accepted(request(&c, &move_to(targets, Some(50.0))));
    let s = wait(&c, "both axes at their targets", |s| {
        let (p, y) = (axis_of(s, "p"), axis_of(s, "y"));
        s.state == "idle"
            && (p.position - 130.0).abs() <= 0.1
            && (y.position - 80.0).abs() <= 0.1
            && p.velocity == 0.0
    });
    assert_eq!(axis_of(&s, "p").mode_display, "pp");

    // The pv axis runs at 20 mm/s until halted.
    accepted(request(
        &c,
        &Request::Velocity {
            axis: "v".into(),
            velocity: 20.0,
            acceleration: None,
            clamp: false,
        },
    ));
    wait(&c, "pv at speed", |s| {
        (axis_of(s, "v").velocity - 20.0).abs() < 0.5
    });
    accepted(request(
        &c,
        &Request::Halt {
            axes: vec!["v".into()],
        },
    ));
    wait(&c, "pv halted", |s| axis_of(s, "v").velocity.abs() < 0.01);

    // The tq axis takes a torque (held by the drive until a halt).
    accepted(request(
        &c,
        &Request::Torque {
            targets: BTreeMap::from([("t".to_string(), 5.0)]),
            seconds: 0.0,
        },
    ));
    wait(&c, "tq moving", |s| axis_of(s, "t").velocity > 1.0);
    accepted(request(&c, &Request::Stop));
    // The first stop of the run: its reason stays in the status once the cell is idle again.
    // The RT thread sets the reason before it publishes the cycle's state, so idle is judged
    // again in a later cycle.
    let seen = wait(&c, "stopped", |s| {
        s.state == "idle" && s.stop_reason.is_some()
    });
    wait(&c, "idle after the stop", |s| {
        s.cycle > seen.cycle && s.state == "idle"
    });

    // Refusals name the axis and its mode.
    let r = rejected(request(
        &c,
        &Request::Velocity {
            axis: "p".into(),
            velocity: 5.0,
            acceleration: None,
            clamp: false,
        },
    ));
    assert!(r.contains("'p'") && r.contains("pp"), "{r}");
    let r = rejected(request(
        &c,
        &move_to(BTreeMap::from([("v".to_string(), 120.0)]), None),
    ));
    assert!(r.contains("'v'") && r.contains("pv"), "{r}");
    let r = rejected(request(
        &c,
        &Request::Torque {
            targets: BTreeMap::from([("t".to_string(), 60.0)]),
            seconds: 0.0,
        },
    ));
    assert!(r.contains("torque limit"), "{r}");

    run_time_mode_switch(&c);

    shutdown.store(true, Ordering::Release);
    controller.join().unwrap().unwrap();
    // One controller at a time in this process (each takes the RT CPU out of its affinity).
    a_program_step_moves_csp_and_pp_axes_and_ends_when_both_are_done("sim", J5);
    // The emulated EtherCAT segment runs the same drives; 6081h–6084h go by CoE SDO.
    a_program_step_moves_csp_and_pp_axes_and_ends_when_both_are_done("ethercat", J5);
    // The MR-J4-TM's profile group runs RxPDO 1601h on the segment (6081h–6084h cyclic).
    a_program_step_moves_csp_and_pp_axes_and_ends_when_both_are_done("ethercat", J4_PROFILE);
}

/// `mode`: the csp axis `y` switches to pp, `move` sends it set-points (its drive moves it),
/// streamed-only commands and programs are refused while it is switched, and it switches back;
/// axes that cannot switch, and unknown modes, are refused naming why.
fn run_time_mode_switch(c: &OperatorClient) {
    let mode = |axis: &str, mode: &str| Request::Mode {
        axis: axis.into(),
        mode: mode.into(),
    };
    let finished_ok = |s: &StatusReport, id: u64| {
        s.last_finished
            .as_ref()
            .is_some_and(|f| f.id == id && f.error.is_none())
    };
    let id = match request(c, &mode("y", "pp")) {
        Reply::Accepted { id } => id,
        r => panic!("{r:?}"),
    };
    let s = wait(c, "y in pp", |s| finished_ok(s, id));
    assert_eq!(axis_of(&s, "y").mode, "pp");
    assert_eq!(axis_of(&s, "y").mode_display, "pp");
    // A move of pp axes only is tracked: it ends when the drive reports its set-point done
    // (Target reached), not when it is sent.
    let id = match request(
        c,
        &move_to(BTreeMap::from([("y".to_string(), 95.0)]), Some(40.0)),
    ) {
        Reply::Accepted { id } => id,
        r => panic!("{r:?}"),
    };
    let s = wait(c, "the move of y done", |s| finished_ok(s, id));
    let y = axis_of(&s, "y");
    assert!(
        (y.position - 95.0).abs() <= 0.1,
        "ended before the drive arrived: {y:?}"
    );
    let r = rejected(request(
        c,
        &Request::Velocity {
            axis: "y".into(),
            velocity: 5.0,
            acceleration: None,
            clamp: false,
        },
    ));
    assert!(r.contains("'y'") && r.contains("pp"), "{r}");
    let r = rejected(request(
        c,
        &Request::Program {
            path: std::env::temp_dir().join("no-such-program.toml"),
        },
    ));
    assert!(
        r.contains("switched to pp") && r.contains("cellrt mode y csp"),
        "{r}"
    );
    let r = rejected(request(c, &mode("y", "pp")));
    assert!(r.contains("already runs in pp"), "{r}");

    let id = match request(c, &mode("y", "csp")) {
        Reply::Accepted { id } => id,
        r => panic!("{r:?}"),
    };
    let s = wait(c, "y back in csp", |s| finished_ok(s, id));
    let y = axis_of(&s, "y");
    assert_eq!((y.mode.as_str(), y.mode_display.as_str()), ("csp", "csp"));
    assert!((y.position - 95.0).abs() <= 0.1, "{y:?}");
    assert!(
        (y.setpoint - 95.0).abs() <= 0.1,
        "the stream takes over where it stands: {y:?}"
    );

    let r = rejected(request(c, &mode("v", "pp")));
    assert!(
        r.contains("'v'") && r.contains("pv") && r.contains("only a csp axis"),
        "{r}"
    );
    let r = rejected(request(c, &mode("y", "pv")));
    assert!(r.contains("'pv'") && r.contains("csp or pp"), "{r}");
    let r = rejected(request(c, &mode("nope", "pp")));
    assert!(r.contains("nope"), "{r}");
}

/// A program step moving a csp and a pp axis over `transport` ends when both are done.
fn a_program_step_moves_csp_and_pp_axes_and_ends_when_both_are_done(transport: &str, pp: &str) {
    use cellrt_runtime::host::controller::Outcome;
    use cellrt_runtime::host::program::Program;
    let name = format!("prof-prog-{transport}-{}-{}", pp.len(), std::process::id());
    let segment = if transport == "ethercat" {
        "[ethercat]\ninterface = \"in-process\"\n"
    } else {
        ""
    };
    let text = format!(
        "[cell]\nname = \"{name}\"\ncycle_time_us = 1000\n[watchdogs]\nmax_consecutive_overruns = 0\n[setpoints]\nlookahead_ms = 1000\n{segment}{}{}{}{}",
        axis_on("p", "pp", transport, pp),
        axis_on("y", "csp", transport, J5),
        axis_on("v", "pv", transport, J5),
        axis_on("t", "tq", transport, J5),
    );
    let cell = CellConfig::parse(Path::new("prof-prog.toml"), &text).unwrap();
    // The pp axis travels 3x further than the csp one: the step waits for its drive.
    let program = r#"
[[step]]
do = "power_on"
[[step]]
do = "move"
target = { p = 250.0, y = 120.0 }
[[step]]
do = "move"
target = { p = 90.0 }
[[step]]
do = "jog"
axis = "v"
velocity = 20.0
seconds = 0.5
[[step]]
do = "torque"
target = { t = 5.0 }
seconds = 0.2
[[step]]
do = "power_off"
"#;
    let program = Program::parse(Path::new("prof-prog-program.toml"), program, &cell).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let summary = run(
        &cell,
        RunOptions {
            program: Some(program),
            record: Some(dir.path().join("prof-prog.mcap")),
            ..RunOptions::default()
        },
    )
    .unwrap();
    assert_eq!(
        summary.outcome,
        Outcome::ProgramCompleted,
        "{transport}: {summary:?}"
    );
    // The second step started only after the first one's pp move was done.
    let log = &summary.recording.event_log;
    let pos = |what: &str, nth: usize| {
        log.iter()
            .enumerate()
            .filter(|(_, l)| l.contains(what))
            .nth(nth)
            .map(|(k, _)| k)
            .unwrap_or_else(|| panic!("no {what} #{nth}: {log:?}"))
    };
    assert!(
        pos("profile_finished", 0) < pos("profile_started", 1),
        "{log:?}"
    );
    assert!(log[pos("profile_finished", 0)].contains("done"), "{log:?}");
    // The first step's pp axis starts in the streamed motion's first cycle (the cycle its
    // blocks name: a late first block shifts the streamed motion by `start_slipped`).
    let cycle = |k: usize| cycle_of(&log[k]);
    let motion = pos("motion_started", 0);
    assert_ne!(cycle(motion), u64::MAX, "{}", log[motion]);
    let slip: u64 = log
        .iter()
        .find(|l| l.contains("start_slipped") && cycle_of(l) == cycle(motion))
        .and_then(|l| l.split("started ").nth(1)?.split(' ').next()?.parse().ok())
        .unwrap_or(0);
    assert_eq!(
        cycle(pos("profile_started", 0)),
        cycle(motion) - slip,
        "{transport}: {log:?}"
    );
    let at = |n: &str| {
        summary
            .axes
            .iter()
            .find(|a| a.name == n)
            .unwrap()
            .final_position
    };
    // Within the in-position range (100 counts = 0.1 mm).
    assert!((at("p") - 90.0).abs() <= 0.1, "{transport}: {}", at("p"));
    assert!((at("y") - 120.0).abs() <= 0.1, "{transport}: {}", at("y"));
    // The tq step: the drive's ramp up, then HALT's ramp back to 0, both done.
    let tq_done = log
        .iter()
        .filter(|l| l.contains("profile_finished [t]: done"))
        .count();
    assert_eq!(tq_done, 2, "{transport}: {log:?}");
    // The pv axis ran about 0.5 s at up to 20 mm/s before its halt (ramps at 1000 mm/s²).
    assert!(
        (108.0..=111.0).contains(&at("v")),
        "{transport}: {}",
        at("v")
    );
}

/// `override` reaches the profile axes' drives: a pp move of the MR-J5 (6081h by SDO) and of
/// the MR-J4-TM in its profile group (6081h in its 1601h) runs at half speed under 50 %,
/// stands under 0 % without ending (the cell stays moving), and reaches its target once the
/// override is back at 100 %.
#[test]
fn the_override_reaches_the_drives_of_profile_axes() {
    let name = format!("prof-ovr-{}", std::process::id());
    let j4 = axis_on("q", "pp", "sim", J4_PROFILE)
        .replace(
            "motor = { counts_per_rev = 10000, rated_speed = 3000 }",
            "motor = { rated_speed = 3000 }",
        )
        .replace("counts_per_unit = 1000", "counts_per_unit = 419430.4");
    let text = format!(
        "[cell]\nname = \"{name}\"\ncycle_time_us = 1000\n[watchdogs]\nmax_consecutive_overruns = 0\n[setpoints]\nlookahead_ms = 1000\n{}{j4}",
        axis("p", "pp"),
    );
    let (c, shutdown, controller) = powered_cell(&name, &text);
    let both = |s: &StatusReport, f: &dyn Fn(&AxisStatus) -> bool| {
        f(axis_of(s, "p")) && f(axis_of(s, "q"))
    };
    accepted(request(
        &c,
        &move_to(
            BTreeMap::from([("p".to_string(), 300.0), ("q".to_string(), 300.0)]),
            Some(40.0),
        ),
    ));
    wait(&c, "both at 40 mm/s", |s| {
        both(s, &|a| (a.velocity - 40.0).abs() < 0.5)
    });
    accepted(request(&c, &Request::Override { percent: 50.0 }));
    wait(&c, "both at 20 mm/s", |s| {
        both(s, &|a| (a.velocity - 20.0).abs() < 0.5)
    });
    accepted(request(&c, &Request::Override { percent: 0.0 }));
    // Standing and settled: the servo loop of the halted drive rings out around zero speed.
    let held = wait(&c, "both standing", |s| {
        both(s, &|a| {
            a.velocity.abs() < 0.01 && a.following_error.abs() < 0.01
        })
    });
    assert!(both(&held, &|a| a.position < 290.0), "{held:?}");
    std::thread::sleep(Duration::from_millis(300));
    let s = status(&c);
    assert!(
        both(&s, &|a| (a.position - axis_of(&held, &a.name).position)
            .abs()
            < 0.01),
        "held: {s:?}"
    );
    accepted(request(&c, &Request::Override { percent: 100.0 }));
    wait(&c, "both at their targets", |s| {
        s.state == "idle"
            && both(s, &|a| {
                (a.position - 300.0).abs() <= 0.1 && a.velocity == 0.0
            })
    });
    shutdown.store(true, Ordering::Release);
    controller.join().unwrap().unwrap();
}
