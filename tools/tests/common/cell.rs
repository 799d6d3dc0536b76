//! A running cell for end-to-end tests of the operator interface: `cellrt run --no-program`
//! driven through the CLI.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use cellrt_runtime::host::operator::wire::StatusReport;

/// A cell run by `cellrt run --no-program` for a test, commanded through the CLI.
pub struct Cell {
    /// The cell's name.
    pub name: String,
    child: Child,
}

impl Cell {
    pub fn start(cfg: &Path, rec: &Path) -> Cell {
        let mut text = std::fs::read_to_string(cfg).unwrap();
        // The operator interface is under test, not the machine's load: no overrun watchdog
        // (a stall of the VM of a few ms would stop the cell), as `common::demo_cell` does.
        if !text.contains("max_consecutive_overruns") {
            text = if text.contains("[watchdogs]") {
                text.replacen(
                    "[watchdogs]",
                    "[watchdogs]\nmax_consecutive_overruns = 0",
                    1,
                )
            } else {
                format!("{text}\n[watchdogs]\nmax_consecutive_overruns = 0\n")
            };
            std::fs::write(cfg, &text).unwrap();
        }
        let name = text
            .lines()
            .find_map(|l| l.strip_prefix("name = \""))
            .and_then(|l| l.strip_suffix('"'))
            .expect("cell name")
            .to_string();
        let child = Command::new(env!("CARGO_BIN_EXE_cellrt"))
            .arg("run")
            .arg(cfg)
            .arg("--no-program")
            .arg("--duration")
            .arg("120")
            .arg("--record")
            .arg(rec)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let cell = Cell { name, child };
        let end = Instant::now() + Duration::from_secs(20);
        while cell.cli(&["status"]).0 != 0 {
            assert!(Instant::now() < end, "the cell did not come up");
            std::thread::sleep(Duration::from_millis(100));
        }
        cell
    }

    /// Runs `cellrt ARGS --cell NAME`; returns exit code, stdout, stderr.
    pub fn cli(&self, args: &[&str]) -> (i32, String, String) {
        super::cellrt_on_cell(&self.name, args)
    }

    pub fn ok(&self, args: &[&str]) -> String {
        let (code, out, err) = self.cli(args);
        assert_eq!(code, 0, "cellrt {args:?}: {out}{err}");
        out
    }

    /// Expects a rejection (exit 3) whose reason contains `why`.
    pub fn rejected(&self, args: &[&str], why: &str) {
        let (code, out, err) = self.cli(args);
        assert_eq!(code, 3, "cellrt {args:?} should be rejected: {out}{err}");
        assert!(err.contains(why), "cellrt {args:?}: '{err}' lacks '{why}'");
    }

    /// `cellrt status --json`'s entry for `axis`.
    pub fn axis_status(&self, axis: &str) -> cellrt_runtime::host::operator::wire::AxisStatus {
        let r: StatusReport = serde_json::from_str(&self.ok(&["status", "--json"])).unwrap();
        r.axes.into_iter().find(|a| a.name == axis).unwrap()
    }

    pub fn wait_state(&self, want: &str) {
        let end = Instant::now() + Duration::from_secs(20);
        loop {
            let s = self.ok(&["status"]);
            if s.contains(&format!("state {want}")) {
                return;
            }
            assert!(Instant::now() < end, "cell never became {want}: {s}");
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    pub fn end(mut self) {
        nix::sys::signal::kill(
            nix::unistd::Pid::from_raw(self.child.id() as i32),
            nix::sys::signal::Signal::SIGINT,
        )
        .unwrap();
        let status = self.child.wait().unwrap();
        assert!(status.success(), "controller exit: {status:?}");
    }
}
