//! Watchdogs and fault reactions, end to end: each injected fault trips its watchdog, the
//! configured reaction runs (seen in the recording: no setpoint step, deceleration within the
//! stop limit), the cell refuses to continue the program, and cellrt exits 1.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use cellrt_config::CellConfig;
use cellrt_runtime::host::record::proto::AxisCycle;
use common::{demo_cell, read_recording, Recording};

const LONG_MOVE: &str = r#"
[[step]]
do = "power_on"
[[step]]
do = "move"
target = { x = 780.0, y = 580.0 }
[[step]]
do = "power_off"
"#;

struct Run {
    code: Option<i32>,
    summary: serde_json::Value,
    rec: Recording,
    cell: CellConfig,
    stderr: String,
}

/// Runs the demo cell with `edits` (from, to) applied to its configuration and `extra` TOML
/// appended.
fn run_with(dir: &Path, edits: &[(&str, &str)], extra: &str) -> Run {
    let cfg = demo_cell(dir, LONG_MOVE);
    let mut text = std::fs::read_to_string(&cfg).unwrap();
    for (from, to) in edits {
        assert!(text.contains(from), "{from}");
        text = text.replace(from, to);
    }
    text.push_str(extra);
    std::fs::write(&cfg, text).unwrap();
    let rec_path: PathBuf = dir.join("run.mcap");
    let json = dir.join("summary.json");
    let out = Command::new(env!("CARGO_BIN_EXE_cellrt"))
        .arg("run")
        .arg(&cfg)
        .arg("--record")
        .arg(&rec_path)
        .arg("--summary-json")
        .arg(&json)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    let summary = serde_json::from_str(
        &std::fs::read_to_string(&json).unwrap_or_else(|_| panic!("no summary; stderr:\n{stderr}")),
    )
    .unwrap();
    Run {
        code: out.status.code(),
        summary,
        rec: read_recording(&rec_path),
        cell: CellConfig::load(&cfg).unwrap(),
        stderr,
    }
}

/// The stop event's detail, e.g. "underrun (controlled_stop)".
fn stop_detail(rec: &Recording) -> (u64, String) {
    let e = rec
        .events
        .iter()
        .find(|e| e.kind == "stop_started")
        .expect("a stop was recorded");
    (e.cycle, e.detail.clone())
}

/// Checks the ramp of `axis` from `from_cycle`: no setpoint step above the velocity limit,
/// deceleration within the stop limit, ends at rest.
fn assert_controlled_stop(run: &Run, axis: &str, from_cycle: u64) {
    let a = &run.cell.axes.on_loop()[run.cell.axis_index(axis).unwrap()];
    let dt = run.cell.period();
    let s: Vec<&AxisCycle> = run.rec.axes[axis]
        .iter()
        .filter(|r| r.cycle >= from_cycle.saturating_sub(1))
        .collect();
    assert!(s.len() > 2, "{axis}: no samples after the stop");
    assert!(
        s[1].setpoint_velocity.abs() > 1.0,
        "{axis} was moving when the stop began"
    );
    for w in s.windows(2) {
        let gap = (w[1].cycle - w[0].cycle) as f64;
        let step = (w[1].setpoint_position - w[0].setpoint_position).abs();
        assert!(
            step <= a.limits.velocity * dt * gap * (1.0 + 1e-6) + 1e-9,
            "{axis}: setpoint step {step} at cycle {}",
            w[1].cycle
        );
        if gap == 1.0 {
            let dec = (w[1].setpoint_velocity - w[0].setpoint_velocity).abs() / dt;
            assert!(
                dec <= a.stop_deceleration.max(a.limits.acceleration) * (1.0 + 1e-6),
                "{axis}: deceleration {dec} at cycle {}",
                w[1].cycle
            );
        }
    }
    let at_rest = s
        .iter()
        .any(|r| r.setpoint_velocity == 0.0 && r.cycle > from_cycle);
    assert!(at_rest, "{axis} never came to rest");
}

#[test]
fn planner_stall_underruns_and_the_rt_thread_stops_the_axes() {
    let dir = tempfile::tempdir().unwrap();
    let run = run_with(
        dir.path(),
        &[],
        "\n[[inject]]\nat_ms = 600\nfault = \"planner_stall\"\nduration_ms = 4000\n",
    );
    assert_eq!(run.code, Some(1), "{}", run.stderr);
    assert_eq!(run.summary["outcome"], "program_failed");
    assert_eq!(run.summary["underruns"], 1);
    let err = run.summary["program_error"].as_str().unwrap();
    assert!(err.contains("underrun"), "{err}");
    assert!(run.rec.events.iter().any(|e| e.kind == "underrun"));
    let (cycle, detail) = stop_detail(&run.rec);
    assert_eq!(detail, "underrun (controlled_stop)");
    assert_controlled_stop(&run, "x", cycle);
    assert_controlled_stop(&run, "y", cycle);
    assert!(run
        .rec
        .events
        .iter()
        .any(|e| e.kind == "cell_state" && e.detail == "stopped"));
}

