//! A `drive = "cia402"` axis described by its ESI file (`configs/cia402-esi.toml` on
//! `configs/esi/cia402-example.xml`: no 60F4h, hm/csp/csv only, its own object dictionary and
//! access rights) comes up on the in-process emulated segment, which presents that device, and
//! runs a program to completion without a fault.

use std::path::Path;

use cellrt_config::CellConfig;
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
        cell.axes.on_loop()[0].ethercat_identity.product_code,
        Some(0xCE11_0403)
    );
    run_to_completion(&path, &cell);
}

/// Runs [`PROGRAM`] on `cell`: it completes without a fault, x back at 50 mm.
fn run_to_completion(path: &Path, cell: &CellConfig) {
    let program = Program::parse(path, PROGRAM, cell).unwrap();
    let summary = run(
        cell,
        RunOptions {
            program: Some(program),
            ..RunOptions::default()
        },
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        summary.outcome,
        Outcome::ProgramCompleted,
        "{:?}: {:#?}",
        summary.program_error,
        summary.recording.event_log
    );
    assert_eq!(summary.counters.faults, 0);
    assert!((summary.axes[0].final_position - 50.0).abs() < 0.05);
}

/// The ESI of `configs/esi/cia402-example.xml` with its PDO configuration fixed: both PDOs
/// `Fixed`, CoE `PdoAssign` and `PdoConfig` false, and the mapping and assignment objects
/// read-only (as many simple devices ship).
fn fixed_pdo_esi() -> String {
    let xml = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs/esi/cia402-example.xml"),
    )
    .unwrap();
    let read_only = |xml: String, data_type: &str| {
        let start = xml.find(&format!("<Name>{data_type}</Name>")).unwrap();
        let end = start + xml[start..].find("</DataType>").unwrap();
        let block = xml[start..end].replace(
            "<Access WriteRestrictions=\"PreOP\">rw</Access>",
            "<Access>ro</Access>",
        );
        format!("{}{block}{}", &xml[..start], &xml[end..])
    };
    let xml = read_only(read_only(xml, "DT1600"), "DT1C12")
        .replace(
            "<RxPdo Mandatory=\"1\"",
            "<RxPdo Fixed=\"1\" Mandatory=\"1\"",
        )
        .replace(
            "<TxPdo Mandatory=\"1\"",
            "<TxPdo Fixed=\"1\" Mandatory=\"1\"",
        )
        .replace(
            "PdoAssign=\"true\" PdoConfig=\"true\"",
            "PdoAssign=\"false\" PdoConfig=\"false\"",
        );
    assert_eq!(xml.matches("Fixed=\"1\"").count(), 2);
    assert!(xml.contains("PdoConfig=\"false\""));
    xml
}

/// A device whose ESI fixes its PDOs (read-only mapping and assignment objects) comes up: bring-up
/// leaves what the ESI fixes as the device has it (conformance made sure it is what the
/// configuration runs) instead of writing it and failing on the read-only abort.
#[test]
fn a_device_with_fixed_pdos_comes_up_without_writing_them() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("fixed.xml"), fixed_pdo_esi()).unwrap();
    let configs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs");
    let text = std::fs::read_to_string(configs.join("cia402-esi.toml"))
        .unwrap()
        .replace(
            "name = \"cia402-esi\"",
            &format!("name = \"cia402-fixed-{}\"", std::process::id()),
        )
        .replace("esi = \"esi/cia402-example.xml\"", "esi = \"fixed.xml\"")
        .replace(
            "max_consecutive_overruns = 100",
            "max_consecutive_overruns = 0",
        )
        + "\n[setpoints]\nlookahead_ms = 1000\n";
    let path = dir.path().join("cell.toml");
    let cell = CellConfig::parse(&path, &text).unwrap_or_else(|e| panic!("{e}"));
    run_to_completion(&path, &cell);
}
