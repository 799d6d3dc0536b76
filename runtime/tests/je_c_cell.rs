//! MR-JE-C axes in cells, end to end through `controller::run`: a cell of one simulated csp axis
//! and one emulated MR-JE-C runs a program that moves both in one step and jogs the MR-JE-C
//! (pv), runs it in tq (a torque step) and homes it (hm, method 37), over each transport (Modbus RTU over a pseudo-terminal), with the RT thread
//! allocation-free; the shipped mixed cell runs its program; point-table and indexer axes run
//! theirs; a cut link stops the MR-JE-C axis by the master's watchdog and the
//! drive by its own time-out (AL. 86.4 from [Pr. PN10], set from the config at start-up).

mod common;

use std::net::{IpAddr, Ipv4Addr};
use std::path::Path;
use std::time::{Duration, Instant};

use cellrt_config::CellConfig;
use cellrt_emulator::mr_je_c::server::{Ports, Server};
use cellrt_emulator::mr_je_c::{MrJeC, MrJeCParams};
use cellrt_fieldbus::mr_je_c::Alarm;
use cellrt_runtime::host::controller::{run, AxisSummary, Outcome, RunOptions, Summary};
use cellrt_runtime::host::je_c::LinkSummary;
use cellrt_runtime::host::program::Program;
use common::{hook, marked_heap_calls};

/// The cell `jec-TAG-PID` with the csp axis x, communication lost handled by `reaction`.
/// Axis `name` of a run's summary, with its MR-JE-C link's figures.
fn linked<'a>(s: &'a Summary, name: &str) -> (&'a AxisSummary, &'a LinkSummary) {
    let a = s
        .axes
        .iter()
        .find(|a| a.name == name)
        .expect("axis in the summary");
    (a, a.link.as_ref().expect("an MR-JE-C axis has a link"))
}

fn cell_head(tag: &str, reaction: &str) -> String {
    format!(
        r#"
[cell]
name = "jec-{tag}-{pid}"
cycle_time_us = 1000

[watchdogs]
max_consecutive_overruns = 0
communication_reaction = "{reaction}"

[setpoints]
lookahead_ms = 1000

[[axes]]
name = "x"
drive = "mr-j4-tm"
mode = "csp"
unit = "mm"
counts_per_unit = 4194.304
limits = {{ position = [0.0, 800.0], velocity = 400.0, acceleration = 2000.0, jerk = 20000.0 }}
sim = {{ initial_position = 50.0 }}
"#,
        pid = std::process::id()
    )
}

fn cell_text(tag: &str, transport: &str, je_c: &str) -> String {
    cell_head(tag, "controlled_stop")
        + &format!(
            r#"
[[axes]]
name = "belt"
drive = "mr-je-c"
transport = "{transport}"
mode = "pp"
unit = "mm"
counts_per_unit = 1310.72
limits = {{ position = [-500.0, 500.0], velocity = 200.0, acceleration = 1000.0, jerk = 10000.0, torque = 20.0 }}
je_c = {{ {je_c} }}
"#
        )
}

const PROGRAM: &str = r#"
[[step]]
do = "power_on"
[[step]]
do = "move"
target = { x = 150.0, belt = 80.0 }
[[step]]
do = "jog"
axis = "belt"
velocity = -40.0
seconds = 0.3
[[step]]
do = "torque"
target = { belt = 10.0 }
seconds = 0.2
[[step]]
do = "move"
target = { belt = -20.0 }
[[step]]
do = "home"
axis = "belt"
[[step]]
do = "power_off"
"#;

fn run_cell(text: &str, program: &str) -> Summary {
    let path = Path::new("je-c-cell.toml");
    let cell = CellConfig::parse(path, text).unwrap_or_else(|e| panic!("{e}"));
    let program = Program::parse(Path::new("je-c-program.toml"), program, &cell)
        .unwrap_or_else(|e| panic!("{e}"));
    run_counted(&cell, program)
}

/// Runs `program` on `cell`; the RT loop must not allocate in steady state.
fn run_counted(cell: &CellConfig, program: Program) -> Summary {
    let before = marked_heap_calls();
    let options = RunOptions {
        program: Some(program),
        hook: Some(hook),
        ..RunOptions::default()
    };
    let summary = run(cell, options).expect("cell runs");
    assert_eq!(marked_heap_calls() - before, 0, "the RT loop allocated");
    summary
}

