//! `cellrt run configs/mixed-cell.toml` (EtherCAT csp axes and two emulated MR-JE-C conveyors)
//! as a user runs it: the start line and the summary name the MR-JE-C axes and their links,
//! and `cellrt replay` of its recording says plainly that they are left out of the
//! bit-identical check while the csp axes replay bit-identical; `cellrt status` of the running
//! cell lists them with their links; the operator powers, moves, jogs, halts and resets them
//! beside the csp axes, with each bad request refused naming the axis and what is wrong; on the
//! shipped positioning cell the operator runs point tables and stations.

mod common;

use std::process::Command;

use common::{cellrt_on_cell, read_recording, run_recorded, unique_cell_name};

const CONFIGS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../configs");

/// The shipped mixed cell named `name`.
fn mixed_cell(name: &str) -> String {
    std::fs::read_to_string(format!("{CONFIGS}/mixed-cell.toml"))
        .unwrap()
        .replace(r#"name = "mixed""#, &format!(r#"name = "{name}""#))
}

/// `text` for [`run_recorded`]: its program as `program.toml`, the overrun watchdog off and a
/// long lookahead (the program's logic is under test, not the machine's load).
fn for_run_recorded(text: &str) -> String {
    text.replace(
        r#"program = "mixed-cell-program.toml""#,
        r#"program = "program.toml""#,
    )
    .replace(
        "max_consecutive_overruns = 100",
        "max_consecutive_overruns = 0",
    ) + "\n[setpoints]\nlookahead_ms = 1000\n"
}

#[test]
fn status_lists_the_je_c_axes_and_their_links() {
    let cell = RunningCell::start();
    let (code, status, err) = cell.cli(&["status"]);
    assert_eq!(code, 0, "{err}");
    assert!(status.contains("exchanges"), "{status}");
    for (axis, transport) in [("infeed", "cclink-ief-basic"), ("outfeed", "modbus-tcp")] {
        let line = status
            .lines()
            .find(|l| l.starts_with(axis))
            .unwrap_or_else(|| panic!("{status}"));
        assert!(
            line.contains(" pp ") && line.contains(&format!("mr-je-c link over {transport},")),
            "{line}"
        );
        assert!(
            line.contains("switch_on_disabled"),
            "not powered yet: {line}"
        );
    }
}

/// The running mixed cell (no program), named `name`, for operator commands; killed on drop.
struct RunningCell {
    child: std::process::Child,
    name: String,
    _dir: tempfile::TempDir,
}

impl RunningCell {
    fn start() -> RunningCell {
        RunningCell::start_shipped("mixed-cell", "mixed")
    }

    /// The shipped cell `configs/CONFIG.toml` (two MR-JE-C axes), named `cell` there, running
    /// under a name of its own without a program.
    fn start_shipped(config: &str, cell: &str) -> RunningCell {
        let dir = tempfile::tempdir().unwrap();
        let name = unique_cell_name();
        let cfg = dir.path().join("cell.toml");
        let text = std::fs::read_to_string(format!("{CONFIGS}/{config}.toml"))
            .unwrap()
            .replace(
                &format!(r#"name = "{cell}""#),
                &format!(r#"name = "{name}""#),
            );
        std::fs::write(&cfg, text).unwrap();
        let program = format!("{config}-program.toml");
        std::fs::copy(format!("{CONFIGS}/{program}"), dir.path().join(&program)).unwrap();
        let child = Command::new(env!("CARGO_BIN_EXE_cellrt"))
            // Killed on drop; the duration only bounds a test that never ends (a loaded
            // machine can stretch a test past two minutes).
            .args(["run", "--no-program", "--no-record", "--duration", "900"])
            .arg(&cfg)
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        let cell = RunningCell {
            child,
            name,
            _dir: dir,
        };
        let end = std::time::Instant::now() + std::time::Duration::from_secs(15);
        // Until the last MR-JE-C axis has exchanged with its drive.
        let answered = |s: serde_json::Value| {
            s["axes"].as_array().is_some_and(|axes| {
                axes.iter()
                    .rfind(|a| !a["link"].is_null())
                    .is_some_and(|a| a["link"]["exchanges"].as_u64().unwrap_or(0) > 0)
            })
        };
        while !answered(cell.status()) {
            assert!(std::time::Instant::now() < end, "the cell never answered");
            std::thread::sleep(std::time::Duration::from_millis(200));
        }
        cell
    }

    fn cli(&self, args: &[&str]) -> (i32, String, String) {
        cellrt_on_cell(&self.name, args)
    }

    fn status(&self) -> serde_json::Value {
        let (code, out, _) = self.cli(&["status", "--json"]);
        if code != 0 {
            return serde_json::Value::Null;
        }
        serde_json::from_str(&out).unwrap_or_default()
    }

    /// The MR-JE-C axis `name` in the status.
    fn je_c(&self, name: &str) -> serde_json::Value {
        let s = self.status();
        s["axes"]
            .as_array()
            .and_then(|a| a.iter().find(|a| a["name"] == name).cloned())
            .unwrap_or_else(|| panic!("no MR-JE-C axis {name} in {s}"))
    }

    /// Asserts that `args` is refused (exit 3) with one line containing `what`.
    fn refused(&self, args: &[&str], what: &str) {
        let (code, out, err) = self.cli(args);
        assert_eq!(code, 3, "{args:?} was not refused: {out}{err}");
        assert!(err.contains(what), "{args:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
    }
}

impl Drop for RunningCell {
    fn drop(&mut self) {
        let _ = Command::new("kill")
            .arg(self.child.id().to_string())
            .status();
        let _ = self.child.wait();
    }
}

#[test]
fn the_operator_moves_jogs_and_halts_the_je_c_axes_beside_the_csp_axes() {
    let cell = RunningCell::start();
    let ok = |args: &[&str]| {
        let (code, out, err) = cell.cli(args);
        assert_eq!(code, 0, "{args:?}: {out}{err}");
    };
    cell.refused(&["move", "infeed=100"], "axis 'infeed' is not enabled");
    ok(&["power", "on"]);
    for axis in ["infeed", "outfeed"] {
        assert_eq!(cell.je_c(axis)["fsa"], "operation_enabled", "{axis}");
    }
    // One move of both kinds; `cellrt move` waits until every axis is done.
    ok(&["move", "x=300", "infeed=100", "outfeed=-50"]);
    let at = |axis: &str| cell.je_c(axis)["position"].as_f64().unwrap();
    assert!(
        (at("infeed") - 100.0).abs() < 0.01,
        "{}",
        cell.je_c("infeed")
    );
    assert!(
        (at("outfeed") + 50.0).abs() < 0.01,
        "{}",
        cell.je_c("outfeed")
    );
    let x = cell.status()["axes"][0]["position"].as_f64().unwrap();
    assert!((x - 300.0).abs() < 0.05, "x at {x}");
    ok(&["move", "--rel", "infeed=-30", "--vel", "50"]);
    assert!(
        (at("infeed") - 70.0).abs() < 0.01,
        "{}",
        cell.je_c("infeed")
    );
    // Refused, naming the axis and the rule; nothing moves.
    cell.refused(
        &["move", "infeed=600"],
        "axis 'infeed': target 600 mm is outside its position range [-500, 500]",
    );
    cell.refused(
        &["move", "infeed=0", "--vel", "300"],
        "axis 'infeed': velocity 300 mm/s exceeds the axis limit 200 mm/s",
    );
    cell.refused(
        &["move", "--line", "x=100", "infeed=0"],
        "axis 'infeed' is moved by its drive's own profile (mr-je-c link): a line needs streamed axes",
    );
    cell.refused(
        &["jog", "outfeed", "250"],
        "axis 'outfeed': velocity 250 mm/s exceeds the axis limit 150 mm/s",
    );
    assert!((at("infeed") - 70.0).abs() < 0.01, "infeed moved");
    // MC_Home in the drive's hm (method 37): the home where the conveyor stands; `cellrt home`
    // waits for Homing attained. Another method or a Controlword2 edge is refused.
    cell.refused(
        &["home", "infeed", "--method", "35"],
        "MR-JE-C axis 'infeed' homes with method 37 only",
    );
    cell.refused(
        &["home", "infeed", "--setting", "clear"],
        "axis 'infeed' is an MR-JE-C axis: it homes in hm",
    );
    ok(&["home", "infeed", "--method", "37"]);
    assert!(at("infeed").abs() < 0.001, "{}", cell.je_c("infeed"));
    ok(&["move", "infeed=70"]);
    // A jog runs until halted; the servo cannot be switched off under it.
    ok(&["jog", "outfeed", "40"]);
    let end = std::time::Instant::now() + std::time::Duration::from_secs(10);
    while cell.je_c("outfeed")["velocity"].as_f64().unwrap() < 39.0 {
        assert!(
            std::time::Instant::now() < end,
            "outfeed never reached 40 mm/s: {}",
            cell.je_c("outfeed")
        );
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    cell.refused(&["power", "off", "outfeed"], "axis 'outfeed' is moving");
    ok(&["halt", "outfeed"]);
    let end = std::time::Instant::now() + std::time::Duration::from_secs(10);
    while cell.je_c("outfeed")["velocity"].as_f64().unwrap() != 0.0 {
        assert!(std::time::Instant::now() < end, "outfeed never stood");
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    // MC_TorqueControl in the drive's tq: it runs up to its speed limit (2D20h = limits.velocity,
    // 150 mm/s) and holds the torque until halted; beyond limits.torque is refused.
    cell.refused(
        &["torque", "outfeed=25"],
        "torque 25 % is outside the torque limit ±20 % of axis 'outfeed'",
    );
    cell.refused(
        &["torque", "outfeed=5", "x=5"],
        "MR-JE-C axes and the cell's other axes in one command",
    );
    ok(&["torque", "outfeed=8"]);
    let speed = |axis: &str| cell.je_c(axis)["velocity"].as_f64().unwrap();
    let end = std::time::Instant::now() + std::time::Duration::from_secs(10);
    while speed("outfeed") < 145.0 {
        assert!(
            std::time::Instant::now() < end,
            "outfeed never ran up under torque: {}",
            cell.je_c("outfeed")
        );
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    assert!(
        speed("outfeed") <= 150.1,
        "2D20h holds it: {}",
        cell.je_c("outfeed")
    );
    ok(&["halt", "outfeed"]);
    let end = std::time::Instant::now() + std::time::Duration::from_secs(10);
    while speed("outfeed") != 0.0 {
        assert!(
            std::time::Instant::now() < end,
            "outfeed never stood after the torque"
        );
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    ok(&["power", "off", "outfeed"]);
    assert_ne!(cell.je_c("outfeed")["fsa"], "operation_enabled");
    assert_eq!(cell.je_c("infeed")["fsa"], "operation_enabled");
    ok(&["power", "off"]);
    assert_ne!(cell.je_c("infeed")["fsa"], "operation_enabled");
}

#[test]
fn the_mixed_cell_runs_and_replay_names_what_it_leaves_out() {
    let dir = tempfile::tempdir().unwrap();
    let text = for_run_recorded(&mixed_cell(&unique_cell_name()));
    let program = std::fs::read_to_string(format!("{CONFIGS}/mixed-cell-program.toml")).unwrap();
    let (out, rec) = run_recorded(dir.path(), &text, &program);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stderr}{stdout}");
    let all = format!("{stderr}{stdout}");
    assert!(
        all.contains("infeed mr-je-c link over cclink-ief-basic every 10 ms, emulated"),
        "{all}"
    );
    assert!(all.contains("program completed"), "{all}");
    for line in ["cclink-ief-basic: ", "modbus-tcp: "] {
        let l = all.lines().find(|l| l.contains(line)).expect(line);
        let exchanges: u64 = l
            .split(": ")
            .nth(1)
            .and_then(|r| r.split(' ').next())
            .and_then(|n| n.parse().ok())
            .expect("N exchanges");
        assert!(exchanges > 20 && !l.contains("stopped"), "{l}");
    }
    // Each MR-JE-C axis has its own topic: one message per exchange (10 ms and 20 ms periods).
    let recording = read_recording(&rec);
    let infeed = recording
        .summary_counts
        .get("/je_c/infeed")
        .copied()
        .unwrap_or(0);
    let outfeed = recording
        .summary_counts
        .get("/je_c/outfeed")
        .copied()
        .unwrap_or(0);
    assert!(
        infeed > 100 && outfeed > 50 && infeed > outfeed,
        "{:?}",
        recording.summary_counts
    );
    assert!(all.contains("MR-JE-C exchange messages"), "{all}");
    let replay = Command::new(env!("CARGO_BIN_EXE_cellrt"))
        .arg("replay")
        .arg(&rec)
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&replay.stdout);
    assert!(replay.status.success(), "{said}");
    assert!(
        said.contains(
            "MR-JE-C axes infeed (cclink-ief-basic), outfeed (modbus-tcp) are NOT replayed"
        ),
        "{said}"
    );
    assert!(
        said.contains("× 2 axes") && said.contains("bit-identical to the recording"),
        "{said}"
    );
}

/// As root, the mixed cell's conveyors as two emulated MR-JE-Cs in a network namespace behind
/// a veth pair (`cellrt drive-sim mr-je-c --listen` at 10.78.0.2 and 10.78.0.3, their own
/// ports): the cell reaches them by `address` and runs its program. Skipped, saying why,
/// without root.
#[test]
fn the_mixed_cell_reaches_drives_in_a_namespace() {
    use cellrt_rt_tests::netns::VethNamespace;
    let ns = match VethNamespace::create(&format!("mx{}", std::process::id() % 100_000)) {
        Ok(ns) => ns,
        Err(why) => {
            println!("SKIPPED the_mixed_cell_reaches_drives_in_a_namespace: {why}");
            return;
        }
    };
    let ip = |args: &[&str]| {
        let ok = Command::new("ip").args(args).status().unwrap().success();
        assert!(ok, "ip {args:?}");
    };
    ip(&["addr", "add", "10.78.0.1/24", "dev", &ns.near]);
    for a in ["10.78.0.2/24", "10.78.0.3/24"] {
        ip(&["-n", &ns.namespace, "addr", "add", a, "dev", &ns.far]);
    }
    let exe = std::path::Path::new(env!("CARGO_BIN_EXE_cellrt"));
    let _drives: Vec<Killed> = ["10.78.0.2", "10.78.0.3"]
        .iter()
        .map(|addr| {
            ns.command(exe)
                .args(["drive-sim", "mr-je-c", "--listen", addr])
                .stdout(std::process::Stdio::null())
                .stderr(std::process::Stdio::null())
                .spawn()
                .map(Killed)
                .unwrap()
        })
        .collect();
    let end = std::time::Instant::now() + std::time::Duration::from_secs(30);
    let modbus = "10.78.0.3:502".parse().unwrap();
    while std::net::TcpStream::connect_timeout(&modbus, std::time::Duration::from_millis(200))
        .is_err()
    {
        assert!(std::time::Instant::now() < end, "drive-sim never listened");
        std::thread::sleep(std::time::Duration::from_millis(100));
    }
    let text = for_run_recorded(&mixed_cell(&unique_cell_name()))
        .replace(
            "je_c = { emulate = true, period_ms = 10,",
            "je_c = { address = \"10.78.0.2\", period_ms = 10,",
        )
        .replace(
            "je_c = { emulate = true, period_ms = 20,",
            "je_c = { address = \"10.78.0.3\", period_ms = 20,",
        );
    assert!(!text.contains("je_c = { emulate"));
    let dir = tempfile::tempdir().unwrap();
    let program = std::fs::read_to_string(format!("{CONFIGS}/mixed-cell-program.toml")).unwrap();
    let (out, _) = run_recorded(dir.path(), &text, &program);
    let all = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stderr),
        String::from_utf8_lossy(&out.stdout)
    );
    assert!(out.status.success(), "{all}");
    assert!(all.contains("program completed"), "{all}");
    assert!(
        all.contains("cclink-ief-basic: ") && all.contains("modbus-tcp: "),
        "{all}"
    );
}

/// A child process killed and reaped when dropped, also when the test fails.
struct Killed(std::process::Child);

impl Drop for Killed {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// `cellrt halt` on a running cell halts an MR-JE-C conveyor in the middle of a program's move
/// (its drive's Halt) and aborts the program.
#[test]
fn halt_stops_a_conveyor_mid_move() {
    let dir = tempfile::tempdir().unwrap();
    let name = unique_cell_name();
    let cfg = dir.path().join("cell.toml");
    std::fs::write(&cfg, mixed_cell(&name)).unwrap();
    let program = dir.path().join("long.toml");
    std::fs::write(
        &program,
        "[[step]]\ndo = \"power_on\"\n[[step]]\ndo = \"move\"\ntarget = { infeed = 400.0 }\nvelocity = 20.0\n",
    )
    .unwrap();
    let _cell = Killed(
        Command::new(env!("CARGO_BIN_EXE_cellrt"))
            .args(["run", "--no-program", "--no-record", "--duration", "30"])
            .arg(&cfg)
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap(),
    );
    let infeed = |status: &str| -> (f64, bool) {
        let line = status
            .lines()
            .find(|l| l.starts_with("infeed"))
            .unwrap_or("");
        let position = line
            .split_whitespace()
            .nth(3)
            .and_then(|p| p.parse().ok())
            .unwrap_or(f64::NAN);
        (position, line.contains("moving"))
    };
    let end = std::time::Instant::now() + std::time::Duration::from_secs(20);
    while cellrt_on_cell(&name, &["status"]).0 != 0 {
        assert!(std::time::Instant::now() < end, "the cell never answered");
        std::thread::sleep(std::time::Duration::from_millis(200));
    }
    let (code, _, err) =
        cellrt_on_cell(&name, &["program", program.to_str().unwrap(), "--no-wait"]);
    assert_eq!(code, 0, "{err}");
    loop {
        assert!(std::time::Instant::now() < end, "the conveyor never moved");
        let (_, out, _) = cellrt_on_cell(&name, &["status"]);
        let (p, moving) = infeed(&out);
        if moving && p > 5.0 {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(200));
    }
    let (code, _, err) = cellrt_on_cell(&name, &["halt"]);
    assert_eq!(code, 0, "{err}");
    std::thread::sleep(std::time::Duration::from_millis(800));
    let (_, first, _) = cellrt_on_cell(&name, &["status"]);
    std::thread::sleep(std::time::Duration::from_millis(300));
    let (_, second, _) = cellrt_on_cell(&name, &["status"]);
    let (p1, _) = infeed(&first);
    let (p2, moving) = infeed(&second);
    assert!(
        p1 < 100.0 && (p1 - p2).abs() < 0.01 && !moving,
        "{first}\n{second}"
    );
}

/// The operator on the shipped positioning cell: a move names the feeder's point table and
/// the turret's station (`cellrt move` waits until both report Target reached), a jog of the
/// point-table axis runs in jg until halted, and what these axes do not take is refused.
#[test]
fn the_operator_runs_point_tables_and_stations() {
    let cell = RunningCell::start_shipped("je-c-positioning", "je-c-positioning");
    let ok = |args: &[&str]| {
        let (code, out, err) = cell.cli(args);
        assert_eq!(code, 0, "{args:?}: {out}{err}");
    };
    let at = |axis: &str| cell.je_c(axis)["position"].as_f64().unwrap();
    assert_eq!(
        (&cell.je_c("feeder")["mode"], &cell.je_c("turret")["mode"]),
        (&"point_table".into(), &"indexer".into())
    );
    ok(&["power", "on"]);
    ok(&["move", "x=200", "feeder=1", "turret=5"]);
    assert!(
        (at("feeder") - 120.0).abs() < 0.01,
        "{}",
        cell.je_c("feeder")
    );
    assert_eq!(at("turret"), 5.0, "{}", cell.je_c("turret"));
    ok(&["move", "feeder=2", "turret=1"]);
    assert!(
        (at("feeder") + 80.0).abs() < 0.01,
        "{}",
        cell.je_c("feeder")
    );
    assert_eq!(at("turret"), 1.0, "{}", cell.je_c("turret"));
    for (args, why) in [
        (
            &["move", "feeder=3"][..],
            "axis 'feeder': 3 is not one of its point tables (1–2)",
        ),
        (
            &["move", "turret=8"][..],
            "axis 'turret': 8 is not one of its stations (0–7)",
        ),
        (
            &["move", "--rel", "turret=1"][..],
            "axis 'turret' runs indexer: a move names its station, not a distance",
        ),
        (
            &["move", "feeder=1", "--vel", "10"][..],
            "axis 'feeder' runs point tables",
        ),
        (
            &["jog", "turret", "1"][..],
            "it turns to stations (move), it does not jog",
        ),
        (&["torque", "feeder=5"][..], "carry no torque command"),
    ] {
        cell.refused(args, why);
    }
    ok(&["jog", "feeder", "-30"]);
    let end = std::time::Instant::now() + std::time::Duration::from_secs(10);
    while cell.je_c("feeder")["velocity"].as_f64().unwrap() > -29.0 {
        assert!(
            std::time::Instant::now() < end,
            "feeder never jogged: {}",
            cell.je_c("feeder")
        );
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    ok(&["halt", "feeder"]);
    let end = std::time::Instant::now() + std::time::Duration::from_secs(10);
    while cell.je_c("feeder")["velocity"].as_f64().unwrap() != 0.0 {
        assert!(std::time::Instant::now() < end, "feeder never stood");
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    ok(&["move", "feeder=1"]);
    assert!(
        (at("feeder") - 120.0).abs() < 0.01,
        "{}",
        cell.je_c("feeder")
    );
    // MC_Stop quick-stops the indexer (its Halt bit is disabled): 6085h, then Switch on
    // disabled (option code 2); it takes motion again after a power on.
    ok(&["move", "--no-wait", "turret=5"]);
    ok(&["stop"]);
    let end = std::time::Instant::now() + std::time::Duration::from_secs(10);
    while cell.je_c("turret")["fsa"] != "switch_on_disabled" {
        assert!(
            std::time::Instant::now() < end,
            "the turret was not quick-stopped: {}",
            cell.je_c("turret")
        );
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    assert_eq!(
        cell.je_c("feeder")["fsa"],
        "operation_enabled",
        "halted only"
    );
    cell.refused(&["move", "turret=2"], "axis 'turret' is not enabled");
    ok(&["power", "on", "turret"]);
    ok(&["move", "turret=2"]);
    assert_eq!(at("turret"), 2.0, "{}", cell.je_c("turret"));
}
