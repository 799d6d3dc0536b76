//! A `drive = "cia402"` axis described by its ESI file (`configs/cia402-esi.toml` on
//! `configs/esi/cia402-example.xml`: no 60F4h, hm/csp/csv only, its own object dictionary and
//! access rights) comes up on the in-process emulated segment, which presents that device, and
//! runs a program to completion without a fault.

use std::path::Path;

use cellrt_runtime::config::CellConfig;
use cellrt_runtime::host::controller::{run, Outcome, RunOptions};
use cellrt_runtime::host::program::Program;

const PROGRAM: &str = r#"
[[step]]
do = "power_on"

[[step]]
do = "move"
target = { x = 300.0 }

[[step]]
do = "move"
target = { x = 50.0 }

[[step]]
do = "power_off"
"#;

#[test]
fn an_esi_described_drive_runs_a_program() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs/cia402-esi.toml");
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace(
            "name = \"cia402-esi\"",
            &format!("name = \"cia402-esi-{}\"", std::process::id()),
        )
        .replace(
            "max_consecutive_overruns = 100",
            "max_consecutive_overruns = 0",
        )
        + "\n[setpoints]\nlookahead_ms = 1000\n";
    let cell = CellConfig::parse(&path, &text).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        cell.axes[0].ethercat_identity.product_code,
        Some(0xCE11_0403)
    );
    let program = Program::parse(&path, PROGRAM, &cell).unwrap();
    let summary = run(
        &cell,
        RunOptions {
            program: Some(program),
            ..RunOptions::default()
        },
    )
    .expect("cell runs");
    assert_eq!(summary.outcome, Outcome::ProgramCompleted, "{summary:?}");
    assert_eq!(summary.counters.faults, 0, "{summary:?}");
    assert!(
        (summary.axes[0].final_position - 50.0).abs() < 0.05,
        "{summary:?}"
    );
}
