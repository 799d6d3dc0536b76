//! The master-side incremental counter on a drive that has one (MR-J3-T04, 2020h/2021h,
//! MR-J3-T04 manual §8.11.1, §5.1, §8.2.3, §7): the counter runs and is recorded every cycle, and an injected counter
//! corruption is detected as a continuous error that stops the cell with the configured
//! communication reaction.

mod common;

use std::process::Command;

use common::{read_recording, run_recorded, unique_cell_name};

const PROGRAM: &str = r#"
[[step]]
do = "power_on"
[[step]]
do = "move"
target = { x = 300.0, y = 200.0 }
"#;

#[test]
fn counter_corruption_on_mr_j3_t04_stops_the_cell() {
    let dir = tempfile::tempdir().unwrap();
    let base = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../configs/mr-j3-t04.toml"
    ))
    .unwrap();
    let text = base
        .replace(r#"name = "mr-j3-t04""#, &format!(r#"name = "{}""#, unique_cell_name()))
        .replace(r#"program = "mr-j3-t04-program.toml""#, r#"program = "program.toml""#)
        + "\n[setpoints]\nlookahead_ms = 1000\n[watchdogs]\nmax_consecutive_overruns = 0\n\
           [[inject]]\nat_ms = 500\nfault = \"counter_corruption\"\naxis = \"x\"\nduration_ms = 20\n";
    assert!(!text.contains(r#"name = "mr-j3-t04""#));
    let (out, rec_path) = run_recorded(dir.path(), &text, PROGRAM);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    let rec = read_recording(&rec_path);

    // Before the injection the counter advances by one every cycle, and the echo read in cycle
    // k answers the value sent two cycles earlier + 1 (it crosses one exchange, plus the echo
    // lag of 1, the documented default): received(k) = sent(k - 2) + 1 = sent(k - 1).
    let x = &rec.axes["x"];
    let steady: Vec<_> = x.iter().filter(|r| r.cycle > 50 && r.cycle < 450).collect();
    assert!(steady.len() > 300);
    for w in steady.windows(2).filter(|w| w[1].cycle == w[0].cycle + 1) {
        assert_eq!(w[1].counter_sent, (w[0].counter_sent + 1) % 256);
        assert_eq!(w[1].counter_received, w[0].counter_sent);
    }

    let err = rec
        .events
        .iter()
        .find(|e| e.kind == "communication_error")
        .expect("the master detected the counter error");
    assert_eq!(err.axis, "x");
    assert!(err.detail.contains("continuous"), "{}", err.detail);
    assert!(err.cycle >= 500, "not before the injection: {}", err.cycle);
    let stop = rec
        .events
        .iter()
        .find(|e| e.kind == "stop_started")
        .unwrap();
    assert!(
        stop.detail.starts_with("communication") || stop.detail.starts_with("drive_fault"),
        "{}",
        stop.detail
    );

    // The replay re-applies the counter and the injected corruption: bit-identical.
    let replay = Command::new(env!("CARGO_BIN_EXE_cellrt"))
        .arg("replay")
        .arg(&rec_path)
        .output()
        .unwrap();
    assert!(
        replay.status.success(),
        "{}{}",
        String::from_utf8_lossy(&replay.stdout),
        String::from_utf8_lossy(&replay.stderr)
    );
}
