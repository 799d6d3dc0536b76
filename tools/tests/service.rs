//! `cellrt run` as a systemd service: the notification protocol (`sd_notify(3)`) against a
//! socket the test owns, and the capability path as `nobody` with file capabilities on a copy
//! of the binary (root only; says SKIPPED otherwise). No systemd runs here, so the unit file's
//! settings are exercised piece by piece.

mod common;

use std::os::unix::net::UnixDatagram;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

/// Runs the demo cell without a program for `seconds` with `env`, collecting every datagram
/// sent to a notification socket in `dir`; returns them and the process' stderr.
fn run_notified(dir: &Path, seconds: &str, env: &[(&str, &str)]) -> (Vec<String>, String) {
    let cfg = common::demo_cell(dir, "");
    let socket_path = dir.join("notify");
    let socket = UnixDatagram::bind(&socket_path).unwrap();
    socket
        .set_read_timeout(Some(Duration::from_millis(50)))
        .unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_cellrt"))
        .args(["run", cfg.to_str().unwrap(), "--no-program", "--no-record"])
        .args(["--duration", seconds])
        .env("NOTIFY_SOCKET", &socket_path)
        .envs(env.iter().copied())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut messages = Vec::new();
    let mut buf = [0u8; 4096];
    loop {
        if let Ok(n) = socket.recv(&mut buf) {
            messages.push(String::from_utf8_lossy(&buf[..n]).into_owned());
        } else if child.try_wait().unwrap().is_some() {
            // The last datagrams may still be queued.
            while let Ok(n) = socket.recv(&mut buf) {
                messages.push(String::from_utf8_lossy(&buf[..n]).into_owned());
            }
            break;
        }
    }
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{stderr}");
    (messages, stderr)
}

#[test]
fn ready_then_watchdog_while_the_loop_runs_then_stopping() {
    let dir = tempfile::tempdir().unwrap();
    // WatchdogSec=400ms: fed every 200 ms over a 2 s run.
    let (m, stderr) = run_notified(dir.path(), "2", &[("WATCHDOG_USEC", "400000")]);
    assert!(
        m.first().is_some_and(|f| f.contains("READY=1\n")
            && f.contains("STATUS=cell '")
            && f.contains("running; RT thread")),
        "{m:?}"
    );
    assert_eq!(m.last().map(String::as_str), Some("STOPPING=1\n"), "{m:?}");
    let feeds = m.iter().filter(|x| *x == "WATCHDOG=1\n").count();
    // Twice per timeout while the RT loop's cycles advance: about 10 in 2 s; a loaded machine
    // delays the host thread, never the count below 2.
    assert!((2..=11).contains(&feeds), "{feeds} feeds: {m:?}");
    assert_eq!(
        m.len(),
        feeds + 2,
        "nothing but READY, feeds and STOPPING: {m:?}"
    );
    assert!(
        stderr.contains("systemd watchdog fed every 200ms"),
        "{stderr}"
    );
}

#[test]
fn a_watchdog_meant_for_another_process_is_not_fed() {
    let dir = tempfile::tempdir().unwrap();
    let (m, stderr) = run_notified(
        dir.path(),
        "0.5",
        &[("WATCHDOG_USEC", "100000"), ("WATCHDOG_PID", "1")],
    );
    assert!(m.iter().all(|x| x != "WATCHDOG=1\n"), "{m:?}");
    assert!(m.first().is_some_and(|f| f.contains("READY=1")), "{m:?}");
    assert!(!stderr.contains("watchdog fed"), "{stderr}");
}