#[test]
fn consecutive_overruns_trip_the_overrun_watchdog() {
    let dir = tempfile::tempdir().unwrap();
    let run = run_with(
        dir.path(),
        &[(
            "max_consecutive_overruns = 0",
            "max_consecutive_overruns = 3",
        )],
        "\n[[inject]]\nat_ms = 800\nfault = \"stall\"\nduration_ms = 6\n",
    );
    assert_eq!(run.code, Some(1), "{}", run.stderr);
    assert!(run.summary["overruns"].as_u64().unwrap() >= 3);
    let (cycle, detail) = stop_detail(&run.rec);
    assert_eq!(detail, "overrun (controlled_stop)");
    let at = |kind: &str| {
        run.rec
            .events
            .iter()
            .find(|e| e.kind == kind)
            .map(|e| e.cycle)
    };
    assert!(
        at("overrun").is_some_and(|c| c <= cycle),
        "the stop follows the overruns"
    );
    // The injected 6 ms stall counts 6 missed deadlines at once; a loaded machine may have
    // stalled the loop 3 deadlines long before it, which trips the same watchdog.
    if at("fault_injected").is_some_and(|c| c <= cycle) {
        let overrun = run
            .rec
            .events
            .iter()
            .find(|e| e.kind == "overrun" && e.value >= 2_000_000)
            .expect("the injected stall is recorded as an overrun with its lateness");
        assert!(cycle >= overrun.cycle);
    }
    assert_controlled_stop(&run, "x", cycle);
}

#[test]
fn overruns_are_counted_and_skipped_without_reaction_when_disabled() {
    let dir = tempfile::tempdir().unwrap();
    let run = run_with(
        dir.path(),
        &[],
        "\n[[inject]]\nat_ms = 800\nfault = \"stall\"\nduration_ms = 40\n",
    );
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert_eq!(run.summary["outcome"], "program_completed");
    let overruns = run.summary["overruns"].as_u64().unwrap();
    // 40 ms at 1 ms: more than two 16-cycle setpoint blocks are skipped at once, and the
    // stream must still continue without an underrun.
    assert!(
        overruns >= 39,
        "a 40 ms stall at 1 ms skips at least 39 deadlines: {overruns}"
    );
    assert_eq!(run.summary["underruns"], 0);
    // Skipped, not caught up: the cycle numbers jump over the stall.
    let jump = run
        .rec
        .cycles
        .windows(2)
        .map(|w| w[1].cycle - w[0].cycle)
        .max()
        .unwrap();
    assert!(jump >= 40, "largest cycle gap {jump}");
    // One record per executed cycle; executed + skipped covers the whole run.
    assert_eq!(
        run.rec.cycles.len() as u64,
        run.summary["cycles"].as_u64().unwrap()
    );
    assert!(!run.rec.events.iter().any(|e| e.kind == "stop_started"));
}

#[test]
fn a_drive_fault_stops_the_other_axes_too() {
    let dir = tempfile::tempdir().unwrap();
    let run = run_with(
        dir.path(),
        &[],
        "\n[[inject]]\nat_ms = 900\nfault = \"drive_alarm\"\naxis = \"y\"\ncode = 0x2220\n",
    );
    assert_eq!(run.code, Some(1), "{}", run.stderr);
    assert_eq!(run.summary["faults"], 1);
    let fault = run
        .rec
        .events
        .iter()
        .find(|e| e.kind == "drive_fault")
        .expect("drive fault event");
    assert_eq!(fault.axis, "y");
    // MR-J5-G-N1's default TxPDO (1A00h) does not map 603Fh (MR-J5-G-N1 manual §4.3): the
    // master reads it once, acyclically, at the fault edge.
    assert_eq!(fault.value, 0x2220, "{}", fault.detail);
    assert!(fault.detail.contains("603Fh = 2220h"), "{}", fault.detail);
    let (cycle, detail) = stop_detail(&run.rec);
    assert_eq!(detail, "drive_fault (controlled_stop)");
    // The healthy axis ramps down; the faulted one is stopped by its drive.
    assert_controlled_stop(&run, "x", cycle);
    let y_fault = run.rec.axes["y"]
        .iter()
        .any(|r| r.statusword & 0x004F == 0x0008);
    assert!(y_fault, "y reports Fault in its statusword");
    assert!(run
        .rec
        .events
        .iter()
        .any(|e| e.kind == "cell_state" && e.detail == "faulted"));
}

#[test]
fn quick_stop_reaction_is_carried_out_by_the_drives() {
    let dir = tempfile::tempdir().unwrap();
    let run = run_with(
        dir.path(),
        &[(
            r#"underrun_reaction = "controlled_stop""#,
            r#"underrun_reaction = "quick_stop""#,
        )],
        "\n[[inject]]\nat_ms = 600\nfault = \"planner_stall\"\nduration_ms = 4000\n",
    );
    assert_eq!(run.code, Some(1), "{}", run.stderr);
    let (cycle, detail) = stop_detail(&run.rec);
    assert_eq!(detail, "underrun (quick_stop)");
    // The master sent Quick stop (0x0002) and the drive went through Quick stop active.
    let x = &run.rec.axes["x"];
    assert!(x
        .iter()
        .any(|r| r.cycle >= cycle && r.controlword & 0x0087 == 0x0002));
    assert!(
        x.iter().any(|r| r.statusword & 0x006F == 0x0007),
        "quick stop active seen"
    );
}
