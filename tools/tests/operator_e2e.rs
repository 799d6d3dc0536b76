//! The operator interface end to end: a running cell (`cellrt run --no-program`) driven from
//! other processes (`cellrt power/move/jog/halt/override/stop/reset/torque/status`) through the
//! iceoryx2 operator service; every check reads the recorded motion, not only the replies.

mod common;

use std::path::Path;
use std::time::{Duration, Instant};

use cellrt_runtime::host::operator::client::OperatorClient;
use cellrt_runtime::host::operator::wire::{Reply, StatusReport};
use common::cell::Cell;
use common::{demo_cell, max_derivatives, read_recording, unique_cell_name};

/// Positions (units) of `axis` per cycle between two cycles.
fn positions(rec: &common::Recording, axis: &str) -> Vec<(u64, f64)> {
    rec.axes[axis]
        .iter()
        .map(|a| (a.cycle, a.setpoint_position))
        .collect()
}

fn cell_config(dir: &Path, extra: &str) -> std::path::PathBuf {
    let cfg = demo_cell(dir, "");
    let text = std::fs::read_to_string(&cfg)
        .unwrap()
        .replace("lookahead_ms = 1000", "lookahead_ms = 200");
    std::fs::write(&cfg, text + extra).unwrap();
    cfg
}

