//! `cellrt bus diag` on a running cell: configs/ethercat-cell.toml on the in-process emulated
//! segment with 20 frames corrupted on the link in front of the third SubDevice (axis z). The
//! reading shows the errors on that SubDevice's port 0 and nowhere else as invalid frames, the
//! forwarded errors behind it and on the way back, and the 20 frames the master lost (cyclic
//! or the mailbox worker's); a cell on simulated drives is refused.

mod common;

use std::path::Path;
use std::time::{Duration, Instant};

/// A shipped configuration running for `cellrt bus diag`.
struct Cell(common::cell::Cell);

impl Cell {
    /// `config` under a unique name, with `append` added to its text, on the in-process bus
    /// for EtherCAT configs.
    fn start(dir: &Path, config: &str, old_name: &str, append: &str, extra: &[&str]) -> Cell {
        let ready = ["status"];
        Cell(common::cell::Cell::shipped(
            dir, config, old_name, extra, append, &ready,
        ))
    }

    fn diag(&self, args: &[&str]) -> (i32, String, String) {
        let all: Vec<&str> = ["bus", "diag"].iter().chain(args).copied().collect();
        self.0.cli(&all)
    }
}

const CORRUPTION: &str = r#"
[[inject]]
at_ms = 300
fault = "frame_corruption"
axis = "z"
duration_ms = 20
"#;

#[test]
fn bus_diag_shows_the_port_of_the_injected_bit_errors() {
    let dir = tempfile::tempdir().unwrap();
    let cell = Cell::start(
        dir.path(),
        "ethercat-cell.toml",
        "ethercat",
        CORRUPTION,
        &["--interface", "in-process"],
    );
    // Until the fault has run its 20 frames (the cycle counts them, not the wall clock).
    let end = Instant::now() + Duration::from_secs(30);
    let reading = loop {
        let (code, out, err) = cell.diag(&["--interval-ms", "0", "--json"]);
        assert_eq!(code, 0, "{out}{err}");
        let v: serde_json::Value = serde_json::from_str(&out).unwrap();
        let first = v["first"].clone();
        // A reading taken while the corruption ran loses its own frames: the SubDevices
        // they were for show as not answering. Wait for one that reached all four.
        let subs = &first["segment"]["subdevices"];
        let all_answered = (0..4).all(|k| subs[k]["answered"] == true);
        if all_answered && subs[2]["ports"][0]["invalid_frames"] == 20 {
            break first;
        }
        assert!(Instant::now() < end, "the corruption never showed: {out}");
        std::thread::sleep(Duration::from_millis(100));
    };
    let subs = reading["segment"]["subdevices"].as_array().unwrap();
    assert_eq!(subs.len(), 4);
    let port = |k: usize, p: usize, what: &str| subs[k]["ports"][p][what].as_u64().unwrap();
    let invalid: Vec<u64> = (0..4).map(|k| port(k, 0, "invalid_frames")).collect();
    assert_eq!(invalid, [0, 0, 20, 0], "{reading}");
    assert_eq!(port(3, 0, "forwarded_errors"), 20);
    let back: Vec<u64> = (0..4).map(|k| port(k, 1, "forwarded_errors")).collect();
    assert_eq!(back, [20, 20, 20, 0]);
    // Each corrupted frame is lost to the master: a cyclic one, or one of the mailbox worker's
    // when this test's own readings were on the wire at the time.
    let segment = &reading["segment"];
    let lost = segment["frames_lost"].as_u64().unwrap();
    assert_eq!(
        lost + segment["mailbox_frames_lost"].as_u64().unwrap(),
        20,
        "{segment}"
    );
    assert!(subs
        .iter()
        .all(|s| s["answered"] == true && s["ports"][0]["link"] == true));
    assert_eq!(reading["stations"][2]["axes"][0], "z");
    // The table names each SubDevice and its axes.
    let (code, table, err) = cell.diag(&["--interval-ms", "0"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        table.contains("mr-j3-t04") && table.contains("OP"),
        "{table}"
    );
    let z = table
        .lines()
        .find(|l| l.contains(" z "))
        .expect("a line for z");
    assert!(z.contains(" 20 "), "{table}");
}

#[test]
fn bus_diag_is_refused_on_simulated_drives() {
    let dir = tempfile::tempdir().unwrap();
    let cell = Cell::start(dir.path(), "demo.toml", "demo", "", &[]);
    let (code, out, err) = cell.diag(&["--interval-ms", "0"]);
    assert_eq!(code, 3, "{out}{err}");
    assert!(err.contains("no EtherCAT segment"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
}
