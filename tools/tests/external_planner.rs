//! The planner as its own process: killing it (SIGKILL) mid-move makes the controller stop every
//! axis with its controlled stop (no setpoint step, deceleration within the limit); a restarted
//! planner reconnects, resets the cell and moves it again. A mixed cell's MR-JE-C axes, run by
//! the controller, move under the external planner's program and its operator's commands; the
//! planner's death halts them, the controller's end fails the planner's step, and a planner of
//! other MR-JE-C axes is refused.

mod common;

use std::ffi::OsStr;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::Receiver;
use std::time::{Duration, Instant};

use cellrt_config::CellConfig;
use common::{demo_cell, read_recording};
use nix::sys::signal::{kill, Signal};
use nix::unistd::Pid;

const FIRST: &str = r#"
[[step]]
do = "power_on"
[[step]]
do = "move"
target = { x = 780.0, y = 580.0 }
"#;

const SECOND: &str = r#"
[[step]]
do = "reset"
[[step]]
do = "move"
target = { x = 100.0, y = 120.0 }
"#;

fn lines(child: &mut Child) -> Receiver<String> {
    let stderr = child.stderr.take().unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            let _ = tx.send(line);
        }
    });
    rx
}

/// Every line of an exited child's stderr: waits for the reader thread to reach end of file
/// (`try_iter` right after the exit could miss lines still in flight).
fn all_lines(rx: &Receiver<String>) -> Vec<String> {
    let mut out = Vec::new();
    while let Ok(l) = rx.recv_timeout(Duration::from_secs(10)) {
        out.push(l);
    }
    out
}

fn wait_line(rx: &Receiver<String>, what: &str, log: &mut Vec<String>) {
    let end = Instant::now() + Duration::from_secs(30);
    loop {
        let left = end.saturating_duration_since(Instant::now());
        match rx.recv_timeout(left) {
            Ok(l) => {
                let hit = l.contains(what);
                log.push(l);
                if hit {
                    return;
                }
            }
            Err(_) => panic!("no '{what}' within 30 s:\n{}", log.join("\n")),
        }
    }
}

/// `cellrt run --external-planner ARGS CFG`, once it waits for a planner: the process, its
/// stderr lines and the log read so far.
fn controller_waiting(cfg: &Path, args: &[&str]) -> (Child, Receiver<String>, Vec<String>) {
    let mut all: Vec<&OsStr> = vec!["run".as_ref(), "--external-planner".as_ref()];
    all.extend(args.iter().map(OsStr::new));
    all.push(cfg.as_os_str());
    let mut controller = cellrt(&all);
    let ctl = lines(&mut controller);
    let mut log = Vec::new();
    wait_line(&ctl, "waiting for a planner", &mut log);
    (controller, ctl, log)
}