#[test]
fn operator_commands_drive_a_running_cell() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = cell_config(dir.path(), "");
    let rec = dir.path().join("run.mcap");
    let cell = Cell::start(&cfg, &rec);

    // Nothing moves while the cell is not powered.
    cell.rejected(&["move", "x=300"], "not powered");
    // MC_Power per axis: x alone, then off again; y takes no motion meanwhile.
    cell.rejected(&["power", "on", "q"], "unknown axis 'q'");
    cell.ok(&["power", "on", "x"]);
    let r: StatusReport = serde_json::from_str(&cell.ok(&["status", "--json"])).unwrap();
    assert_eq!(r.state, "idle");
    let axis = |n: &str| r.axes.iter().find(|a| a.name == n).unwrap().clone();
    assert!(axis("x").powered && axis("x").fsa == "operation_enabled");
    assert!(!axis("y").powered && axis("y").fsa != "operation_enabled");
    // Status DO from the MR-J5-G-N1's TxPDO: x servo on at rest, y servo off.
    assert_eq!(
        axis("x").status_do,
        ["S_SA", "S_MBR", "S_INP", "S_ZSP", "S_DB"],
        "x"
    );
    assert_eq!(axis("y").status_do, ["S_ZSP"], "y");
    cell.rejected(&["move", "x=300", "y=200"], "axis 'y' is not powered");
    cell.ok(&["power", "off", "x"]);
    cell.wait_state("disabled");
    cell.ok(&["power", "on"]);
    let text = cell.ok(&["status"]);
    assert!(
        text.contains("operation_enabled") && text.contains("S_INP S_ZSP"),
        "{text}"
    );
    // The status publish-subscribe service: per-axis state, cell state, last command, events.
    let node = cellrt_runtime::services::node(&cell.name, "test-status").unwrap();
    let sub = cellrt_runtime::services::operator_status_subscriber(&node, &cell.name).unwrap();
    let end = Instant::now() + Duration::from_secs(5);
    let report: StatusReport = loop {
        if let Ok(Some(s)) = sub.receive() {
            let r: StatusReport = serde_json::from_slice(s.payload()).unwrap();
            if r.state == "idle" {
                break r;
            }
        }
        assert!(Instant::now() < end, "no status sample");
        std::thread::sleep(Duration::from_millis(10));
    };
    assert_eq!(report.axes.len(), 4);
    assert!(report
        .axes
        .iter()
        .all(|a| a.fsa == "operation_enabled" && a.mode_display == "csp"));
    assert_eq!(
        report.last_finished.as_ref().map(|f| f.command.as_str()),
        None
    );
    assert!(
        report
            .recent_events
            .iter()
            .any(|e| e.contains("cell_state: idle")),
        "{:?}",
        report.recent_events
    );

    // Bad input, each refused with its reason; nothing moves.
    cell.rejected(&["move", "q=1"], "unknown axis 'q'");
    cell.rejected(&["move", "x=900"], "outside");
    let (code, _, err) = cell.cli(&["move", "x=nan"]);
    assert!(code == 2 && err.contains("not a finite number"), "{err}");
    cell.rejected(&["move", "x=200", "--vel", "500"], "exceeds the axis limit");
    cell.rejected(&["jog", "x", "401"], "exceeds the axis limit");
    cell.rejected(&["override", "150"], "outside 0–100 %");
    // A program that is a FIFO (or a device) is refused at once: the service is not blocked.
    let fifo = dir.path().join("program.fifo");
    nix::unistd::mkfifo(&fifo, nix::sys::stat::Mode::S_IRWXU).unwrap();
    cell.rejected(&["program", fifo.to_str().unwrap()], "not a regular file");
    cell.rejected(&["program", "/dev/zero"], "not a regular file");
    assert!(cell.ok(&["status"]).contains("state idle"));
    cell.rejected(&["torque", "x=10"], "mode = \"cst\"");
    cell.rejected(&["home", "x"], "lists no homing methods");
    let (code, _, err) = cell.cli(&["move", "x100"]);
    assert_eq!(code, 2, "{err}");
    let client = OperatorClient::connect(Some(&cell.name)).unwrap();
    match client
        .request_bytes(
            b"{\"command\": \"move\", \"targets\": 7}",
            Duration::from_secs(5),
        )
        .unwrap()
    {
        Reply::Rejected { reason } => assert!(reason.contains("malformed request"), "{reason}"),
        other => panic!("{other:?}"),
    }

    // A synchronised move, waited for.
    cell.ok(&["move", "x=300", "y=200"]);
    // Clamping on request: the velocity above the limit is lowered to it.
    cell.ok(&["move", "y=150", "--vel", "1000", "--clamp"]);
    // Re-target mid-move: x heads for 780, then turns round to 100.
    cell.ok(&["move", "x=780", "--no-wait"]);
    std::thread::sleep(Duration::from_millis(700));
    cell.ok(&["move", "x=100"]);
    // Jog, then halt.
    cell.ok(&["jog", "y", "100"]);
    std::thread::sleep(Duration::from_millis(800));
    cell.ok(&["halt"]);
    cell.wait_state("idle");
    // Feed override at 50 %.
    cell.ok(&["override", "50"]);
    cell.ok(&["move", "x=500"]);
    cell.ok(&["override", "100"]);
    // MC_Stop mid-move: the RT thread's controlled stop; the move fails, the cell is ready.
    cell.ok(&["move", "x=100", "--no-wait"]);
    std::thread::sleep(Duration::from_millis(500));
    cell.ok(&["stop"]);
    cell.wait_state("idle");
    let s = cell.ok(&["status"]);
    assert!(s.contains("stopped by the RT thread (command)"), "{s}");
    // A waypoint path: through (200, 100) and (350, 250), to (250, 400) at rest.
    cell.rejected(&["path", "x=200,y=100", "x=350"], "names other axes");
    cell.rejected(&["path", "x=200,y=900", "x=250,y=400"], "waypoint 0");
    cell.ok(&["path", "x=200,y=100", "x=350,y=250", "x=250,y=400"]);
    // A straight line of the gantry axes at 250 mm/s path speed.
    cell.rejected(
        &[
            "move", "x=450", "y=300", "z=-120", "--line", "--vel", "1000",
        ],
        "the most every axis allows",
    );
    cell.ok(&["move", "x=450", "y=300", "z=-120", "--line", "--vel", "250"]);
    cell.ok(&["power", "off"]);
    cell.end();

    let r = read_recording(&rec);
    let dt = 1e-3;
    let x = positions(&r, "x");
    let y = positions(&r, "y");
    let (vx, ax, _) = max_derivatives(&x, dt);
    let (vy, ay, _) = max_derivatives(&y, dt);
    assert!(
        vx <= 400.0 * 1.01 && ax <= 2000.0 * 1.05,
        "x: v {vx} a {ax}"
    );
    assert!(
        vy <= 400.0 * 1.01 && ay <= 2000.0 * 1.05,
        "y: v {vy} a {ay}"
    );
    // The re-target: x turned round before 780, then reached 100 exactly.
    let peak = x.iter().map(|p| p.1).fold(f64::MIN, f64::max);
    assert!(peak > 400.0 && peak < 779.0, "x peak {peak}");
    let turned = x.iter().position(|p| p.1 == peak).unwrap();
    assert!(
        x[turned..].iter().any(|p| (p.1 - 100.0).abs() < 1e-6),
        "x reached 100 after the re-target"
    );
    // The jog reached 100 mm/s on y.
    let at_jog_velocity = r.axes["y"]
        .iter()
        .filter(|a| (a.setpoint_velocity - 100.0).abs() < 1e-6)
        .count();
    assert!(
        at_jog_velocity > 300,
        "{at_jog_velocity} cycles at 100 mm/s"
    );
    // The 50 % override move (x from 100 to 500) ran at most 200 mm/s.
    let start = x[turned..]
        .iter()
        .position(|p| (p.1 - 100.0).abs() < 1e-6)
        .unwrap()
        + turned;
    let to_500 = x[start..]
        .iter()
        .position(|p| (p.1 - 500.0).abs() < 1e-6)
        .unwrap()
        + start;
    let (v_ov, _, _) = max_derivatives(&x[start..=to_500], dt);
    assert!(
        v_ov <= 200.0 * 1.01 && v_ov > 190.0,
        "override move at {v_ov} mm/s"
    );
    // Matched csp axes: the actual path stays within 0.05 mm of the line.
    assert_last_motion_on_line(&r, [450.0, 300.0, -120.0], 250.0, dt, 0.05);
    // The path (the motion before the line) passed its waypoints and ended on its target.
    let starts: Vec<u64> = r
        .events
        .iter()
        .filter(|e| e.kind == "motion_started")
        .map(|e| e.cycle)
        .collect();
    let (from, to) = (starts[starts.len() - 2], starts[starts.len() - 1]);
    let xy: Vec<(f64, f64)> = r.axes["x"]
        .iter()
        .zip(&r.axes["y"])
        .filter(|(a, _)| a.cycle >= from && a.cycle < to)
        .map(|(a, b)| (a.setpoint_position, b.setpoint_position))
        .collect();
    for w in [(200.0, 100.0), (350.0, 250.0)] {
        let d = xy
            .iter()
            .map(|p| ((p.0 - w.0).powi(2) + (p.1 - w.1).powi(2)).sqrt())
            .fold(f64::INFINITY, f64::min);
        // Sampled every 1 ms at ≤ 400 mm/s per axis.
        assert!(d < 0.6, "the path passed {w:?} at {d} mm");
    }
    let end = xy.last().unwrap();
    assert!(
        (end.0 - 250.0).abs() < 1e-6 && (end.1 - 400.0).abs() < 1e-6,
        "{end:?}"
    );
}

