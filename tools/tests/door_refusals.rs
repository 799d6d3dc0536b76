//! Refusals at the door (issue 33): a move whose own limits would make it take longer than a
//! motion may (one day), or whose values the planner cannot work with, is refused in one line
//! before anything is sent — by the CLI with exit 2, and by the cell for any other client — and
//! an error line repeats at most a short prefix of a long argument.

mod common;

use std::collections::BTreeMap;
use std::time::Duration;

use cellrt_config::echo::MAX_ECHO_CHARS;
use cellrt_runtime::host::operator::client::OperatorClient;
use cellrt_runtime::host::operator::wire::{Reply, Request};
use common::cell::Cell;
use common::demo_cell;

/// The longest error line a refusal may print: the fixed text and one echoed argument.
const LONGEST_LINE: usize = 2 * MAX_ECHO_CHARS + 160;

fn cellrt(args: &[&str]) -> (i32, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_cellrt"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// `stderr` is one error line (no planner dump) that contains `says`.
fn one_line(stderr: &str, says: &str) {
    let lines: Vec<&str> = stderr.trim().lines().collect();
    assert_eq!(lines.len(), 1, "one line: {stderr}");
    assert!(lines[0].starts_with("error: "), "{stderr}");
    assert!(lines[0].contains(says), "'{stderr}' lacks '{says}'");
    assert!(lines[0].chars().count() < LONGEST_LINE, "{stderr}");
}

#[test]
fn moves_too_long_to_plan_are_refused_in_one_line_before_anything_is_sent() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = demo_cell(dir.path(), "");
    let cell = Cell::start(&cfg, &dir.path().join("run.mcap"));
    cell.ok(&["power", "on"]);
    let before = cell.axis_status("x").position;
    for (args, says) in [
        (
            &["move", "x=100", "y=100", "--line", "--vel", "1e-300"][..],
            "move: the line: ",
        ),
        (
            &["move", "x=100", "y=100", "--vel", "1e-300"],
            "axis 'x' (mm)",
        ),
        (&["move", "x=300", "--rel", "--acc", "1e-300"], "axis 'x'"),
        (&["move", "x=300", "--jerk", "1e-300"], "axis 'x'"),
        // 650 mm at 1 µm/s: 7.5 days.
        (
            &["move", "x=700", "--vel", "1e-3"],
            "longer than a motion may take",
        ),
        // Through a waypoint and back: 1300 mm at 10 µm/s.
        (
            &["path", "x=700,y=50", "x=50,y=50", "--vel", "1e-2"],
            "path: axis 'x' (mm)",
        ),
    ] {
        let (code, _, err) = cell.cli(args);
        assert_eq!(code, 2, "cellrt {args:?}: {err}");
        one_line(&err, says);
        assert!(err.contains("one day"), "{err}");
    }
    // A torque held for longer than a day is refused by clap's check of --seconds.
    let (code, _, err) = cell.cli(&["torque", "c=10", "--seconds", "1e300"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("1e300 s is longer than 86400 s"), "{err}");
    // Nothing was sent: no command ran, the axis stands where it stood.
    let status = cell.ok(&["status", "--json"]);
    let report: cellrt_runtime::host::operator::wire::StatusReport =
        serde_json::from_str(&status).unwrap();
    assert!(report.active_command.is_none(), "{status}");
    assert_eq!(cell.axis_status("x").position, before);

    // Another client is refused by the cell, in one line, before anything moves.
    let client = OperatorClient::connect(Some(&cell.name)).unwrap();
    let mv = |velocity: f64, line: bool| Request::Move {
        targets: BTreeMap::from([("x".to_string(), 600.0), ("y".to_string(), 600.0)]),
        relative: false,
        velocity: Some(velocity),
        acceleration: None,
        jerk: None,
        clamp: false,
        line,
    };
    for (req, says) in [
        (mv(1e-300, true), "too small to plan with"),
        (mv(1e-3, true), "longer than a motion may take"),
        (mv(1e-300, false), "too small to plan with"),
        (mv(1e-3, false), "longer than a motion may take"),
        (
            Request::Path {
                waypoints: vec![
                    BTreeMap::from([("x".to_string(), 600.0)]),
                    BTreeMap::from([("x".to_string(), 50.0)]),
                ],
                velocity: Some(1e-2),
                acceleration: None,
                jerk: None,
                clamp: false,
            },
            "path: axis 'x' (mm)",
        ),
        (
            Request::Torque {
                targets: BTreeMap::from([("c".to_string(), 10.0)]),
                seconds: 1e300,
            },
            "longer than a motion may take",
        ),
    ] {
        match client.request(&req, Duration::from_secs(10)).unwrap() {
            Reply::Rejected { reason } => {
                assert_eq!(reason.lines().count(), 1, "{reason}");
                assert!(reason.chars().count() < LONGEST_LINE, "{reason}");
                assert!(reason.contains(says), "{reason}");
            }
            r => panic!("{req:?}: {r:?}"),
        }
    }
    assert_eq!(cell.axis_status("x").position, before);
    cell.end();
}

#[test]
fn an_error_line_repeats_a_short_prefix_of_a_long_argument() {
    let long = "a".repeat(100_000);
    let long_pair = format!("x={long}");
    let long_digits = format!("x=1{}", "0".repeat(100_000));
    for (args, code, says) in [
        // The CLI's own refusals (no cell needed: refused before connecting).
        (vec!["move", long.as_str()], 2, "is not AXIS=VALUE"),
        (vec!["move", long_pair.as_str()], 2, "is not a number"),
        (
            vec!["move", long_digits.as_str()],
            2,
            "is not a finite number",
        ),
        (
            vec!["move", "x=1", "--vel", long.as_str()],
            2,
            "is not a number",
        ),
        // No such cell.
        (vec!["status", "--cell", long.as_str()], 4, "no cell named"),
    ] {
        let (got, err) = cellrt(&args);
        assert_eq!(got, code, "{}", &err[..err.len().min(300)]);
        assert!(err.contains(says), "{}", &err[..err.len().min(300)]);
        assert!(
            err.contains(" characters)"),
            "{}",
            &err[..err.len().min(300)]
        );
        for line in err.lines() {
            assert!(line.chars().count() < LONGEST_LINE, "{line}");
        }
    }
}