/// The program completes, both kinds of axis end at their targets, the RT thread allocates
/// nothing. The emulated drive answers from threads of this (possibly loaded) machine: the
/// master's watchdog is off and its answer deadline generous, since the program's logic is
/// under test here (the watchdog has its own test below).
fn runs_end_to_end(transport: &str, je_c: &str) {
    let je_c = format!("{je_c}, watchdog_missed = 0, response_timeout_ms = 200");
    let s = run_cell(&cell_text(transport, transport, &je_c), PROGRAM);
    let log = &s.recording.event_log;
    assert_eq!(
        s.outcome,
        Outcome::ProgramCompleted,
        "{:?} {log:?}",
        s.program_error
    );
    assert!(
        (s.axes[0].final_position - 150.0).abs() < 0.05,
        "{:?}",
        s.axes
    );
    let (belt, link) = linked(&s, "belt");
    assert_eq!(belt.backend, "mr-je-c link");
    assert_eq!(link.transport, transport);
    // Homed (method 37) where the move to -20 mm ended: the home position 0.
    assert!(belt.final_position.abs() < 1e-9, "{belt:?}");
    assert!(link.exchanges > 10 && link.stopped.is_none(), "{belt:?}");
}

#[test]
fn cclink_cell_runs_a_program() {
    runs_end_to_end(
        "cclink-ief-basic",
        "emulate = true, drive_timeout_ms = 1000",
    );
}

#[test]
fn slmp_cell_runs_a_program() {
    runs_end_to_end("slmp", "emulate = true, drive_timeout_ms = 2000");
}

#[test]
fn modbus_tcp_cell_runs_a_program() {
    runs_end_to_end("modbus-tcp", "emulate = true");
}

#[test]
fn modbus_rtu_cell_runs_a_program_over_a_pty() {
    runs_end_to_end(
        "modbus-rtu",
        "emulate = true, station = 2, drive_timeout_ms = 3000",
    );
}

#[test]
fn the_shipped_mixed_cell_runs_its_program() {
    let configs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs");
    let path = configs.join("mixed-cell.toml");
    let text = std::fs::read_to_string(&path).unwrap().replace(
        "name = \"mixed\"",
        &format!("name = \"mixed-{}\"", std::process::id()),
    ) + "\n[setpoints]\nlookahead_ms = 1000\n";
    let text = text.replace(
        "max_consecutive_overruns = 100",
        "max_consecutive_overruns = 0",
    );
    let cell = CellConfig::parse(&path, &text).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        (cell.axes.on_loop().len(), cell.axes.on_link().len()),
        (2, 2)
    );
    let program = Program::load(&configs.join("mixed-cell-program.toml"), &cell).unwrap();
    let s = run_counted(&cell, program);
    assert_eq!(
        s.outcome,
        Outcome::ProgramCompleted,
        "{:?}",
        s.program_error
    );
    for a in s.axes.iter().filter(|a| a.link.is_some()) {
        assert!(a.final_position.abs() < 0.08, "{a:?}");
    }
}

/// A long move of the belt: 400 mm at 50 mm/s.
const LONG_BELT_MOVE: &str = r#"
[[step]]
do = "power_on"
[[step]]
do = "move"
target = { belt = 400.0 }
velocity = 50.0
"#;

/// An emulated MR-JE-C served on this host's loopback.
fn local_drive() -> Server {
    Server::start(
        MrJeC::new(MrJeCParams::default()),
        IpAddr::V4(Ipv4Addr::LOCALHOST),
        Ports::ANY,
    )
    .unwrap()
}

/// Waits until `server`'s drive is enabled and its position has left 0 (at most 20 s).
fn wait_until_moving(server: &Server) {
    let end = Instant::now() + Duration::from_secs(20);
    while server.drive().state() != cellrt_cia402::fsa::FsaState::OperationEnabled
        || server
            .drive()
            .read(cellrt_fieldbus::mr_je_c::ObjectId::new(0x6064, 0))
            .is_ok_and(|v| v.as_i64() == Some(0))
    {
        assert!(Instant::now() < end, "the belt never moved");
        std::thread::sleep(Duration::from_millis(10));
    }
}

