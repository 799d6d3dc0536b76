//! Triggered capture (`[recording] mode = "triggered"`): no continuous recording, one complete
//! MCAP file around each trigger — an event kind, an axis threshold, or `cellrt capture` — with
//! `pre_s` before and `post_s` after, judged in cycles of the cell's clock.

mod common;

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use common::{cellrt_on_cell, demo_cell, read_recording, run_recorded};

const MOVE: &str = r#"
[[step]]
do = "power_on"
[[step]]
do = "move"
target = { x = 300.0 }
[[step]]
do = "wait"
seconds = 0.5
"#;

/// The demo cell with triggered recording (`pre_s` 0.5, `post_s` 0.3) and `extra` appended.
fn triggered(dir: &Path, triggers: &str, extra: &str) -> String {
    let cfg = std::fs::read_to_string(demo_cell(dir, MOVE)).unwrap();
    cfg.replacen(
        "[recording]\n",
        &format!("[recording]\nmode = \"triggered\"\npre_s = 0.5\npost_s = 0.3\ntriggers = [{triggers}]\n"),
        1,
    ) + extra
}

fn capture(rec: &Path, n: u32) -> PathBuf {
    rec.with_file_name(format!("run-capture-{n}.mcap"))
}

/// The `cellrt.capture` metadata of a capture file.
fn capture_metadata(path: &Path) -> std::collections::BTreeMap<String, String> {
    let bytes = std::fs::read(path).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().expect("a summary");
    for idx in &summary.metadata_indexes {
        let m = mcap::read::metadata(&bytes, idx).unwrap();
        if m.name == "cellrt.capture" {
            return m.metadata;
        }
    }
    panic!("no cellrt.capture metadata in {}", path.display());
}

/// A cell run by `cellrt run --no-program` with `cfg_text`, recording (triggered) to
/// `dir/run.mcap`; stopped by SIGINT on drop.
struct Running {
    name: String,
    rec: PathBuf,
    child: std::process::Child,
}

impl Running {
    fn start(dir: &Path, cfg_text: &str) -> Running {
        let name = common::cell_name_of(cfg_text);
        let cfg = dir.join("cell.toml");
        std::fs::write(&cfg, cfg_text).unwrap();
        let rec = dir.join("run.mcap");
        let child = std::process::Command::new(env!("CARGO_BIN_EXE_cellrt"))
            .arg("run")
            .arg(&cfg)
            .args(["--no-program", "--duration", "60", "--record"])
            .arg(&rec)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        let end = Instant::now() + Duration::from_secs(30);
        while cellrt_on_cell(&name, &["status"]).0 != 0 {
            assert!(Instant::now() < end, "the cell did not come up");
            std::thread::sleep(Duration::from_millis(100));
        }
        Running { name, rec, child }
    }

    /// Capture `n` once finished (its summary written).
    fn finished_capture(&self, n: u32) -> PathBuf {
        let file = capture(&self.rec, n);
        let end = Instant::now() + Duration::from_secs(30);
        while !file.exists()
            || mcap::Summary::read(&std::fs::read(&file).unwrap())
                .ok()
                .flatten()
                .is_none()
        {
            assert!(Instant::now() < end, "no finished capture {n}");
            std::thread::sleep(Duration::from_millis(100));
        }
        file
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        let _ = nix::sys::signal::kill(
            nix::unistd::Pid::from_raw(self.child.id() as i32),
            nix::sys::signal::Signal::SIGINT,
        );
        let _ = self.child.wait();
    }
}

#[test]
fn a_drive_fault_writes_one_capture_around_it() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = triggered(
        dir.path(),
        "\"drive_fault\"",
        "\n[[inject]]\nat_ms = 1500\nfault = \"drive_alarm\"\naxis = \"y\"\ncode = 0x2220\n",
    );
    let cell = Running::start(dir.path(), &cfg);
    let file = cell.finished_capture(1);
    assert!(
        !cell.rec.exists(),
        "no continuous recording in triggered mode"
    );
    let r = read_recording(&file);
    assert!(r.indexed);
    let fault = r
        .events
        .iter()
        .find(|e| e.kind == "drive_fault")
        .expect("the trigger's event is in the capture");
    let first = r.cycles.first().unwrap().cycle;
    let last = r.cycles.last().unwrap().cycle;
    // 0.5 s before (500 cycles at 1 ms; the capture opens at the cycle after the recorder
    // read the event) and 0.3 s after.
    let (before, after) = (fault.cycle - first, last - fault.cycle);
    assert!(
        (490..=700).contains(&before),
        "{first} {} {last}",
        fault.cycle
    );
    assert!(
        (290..=420).contains(&after),
        "{first} {} {last}",
        fault.cycle
    );
    // Every cycle in between (an overrun skips cycle numbers: the cycle records count).
    let cycles: Vec<u64> = r.cycles.iter().map(|c| c.cycle).collect();
    let xs: Vec<u64> = r.axes["x"].iter().map(|a| a.cycle).collect();
    assert_eq!(xs, cycles);
    let m = capture_metadata(&file);
    assert!(m["trigger_0"].contains("drive_fault"), "{m:?}");
    assert_eq!(m["pre_s"], "0.5");
    std::thread::sleep(Duration::from_millis(500));
    assert!(!capture(&cell.rec, 2).exists(), "one trigger, one capture");
}

#[test]
fn a_threshold_on_an_axis_triggers_where_it_is_crossed() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = triggered(dir.path(), "\"/axis/x.actual_position > 200\"", "");
    let (out, rec) = run_recorded(dir.path(), &cfg, MOVE);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r = read_recording(&capture(&rec, 1));
    let x = &r.axes["x"];
    let crossing = x
        .iter()
        .position(|a| a.actual_position > 200.0)
        .expect("crossed");
    assert!(
        crossing >= 450,
        "about 0.5 s of history before the crossing: {crossing}"
    );
    assert!(x[..crossing].iter().all(|a| a.actual_position <= 200.0));
    assert!(
        !capture(&rec, 2).exists(),
        "above the threshold while the capture is open: one file"
    );
    assert!(capture_metadata(&capture(&rec, 1))["trigger_0"].contains("actual_position"));
}

#[test]
fn cellrt_capture_writes_the_ring_on_demand_and_is_refused_without_one() {
    let dir = tempfile::tempdir().unwrap();
    let cell = Running::start(dir.path(), &triggered(dir.path(), "", ""));
    std::thread::sleep(Duration::from_millis(800));
    let (code, out, err) = cellrt_on_cell(&cell.name, &["capture"]);
    assert_eq!(code, 0, "{out}{err}");
    let file = cell.finished_capture(1);
    let n = read_recording(&file).cycles.len();
    assert!((700..=900).contains(&n), "about 0.8 s of cycles: {n}");
    assert!(capture_metadata(&file)["trigger_0"].contains("operator request"));
    drop(cell);

    // A cell recording continuously has no ring.
    let dir = tempfile::tempdir().unwrap();
    let cell = common::cell::Cell::start(&demo_cell(dir.path(), MOVE), &dir.path().join("r.mcap"));
    let (code, _, err) = cellrt_on_cell(&cell.name, &["capture"]);
    assert_eq!(code, 3, "{err}");
    assert!(err.contains("no capture ring"), "{err}");
}