/// A copy of an example cell config with a unique name, no CPU pinning, no program, and
/// `extra` appended.
fn example_cell(dir: &Path, config: &str, extra: &str) -> std::path::PathBuf {
    let text = std::fs::read_to_string(format!(
        "{}/../configs/{config}",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    let name = unique_cell_name();
    let own = text
        .lines()
        .find(|l| l.starts_with("name = "))
        .unwrap()
        .to_string();
    let text = text
        .replacen(&own, &format!("name = \"{name}\""), 1)
        .lines()
        .map(|l| {
            if l.starts_with("cpu = ") || l.starts_with("program = ") {
                format!("# {l}")
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
        + extra;
    let cfg = dir.join("cell.toml");
    std::fs::write(&cfg, text).unwrap();
    cfg
}

#[test]
fn homing_in_the_drive_homing_mode_through_the_operator_service() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = example_cell(dir.path(), "mr-j4-tm.toml", "");
    // z stands 10 mm below a positive stroke end and has no home dog.
    let text = std::fs::read_to_string(&cfg).unwrap();
    let z = "limits = { position = [-200.0, 0.0], velocity = 250.0, acceleration = 1500.0, jerk = 15000.0 }\nsim = { initial_position = 0.0 }";
    assert!(text.contains(z), "{text}");
    let text = text.replacen(
        z,
        &z.replace(
            "sim = { initial_position = 0.0 }",
            "sim = { initial_position = -100.0, positive_limit = -90.0 }",
        ),
        1,
    );
    std::fs::write(&cfg, text).unwrap();
    let rec = dir.path().join("run.mcap");
    let cell = Cell::start(&cfg, &rec);
    cell.rejected(&["home", "x"], "homing starts from idle");
    cell.ok(&["power", "on"]);
    cell.ok(&["move", "x=300"]);
    cell.rejected(
        &["home", "x", "--method", "99"],
        "lists no homing method 99",
    );
    // Method -3 (data set, the default): home = here; the drive presets 6064h to the home
    // position address (0), the setpoint follows, nothing moves.
    cell.ok(&["home", "x"]);
    let s = cell.ok(&["status"]);
    assert!(s.contains("last    home"), "{s}");
    // Method 3 (last Z before the dog, forward) without a dog: the stroke end ends the
    // search, and the drive reports a homing error (MR-J4-TM AL. 90).
    let (code, _, err) = cell.cli(&["home", "z", "--method", "3"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("homing error"), "{err}");
    // The cell is usable after both; moves are in the new reference.
    cell.ok(&["move", "x=120"]);
    cell.ok(&["power", "off"]);
    cell.end();

    let r = read_recording(&rec);
    let x = &r.axes["x"];
    let homing: Vec<_> = x.iter().filter(|a| a.mode == 6).collect();
    assert!(!homing.is_empty(), "x never in hm");
    assert!(
        homing.iter().any(|a| a.controlword & (1 << 4) != 0),
        "no HOS"
    );
    assert!(
        homing.iter().any(|a| a.statusword & (1 << 12) != 0),
        "no homing attained"
    );
    let after = x
        .iter()
        .find(|a| a.cycle > homing.last().unwrap().cycle && a.mode == 8)
        .unwrap();
    assert!(
        after.actual_position.abs() < 1e-3,
        "x after homing: {after:?}"
    );
    assert!(
        (after.setpoint_position - after.actual_position).abs() < 1e-3,
        "setpoint follows the preset: {after:?}"
    );
    // No position step against the preset: around the homing the axis stands still, its
    // setpoint following the preset actual position (no following error).
    let (from, to) = (homing[0].cycle - 5, after.cycle + 50);
    let worst = x
        .iter()
        .filter(|a| a.cycle >= from && a.cycle <= to)
        .map(|a| a.following_error.abs())
        .fold(0.0, f64::max);
    assert!(worst < 0.01, "following error around the homing: {worst}");
    assert!(r
        .events
        .iter()
        .any(|e| e.kind == "homing_finished" && e.axis == "x" && e.detail == "homing attained"));
    assert!(r.events.iter().any(|e| e.kind == "homing_finished"
        && e.axis == "z"
        && e.detail.contains("homing error")));
    assert!(r.events.iter().all(|e| e.kind != "drive_fault"));
    let x_end = x.last().unwrap().setpoint_position;
    assert!((x_end - 120.0).abs() < 1e-3, "{x_end}");
}

#[test]
fn home_setting_by_controlword2_on_the_mr_j3_t04() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = example_cell(dir.path(), "mr-j3-t04.toml", "");
    // x's encoder Z phase at 100 mm (one per motor revolution = 1000 mm).
    let text = std::fs::read_to_string(&cfg).unwrap().replacen(
        "sim = { initial_position = 50.0 }",
        "sim = { initial_position = 50.0, z_phase_position = 100.0 }",
        1,
    );
    std::fs::write(&cfg, text).unwrap();
    let rec = dir.path().join("run.mcap");
    let cell = Cell::start(&cfg, &rec);
    cell.ok(&["power", "on"]);
    // hm cannot be told apart without 6061h in the TxPDO: a method is refused.
    cell.rejected(&["home", "x", "--method", "35"], "6061h");
    // C_CR2 before the Z phase was passed: AL.96, home unchanged, the cell usable.
    let (code, _, err) = cell.cli(&["home", "x", "--setting", "clear-z"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("AL.96"), "{err}");
    // Pass the Z phase at 100 mm, stop at 300 mm: C_CR2 sets home at the Z phase (x = 200).
    cell.ok(&["move", "x=150"]);
    cell.ok(&["move", "x=300"]);
    cell.ok(&["home", "x", "--setting", "clear-z"]);
    let x = cell.axis_status("x");
    assert!((x.position - 200.0).abs() < 0.01, "{x:?}");
    // The default: the manual's clear method, C_CR, home where x stands (x = 0).
    cell.ok(&["home", "x"]);
    let x = cell.axis_status("x");
    assert!(x.position.abs() < 0.01 && x.setpoint.abs() < 0.01, "{x:?}");
    // Moves are in the new reference.
    cell.ok(&["move", "x=100"]);
    cell.ok(&["power", "off"]);
    cell.end();

    let r = read_recording(&rec);
    let x = &r.axes["x"];
    let end = x.last().unwrap();
    // One count is 1/262.144 mm.
    assert!((end.setpoint_position - 100.0).abs() < 0.01, "{end:?}");
    assert!((end.actual_position - 100.0).abs() < 0.01, "{end:?}");
    // No mode change and no position step: x never left csp, never a following error.
    assert!(x.iter().all(|a| a.mode == 8), "x left csp");
    let worst = x
        .iter()
        .map(|a| a.following_error.abs())
        .fold(0.0, f64::max);
    assert!(worst < 5.0, "following error {worst}");
    let homings: Vec<_> = r
        .events
        .iter()
        .filter(|e| e.kind == "homing_started" && e.axis == "x")
        .map(|e| e.detail.clone())
        .collect();
    assert_eq!(homings.len(), 3, "{homings:?}");
    assert!(
        homings[0].contains("C_CR2") && homings[2].contains("C_CR "),
        "{homings:?}"
    );
    let finished: Vec<_> = r
        .events
        .iter()
        .filter(|e| e.kind == "homing_finished" && e.axis == "x")
        .map(|e| e.detail.clone())
        .collect();
    assert!(finished[0].contains("AL.96"), "{finished:?}");
    assert_eq!(finished[1..], ["homing attained", "homing attained"]);
    assert!(r.events.iter().all(|e| e.kind != "drive_fault"));
}

#[test]
fn torque_and_reset_after_a_fault_through_the_operator_service() {
    let dir = tempfile::tempdir().unwrap();
    // The MR-JET cell: c runs in cst.
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../configs/mr-jet-g-n1.toml"
    ))
    .unwrap();
    let name = unique_cell_name();
    let text = text
        .lines()
        .map(|l| {
            if l.starts_with("name = ") && !l.contains("\"x\"") && l.contains("jet") {
                format!("name = \"{name}\"")
            } else if l.starts_with("cpu = ") || l.starts_with("program = ") {
                format!("# {l}")
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
        // Generous lookahead and no overrun watchdog: the commands' logic is under test, not
        // the machine's load.
        + "\n[setpoints]\nlookahead_ms = 1000\n[watchdogs]\nmax_consecutive_overruns = 0\n"
        // The alarm comes in the run's first cycles, before any command.
        + "\n[[inject]]\nat_ms = 1\nfault = \"drive_alarm\"\naxis = \"y\"\ncode = 0x2220\n";
    assert!(text.contains(&name), "cell name replaced");
    let cfg = dir.path().join("cell.toml");
    std::fs::write(&cfg, text).unwrap();
    let rec = dir.path().join("run.mcap");
    let cell = Cell::start(&cfg, &rec);
    // Powering on with y's drive in fault faults the cell (had the alarm come later, it would
    // fault the enabled cell: either way it ends faulted); reset, power on, torque and move.
    let (code, out, err) = cell.cli(&["power", "on"]);
    assert!(
        code == 0 || err.contains("the cell faulted (drive_fault)"),
        "{out}{err}"
    );
    cell.wait_state("faulted");
    cell.rejected(&["power", "on"], "reset it first");
    cell.ok(&["reset"]);
    cell.ok(&["power", "on"]);
    cell.ok(&["torque", "c=30", "--seconds", "0.3"]);
    cell.rejected(&["torque", "c=500"], "outside the torque limit");
    cell.ok(&["move", "x=120"]);
    cell.rejected(&["move", "x=100", "c=10", "--line"], "one unit");
    // A line halted midway stops on the line; nothing else is taken while it runs.
    cell.ok(&[
        "move",
        "x=400",
        "y=300",
        "z=-100",
        "--line",
        "--vel",
        "100",
        "--no-wait",
    ]);
    std::thread::sleep(Duration::from_millis(400));
    cell.rejected(&["move", "x=200"], "line move is active");
    cell.ok(&["halt"]);
    cell.wait_state("idle");
    cell.ok(&["power", "off"]);
    cell.end();

    let r = read_recording(&rec);
    let c = &r.axes["c"];
    let peak = c.iter().map(|a| a.setpoint_torque).max().unwrap();
    assert_eq!(peak, 300, "30 % in 0.1 % units");
    // Ramped: no torque step above the slope (500 %/s = 2.5 × 0.1 % per 0.5 ms cycle), per
    // elapsed cycle (an overrun skips cycles).
    let period_s = 0.5e-3;
    let max_step = c
        .windows(2)
        .map(|w| {
            f64::from((w[1].setpoint_torque - w[0].setpoint_torque).abs())
                / (w[1].cycle - w[0].cycle) as f64
        })
        .fold(0.0, f64::max);
    assert!(
        max_step <= 500.0 * 10.0 * period_s + 1.0,
        "torque step {max_step} per cycle"
    );
    assert!(
        r.events.iter().any(|e| e.kind == "drive_fault"
            && e.axis == "y"
            && e.detail.contains("603Fh = 2220h")),
        "the alarm is recorded: {:?}",
        r.events
    );
    assert!(
        r.axes["x"]
            .iter()
            .any(|a| (a.setpoint_position - 120.0).abs() < 1e-6),
        "moved after the reset"
    );
    // The halted line: from its start, every setpoint on the line to (400, 300, -100), ending
    // at rest short of it.
    let last_start = r
        .events
        .iter()
        .rfind(|e| e.kind == "motion_started")
        .unwrap()
        .cycle;
    let last_end = r
        .events
        .iter()
        .rfind(|e| e.kind == "motion_finished")
        .unwrap()
        .cycle;
    let point = |cycle: u64| -> Vec<f64> {
        ["x", "y", "z"]
            .iter()
            .map(|n| at(&r, n, cycle).setpoint_position)
            .collect()
    };
    let a = point(last_start - 1);
    let b = [400.0, 300.0, -100.0];
    for cycle in last_start..=last_end {
        let p = point(cycle);
        assert!(
            off_line(&p, &a, &b) < 1e-6,
            "cycle {cycle}: {p:?} off the line"
        );
    }
    let stop = point(last_end);
    assert!(
        stop[0] > a[0] + 1.0 && stop[0] < 399.0,
        "halted at {stop:?}"
    );
}

/// The last motion of `r` is a line of x, y, z to `b`: every setpoint between its start and end
/// lies on the line (to 1 nm), every actual position within `actual_tol` mm of it, the path speed
/// at most `v` (and close to it).
fn assert_last_motion_on_line(
    r: &common::Recording,
    b: [f64; 3],
    v: f64,
    period_s: f64,
    actual_tol: f64,
) {
    let started = r
        .events
        .iter()
        .rfind(|e| e.kind == "motion_started")
        .unwrap()
        .cycle;
    let finished = r
        .events
        .iter()
        .rfind(|e| e.kind == "motion_finished")
        .unwrap()
        .cycle;
    // Cycles an overrun skipped have no record: look up the ones that exist.
    let cycles: Vec<u64> = r.axes["x"]
        .iter()
        .map(|a| a.cycle)
        .filter(|c| (started..finished).contains(c))
        .collect();
    let at = |axis: &str, cycle: u64| at(r, axis, cycle);
    let a: Vec<f64> = ["x", "y", "z"]
        .iter()
        .map(|n| at(n, started - 1).setpoint_position)
        .collect();
    let (mut worst_set, mut worst_act, mut speed) = (0.0f64, 0.0f64, 0.0f64);
    let mut prev: Option<(u64, Vec<f64>)> = None;
    for &cycle in &cycles {
        let s: Vec<_> = ["x", "y", "z"].iter().map(|n| at(n, cycle)).collect();
        let set: Vec<f64> = s.iter().map(|c| c.setpoint_position).collect();
        let act: Vec<f64> = s.iter().map(|c| c.actual_position).collect();
        worst_set = worst_set.max(off_line(&set, &a, &b));
        worst_act = worst_act.max(off_line(&act, &a, &b));
        if let Some((c, p)) = &prev {
            let d: f64 = p.iter().zip(&set).map(|(p, q)| (q - p).powi(2)).sum();
            speed = speed.max(d.sqrt() / (period_s * (cycle - c) as f64));
        }
        prev = Some((cycle, set));
    }
    assert!(worst_set < 1e-6, "setpoints {worst_set} mm off the line");
    assert!(
        worst_act < actual_tol,
        "actual positions {worst_act} mm off the line"
    );
    assert!(speed <= v * 1.001 && speed > v * 0.96, "path speed {speed}");
    let end: Vec<f64> = ["x", "y", "z"]
        .iter()
        .map(|n| at(n, finished).setpoint_position)
        .collect();
    assert!(
        end.iter().zip(&b).all(|(e, t)| (e - t).abs() < 1e-6),
        "{end:?}"
    );
}

/// The record of `axis` at `cycle`, or the last before it (an overrun skips cycles).
fn at(
    r: &common::Recording,
    axis: &str,
    cycle: u64,
) -> cellrt_runtime::host::record::proto::AxisCycle {
    *r.axes[axis].iter().rfind(|a| a.cycle <= cycle).unwrap()
}

/// Distance of `p` from the line through `a` and `b`.
fn off_line(p: &[f64], a: &[f64], b: &[f64]) -> f64 {
    let d: Vec<f64> = a.iter().zip(b).map(|(a, b)| b - a).collect();
    let len = d.iter().map(|x| x * x).sum::<f64>().sqrt();
    let w: Vec<f64> = p.iter().zip(a).map(|(p, a)| p - a).collect();
    let t = w.iter().zip(&d).map(|(w, d)| w * d).sum::<f64>() / len;
    w.iter()
        .zip(&d)
        .map(|(w, d)| (w - t * d / len).powi(2))
        .sum::<f64>()
        .sqrt()
}