#[test]
fn a_cut_link_stops_the_axis_and_the_drive_raises_al_86_4() {
    let server = local_drive();
    let je_c = format!(
        "address = \"127.0.0.1\", port = {}, drive_timeout_ms = 1000, watchdog_missed = 3",
        server.modbus_tcp.port()
    );
    let program = LONG_BELT_MOVE;
    let text = cell_text("cut", "modbus-tcp", &je_c);
    let cutter = std::thread::scope(|scope| {
        let cut = scope.spawn(|| {
            // Once the belt moves, pull the cable.
            wait_until_moving(&server);
            std::thread::sleep(Duration::from_millis(300));
            server.cut_link(true);
            Instant::now()
        });
        let s = run_cell(&text, program);
        (s, cut.join().unwrap())
    });
    let (s, cut_at) = cutter;
    assert_eq!(s.outcome, Outcome::ProgramFailed);
    let err = s.program_error.clone().unwrap_or_default();
    assert!(err.contains("communication lost"), "{err}");
    let (belt, link) = linked(&s, "belt");
    assert!(
        link.stopped
            .as_deref()
            .unwrap_or("")
            .contains("3 answers missed"),
        "{belt:?}"
    );
    // [Pr. PN10] = 1 s from the config: the drive raises AL. 86.4 a second after the cut and
    // its motor stands.
    while server.drive().alarm().is_none() && cut_at.elapsed() < Duration::from_secs(5) {
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(cut_at.elapsed() >= Duration::from_millis(900));
    assert_eq!(server.drive().alarm(), Some(Alarm::NETWORK_4));
    let at = server
        .drive()
        .read(cellrt_fieldbus::mr_je_c::ObjectId::new(0x6064, 0))
        .unwrap();
    std::thread::sleep(Duration::from_millis(100));
    assert_eq!(
        server
            .drive()
            .read(cellrt_fieldbus::mr_je_c::ObjectId::new(0x6064, 0))
            .unwrap(),
        at
    );
    assert!(
        at.as_i64().unwrap() < 400 * 1310,
        "stopped short of the target: {at}"
    );
}

/// A home step on an MR-JE-C axis takes no method but 37 and no Controlword2 edge: refused at
/// load naming the step's key.
#[test]
fn je_c_home_steps_other_than_method_37_are_refused_at_load() {
    let text = cell_text("home", "modbus-tcp", "emulate = true");
    let cell = CellConfig::parse(Path::new("je-c-cell.toml"), &text).unwrap();
    let parse = |step: &str| {
        Program::parse(Path::new("p.toml"), &format!("[[step]]\n{step}\n"), &cell)
            .map(|_| ())
            .map_err(|e| e.to_string())
    };
    assert_eq!(parse("do = \"home\"\naxis = \"belt\"\nmethod = 37"), Ok(()));
    let e = parse("do = \"home\"\naxis = \"belt\"\nmethod = 35").unwrap_err();
    assert!(
        e.contains("step[0].method") && e.contains("MR-JE-C axis 'belt' homes with method 37 only"),
        "{e}"
    );
    let e = parse("do = \"home\"\naxis = \"belt\"\nsetting = \"clear\"").unwrap_err();
    assert!(
        e.contains("step[0].setting") && e.contains("it homes in hm"),
        "{e}"
    );
}

/// A torque step on an MR-JE-C axis is checked at load: within `limits.torque`, not mixed with
/// the cell's other axes; an axis without `limits.torque`, and a tq axis without it in the
/// config, are refused naming the key.
#[test]
fn je_c_torque_steps_are_checked_at_load() {
    let text = cell_text("torque", "modbus-tcp", "emulate = true");
    let cell = CellConfig::parse(Path::new("je-c-cell.toml"), &text).unwrap();
    let parse = |step: &str| {
        Program::parse(Path::new("p.toml"), &format!("[[step]]\n{step}\n"), &cell)
            .map(|_| ())
            .map_err(|e| e.to_string())
    };
    let step = |target: &str| format!("do = \"torque\"\ntarget = {{ {target} }}\nseconds = 0.1");
    assert_eq!(parse(&step("belt = -20.0")), Ok(()));
    let e = parse(&step("belt = 25.0")).unwrap_err();
    assert!(
        e.contains("step[0].target.belt") && e.contains("outside the torque limit ±20"),
        "{e}"
    );
    let e = parse(&step("belt = 5.0, x = 5.0")).unwrap_err();
    assert!(
        e.contains("step[0].target") && e.contains("MR-JE-C axes and"),
        "{e}"
    );

    let no_limit = text.replace(", torque = 20.0 }", " }");
    let cell = CellConfig::parse(Path::new("je-c-cell.toml"), &no_limit).unwrap();
    let e = Program::parse(
        Path::new("p.toml"),
        &format!("[[step]]\n{}\n", step("belt = 5.0")),
        &cell,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("needs limits.torque"), "{e}");
    let tq = no_limit.replacen("mode = \"pp\"", "mode = \"tq\"", 1);
    let e = CellConfig::parse(Path::new("je-c-cell.toml"), &tq)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("axes[1].limits.torque") && e.contains("runs in tq"),
        "{e}"
    );
    // With the limit, a tq axis loads.
    let tq = text.replacen("mode = \"pp\"", "mode = \"tq\"", 1);
    assert!(CellConfig::parse(Path::new("je-c-cell.toml"), &tq).is_ok());
}