#[test]
fn nobody_with_file_capabilities_gets_sched_fifo_and_locked_memory() {
    if !nix::unistd::geteuid().is_root() {
        eprintln!("SKIPPED: needs root (setcap on a copy of the binary, setpriv to nobody)");
        return;
    }
    for tool in ["setcap", "setpriv"] {
        if Command::new(tool).arg("--help").output().is_err() {
            eprintln!("SKIPPED: {tool} is missing (apt install libcap2-bin util-linux)");
            return;
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cfg = common::demo_cell(d, "");
    let exe = d.join("cellrt");
    std::fs::copy(env!("CARGO_BIN_EXE_cellrt"), &exe).unwrap();
    let caps = "cap_sys_nice,cap_ipc_lock,cap_net_raw+ep";
    let set = Command::new("setcap").arg(caps).arg(&exe).output().unwrap();
    assert!(
        set.status.success(),
        "{}",
        String::from_utf8_lossy(&set.stderr)
    );
    Command::new("chmod")
        .arg("-R")
        .arg("a+rwX")
        .arg(d)
        .status()
        .unwrap();
    let summary = d.join("summary.json");
    let out = Command::new("setpriv")
        .args(["--reuid=65534", "--regid=65534", "--clear-groups"])
        .arg(&exe)
        .args(["run", cfg.to_str().unwrap(), "--no-program", "--no-record"])
        .args([
            "--duration",
            "0.5",
            "--summary-json",
            summary.to_str().unwrap(),
        ])
        .env("HOME", d)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
    assert_eq!(s["privileges"]["uid"], 65534, "{s}");
    assert_eq!(s["privileges"]["missing"], serde_json::json!([]), "{s}");
    assert_eq!(s["rt"]["policy"], "SCHED_FIFO", "{s}");
    assert_eq!(s["rt"]["memory_locked"], true, "{s}");
    assert!(
        stderr.contains("privileges: uid 65534 with CAP_NET_RAW"),
        "{stderr}"
    );
    // /dev/cpu_dma_latency is root's (mode 0600) whatever the capabilities: the README's
    // deployment section gives the udev rule that opens it to the service's group.
    assert!(
        !stderr
            .lines()
            .any(|l| l.contains("refused") && !l.contains("/dev/cpu_dma_latency")),
        "no privilege but cpu_dma_latency refused: {stderr}"
    );
}

/// The datagrams tracing-journald sent to a journal socket the test owns, from a demo run
/// with `CELLRT_LOG=debug` and stderr as the journal stream: the run sees the test's socket
/// at `/run/systemd/journal/socket` through a private mount namespace.
fn journal_of_a_run(dir: &Path) -> Vec<Vec<u8>> {
    let cfg = common::demo_cell(dir, "");
    let journal = dir.join("journal");
    std::fs::create_dir(&journal).unwrap();
    let socket = UnixDatagram::bind(journal.join("socket")).unwrap();
    socket
        .set_read_timeout(Some(Duration::from_millis(50)))
        .unwrap();
    let stderr_file = std::fs::File::create(dir.join("stderr")).unwrap();
    let meta = stderr_file.metadata().unwrap();
    use std::os::unix::fs::MetadataExt;
    let stream = format!("{}:{}", meta.dev(), meta.ino());
    let script = format!(
        "mount -t tmpfs tmpfs /run/systemd && mkdir /run/systemd/journal && \
         mount --bind {} /run/systemd/journal && exec {} run {} --no-program --no-record \
         --duration 0.5",
        journal.display(),
        env!("CARGO_BIN_EXE_cellrt"),
        cfg.display()
    );
    let mut child = Command::new("unshare")
        .args(["--mount", "--propagation", "private", "sh", "-c", &script])
        .env("JOURNAL_STREAM", &stream)
        .env("CELLRT_LOG", "debug")
        .stdout(Stdio::null())
        .stderr(stderr_file)
        .spawn()
        .unwrap();
    let mut entries = Vec::new();
    let mut buf = vec![0u8; 65536];
    loop {
        if let Ok(n) = socket.recv(&mut buf) {
            entries.push(buf[..n].to_vec());
        } else if child.try_wait().unwrap().is_some() {
            while let Ok(n) = socket.recv(&mut buf) {
                entries.push(buf[..n].to_vec());
            }
            break;
        }
    }
    let status = child.wait().unwrap();
    let stderr = std::fs::read_to_string(dir.join("stderr")).unwrap();
    assert!(status.success(), "{stderr}");
    entries
}

/// The fields of one entry of the journal's native protocol: `KEY=value` lines, or `KEY`, a
/// 64-bit little-endian length and the value for values that may hold newlines.
fn fields(entry: &[u8]) -> std::collections::BTreeMap<String, String> {
    let mut out = std::collections::BTreeMap::new();
    let mut rest = entry;
    while let Some(nl) = rest.iter().position(|&b| b == b'\n') {
        let line = &rest[..nl];
        if let Some(eq) = line.iter().position(|&b| b == b'=') {
            let key = String::from_utf8_lossy(&line[..eq]).into_owned();
            out.insert(key, String::from_utf8_lossy(&line[eq + 1..]).into_owned());
            rest = &rest[nl + 1..];
        } else {
            let key = String::from_utf8_lossy(line).into_owned();
            let len = u64::from_le_bytes(rest[nl + 1..nl + 9].try_into().unwrap()) as usize;
            let value = &rest[nl + 9..nl + 9 + len];
            out.insert(key, String::from_utf8_lossy(value).into_owned());
            rest = &rest[nl + 9 + len + 1..];
        }
    }
    out
}

#[test]
fn the_journal_gets_priority_cell_and_axis_fields() {
    if !nix::unistd::geteuid().is_root() || Command::new("unshare").arg("--help").output().is_err()
    {
        eprintln!(
            "SKIPPED: needs root and unshare (a private mount namespace for the journal socket)"
        );
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let entries: Vec<_> = journal_of_a_run(dir.path())
        .iter()
        .map(|e| fields(e))
        .collect();
    let privileges = entries
        .iter()
        .find(|e| {
            e.get("MESSAGE")
                .is_some_and(|m| m.starts_with("privileges: root"))
        })
        .unwrap_or_else(|| panic!("no privileges line: {entries:?}"));
    // tracing-journald's mapping: INFO is notice (5), DEBUG informational (6).
    assert_eq!(privileges["PRIORITY"], "5", "{privileges:?}");
    assert_eq!(privileges["SYSLOG_IDENTIFIER"], "cellrt", "{privileges:?}");
    assert!(privileges["CELL"].starts_with('t'), "{privileges:?}");
    // The first cycle's FSA state of each axis: a debug event with its fields.
    let fsa = entries
        .iter()
        .find(|e| {
            e.get("EVENT").is_some_and(|v| v == "fsa_state")
                && e.get("AXIS").is_some_and(|v| v == "x")
        })
        .unwrap_or_else(|| panic!("no fsa_state event of x: {entries:?}"));
    assert_eq!(fsa["PRIORITY"], "6", "{fsa:?}");
    assert_eq!(fsa["CELL"], privileges["CELL"]);
    assert!(
        fsa["MESSAGE"].starts_with(&format!("cycle {}: fsa_state [x]", fsa["CYCLE"])),
        "{fsa:?}"
    );
}

#[test]
fn the_shipped_unit_file_is_one_systemd_accepts() {
    let unit = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../deploy/systemd/cellrt@.service"
    ))
    .unwrap();
    assert!(unit.contains("\nType=notify\n") && unit.contains("\nWatchdogSec="));
    // The capabilities it grants are the ones the summary reports on, no more.
    let ambient = unit
        .lines()
        .find_map(|l| l.strip_prefix("AmbientCapabilities="))
        .unwrap();
    let mut granted: Vec<&str> = ambient.split_whitespace().collect();
    granted.sort_unstable();
    assert_eq!(granted, ["CAP_IPC_LOCK", "CAP_NET_RAW", "CAP_SYS_NICE"]);
    let Ok(probe) = Command::new("systemd-analyze").arg("--version").output() else {
        eprintln!("SKIPPED: systemd-analyze is missing; the unit's syntax went unchecked");
        return;
    };
    assert!(probe.status.success());
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cellrt@t.service");
    let local = unit.replace("/usr/local/bin/cellrt", env!("CARGO_BIN_EXE_cellrt"));
    std::fs::write(&path, local).unwrap();
    let out = Command::new("systemd-analyze")
        .arg("verify")
        .arg(&path)
        .current_dir(dir.path())
        .output()
        .unwrap();
    let said =
        String::from_utf8_lossy(&out.stderr).into_owned() + &String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && said.trim().is_empty(), "{said}");
}
