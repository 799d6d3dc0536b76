//! `cellrt run configs/mixed-cell.toml` (EtherCAT csp axes and two emulated MR-JE-C conveyors)
//! as a user runs it: the start line and the summary name the MR-JE-C axes and their links,
//! and `cellrt replay` of its recording says plainly that they are left out of the
//! bit-identical check while the csp axes replay bit-identical.

mod common;

use std::process::Command;

use common::{run_recorded, unique_cell_name};

#[test]
fn the_mixed_cell_runs_and_replay_names_what_it_leaves_out() {
    let dir = tempfile::tempdir().unwrap();
    let configs = concat!(env!("CARGO_MANIFEST_DIR"), "/../configs");
    let text = std::fs::read_to_string(format!("{configs}/mixed-cell.toml"))
        .unwrap()
        .replace(
            r#"name = "mixed""#,
            &format!(r#"name = "{}""#, unique_cell_name()),
        )
        .replace(
            r#"program = "mixed-cell-program.toml""#,
            r#"program = "program.toml""#,
        )
        .replace(
            "max_consecutive_overruns = 100",
            "max_consecutive_overruns = 0",
        )
        + "\n[setpoints]\nlookahead_ms = 1000\n";
    let program = std::fs::read_to_string(format!("{configs}/mixed-cell-program.toml")).unwrap();
    let (out, rec) = run_recorded(dir.path(), &text, &program);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stderr}{stdout}");
    let all = format!("{stderr}{stdout}");
    assert!(
        all.contains("MR-JE-C axes infeed over cclink-ief-basic every 10 ms, emulated"),
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