/// A cell with a point-table axis over the cyclic link (Table 2.3) and an indexer axis over
/// SLMP beside a csp axis.
fn positioning_cell(program_extra: &str) -> (CellConfig, Result<Program, String>) {
    let text = cell_head("positioning", "quick_stop")
        + r#"
[[axes]]
name = "feeder"
drive = "mr-je-c"
transport = "cclink-ief-basic"
mode = "point_table"
unit = "mm"
counts_per_unit = 1310.72
limits = { position = [-500.0, 500.0], velocity = 200.0, acceleration = 1000.0, jerk = 10000.0 }
[axes.je_c]
emulate = true
watchdog_missed = 0
response_timeout_ms = 200
[[axes.je_c.point_table]]
position = 100.0
velocity = 150.0
[[axes.je_c.point_table]]
position = -50.0
acceleration = 500.0
m_code = 7

[[axes]]
name = "turret"
drive = "mr-je-c"
transport = "slmp"
mode = "indexer"
unit = "station"
counts_per_unit = 1.0
limits = { position = [0.0, 7.0], velocity = 2.0, acceleration = 20.0, jerk = 100.0 }
je_c = { emulate = true, stations = 8, watchdog_missed = 0, response_timeout_ms = 200 }
"#;
    let cell =
        CellConfig::parse(Path::new("positioning.toml"), &text).unwrap_or_else(|e| panic!("{e}"));
    let program = format!(
        r#"
[[step]]
do = "power_on"
{program_extra}
[[step]]
do = "power_off"
"#
    );
    let p = Program::parse(Path::new("positioning-program.toml"), &program, &cell)
        .map_err(|e| e.to_string());
    (cell, p)
}

/// A move step names point table 1 and station 3 beside x's position; the feeder jogs (jg,
/// reverse) and runs table 2; the turret turns to station 6: each ends where its table or
/// station is, and the summary's error is measured against it.
#[test]
fn point_table_and_indexer_axes_run_a_program() {
    let (cell, program) = positioning_cell(
        r#"
[[step]]
do = "move"
target = { x = 150.0, feeder = 1, turret = 3 }
[[step]]
do = "jog"
axis = "feeder"
velocity = -40.0
seconds = 0.3
[[step]]
do = "move"
target = { feeder = 2 }
[[step]]
do = "move"
target = { turret = 6 }
"#,
    );
    let s = run_counted(&cell, program.unwrap());
    assert_eq!(
        s.outcome,
        Outcome::ProgramCompleted,
        "{:?} {:?}",
        s.program_error,
        s.recording.event_log
    );
    assert!((s.axes[0].final_position - 150.0).abs() < 0.05);
    let (feeder, _) = linked(&s, "feeder");
    assert_eq!(feeder.target, Some(-50.0), "{feeder:?}");
    assert!(feeder.error.unwrap().abs() < 0.08, "{feeder:?}");
    let (turret, _) = linked(&s, "turret");
    assert_eq!(
        (turret.target, turret.final_position),
        (Some(6.0), 6.0),
        "{turret:?}"
    );
}

