//! The live view (`cellrt run --live ADDR`, Foxglove WebSocket protocol) against an independent
//! client written with PyPI's `websockets` and `protobuf` (`tools/tests/python/live_view.py`,
//! `$CELLRT_PYTHON` as CI sets it up; outside CI a missing package skips the test, saying so):
//! the recording's topics are advertised with their protobuf schemas, the cycle and axis
//! messages decode and come in order while the demo moves, and a viewer that stops reading
//! slows nothing — the cell completes its program and the recording drops no record.

mod common;

use std::net::TcpListener;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::demo_cell;

const PROGRAM: &str = r#"
[[step]]
do = "power_on"
[[step]]
do = "move"
target = { x = 700.0 }
[[step]]
do = "move"
target = { x = 100.0 }
[[step]]
do = "wait"
seconds = 8
[[step]]
do = "power_off"
"#;

/// The Python with websockets and protobuf, or why there is none.
fn python() -> Result<String, String> {
    let python = std::env::var("CELLRT_PYTHON").unwrap_or_else(|_| "python3".into());
    let ok = Command::new(&python)
        .args(["-c", "import websockets, google.protobuf"])
        .output()
        .is_ok_and(|o| o.status.success());
    if ok {
        Ok(python)
    } else {
        Err(format!(
            "{python} lacks websockets / protobuf (pip install websockets protobuf)"
        ))
    }
}

fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

/// Runs the demo program with the live view on and `viewer` clients; returns the clients'
/// JSON lines and the run's summary JSON.
fn run_with_viewers(viewers: &[&[&str]]) -> Option<(Vec<serde_json::Value>, serde_json::Value)> {
    let python = match python() {
        Ok(p) => p,
        Err(why) => {
            assert!(
                std::env::var_os("CI").is_none(),
                "CI must run the live view test: {why}"
            );
            println!("SKIPPED: {why}");
            return None;
        }
    };
    let dir = tempfile::tempdir().unwrap();
    let cfg = demo_cell(dir.path(), PROGRAM);
    let port = free_port();
    let json = dir.path().join("summary.json");
    let cell = Command::new(env!("CARGO_BIN_EXE_cellrt"))
        .arg("run")
        .arg(&cfg)
        .args(["--live", &format!("127.0.0.1:{port}"), "--summary-json"])
        .arg(&json)
        .arg("--record")
        .arg(dir.path().join("run.mcap"))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let end = Instant::now() + Duration::from_secs(30);
    while std::net::TcpStream::connect(("127.0.0.1", port)).is_err() {
        assert!(Instant::now() < end, "the live view did not listen");
        std::thread::sleep(Duration::from_millis(20));
    }
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/python/live_view.py");
    let clients: Vec<_> = viewers
        .iter()
        .map(|args| {
            Command::new(&python)
                .arg(script)
                .arg(format!("ws://127.0.0.1:{port}"))
                .args(*args)
                .output()
        })
        .collect();
    let out = cell.wait_with_output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let results = clients
        .into_iter()
        .map(|c| {
            let c = c.unwrap();
            assert!(
                c.status.success(),
                "viewer: {}",
                String::from_utf8_lossy(&c.stderr)
            );
            serde_json::from_slice(&c.stdout).unwrap()
        })
        .collect();
    let summary = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    Some((results, summary))
}

#[test]
fn a_foxglove_client_decodes_the_live_cycle_and_axis_messages() {
    let Some((viewers, summary)) = run_with_viewers(&[&["2"]]) else {
        return;
    };
    let v = &viewers[0];
    for topic in ["/cell/cycle", "/cell/events", "/axis/x", "/axis/c"] {
        assert!(
            v["topics"].as_array().unwrap().iter().any(|t| t == topic),
            "{v}"
        );
    }
    assert!(v["cycles"].as_u64().unwrap() > 500, "{v}");
    assert_eq!(v["increasing"], true, "{v}");
    assert!(v["positions"].as_u64().unwrap() > 500, "{v}");
    assert!(v["max_position"].as_f64().unwrap() > 50.0, "{v}");
    assert_eq!(summary["outcome"], "program_completed");
}

#[test]
fn a_stuck_viewer_slows_neither_the_cell_nor_the_recording() {
    // The viewer reads 100 cycles, then stops reading for 4 s.
    let Some((viewers, summary)) = run_with_viewers(&[&["8", "--stall", "4"]]) else {
        return;
    };
    assert_eq!(summary["outcome"], "program_completed", "{summary}");
    assert_eq!(summary["dropped_records"], 0, "{summary}");
    let cycles = summary["cycles"].as_u64().unwrap();
    assert_eq!(
        summary["recording"]["axis_messages"].as_u64(),
        Some(4 * cycles)
    );
    assert!(
        summary["live"]["messages_sent"].as_u64().unwrap() > 4 * cycles,
        "{summary}"
    );
    let v = &viewers[0];
    assert_eq!(v["increasing"], true, "{v}");
    assert!(v["cycles"].as_u64().unwrap() > 100, "{v}");
}
