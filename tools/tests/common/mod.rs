//! Helpers shared by the end-to-end tests: run the binary, read a recording back.

#![allow(dead_code)]

pub mod cell;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use cellrt_runtime::host::record::proto::{AxisCycle, CycleStats, Event, JecExchange};
use cellrt_runtime::host::record::topics::{
    AXIS_TOPIC_PREFIX, CYCLE_TOPIC, EVENTS_TOPIC, JE_C_TOPIC_PREFIX,
};
use prost::Message;

/// The demo configuration, rewritten into `dir` with the given program, a unique cell name, a
/// long setpoint lookahead and without CPU pinning (the test machine may have fewer CPUs).
pub fn demo_cell(dir: &Path, program: &str) -> PathBuf {
    let demo =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../configs/demo.toml"))
            .expect("configs/demo.toml");
    let text = demo
        .replace("cpu = 1 ", "# cpu = 1 ")
        .replace(
            r#"program = "demo-program.toml""#,
            r#"program = "program.toml""#,
        )
        .replace(
            r#"name = "demo""#,
            &format!(r#"name = "{}""#, unique_cell_name()),
        )
        // Generous lookahead and no overrun watchdog: a test must not depend on how loaded the
        // machine is (the watchdog tests switch it back on).
        .replace("lookahead_ms = 100", "lookahead_ms = 1000")
        .replace(
            "max_consecutive_overruns = 100",
            "max_consecutive_overruns = 0",
        );
    assert!(!text.contains(r#"name = "demo""#) && text.contains("lookahead_ms = 1000"));
    assert!(text.contains("max_consecutive_overruns = 0"));
    std::fs::write(dir.join("program.toml"), program).unwrap();
    let cfg = dir.join("cell.toml");
    std::fs::write(&cfg, text).unwrap();
    cfg
}

/// Writes `config` and `program` (as `cell.toml` / `program.toml`) into `dir` and runs
/// `cellrt run` on them with a recording; returns the process output and the recording path.
pub fn run_recorded(dir: &Path, config: &str, program: &str) -> (std::process::Output, PathBuf) {
    let cfg = dir.join("cell.toml");
    std::fs::write(&cfg, config).unwrap();
    std::fs::write(dir.join("program.toml"), program).unwrap();
    let rec = dir.join("run.mcap");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_cellrt"))
        .arg("run")
        .arg(&cfg)
        .arg("--record")
        .arg(&rec)
        .output()
        .unwrap();
    (out, rec)
}

/// The `name = "…"` of a cell configuration's text.
pub fn cell_name_of(config: &str) -> String {
    config
        .lines()
        .find_map(|l| l.strip_prefix("name = \""))
        .and_then(|l| l.strip_suffix('"'))
        .expect("a cell name")
        .to_string()
}

/// Runs `cellrt ARGS --cell CELL` (an operator command to a running cell); returns the exit
/// code, stdout and stderr.
pub fn cellrt_on_cell(cell: &str, args: &[&str]) -> (i32, String, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_cellrt"))
        .args(args)
        .arg("--cell")
        .arg(cell)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A cell name no other test or user run shares (services and locks are per cell name).
pub fn unique_cell_name() -> String {
    use std::sync::atomic::{AtomicU32, Ordering};
    static N: AtomicU32 = AtomicU32::new(0);
    format!(
        "t{}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    )
}

/// A recording decoded per topic.
#[derive(Debug, Default)]
pub struct Recording {
    pub cycles: Vec<CycleStats>,
    pub axes: BTreeMap<String, Vec<AxisCycle>>,
    pub events: Vec<Event>,
    /// The MR-JE-C axes' exchanges, per axis.
    pub je_c: BTreeMap<String, Vec<JecExchange>>,
    /// Whether the file has a summary section with chunk indexes.
    pub indexed: bool,
    /// Message counts from the summary's statistics, per topic.
    pub summary_counts: BTreeMap<String, u64>,
}

/// Reads and decodes a recording with the mcap crate.
pub fn read_recording(path: &Path) -> Recording {
    let bytes = std::fs::read(path).expect("recording exists");
    let mut rec = Recording::default();
    for msg in mcap::MessageStream::new(&bytes).expect("valid mcap") {
        let msg = msg.expect("readable message");
        let topic = msg.channel.topic.as_str();
        let schema = msg.channel.schema.as_ref().expect("channel has a schema");
        assert_eq!(schema.encoding, "protobuf");
        assert_eq!(msg.channel.message_encoding, "protobuf");
        if topic == CYCLE_TOPIC {
            rec.cycles
                .push(CycleStats::decode(&*msg.data).expect("CycleStats"));
        } else if topic == EVENTS_TOPIC {
            rec.events.push(Event::decode(&*msg.data).expect("Event"));
        } else if let Some(axis) = topic.strip_prefix(AXIS_TOPIC_PREFIX) {
            rec.axes
                .entry(axis.to_string())
                .or_default()
                .push(AxisCycle::decode(&*msg.data).expect("AxisCycle"));
        } else if let Some(axis) = topic.strip_prefix(JE_C_TOPIC_PREFIX) {
            rec.je_c
                .entry(axis.to_string())
                .or_default()
                .push(JecExchange::decode(&*msg.data).expect("JecExchange"));
        } else {
            panic!("unexpected topic {topic}");
        }
    }
    if let Ok(Some(summary)) = mcap::Summary::read(&bytes) {
        rec.indexed = !summary.chunk_indexes.is_empty();
        if let Some(stats) = &summary.stats {
            for (id, count) in &stats.channel_message_counts {
                if let Some(ch) = summary.channels.get(id) {
                    rec.summary_counts.insert(ch.topic.clone(), *count);
                }
            }
        }
    }
    rec
}

/// Largest |finite difference| of order 1..=3 of `p` over runs of consecutive cycles, per
/// second, second² and second³.
pub fn max_derivatives(samples: &[(u64, f64)], dt: f64) -> (f64, f64, f64) {
    let (mut v, mut a, mut j) = (0.0f64, 0.0f64, 0.0f64);
    for w in samples.windows(4) {
        let consecutive = w.windows(2).all(|p| p[1].0 == p[0].0 + 1);
        if !consecutive {
            continue;
        }
        let p: Vec<f64> = w.iter().map(|s| s.1).collect();
        v = v.max(((p[1] - p[0]) / dt).abs());
        a = a.max(((p[2] - 2.0 * p[1] + p[0]) / (dt * dt)).abs());
        j = j.max(((p[3] - 3.0 * p[2] + 3.0 * p[1] - p[0]) / (dt * dt * dt)).abs());
    }
    (v, a, j)
}

/// Starts `cellrt drive-sim ethercat` with the drives of `cfg` on the far end of `ns`, gaps in
/// the master's frames excused as stalls of this machine (`--excuse-host-stalls`, for cells
/// with `rt.missed_deadlines = "stretch"`), and waits until it serves; returns the process and
/// the rest of its stderr, line by line.
pub fn spawn_drive_sim(
    ns: &cellrt_rt_tests::netns::VethNamespace,
    cfg: &Path,
) -> (
    std::process::Child,
    std::io::Lines<std::io::BufReader<std::process::ChildStderr>>,
) {
    spawn_drive_sim_with(
        ns,
        &[
            "--cell".as_ref(),
            cfg.as_os_str(),
            "--excuse-host-stalls".as_ref(),
        ],
    )
}

/// Starts `cellrt drive-sim ethercat` with `drives` (its arguments besides the interface) on
/// the far end of `ns` and waits until it serves; returns the process and the rest of its
/// stderr, line by line.
pub fn spawn_drive_sim_with(
    ns: &cellrt_rt_tests::netns::VethNamespace,
    drives: &[&std::ffi::OsStr],
) -> (
    std::process::Child,
    std::io::Lines<std::io::BufReader<std::process::ChildStderr>>,
) {
    use std::io::BufRead;
    let mut child = ns
        .command(Path::new(env!("CARGO_BIN_EXE_cellrt")))
        .args(["drive-sim", "ethercat", "--interface", &ns.far])
        .args(drives)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("start cellrt drive-sim in the namespace");
    let mut lines = std::io::BufReader::new(child.stderr.take().unwrap()).lines();
    let ready = lines
        .by_ref()
        .map_while(Result::ok)
        .find(|l| l.contains("EtherCAT SubDevice(s) on"));
    assert!(ready.is_some(), "cellrt drive-sim did not start");
    (child, lines)
}
