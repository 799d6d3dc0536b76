//! The example cell of the generic CiA 402 model (`configs/cia402-generic.toml`): two
//! `drive = "cia402"` axes on the in-process emulated EtherCAT segment (brought up to OP with
//! the configured identity, x on a remapped csp RxPDO, y in cst) run the cell's own program to
//! completion without a fault and without allocating on the RT thread; the same cell on
//! simulated drives needs no identity and runs it too.

mod common;

use std::path::Path;

use cellrt_config::CellConfig;
use cellrt_runtime::host::controller::{run, Outcome, RunOptions};
use cellrt_runtime::host::program::Program;
use common::{hook, marked_heap_calls};

/// The example cell's text with a unique cell name, a long planner lookahead, the overrun
/// watchdog off and late cycles stretching the cell's clock (the program's logic is under
/// test, not the machine's load: the emulated drives live on the cell's clock, so a stall of
/// the machine is no missed SYNC0 for them).
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
        .replace(
            "[rt]\npriority = 80\n",
            "[rt]\npriority = 80\nmissed_deadlines = \"stretch\"\n",
        )
        + "\n[setpoints]\nlookahead_ms = 1000\n"
}

fn run_cell(text: &str) -> cellrt_runtime::host::controller::Summary {
    let configs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs");
    let path = configs.join("cia402-generic.toml");
    let cell = CellConfig::parse(&path, text).unwrap_or_else(|e| panic!("{e}"));
    let program = Program::load(&configs.join("cia402-generic-program.toml"), &cell).unwrap();
    assert!(program
        .steps
        .iter()
        .any(|s| matches!(s, cellrt_runtime::host::program::Step::Torque { .. })));
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

fn assert_completed(summary: &cellrt_runtime::host::controller::Summary, what: &str) {
    let log = &summary.recording.event_log;
    assert_eq!(
        summary.outcome,
        Outcome::ProgramCompleted,
        "{what}: {log:?}"
    );
    assert_eq!(summary.counters.faults, 0, "{what}: {log:?}");
    // Home within 0.05 mm at 1 ms (as the models' end-to-end tests ask); y ends its last move
    // in csv, whose master-side position correction settles in proportion to the cycle.
    let tolerance = 0.05 * f64::from(summary.cycle_time_us) / 1000.0;
    for a in &summary.axes {
        assert!(
            (a.final_position - 50.0).abs() < tolerance,
            "{what}: {} ends at {} (overruns {}; events {log:?})",
            a.name,
            a.final_position,
            summary.counters.overruns
        );
    }
}

/// Runs the cell `text` once and asserts the RT loop did not allocate in steady state.
fn run_without_allocating(text: &str) -> cellrt_runtime::host::controller::Summary {
    let before = marked_heap_calls();
    let summary = run_cell(text);
    assert_eq!(
        marked_heap_calls() - before,
        0,
        "the RT loop allocated in steady state"
    );
    summary
}

#[test]
fn the_generic_cia402_cell_runs_its_program_on_ethercat_and_on_sim() {
    let text = cell_text("ec");
    assert!(text.contains("missed_deadlines = \"stretch\""));
    let summary = run_without_allocating(&text);
    assert_completed(&summary, "EtherCAT (in-process)");

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

/// x's TxPDO without 60F4h (the master computes the following error) and x's emulated
/// SubDevice without it, its 1C32h:02 read-only.
fn without_60f4h(text: String) -> String {
    text.replacen(
        "pdo = { rx = [0x60400010, 0x60600008, 0x00000008, 0x607A0020] }",
        "pdo = { rx = [0x60400010, 0x60600008, 0x00000008, 0x607A0020], tx = [0x60410010, 0x60610008, 0x00000008, 0x60640020, 0x606C0020, 0x603F0010] }",
        1,
    )
    .replacen(
        "sim = { initial_position = 50.0 }",
        "sim = { initial_position = 50.0, cycle_time_object = \"read-only\", following_error_object = false }",
        1,
    )
}

/// Any standard CiA 402 SubDevice comes up: x presents 1C32h:02 read-only (holding the cycle)
/// and no 60F4h, y has no 1C32h:02 at all (skipped under SYNC0 with a `bring_up_warning`
/// naming y and the object); both run the program. Then the same with distributed clocks off
/// on both SubDevices (free-run; y's 1C32h:02 read-write again, which free-run needs).
#[test]
fn a_subdevice_with_read_only_cycle_time_and_no_60f4h_runs_the_program_with_dc_on_and_off() {
    let dc_on = |n: usize| {
        without_60f4h(cell_text(&format!("ro{n}"))).replacen(
            "sim = { initial_position = 50.0 }",
            "sim = { initial_position = 50.0, cycle_time_object = \"absent\" }",
            1,
        )
    };
    assert_eq!(dc_on(0).matches("cycle_time_object").count(), 2);
    let summary = run_without_allocating(&dc_on(0));
    assert_completed(&summary, "DC on");
    let log = &summary.recording.event_log;
    let warnings: Vec<&String> = log
        .iter()
        .filter(|l| l.contains("bring_up_warning"))
        .collect();
    assert_eq!(warnings.len(), 1, "{log:?}");
    assert!(
        warnings[0].contains("[y]") && warnings[0].contains("1C32h:02 aborted with 0602 0000h"),
        "{}",
        warnings[0]
    );

    let dc_off = |n: usize| {
        without_60f4h(cell_text(&format!("fr{n}"))).replace(
            "product_code = 0xCE110402 }",
            "product_code = 0xCE110402, distributed_clocks = false }",
        )
    };
    assert_eq!(dc_off(0).matches("distributed_clocks = false").count(), 2);
    let summary = run_without_allocating(&dc_off(0));
    assert_completed(&summary, "DC off");
    assert!(
        summary.dc_phase_error.is_none(),
        "no SYNC0 grid in free-run"
    );
    assert!(!summary
        .recording
        .event_log
        .iter()
        .any(|l| l.contains("bring_up_warning")));
}
