//! The recording's disk failing: a path that cannot be created is refused before the cell
//! starts (exit 2); a disk that fills up while the cell runs stops the recording, not the cell,
//! and the summary says where and why.

mod common;

use std::process::Command;

use common::demo_cell;

#[test]
fn an_unwritable_recording_path_is_refused_before_the_cell_starts() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = demo_cell(dir.path(), "");
    let file = dir.path().join("a-file");
    std::fs::write(&file, "not a directory").unwrap();
    let rec = file.join("run.mcap");
    let o = Command::new(env!("CARGO_BIN_EXE_cellrt"))
        .arg("run")
        .arg(&cfg)
        .args(["--no-program", "--duration", "1", "--record"])
        .arg(&rec)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains(&format!("cannot create recording {}", rec.display())),
        "{err}"
    );
    assert!(!err.contains("RT thread:"), "the cell did not start: {err}");
}

/// A tmpfs of `size` mounted on a temp dir, unmounted on drop.
struct SmallDisk(tempfile::TempDir);

impl SmallDisk {
    fn mount(size: &str) -> Option<SmallDisk> {
        let dir = tempfile::tempdir().unwrap();
        let ok = Command::new("mount")
            .args(["-t", "tmpfs", "-o", &format!("size={size}"), "tmpfs"])
            .arg(dir.path())
            .status()
            .is_ok_and(|s| s.success());
        ok.then_some(SmallDisk(dir))
    }
}

impl Drop for SmallDisk {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(self.0.path()).status();
    }
}

#[test]
fn a_full_recording_disk_stops_the_recording_and_not_the_cell() {
    if !nix::unistd::getuid().is_root() {
        eprintln!("SKIPPED a_full_recording_disk_stops_the_recording_and_not_the_cell: needs root to mount a tmpfs");
        return;
    }
    let Some(disk) = SmallDisk::mount("128k") else {
        eprintln!("SKIPPED a_full_recording_disk_stops_the_recording_and_not_the_cell: cannot mount a tmpfs here");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let cfg = demo_cell(dir.path(), "");
    let rec = disk.0.path().join("run.mcap");
    let json = dir.path().join("summary.json");
    // 4 axes at 1 kHz for 5 s: about 2 MB of records before compression, far over 128 KiB.
    let o = Command::new(env!("CARGO_BIN_EXE_cellrt"))
        .arg("run")
        .arg(&cfg)
        .args(["--no-program", "--duration", "5", "--record"])
        .arg(&rec)
        .arg("--summary-json")
        .arg(&json)
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{out}{err}");
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    // The cell ran its whole duration under control.
    assert_eq!(s["outcome"], "duration_elapsed", "{s}");
    assert_eq!(s["faults"], 0, "{s}");
    let stopped = s["recording"]["stopped"]
        .as_str()
        .expect("the loss is in the summary");
    assert!(
        stopped.starts_with("at cycle ") && stopped.contains("No space left on device"),
        "{stopped}"
    );
    assert!(out.contains("STOPPED at cycle"), "{out}");
    assert_eq!(s["recording"]["files"][0], rec.display().to_string());
    // What was flushed before the disk filled is a recording `cellrt recover` completes.
    let fixed = dir.path().join("fixed.mcap");
    let r = Command::new(env!("CARGO_BIN_EXE_cellrt"))
        .arg("recover")
        .arg(&rec)
        .arg(&fixed)
        .output()
        .unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert!(!common::read_recording(&fixed).cycles.is_empty());
}
