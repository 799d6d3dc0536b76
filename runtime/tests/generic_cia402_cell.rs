//! The example cell of the generic CiA 402 model (`configs/cia402-generic.toml`): two
//! `drive = "cia402"` axes on the in-process emulated EtherCAT segment (brought up to OP with
//! the configured identity, x on a remapped csp RxPDO, y in cst) run the cell's own program to
//! completion without a fault and without allocating on the RT thread; the same cell on
//! simulated drives needs no identity and runs it too.

mod common;

use std::path::Path;
use std::sync::atomic::Ordering;

use cellrt_runtime::config::CellConfig;
use cellrt_runtime::controller::{run, Outcome, RunOptions};
use cellrt_runtime::program::Program;
use common::{hook, ALLOCATIONS};

/// The example cell's text with a unique cell name, a long planner lookahead and the overrun
/// watchdog off (the program's logic is under test, not the machine's load).
fn cell_text(tag: &str) -> String {
    let configs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs");
    std::fs::read_to_string(configs.join("cia402-generic.toml"))
        .unwrap()
        .replace(
            "name = \"cia402-generic\"",
            &format!("name = \"cia402-{tag}-{}\"", std::process::id()),
        )
        .replace(
            "max_consecutive_overruns = 100",
            "max_consecutive_overruns = 0",
        )
        + "\n[setpoints]\nlookahead_ms = 1000\n"
}

fn run_cell(text: &str) -> cellrt_runtime::controller::Summary {
    let configs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs");
    let path = configs.join("cia402-generic.toml");
    let cell = CellConfig::parse(&path, text).unwrap_or_else(|e| panic!("{e}"));
    let program = Program::load(&configs.join("cia402-generic-program.toml"), &cell).unwrap();
    assert!(program
        .steps
        .iter()
        .any(|s| matches!(s, cellrt_runtime::program::Step::Torque { .. })));
    run(
        &cell,
        RunOptions {
            program: Some(program),
            hook: Some(hook),
            ..RunOptions::default()
        },
    )
    .expect("cell runs")
}

fn assert_completed(summary: &cellrt_runtime::controller::Summary, what: &str) {
    assert_eq!(
        summary.outcome,
        Outcome::ProgramCompleted,
        "{what}: {summary:?}"
    );
    assert_eq!(summary.counters.faults, 0, "{what}: {summary:?}");
    for a in &summary.axes {
        assert!(
            (a.final_position - 50.0).abs() < 0.05,
            "{what}: {} ends at {}",
            a.name,
            a.final_position
        );
    }
}

#[test]
fn the_generic_cia402_cell_runs_its_program_on_ethercat_and_on_sim() {
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    let summary = run_cell(&cell_text("ec"));
    assert_completed(&summary, "EtherCAT (in-process)");
    assert_eq!(
        ALLOCATIONS.load(Ordering::Relaxed) - before,
        0,
        "the RT loop allocated in steady state"
    );

    // transport = "sim", no [ethercat] and no identity.
    let sim: String = cell_text("sim")
        .replace("transport = \"ethercat\"", "transport = \"sim\"")
        .lines()
        .filter(|l| {
            !l.starts_with("ethercat = ")
                && *l != "[ethercat]"
                && !l.starts_with("interface = ")
                && !l.starts_with("frame_timeout_us")
        })
        .map(|l| format!("{l}\n"))
        .collect();
    assert!(!sim.contains("vendor_id"));
    let summary = run_cell(&sim);
    assert_completed(&summary, "sim");
}
