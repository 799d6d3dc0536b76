//! External tools: finding (or, as root, installing) `cyclictest` and `stress-ng`, and a
//! bounded `stress-ng` load that is always stopped.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use crate::error::BenchError;

/// `name` in `$PATH`, if there.
pub fn find_in_path(name: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .chain([PathBuf::from("/usr/sbin"), PathBuf::from("/usr/bin")])
        .map(|d| d.join(name))
        .find(|p| is_executable(p))
}

fn is_executable(p: &Path) -> bool {
    use std::os::unix::fs::PermissionsExt;
    std::fs::metadata(p).is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
}

/// Whether we run as root.
pub fn is_root() -> bool {
    // SAFETY: geteuid has no preconditions.
    unsafe { libc::geteuid() == 0 }
}

/// Finds `binary`; if it is missing and we are root, installs Debian's `package` with
/// `apt-get install -y` (after `apt-get update` if the first attempt fails). Otherwise the error
/// says how to install it.
pub fn ensure_tool(binary: &str, package: &str) -> Result<PathBuf, BenchError> {
    if let Some(p) = find_in_path(binary) {
        return Ok(p);
    }
    if !is_root() {
        return Err(BenchError::failed(format!(
            "{binary} not found: install it with `sudo apt-get install {package}` (Debian/Ubuntu), \
             or run this command as root to let cellrt install it"
        )));
    }
    eprintln!("cellrt: {binary} not found; installing {package} (apt-get install -y {package})");
    let install = || {
        Command::new("apt-get")
            .args(["install", "-y", package])
            .env("DEBIAN_FRONTEND", "noninteractive")
            .stdout(Stdio::null())
            .status()
            .is_ok_and(|s| s.success())
    };
    if !install() {
        eprintln!("cellrt: apt-get install failed; running apt-get update and retrying");
        let _ = Command::new("apt-get")
            .arg("update")
            .stdout(Stdio::null())
            .status();
        if !install() {
            return Err(BenchError::failed(format!(
                "{binary} not found and `apt-get install -y {package}` failed; install {package} by hand"
            )));
        }
    }
    find_in_path(binary).ok_or_else(|| {
        BenchError::failed(format!(
            "{package} was installed but {binary} is still not in PATH"
        ))
    })
}

/// A running `stress-ng`, stopped (SIGTERM, then SIGKILL to its process group) when dropped.
#[derive(Debug)]
pub struct Load {
    child: Option<Child>,
    /// What runs, for the report.
    pub command: String,
}

impl Load {
    /// Starts `stress-ng` for at most `seconds`: one CPU hog per online CPU, one memory
    /// worker, one I/O-syscall worker and one context-switch worker, all SCHED_OTHER; their
    /// scratch files go to `temp_dir`.
    pub fn start(seconds: u64, temp_dir: &Path) -> Result<Load, BenchError> {
        use std::os::unix::process::CommandExt;
        let bin = ensure_tool("stress-ng", "stress-ng")?;
        let timeout = format!("{seconds}s");
        let args = [
            "--cpu",
            "0",
            "--vm",
            "1",
            "--vm-bytes",
            "128M",
            "--iomix",
            "1",
            "--switch",
            "1",
            "--timeout",
            timeout.as_str(),
            "--quiet",
        ];
        let child = Command::new(&bin)
            .args(args)
            .arg("--temp-path")
            .arg(temp_dir)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .process_group(0)
            .spawn()
            .map_err(|e| BenchError::failed(format!("cannot start {}: {e}", bin.display())))?;
        Ok(Load {
            child: Some(child),
            command: format!("stress-ng {}", args.join(" ")),
        })
    }

    /// Stops the load and waits for it.
    pub fn stop(&mut self) {
        let Some(mut child) = self.child.take() else {
            return;
        };
        let pgid = child.id() as i32;
        // SAFETY: signalling the process group we created for this child.
        unsafe { libc::kill(-pgid, libc::SIGTERM) };
        let end = Instant::now() + Duration::from_secs(5);
        while Instant::now() < end {
            if let Ok(Some(_)) = child.try_wait() {
                break;
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        // Workers that outlived their parent, or a parent that ignored SIGTERM.
        // SAFETY: as above.
        unsafe { libc::kill(-pgid, libc::SIGKILL) };
        let _ = child.wait();
        // Wait until the group is empty (orphaned workers are reaped by init).
        let end = Instant::now() + Duration::from_secs(2);
        // SAFETY: signal 0 only checks whether the group still exists.
        while unsafe { libc::kill(-pgid, 0) } == 0 && Instant::now() < end {
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

impl Drop for Load {
    fn drop(&mut self) {
        self.stop();
    }
}
