//! SIGINT during a move: the RT thread ramps every axis down (no setpoint step above one cycle
//! at the velocity limit), the cell powers off, the recording is complete, and cellrt exits 0.

mod common;

use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use cellrt_config::CellConfig;
use common::{demo_cell, read_recording};
use nix::sys::signal::{kill, Signal};
use nix::unistd::Pid;

const PROGRAM: &str = r#"
[[step]]
do = "power_on"
[[step]]
do = "move"
target = { x = 780.0, y = 580.0 }
[[step]]
do = "power_off"
"#;

#[test]
fn sigint_mid_move_ramps_down_and_finishes_the_recording() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = demo_cell(dir.path(), PROGRAM);
    let rec_path = dir.path().join("run.mcap");
    let json_path = dir.path().join("summary.json");
    let mut child = Command::new(env!("CARGO_BIN_EXE_cellrt"))
        .arg("run")
        .arg(&cfg)
        .arg("--record")
        .arg(&rec_path)
        .arg("--summary-json")
        .arg(&json_path)
        .env("CELLRT_LOG", "debug")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("cellrt starts");

    // Wait until the move has started (the event is logged at debug level), then let it run.
    let stderr = child.stderr.take().unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            let _ = tx.send(line);
        }
    });
    let deadline = Instant::now() + Duration::from_secs(30);
    let mut log = Vec::new();
    loop {
        let line = rx
            .recv_timeout(deadline.saturating_duration_since(Instant::now()))
            .unwrap_or_else(|_| panic!("no motion_started within 30 s:\n{}", log.join("\n")));
        let started = line.contains("motion_started");
        log.push(line);
        if started {
            break;
        }
    }
    std::thread::sleep(Duration::from_millis(600));
    kill(Pid::from_raw(child.id() as i32), Signal::SIGINT).expect("SIGINT sent");

    let end = Instant::now() + Duration::from_secs(30);
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if Instant::now() > end {
            let _ = child.kill();
            panic!("cellrt did not exit within 30 s of SIGINT");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    while let Ok(l) = rx.try_recv() {
        log.push(l);
    }
    assert_eq!(status.code(), Some(0), "exit status\n{}", log.join("\n"));

    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json_path).unwrap()).unwrap();
    assert_eq!(summary["outcome"], "interrupted");
    assert_eq!(summary["final_state"], "disabled");

    // The recording is complete and indexed, one record per cycle and axis.
    let rec = read_recording(&rec_path);
    let cycles = summary["cycles"].as_u64().unwrap();
    assert!(rec.indexed);
    assert_eq!(rec.cycles.len() as u64, cycles);
    for samples in rec.axes.values() {
        assert_eq!(samples.len() as u64, cycles);
    }
    let stop = rec
        .events
        .iter()
        .find(|e| e.kind == "stop_started")
        .expect("a controlled stop was recorded");
    assert_eq!(stop.detail, "command (controlled_stop)");
    assert!(rec.events.iter().any(|e| e.kind == "stop_finished"));
    assert!(
        !rec.events.iter().any(|e| e.kind == "motion_finished"),
        "the move was cut short"
    );

    // The ramp: no setpoint step above one cycle at the velocity limit, velocity ends at zero,
    // and the axis stopped short of its target.
    let cell = CellConfig::load(&cfg).unwrap();
    let dt = cell.period();
    for (name, target) in [("x", 780.0), ("y", 580.0)] {
        let a = &cell.axes.on_loop()[cell.axis_index(name).unwrap()];
        let s = &rec.axes[name];
        let max_step = a.limits.velocity * dt * (1.0 + 1e-6);
        for w in s.windows(2) {
            let gap = (w[1].cycle - w[0].cycle) as f64;
            let step = (w[1].setpoint_position - w[0].setpoint_position).abs();
            assert!(
                step <= max_step * gap + 1e-9,
                "{name}: setpoint step {step} at cycle {}",
                w[1].cycle
            );
        }
        let stop_cycle = stop.cycle;
        let at_stop = s.iter().find(|r| r.cycle >= stop_cycle).unwrap();
        assert!(
            at_stop.setpoint_velocity.abs() > 1.0,
            "{name} was moving when the stop began"
        );
        // Deceleration during the ramp stays within the configured stop deceleration.
        let ramp: Vec<_> = s.iter().filter(|r| r.cycle >= stop_cycle).collect();
        for w in ramp.windows(2) {
            if w[1].cycle == w[0].cycle + 1 {
                let dec = (w[1].setpoint_velocity - w[0].setpoint_velocity).abs() / dt;
                assert!(
                    dec <= a.stop_deceleration * (1.0 + 1e-6),
                    "{name}: decel {dec}"
                );
            }
        }
        let last = s.last().unwrap();
        assert_eq!(last.setpoint_velocity, 0.0);
        assert!(
            (last.actual_position - target).abs() > 1.0,
            "{name} should have stopped short of {target}, is at {}",
            last.actual_position
        );
    }
}