/// `cellrt ARGS` with its stderr piped (read it with [`lines`]).
fn cellrt(args: &[&OsStr]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_cellrt"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

fn planner(cfg: &Path, program: &Path) -> Child {
    cellrt(&[
        "planner".as_ref(),
        cfg.as_os_str(),
        "--program".as_ref(),
        program.as_os_str(),
    ])
}

fn wait_exit(child: &mut Child, secs: u64) -> Option<i32> {
    let end = Instant::now() + Duration::from_secs(secs);
    loop {
        if let Some(s) = child.try_wait().unwrap() {
            return s.code();
        }
        if Instant::now() > end {
            let _ = child.kill();
            panic!("process did not exit within {secs} s");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Stops the controller with SIGINT; it must exit 0 (`log`: its lines so far, for the message).
fn interrupt(controller: &mut Child, log: &[String]) {
    kill(Pid::from_raw(controller.id() as i32), Signal::SIGINT).unwrap();
    assert_eq!(wait_exit(controller, 30), Some(0), "{}", log.join("\n"));
}

#[test]
fn killed_planner_stops_the_cell_and_a_new_one_takes_over() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = demo_cell(dir.path(), FIRST);
    let second = dir.path().join("second.toml");
    std::fs::write(&second, SECOND).unwrap();
    let rec_path = dir.path().join("run.mcap");
    let json = dir.path().join("summary.json");

    let mut controller = Command::new(env!("CARGO_BIN_EXE_cellrt"))
        .args(["run", "--external-planner", "--record"])
        .arg(&rec_path)
        .arg("--summary-json")
        .arg(&json)
        .arg(&cfg)
        .env("CELLRT_LOG", "debug")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let ctl = lines(&mut controller);
    let mut log = Vec::new();
    wait_line(&ctl, "waiting for a planner", &mut log);

    // First planner: power on and a long move; killed mid-move.
    let mut p1 = planner(&cfg, &dir.path().join("program.toml"));
    wait_line(&ctl, "motion_started", &mut log);
    std::thread::sleep(Duration::from_millis(500));
    kill(Pid::from_raw(p1.id() as i32), Signal::SIGKILL).unwrap();
    let _ = p1.wait();
    wait_line(&ctl, "stop_finished", &mut log);

    // Second planner: reset, then a move that must complete.
    let mut p2 = planner(&cfg, &second);
    let p2_log = lines(&mut p2);
    let code = wait_exit(&mut p2, 30);
    let p2_text: Vec<String> = all_lines(&p2_log);
    assert_eq!(code, Some(0), "second planner: {}", p2_text.join("\n"));

    interrupt(&mut controller, &log);

    let rec = read_recording(&rec_path);
    let kinds: Vec<(&str, &str)> = rec
        .events
        .iter()
        .map(|e| (e.kind.as_str(), e.detail.as_str()))
        .collect();
    let count = |k: &str| kinds.iter().filter(|(kind, _)| *kind == k).count();
    assert_eq!(count("planner_connected"), 2, "{kinds:?}");
    assert!(count("planner_lost") >= 1, "{kinds:?}");
    let stop = rec
        .events
        .iter()
        .find(|e| e.kind == "stop_started")
        .expect("stop");
    assert_eq!(stop.detail, "planner_lost (controlled_stop)", "{kinds:?}");
    assert_eq!(
        count("motion_finished"),
        1,
        "the second planner's move ends: {kinds:?}"
    );

    // The stop: no setpoint step above the velocity limit, deceleration within the stop limit.
    let cell = CellConfig::load(&cfg).unwrap();
    let dt = cell.period();
    for name in ["x", "y"] {
        let a = &cell.axes.on_loop()[cell.axis_index(name).unwrap()];
        let s = &rec.axes[name];
        for w in s.windows(2) {
            let gap = (w[1].cycle - w[0].cycle) as f64;
            let step = (w[1].setpoint_position - w[0].setpoint_position).abs();
            assert!(step <= a.limits.velocity * dt * gap * (1.0 + 1e-6) + 1e-9);
            if gap == 1.0 && w[0].cycle >= stop.cycle {
                let dec = (w[1].setpoint_velocity - w[0].setpoint_velocity).abs() / dt;
                assert!(dec <= a.limits.acceleration * (1.0 + 1e-6), "{name}: {dec}");
            }
        }
        let at_stop = s.iter().find(|r| r.cycle >= stop.cycle).unwrap();
        assert!(at_stop.setpoint_velocity.abs() > 1.0, "{name} was moving");
    }
    // The second planner's targets were reached.
    let last = |n: &str| {
        rec.axes[n]
            .iter()
            .rev()
            .find(|r| r.fsa_state == 5)
            .unwrap()
            .setpoint_position
    };
    assert!((last("x") - 100.0).abs() < 1e-6, "x {}", last("x"));
    assert!((last("y") - 120.0).abs() < 1e-6, "y {}", last("y"));
}

#[test]
fn a_planner_with_another_cells_timing_is_refused_and_nothing_moves() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = demo_cell(dir.path(), FIRST);
    // Same cell name, other cycle time: its setpoints would be sampled for another cell.
    let other = dir.path().join("other.toml");
    let text = std::fs::read_to_string(&cfg)
        .unwrap()
        .replace("cycle_time_us = 1000", "cycle_time_us = 2000");
    std::fs::write(&other, text).unwrap();
    let (mut controller, _ctl, _log, json) = controller_with_summary(&cfg, dir.path());

    let (code, text) = planner_outcome(&other, &dir.path().join("program.toml"), 30);
    assert_eq!(code, Some(1), "{text:?}");
    let err = error_line(&text);
    assert!(err.contains("runs 4 axes at 1000 µs"), "{err}");
    assert!(err.contains("4 axes at 2000 µs"), "{err}");

    kill(Pid::from_raw(controller.id() as i32), Signal::SIGINT).unwrap();
    assert_eq!(wait_exit(&mut controller, 30), Some(0));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(summary["final_state"], "disabled", "never powered on");
    for a in summary["axes"].as_array().unwrap() {
        let start = if a["name"] == "x" || a["name"] == "y" {
            50.0
        } else {
            0.0
        };
        assert_eq!(a["final_position"].as_f64(), Some(start), "{a}");
    }
}

/// `cellrt sdo` on a cell whose planner is its own process: the planner's operator service
/// sends the request over the cell's SDO link service, the controller's link thread hands it
/// to the RT thread and the outcome comes back the same way. The drive was powered on by the
/// planner's program: Operation enabled in 6041h, csp in 6061h; a write is refused while the
/// program runs.
#[test]
fn sdo_reaches_the_drives_through_an_external_planner() {
    const HOLD: &str = r#"
[[step]]
do = "power_on"
[[step]]
do = "wait"
seconds = 60
"#;
    let dir = tempfile::tempdir().unwrap();
    let cfg = dir.path().join("cell.toml");
    let cfg_text = std::fs::read_to_string(demo_cell(dir.path(), HOLD)).unwrap();
    let name = common::cell_name_of(&cfg_text);
    let (mut controller, _ctl, _log) =
        controller_waiting(&cfg, &["--no-record", "--duration", "120"]);
    let mut p = planner(&cfg, &dir.path().join("program.toml"));
    let sdo = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_cellrt"))
            .arg("sdo")
            .args(args)
            .args(["--cell", &name])
            .output()
            .unwrap();
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stdout).into_owned(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    // Until the planner's program has powered the axis on.
    let end = Instant::now() + Duration::from_secs(30);
    let statusword = loop {
        let (code, out, err) = sdo(&["read", "y", "6041"]);
        if code == Some(0) {
            let v: i64 = out
                .split('=')
                .nth(1)
                .unwrap()
                .split_whitespace()
                .next()
                .unwrap()
                .parse()
                .unwrap();
            if v & 0x6F == 0x27 {
                break v;
            }
        }
        assert!(
            Instant::now() < end,
            "no Operation enabled over the link: {out}{err}"
        );
        std::thread::sleep(Duration::from_millis(200));
    };
    assert_eq!(statusword & 0x6F, 0x27);
    // 6061h: cyclic synchronous position (8) as configured.
    let (code, out, err) = sdo(&["read", "y", "6061"]);
    assert_eq!(code, Some(0), "{out}{err}");
    assert!(out.contains("= 8 "), "{out}");
    // A write while the planner's program runs is refused by its operator service.
    let (code, _, err) = sdo(&["write", "y", "6085", "123456"]);
    assert_eq!(code, Some(3), "{err}");
    assert!(err.contains("a program is running"), "{err}");
    let _ = p.kill();
    let _ = p.wait();
    kill(Pid::from_raw(controller.id() as i32), Signal::SIGINT).unwrap();
    let _ = wait_exit(&mut controller, 30);
}

/// A profile axis driven by a planner in another process: z of the demo cell in pp, moved in
/// one step with the csp axis x under a 50 % override. Its drive-side motion and the override
/// cross to the controller over the cell's services; both axes reach their targets, z's drive
/// at half its velocity limit, and the step ends when both are done (the planner's program
/// completes).
#[test]
fn a_profile_axis_moves_under_an_external_planner() {
    const PROGRAM: &str = r#"
[[step]]
do = "power_on"
[[step]]
do = "override"
percent = 50
[[step]]
do = "move"
target = { x = 200.0, z = -120.0 }
[[step]]
do = "wait"
seconds = 0.1
"#;
    let dir = tempfile::tempdir().unwrap();
    let cfg = demo_cell(dir.path(), PROGRAM);
    let text = std::fs::read_to_string(&cfg).unwrap();
    let z = "name = \"z\"\ndrive = \"mr-j5-g-n1\"\nmotor = { counts_per_rev = 10000 }";
    assert!(text.contains(z));
    let text = text.replacen(
        z,
        "name = \"z\"\ndrive = \"mr-j5-g-n1\"\nmode = \"pp\"\nmotor = { counts_per_rev = 10000, rated_speed = 3000 }",
        1,
    );
    std::fs::write(&cfg, text).unwrap();
    let rec_path = dir.path().join("run.mcap");
    let rec_arg = rec_path.to_str().unwrap().to_owned();
    let (mut controller, ctl, mut log) = controller_waiting(&cfg, &["--record", &rec_arg]);
    let (code, p_text) = planner_outcome(&cfg, &dir.path().join("program.toml"), 60);
    assert_eq!(code, Some(0), "planner: {}", p_text.join("\n"));
    log.extend(ctl.try_iter());
    interrupt(&mut controller, &log);

    let rec = read_recording(&rec_path);
    let last = |n: &str| rec.axes[n].last().unwrap().actual_position;
    assert!((last("x") - 200.0).abs() < 0.05, "x ends at {}", last("x"));
    assert!((last("z") + 120.0).abs() < 0.05, "z ends at {}", last("z"));
    // z's drive ran at half of z's 250 mm/s.
    let peak = rec.axes["z"]
        .iter()
        .map(|r| r.actual_velocity.abs())
        .fold(0.0, f64::max);
    assert!((peak - 125.0).abs() < 3.0, "z's peak {peak} mm/s");
    // z was moved by its drive in pp (6061h = 1), never streamed.
    assert!(rec.axes["z"]
        .iter()
        .all(|r| r.mode_display == 1 || r.fsa_state != 5));
    let started = rec
        .events
        .iter()
        .filter(|e| e.kind == "profile_started")
        .count();
    assert!(started >= 1, "{:?}", rec.events);
}

/// configs/mixed-cell.toml (EtherCAT csp x, y; emulated MR-JE-C infeed over CC-Link IE Field
/// Basic, outfeed over Modbus/TCP) in `dir` under a unique name with `program` as its program,
/// the overrun watchdog and the MR-JE-C master's watchdog off, a generous answer deadline and
/// a long lookahead: the link to the planner is under test, not the machine's load. Returns
/// the configuration's path and the cell's name.
fn mixed_cell(dir: &Path, program: &str) -> (PathBuf, String) {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../configs/mixed-cell.toml"
    ))
    .unwrap();
    let name = common::unique_cell_name();
    let text = text
        .replace(r#"name = "mixed""#, &format!(r#"name = "{name}""#))
        .replace(
            r#"program = "mixed-cell-program.toml""#,
            r#"program = "program.toml""#,
        )
        .replace(
            "max_consecutive_overruns = 100",
            "max_consecutive_overruns = 0",
        )
        .replace(
            "watchdog_missed = 5,",
            "watchdog_missed = 0, response_timeout_ms = 200,",
        )
        .replace(
            "watchdog_missed = 3 }",
            "watchdog_missed = 0, response_timeout_ms = 200 }",
        );
    assert!(text.contains(&name) && !text.contains("watchdog_missed = 5"));
    assert!(!text.contains("watchdog_missed = 3"));
    std::fs::write(dir.join("program.toml"), program).unwrap();
    let cfg = dir.join("cell.toml");
    std::fs::write(&cfg, text + "\n[setpoints]\nlookahead_ms = 1000\n").unwrap();
    (cfg, name)
}

/// The controller of `cfg` waiting for a planner, writing its summary to `dir`/summary.json
/// (returned last) when it ends.
fn controller_with_summary(
    cfg: &Path,
    dir: &Path,
) -> (Child, Receiver<String>, Vec<String>, PathBuf) {
    let json = dir.join("summary.json");
    let json_arg = json.to_str().unwrap().to_owned();
    let (controller, ctl, log) =
        controller_waiting(cfg, &["--no-record", "--summary-json", &json_arg]);
    (controller, ctl, log, json)
}

/// Runs a planner of `cfg` on `program` to its end (at most `secs`); its exit code and
/// stderr lines.
fn planner_outcome(cfg: &Path, program: &Path, secs: u64) -> (Option<i32>, Vec<String>) {
    let mut p = planner(cfg, program);
    let p_log = lines(&mut p);
    let code = wait_exit(&mut p, secs);
    (code, all_lines(&p_log))
}

/// The `error: …` line of a command's stderr lines.
fn error_line(text: &[String]) -> &str {
    text.iter()
        .find(|l| l.starts_with("error: "))
        .unwrap_or_else(|| panic!("no error line: {text:?}"))
}

/// The MR-JE-C axis `axis` in `cellrt status --json` of `cell` (served by the planner's
/// operator service), if the cell answers.
fn je_c_status(cell: &str, axis: &str) -> Option<serde_json::Value> {
    let (code, out, _) = common::cellrt_on_cell(cell, &["status", "--json"]);
    if code != 0 {
        return None;
    }
    let v: serde_json::Value = serde_json::from_str(&out).ok()?;
    v["axes"]
        .as_array()?
        .iter()
        .find(|a| a["name"] == axis)
        .cloned()
}

/// Polls `axis`' status until `ready` holds (a hang guard of 30 s); returns that status.
fn wait_je_c(
    cell: &str,
    axis: &str,
    what: &str,
    ready: impl Fn(&serde_json::Value) -> bool,
) -> serde_json::Value {
    let end = Instant::now() + Duration::from_secs(30);
    let mut last = None;
    loop {
        if let Some(s) = je_c_status(cell, axis) {
            if ready(&s) {
                return s;
            }
            last = Some(s);
        }
        assert!(Instant::now() < end, "{axis} never {what}: {last:?}");
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// Waits until [`SLOW_INFEED`]'s move runs: infeed busy and past 2 mm.
fn wait_infeed_moving(cell: &str) -> serde_json::Value {
    wait_je_c(cell, "infeed", "moved", |s| {
        s["link"]["busy"] == true && s["position"].as_f64().is_some_and(|p| p > 2.0)
    })
}

/// The final position of `axis` (MR-JE-C axes included) in the controller's `--summary-json`.
fn final_position(json: &Path, axis: &str) -> f64 {
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
    summary["axes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["name"] == axis)
        .and_then(|a| a["final_position"].as_f64())
        .unwrap_or_else(|| panic!("no {axis} in {summary}"))
}

/// A program moving the conveyor `infeed` slowly to 400 mm (80 s): long enough that only a
/// halt ends it within the tests' hang guards.
const SLOW_INFEED: &str = r#"
[[step]]
do = "power_on"
[[step]]
do = "move"
target = { infeed = 400.0 }
velocity = 5.0
"#;

/// The mixed cell's program under an external planner: moves of the csp and MR-JE-C axes in
/// one step, a jog (pv), a torque step (tq), a homing (hm) and the power sequence of the
/// MR-JE-C axes all cross to the controller's axis threads; every axis ends at its last target.
#[test]
fn je_c_axes_move_beside_the_csp_axes_under_an_external_planner() {
    const PROGRAM: &str = r#"
[[step]]
do = "power_on"
[[step]]
do = "move"
target = { x = 300.0, y = 200.0, infeed = 100.0, outfeed = -50.0 }
[[step]]
do = "jog"
axis = "infeed"
velocity = -40.0
seconds = 0.3
[[step]]
do = "torque"
target = { outfeed = 5.0 }
seconds = 0.2
[[step]]
do = "move"
target = { outfeed = -20.0 }
[[step]]
do = "home"
axis = "outfeed"
[[step]]
do = "move"
target = { x = 100.0, infeed = 20.0, outfeed = 30.0 }
[[step]]
do = "power_off"
"#;
    let dir = tempfile::tempdir().unwrap();
    let (cfg, _) = mixed_cell(dir.path(), PROGRAM);
    let (mut controller, ctl, mut log, json) = controller_with_summary(&cfg, dir.path());
    let (code, p_text) = planner_outcome(&cfg, &dir.path().join("program.toml"), 120);
    let p_text = p_text.join("\n");
    assert_eq!(code, Some(0), "planner: {p_text}");
    assert!(p_text.contains("program ended"), "{p_text}");
    log.extend(ctl.try_iter());
    interrupt(&mut controller, &log);

    for (axis, target, tolerance) in [
        ("x", 100.0, 0.05),
        ("y", 200.0, 0.05),
        ("infeed", 20.0, 0.01),
        // Homed at -20 mm (method 37: the home where it stands), then moved to 30.
        ("outfeed", 30.0, 0.01),
    ] {
        let p = final_position(&json, axis);
        assert!((p - target).abs() < tolerance, "{axis} ends at {p}");
    }
}

/// The shipped positioning cell's program under an external planner: point tables, a jg jog
/// and stations cross to the controller's axis threads and end where the tables and stations
/// are.
#[test]
fn point_tables_and_stations_run_under_an_external_planner() {
    let dir = tempfile::tempdir().unwrap();
    let configs = concat!(env!("CARGO_MANIFEST_DIR"), "/../configs");
    let name = common::unique_cell_name();
    let text = std::fs::read_to_string(format!("{configs}/je-c-positioning.toml"))
        .unwrap()
        .replace(
            r#"name = "je-c-positioning""#,
            &format!(r#"name = "{name}""#),
        )
        .replace(
            r#"program = "je-c-positioning-program.toml""#,
            r#"program = "program.toml""#,
        )
        .replace(
            "max_consecutive_overruns = 100",
            "max_consecutive_overruns = 0",
        )
        .replace(
            "drive_timeout_ms = 500\n",
            "drive_timeout_ms = 500\nwatchdog_missed = 0\nresponse_timeout_ms = 200\n",
        )
        .replace(
            "drive_timeout_ms = 1000 }",
            "drive_timeout_ms = 1000, watchdog_missed = 0, response_timeout_ms = 200 }",
        );
    assert_eq!(text.matches("watchdog_missed = 0").count(), 2, "{text}");
    std::fs::copy(
        format!("{configs}/je-c-positioning-program.toml"),
        dir.path().join("program.toml"),
    )
    .unwrap();
    let cfg = dir.path().join("cell.toml");
    std::fs::write(&cfg, text + "\n[setpoints]\nlookahead_ms = 1000\n").unwrap();
    let (mut controller, ctl, mut log, json) = controller_with_summary(&cfg, dir.path());
    let (code, p_text) = planner_outcome(&cfg, &dir.path().join("program.toml"), 120);
    let p_text = p_text.join("\n");
    assert_eq!(code, Some(0), "planner: {p_text}");
    log.extend(ctl.try_iter());
    interrupt(&mut controller, &log);
    // The program ends with the feeder at table 2 (-80 mm) and the turret at station 0.
    for (axis, target, tolerance) in [
        ("x", 50.0, 0.05),
        ("feeder", -80.0, 0.01),
        ("turret", 0.0, 1e-9),
    ] {
        let p = final_position(&json, axis);
        assert!((p - target).abs() <= tolerance, "{axis} ends at {p}");
    }
}

/// The operator's commands on an MR-JE-C axis reach it through the external planner's
/// operator service: `cellrt status` shows the conveyor moving in the controller, `cellrt halt
/// infeed` halts it on its drive (the move's job ends at once instead of after 80 s, which
/// ends the planner's program) and it stands far short of its target.
#[test]
fn the_operator_halts_a_je_c_axis_under_an_external_planner() {
    let dir = tempfile::tempdir().unwrap();
    let (cfg, name) = mixed_cell(dir.path(), SLOW_INFEED);
    let (mut controller, ctl, mut log, json) = controller_with_summary(&cfg, dir.path());
    let mut p = planner(&cfg, &dir.path().join("program.toml"));
    let p_log = lines(&mut p);
    let moving = wait_infeed_moving(&name);
    assert_eq!(moving["fsa"], "operation_enabled", "{moving}");
    assert_eq!(moving["link"]["transport"], "cclink-ief-basic", "{moving}");
    let (code, out, err) = common::cellrt_on_cell(&name, &["halt", "infeed"]);
    assert_eq!(code, 0, "halt: {out}{err}");
    let code = wait_exit(&mut p, 30);
    let p_text = all_lines(&p_log).join("\n");
    assert_eq!(code, Some(1), "planner: {p_text}");
    assert!(
        p_text.contains("halted or stopped by the operator")
            || p_text.contains("MR-JE-C axis 'infeed': the move was refused or cut short"),
        "{p_text}"
    );
    log.extend(ctl.try_iter());
    interrupt(&mut controller, &log);
    let infeed = final_position(&json, "infeed");
    assert!(infeed > 2.0 && infeed < 100.0, "infeed ends at {infeed}");
}

/// A planner killed (SIGKILL) while an MR-JE-C conveyor moves: the controller halts the
/// conveyor on its drive's ramp. The next planner's operator status shows it standing, far
/// short of the 80 s move's target, with its servo still on.
#[test]
fn a_killed_planner_halts_the_je_c_axes() {
    const HOLD: &str = "[[step]]\ndo = \"wait\"\nseconds = 60\n";
    let dir = tempfile::tempdir().unwrap();
    let (cfg, name) = mixed_cell(dir.path(), SLOW_INFEED);
    let hold = dir.path().join("hold.toml");
    std::fs::write(&hold, HOLD).unwrap();
    let (mut controller, ctl, mut log) = controller_waiting(&cfg, &["--no-record"]);
    let mut p1 = planner(&cfg, &dir.path().join("program.toml"));
    wait_infeed_moving(&name);
    kill(Pid::from_raw(p1.id() as i32), Signal::SIGKILL).unwrap();
    let _ = p1.wait();
    wait_line(
        &ctl,
        "planner lost: MR-JE-C axes infeed, outfeed stopped",
        &mut log,
    );

    let mut p2 = planner(&cfg, &hold);
    // Its job (the halt) done: the drive reported standstill (Target reached under Halt).
    let standing = wait_je_c(&name, "infeed", "stood", |s| s["link"]["busy"] == false);
    let at = standing["position"].as_f64().unwrap();
    assert!(at > 2.0 && at < 100.0, "{standing}");
    assert_eq!(standing["fsa"], "operation_enabled", "{standing}");
    assert!(standing["link"]["stopped"].is_null(), "{standing}");
    let _ = p2.kill();
    let _ = p2.wait();
    log.extend(ctl.try_iter());
    interrupt(&mut controller, &log);
}

/// Starts a mixed cell's controller and a planner on it (running `program`, or serving the
/// operator without one), ends the controller once `running(cell)` returns, and returns the
/// cell's name and the planner's error line (it must exit 1).
fn planner_error_when_the_controller_ends(
    program: Option<&str>,
    running: impl Fn(&str),
) -> (String, String) {
    let dir = tempfile::tempdir().unwrap();
    let (cfg, name) = mixed_cell(dir.path(), program.unwrap_or(SLOW_INFEED));
    let (mut controller, _ctl, log) = controller_waiting(&cfg, &["--no-record"]);
    let (mut p, p_log) = match program {
        Some(_) => {
            let mut p = planner(&cfg, &dir.path().join("program.toml"));
            let p_log = lines(&mut p);
            (p, p_log)
        }
        None => operator_planner(&cfg),
    };
    running(&name);
    interrupt(&mut controller, &log);
    let code = wait_exit(&mut p, 30);
    let p_text = all_lines(&p_log);
    assert_eq!(code, Some(1), "planner: {p_text:?}");
    (name, error_line(&p_text).to_string())
}

/// The controller ending while the external planner waits on an MR-JE-C move: the planner's
/// step fails naming the axis and the lost controller (its feedback stopped).
#[test]
fn a_planner_fails_clearly_when_the_controller_of_its_je_c_axes_ends() {
    let (_, err) = planner_error_when_the_controller_ends(Some(SLOW_INFEED), |name| {
        wait_infeed_moving(name);
    });
    assert!(
        err.contains("MR-JE-C axis 'infeed': the controller stopped sending its feedback"),
        "{err}"
    );
}

/// A planner whose configuration has other MR-JE-C axes than the controller's (one fewer; one
/// renamed) is refused with an error naming the cell, and nothing moves.
#[test]
fn a_planner_of_other_je_c_axes_is_refused() {
    const PROGRAM: &str = r#"
[[step]]
do = "power_on"
[[step]]
do = "move"
target = { infeed = 50.0 }
"#;
    let dir = tempfile::tempdir().unwrap();
    let (cfg, name) = mixed_cell(dir.path(), PROGRAM);
    let text = std::fs::read_to_string(&cfg).unwrap();
    let outfeed = text.find("[[axes]]\nname = \"outfeed\"").unwrap();
    let setpoints = text.find("\n[setpoints]").unwrap();
    let fewer = dir.path().join("fewer.toml");
    std::fs::write(
        &fewer,
        format!("{}{}", &text[..outfeed], &text[setpoints..]),
    )
    .unwrap();
    let renamed = dir.path().join("renamed.toml");
    std::fs::write(
        &renamed,
        text.replace("name = \"outfeed\"", "name = \"outfeed2\""),
    )
    .unwrap();
    let (mut controller, _ctl, log, json) = controller_with_summary(&cfg, dir.path());
    for (other, why) in [
        (
            &fewer,
            format!("cell '{name}': its controller runs 2 MR-JE-C axes, this planner's configuration has 1 (infeed)"),
        ),
        (
            &renamed,
            format!("cell '{name}': its controller's MR-JE-C axes differ from this planner's configuration (infeed, outfeed2"),
        ),
    ] {
        let (code, p_text) = planner_outcome(other, &dir.path().join("program.toml"), 30);
        assert_eq!(code, Some(1), "{p_text:?}");
        let err = error_line(&p_text);
        assert!(err.contains(&why), "{err}");
    }
    interrupt(&mut controller, &log);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(summary["final_state"], "disabled", "never powered on");
    let infeed = final_position(&json, "infeed");
    assert!(infeed.abs() < 1e-9, "infeed moved to {infeed}");
}

/// `cellrt planner --no-program CFG`: a planner serving the operator; with its stderr lines.
fn operator_planner(cfg: &Path) -> (Child, Receiver<String>) {
    let mut p = cellrt(&["planner".as_ref(), "--no-program".as_ref(), cfg.as_os_str()]);
    let p_log = lines(&mut p);
    (p, p_log)
}

/// A planner serving the operator ends, saying why, when its controller ends.
#[test]
fn a_planner_without_program_ends_with_its_controller() {
    let (name, err) = planner_error_when_the_controller_ends(None, |name| {
        wait_je_c(name, "infeed", "listed", |_| true);
    });
    assert!(
        err.contains(&format!("cell '{name}' stopped publishing its status")),
        "{err}"
    );
}

/// A planner serving the operator (`cellrt planner --no-program`) of a mixed cell: the
/// operator's power, move (csp and MR-JE-C axes in one command, which waits until all are
/// done), home, jog, torque, halt, stop and reset reach the MR-JE-C axes' threads in the
/// controller, `cellrt status` shows their drives' state, and SIGTERM ends the planner.
#[test]
fn the_operator_commands_je_c_axes_through_a_planner_without_program() {
    let dir = tempfile::tempdir().unwrap();
    let (cfg, name) = mixed_cell(dir.path(), SLOW_INFEED);
    let (mut controller, ctl, mut log, json) = controller_with_summary(&cfg, dir.path());
    let (mut p, p_log) = operator_planner(&cfg);
    let ok = |args: &[&str]| {
        let (code, out, err) = common::cellrt_on_cell(&name, args);
        assert_eq!(code, 0, "{args:?}: {out}{err}");
    };
    let listed = wait_je_c(&name, "outfeed", "listed", |_| true);
    assert_eq!(listed["fsa"], "switch_on_disabled", "{listed}");
    ok(&["power", "on"]);
    for axis in ["infeed", "outfeed"] {
        wait_je_c(&name, axis, "enabled", |s| s["fsa"] == "operation_enabled");
    }
    ok(&["move", "x=300", "infeed=100", "outfeed=-50"]);
    let at = |axis: &str| {
        je_c_status(&name, axis).unwrap()["position"]
            .as_f64()
            .unwrap()
    };
    assert!(
        (at("infeed") - 100.0).abs() < 0.01,
        "infeed at {}",
        at("infeed")
    );
    assert!(
        (at("outfeed") + 50.0).abs() < 0.01,
        "outfeed at {}",
        at("outfeed")
    );
    // Method 37: the home where the conveyor stands.
    ok(&["home", "infeed", "--method", "37"]);
    assert!(at("infeed").abs() < 0.001, "infeed at {}", at("infeed"));
    ok(&["jog", "outfeed", "40"]);
    wait_je_c(&name, "outfeed", "reached 40 mm/s", |s| {
        s["velocity"].as_f64().is_some_and(|v| v >= 39.0)
    });
    ok(&["halt", "outfeed"]);
    wait_je_c(&name, "outfeed", "stood", |s| s["link"]["busy"] == false);
    // In tq up to its speed limit (2D20h = limits.velocity, 150 mm/s), held until the stop.
    ok(&["torque", "outfeed=8"]);
    wait_je_c(&name, "outfeed", "ran up under torque", |s| {
        s["velocity"].as_f64().is_some_and(|v| v >= 145.0)
    });
    ok(&["stop"]);
    wait_je_c(&name, "outfeed", "halted its torque", |s| {
        s["link"]["busy"] == false
    });
    ok(&["reset"]);
    ok(&["power", "off"]);
    for axis in ["infeed", "outfeed"] {
        wait_je_c(&name, axis, "disabled", |s| s["fsa"] != "operation_enabled");
    }
    kill(Pid::from_raw(p.id() as i32), Signal::SIGTERM).unwrap();
    let code = wait_exit(&mut p, 30);
    let p_text = all_lines(&p_log).join("\n");
    assert_eq!(code, Some(0), "planner: {p_text}");
    assert!(p_text.contains("cellrt planner: stopped"), "{p_text}");
    log.extend(ctl.try_iter());
    interrupt(&mut controller, &log);
    assert!((final_position(&json, "x") - 300.0).abs() < 0.05);
    assert!(final_position(&json, "infeed").abs() < 0.001);
}
