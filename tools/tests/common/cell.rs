//! A running cell for end-to-end tests of the operator interface: `cellrt run --no-program`
//! driven through the CLI, stopped by SIGINT at [`Cell::end`] or when dropped.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use cellrt_runtime::host::operator::wire::StatusReport;

/// A cell run by `cellrt run --no-program` for a test, commanded through the CLI.
pub struct Cell {
    /// The cell's name.
    pub name: String,
    /// The controller process, until [`Cell::end`] reaped it.
    child: Option<Child>,
}

impl Cell {
    pub fn start(cfg: &Path, rec: &Path) -> Cell {
        let text = without_overrun_watchdog(std::fs::read_to_string(cfg).unwrap());
        std::fs::write(cfg, &text).unwrap();
        let name = text
            .lines()
            .find_map(|l| l.strip_prefix("name = \""))
            .and_then(|l| l.strip_suffix('"'))
            .expect("cell name")
            .to_string();
        let record = [std::ffi::OsStr::new("--record"), rec.as_os_str()];
        Cell::spawn(name, cfg, &record, &["status"])
    }

    /// Starts `config` (a file in configs/ whose cell is `old_name`) in `dir` under a unique
    /// name, without CPU pinning, the overrun watchdog or a recording, with `extra` arguments
    /// and `toml` appended to the configuration; returns once `ready` (a CLI command on the
    /// cell) succeeds.
    pub fn shipped(
        dir: &Path,
        config: &str,
        old_name: &str,
        extra: &[&str],
        toml: &str,
        ready: &[&str],
    ) -> Cell {
        let configs = concat!(env!("CARGO_MANIFEST_DIR"), "/../configs");
        let name = super::unique_cell_name();
        let text = std::fs::read_to_string(format!("{configs}/{config}"))
            .unwrap()
            .replace(
                &format!("name = \"{old_name}\""),
                &format!("name = \"{name}\""),
            )
            .replace("cpu = 1", "# cpu = 1")
            .replace("esi = \"esi/", &format!("esi = \"{configs}/esi/"))
            .replace(
                "max_consecutive_overruns = 100",
                "max_consecutive_overruns = 0",
            );
        let text = without_overrun_watchdog(text);
        assert!(text.contains(&name));
        let cfg = dir.join(config);
        std::fs::write(&cfg, format!("{text}\n{toml}")).unwrap();
        let args: Vec<&std::ffi::OsStr> = std::iter::once("--no-record")
            .chain(extra.iter().copied())
            .map(std::ffi::OsStr::new)
            .collect();
        Cell::spawn(name, &cfg, &args, ready)
    }

    /// Runs `cellrt run CFG --no-program --duration 120 ARGS` and waits until `ready` succeeds.
    fn spawn(name: String, cfg: &Path, args: &[&std::ffi::OsStr], ready: &[&str]) -> Cell {
        let child = Command::new(env!("CARGO_BIN_EXE_cellrt"))
            .arg("run")
            .arg(cfg)
            .args(["--no-program", "--duration", "120"])
            .args(args)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let cell = Cell {
            name,
            child: Some(child),
        };
        let end = Instant::now() + Duration::from_secs(30);
        while cell.cli(ready).0 != 0 {
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

    /// The output of a successful `cellrt ARGS`, trimmed.
    pub fn out(&self, args: &[&str]) -> String {
        self.ok(args).trim().to_string()
    }

    /// Expects a rejection (exit 3) whose reason contains `why`; returns it.
    pub fn rejected(&self, args: &[&str], why: &str) -> String {
        let (code, out, err) = self.cli(args);
        assert_eq!(code, 3, "cellrt {args:?} should be rejected: {out}{err}");
        assert!(err.contains(why), "cellrt {args:?}: '{err}' lacks '{why}'");
        err
    }

    /// Expects a rejection in one line (exit 3) containing `why`; returns it.
    pub fn refused(&self, args: &[&str], why: &str) -> String {
        let err = self.rejected(args, why);
        assert_eq!(err.trim().lines().count(), 1, "one line: {err}");
        err
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

    /// Stops the cell by SIGINT; its controller must exit cleanly.
    pub fn end(mut self) {
        let mut child = self.child.take().expect("running");
        interrupt(&child);
        let status = child.wait().unwrap();
        assert!(status.success(), "controller exit: {status:?}");
    }
}

/// `text` with the overrun watchdog off where it does not set it: the operator interface is
/// under test, not the machine's load (a stall of the VM of a few ms would stop the cell), as
/// `common::demo_cell` does.
fn without_overrun_watchdog(text: String) -> String {
    if text.contains("max_consecutive_overruns") {
        text
    } else if text.contains("[watchdogs]") {
        text.replacen(
            "[watchdogs]",
            "[watchdogs]\nmax_consecutive_overruns = 0",
            1,
        )
    } else {
        format!("{text}\n[watchdogs]\nmax_consecutive_overruns = 0\n")
    }
}

/// SIGINT to the (unreaped) controller.
fn interrupt(child: &Child) {
    let _ = nix::sys::signal::kill(
        nix::unistd::Pid::from_raw(child.id() as i32),
        nix::sys::signal::Signal::SIGINT,
    );
}

impl Drop for Cell {
    fn drop(&mut self) {
        if let Some(mut child) = self.child.take() {
            interrupt(&child);
            let _ = child.wait();
        }
    }
}
