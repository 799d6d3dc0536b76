//! Every example cell in `configs/` runs its own program to completion (what the README and the
//! config headers promise a user who tries them), with a unique cell name and no CPU pinning.

mod common;

use common::unique_cell_name;

#[test]
fn every_example_cell_completes_its_program() {
    let dir = tempfile::tempdir().unwrap();
    let configs = concat!(env!("CARGO_MANIFEST_DIR"), "/../configs");
    let mut names: Vec<_> = std::fs::read_dir(configs)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".toml") && !n.ends_with("-program.toml"))
        .collect();
    names.sort();
    assert!(names.len() >= 7, "{names:?}");
    // (config, program): each config's own program, and the example programs the README
    // runs on the demo cell.
    let mut runs: Vec<(String, String)> = Vec::new();
    for name in &names {
        let text = std::fs::read_to_string(format!("{configs}/{name}")).unwrap();
        if let Some(program) = text
            .lines()
            .find_map(|l| l.strip_prefix("program = \""))
            .and_then(|l| l.split('"').next())
        {
            runs.push((name.clone(), program.to_string()));
        }
    }
    runs.push(("demo.toml".into(), "demo-pick-and-place.toml".into()));
    runs.push(("mr-j4-tm.toml".into(), "mr-j4-tm-homing-jog.toml".into()));
    let mut failures = Vec::new();
    for (name, program) in &runs {
        let text = std::fs::read_to_string(format!("{configs}/{name}")).unwrap();
        let own = text
            .lines()
            .find(|l| l.starts_with("program = "))
            .expect("program line")
            .to_string();
        let text = text.replacen(&own, &format!("program = \"{program}\""), 1);
        // Same folder layout: the program sits beside the config.
        std::fs::copy(format!("{configs}/{program}"), dir.path().join(program)).unwrap();
        let cell_line = text
            .lines()
            .find(|l| l.starts_with("name = "))
            .expect("cell name")
            .to_string();
        let text = text
            .replacen(&cell_line, &format!("name = \"{}\"", unique_cell_name()), 1)
            .lines()
            .map(|l| {
                if l.starts_with("cpu = ") {
                    format!("# {l}")
                } else {
                    l.to_string()
                }
            })
            .collect::<Vec<_>>()
            .join("\n");
        // The program's logic is under test, not the machine's load: no overrun watchdog, late
        // cycles stretching the cell's clock (the emulated drives live on it, so a stall of
        // the machine is no missed SYNC0 for them), and a generous lookahead (a planner starved
        // by a loaded machine would underrun the configured one), as in the other end-to-end
        // tests.
        let text = set_key(&text, "watchdogs", "max_consecutive_overruns", "0");
        let text = set_key(&text, "rt", "missed_deadlines", "\"stretch\"");
        let text = set_key(&text, "setpoints", "lookahead_ms", "1000");
        let cfg = dir.path().join(format!("{program}.cell.toml"));
        std::fs::write(&cfg, text).unwrap();
        let json = dir.path().join(format!("{program}.json"));
        // EtherCAT cells run on the in-process emulated segment here; the veth test
        // (rt-tests) runs one on a network interface.
        let interface: &[&str] = if std::fs::read_to_string(&cfg)
            .unwrap()
            .contains("[ethercat]")
        {
            &["--interface", "in-process"]
        } else {
            &[]
        };
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_cellrt"))
            .arg("run")
            .arg(&cfg)
            .args(interface)
            .arg("--no-record")
            .arg("--summary-json")
            .arg(&json)
            .output()
            .unwrap();
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&json).unwrap_or_default())
                .unwrap_or_default();
        if !out.status.success() || summary["outcome"] != "program_completed" {
            failures.push(format!(
                "{name} with {program}: {}{}",
                String::from_utf8_lossy(&out.stdout),
                String::from_utf8_lossy(&out.stderr)
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

/// `text` with `key = value` in `[section]`: the key's line replaced where it is set, else added
/// to the section (appended with it where the section is missing).
fn set_key(text: &str, section: &str, key: &str, value: &str) -> String {
    let line = format!("{key} = {value}");
    let prefix = format!("{key} = ");
    if text.lines().any(|l| l.starts_with(&prefix)) {
        return text
            .lines()
            .map(|l| {
                if l.starts_with(&prefix) {
                    line.as_str()
                } else {
                    l
                }
            })
            .collect::<Vec<_>>()
            .join("\n");
    }
    let header = format!("[{section}]");
    if text.lines().any(|l| l == header) {
        text.replacen(&header, &format!("{header}\n{line}"), 1)
    } else {
        format!("{text}\n\n{header}\n{line}\n")
    }
}
