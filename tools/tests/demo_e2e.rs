//! End to end: `cellrt run` on the demo cell with a short program; checks the final positions,
//! the recorded setpoints against the limits, the recording's completeness and the summary.

mod common;

use std::process::Command;

use cellrt_config::CellConfig;
use cellrt_runtime::host::record::proto::FsaState;
use common::{demo_cell, max_derivatives, read_recording};

const PROGRAM: &str = r#"
[[step]]
do = "power_on"
[[step]]
do = "move"
target = { x = 300.0, y = 200.0, c = 45.0 }
[[step]]
do = "move"
target = { z = -100.0 }
acceleration = 1000.0
[[step]]
do = "move"
target = { x = 60.0, y = 60.0, z = -10.0, c = 0.0 }
[[step]]
do = "power_off"
"#;

/// Final positions must be within this of the targets (units: mm and deg); the simulated
/// servo settles to within a few counts (1 count = 0.001).
const POSITION_TOLERANCE: f64 = 0.01;

#[test]
fn demo_program_runs_records_and_respects_limits() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = demo_cell(dir.path(), PROGRAM);
    let rec_path = dir.path().join("run.mcap");
    let json_path = dir.path().join("summary.json");
    let out = Command::new(env!("CARGO_BIN_EXE_cellrt"))
        .arg("run")
        .arg(&cfg)
        .arg("--record")
        .arg(&rec_path)
        .arg("--summary-json")
        .arg(&json_path)
        .output()
        .expect("cellrt runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "exit {:?}\n{stdout}\n{stderr}",
        out.status
    );
    assert!(stdout.contains("cellrt summary"), "{stdout}");

    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json_path).unwrap()).unwrap();
    assert_eq!(summary["outcome"], "program_completed", "{summary:#}");
    assert_eq!(summary["final_state"], "disabled");
    assert_eq!(summary["underruns"], 0);
    assert_eq!(summary["faults"], 0);
    assert_eq!(summary["dropped_records"], 0);

    // Every axis ends at its target.
    let targets = [("x", 60.0), ("y", 60.0), ("z", -10.0), ("c", 0.0)];
    for (name, target) in targets {
        let axis = summary["axes"]
            .as_array()
            .unwrap()
            .iter()
            .find(|a| a["name"] == name)
            .unwrap();
        let pos = axis["final_position"].as_f64().unwrap();
        assert!(
            (pos - target).abs() <= POSITION_TOLERANCE,
            "axis {name} ended at {pos}, target {target}"
        );
        assert_eq!(axis["target"].as_f64(), Some(target));
    }

    // The recording holds one record per cycle on each per-cycle channel.
    let rec = read_recording(&rec_path);
    let cycles = summary["cycles"].as_u64().unwrap();
    assert_eq!(rec.cycles.len() as u64, cycles);
    assert!(rec.indexed, "summary section with chunk indexes");
    assert_eq!(rec.summary_counts.get("/cell/cycle"), Some(&cycles));
    assert!(rec.cycles.windows(2).all(|w| w[1].cycle > w[0].cycle));
    let cycle_numbers: Vec<u64> = rec.cycles.iter().map(|c| c.cycle).collect();
    assert_eq!(rec.axes.len(), 4);
    for (name, samples) in &rec.axes {
        assert_eq!(samples.len() as u64, cycles, "axis {name}");
        let nums: Vec<u64> = samples.iter().map(|s| s.cycle).collect();
        assert_eq!(nums, cycle_numbers, "axis {name} cycles");
    }
    assert!(rec.events.iter().any(|e| e.kind == "motion_finished"));

    // Recorded setpoints respect the configured limits while the drive follows them (Operation
    // enabled; a disabled drive's setpoint tracks its actual position). Finite differences over
    // consecutive cycles; tolerance: floating-point noise only.
    let cell = CellConfig::load(&cfg).unwrap();
    let dt = cell.period();
    for a in cell.axes.on_loop() {
        let samples: Vec<(u64, f64)> = rec.axes[&a.name]
            .iter()
            .filter(|s| s.fsa_state == FsaState::OperationEnabled as i32)
            .map(|s| (s.cycle, s.setpoint_position))
            .collect();
        assert!(
            samples.len() > 1000,
            "{}: enabled for {} cycles",
            a.name,
            samples.len()
        );
        let (v, acc, j) = max_derivatives(&samples, dt);
        let l = a.limits;
        assert!(
            v <= l.velocity * (1.0 + 1e-6) + 1e-6,
            "{}: v {v} > {}",
            a.name,
            l.velocity
        );
        assert!(
            acc <= l.acceleration * (1.0 + 1e-6) + 1e-3,
            "{}: a {acc} > {}",
            a.name,
            l.acceleration
        );
        assert!(
            j <= l.jerk * (1.0 + 1e-6) + 1.0,
            "{}: j {j} > {}",
            a.name,
            l.jerk
        );
        assert!(
            v > 0.1 * l.velocity.min(100.0),
            "{}: axis did not move",
            a.name
        );
        // The plant is real: it lags the setpoint while moving, within the alarm limit.
        let fe = rec.axes[&a.name]
            .iter()
            .map(|s| s.following_error.abs())
            .fold(0.0, f64::max);
        assert!(
            fe > 0.0 && fe < a.following_error_limit,
            "{}: following error {fe}",
            a.name
        );
    }
}