/// A move to a point table waits for the table's own profile (table 1: 150 mm/s, the axis'
/// 1000 mm/s²; table 2: the axis' 200 mm/s, 500 mm/s²), not the axis' limits.
#[test]
fn a_point_table_move_is_timed_by_its_table() {
    let (_, p) = positioning_cell("[[step]]\ndo = \"move\"\ntarget = { feeder = 1, turret = 2 }\n[[step]]\ndo = \"move\"\ntarget = { feeder = 2 }");
    let p = p.unwrap();
    let je_c = |k: usize| match &p.steps[k] {
        cellrt_runtime::host::program::Step::Move(t) => t
            .iter()
            .filter_map(|t| match t {
                cellrt_runtime::host::program::AxisMove::Drive(d) => Some(d.clone()),
                cellrt_runtime::host::program::AxisMove::Planned(_) => None,
            })
            .collect::<Vec<_>>(),
        other => panic!("{other:?}"),
    };
    let profile = |t: &cellrt_runtime::host::program::DriveMove| (t.velocity, t.acceleration);
    let first = je_c(1);
    assert_eq!(profile(&first[0]), (150.0, 1000.0));
    assert_eq!(profile(&first[1]), (2.0, 20.0), "the turret at its limits");
    assert_eq!(profile(&je_c(2)[0]), (200.0, 500.0));
}

/// What a point-table or indexer axis does not take is refused at load, naming it.
#[test]
fn positioning_axes_refuse_what_they_do_not_take() {
    for (step, why) in [
        (
            "do = \"move\"\ntarget = { feeder = 3 }",
            "3 is not one of its point tables (1–2)",
        ),
        (
            "do = \"move\"\ntarget = { feeder = 1.5 }",
            "1.5 is not one of its point tables",
        ),
        (
            "do = \"move\"\ntarget = { turret = 8 }",
            "8 is not one of its stations (0–7)",
        ),
        (
            "do = \"move\"\ntarget = { feeder = 1 }\nvelocity = 10.0",
            "axis 'feeder' runs point tables",
        ),
        (
            "do = \"jog\"\naxis = \"turret\"\nvelocity = 1.0\nseconds = 0.1",
            "it turns to stations (move), it does not jog",
        ),
        (
            "do = \"torque\"\ntarget = { feeder = 5.0 }\nseconds = 0.1",
            "carry no torque command",
        ),
    ] {
        let (_, p) = positioning_cell(&format!("[[step]]\n{step}"));
        let e = p.expect_err(step);
        assert!(e.contains(why), "{step}: {e}");
    }
}

/// Faults in words (issue 32) on the MR-JE-C: its drive raises AL. 86.1 while the belt moves;
/// the program fails, and the summary's failed step names the belt and the alarm by the
/// manual's number, name and cause (MR-JE-C manual §5.2.3), as do the program error and the
/// link's stop reason. The alarm is raised once the belt is seen moving, so the failing step is
/// the move whatever the machine's speed.
#[test]
fn a_drive_alarm_on_the_mr_je_c_is_named_in_the_summary() {
    let server = local_drive();
    let je_c = format!(
        "address = \"127.0.0.1\", port = {}, watchdog_missed = 0, response_timeout_ms = 200",
        server.modbus_tcp.port()
    );
    let program = LONG_BELT_MOVE;
    let text = cell_text("alarm", "modbus-tcp", &je_c);
    let s = std::thread::scope(|scope| {
        scope.spawn(|| {
            // Once the belt moves, the drive raises its alarm.
            wait_until_moving(&server);
            server.drive().raise(Alarm::NETWORK_1);
        });
        run_cell(&text, program)
    });
    assert_eq!(s.outcome, Outcome::ProgramFailed);
    let failed = s.failed_step.as_ref().expect("a failed step");
    assert_eq!((failed.step, failed.what), (1, "move"));
    let fault = failed
        .faults
        .iter()
        .find(|f| f.axis == "belt")
        .unwrap_or_else(|| panic!("the belt's fault in {failed:?}"));
    assert_eq!(
        fault.alarm.as_deref(),
        Some("AL. 86.1 Network communication error 1")
    );
    assert_eq!(fault.code, Some(0x8601));
    assert!(
        fault.cause.is_some_and(|c| c.contains("[Pr. PN02]")),
        "{fault:?}"
    );
    assert_eq!(fault.remedy, None, "the manual gives no remedy");
    let err = s.program_error.clone().unwrap_or_default();
    assert!(
        err.contains("MR-JE-C axis 'belt': drive alarm AL. 86.1 Network communication error 1"),
        "{err}"
    );
    let (_, link) = linked(&s, "belt");
    assert!(
        link.stopped
            .as_deref()
            .is_some_and(|a| a.starts_with("drive alarm AL. 86.1 Network communication error 1")),
        "{link:?}"
    );
}
