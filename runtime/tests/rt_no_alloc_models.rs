//! Rule 1 of the RT thread for a cell of each drive model (issue 3): the example cell of every
//! model runs its program — csp, csv and (where the model has it) a cst torque step with the
//! braking after it, then power off — and the RT loop allocates nothing in steady state.

mod common;

use std::path::Path;
use std::sync::atomic::Ordering;

use cellrt_config::CellConfig;
use cellrt_runtime::host::controller::{run, Outcome, RunOptions};
use cellrt_runtime::host::program::Program;
use common::{hook, marked_heap_calls, LOOPS_EXITED};

const MODELS: [&str; 6] = [
    "mr-j3-t04",
    "mr-j4-tm",
    "mr-jet-g-n1",
    "mr-j5-g-n1",
    "mr-j5w2-g-n1",
    "mr-j5w3-g-n1",
];

#[test]
fn a_cell_of_each_model_runs_without_allocating_on_the_rt_thread() {
    let configs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs");
    let mut torque_steps = 0;
    for (i, model) in MODELS.iter().enumerate() {
        let text = std::fs::read_to_string(configs.join(format!("{model}.toml"))).unwrap();
        let text = text.replace(
            &format!("name = \"{model}\""),
            &format!("name = \"na-{}-{i}\"", std::process::id()),
        )
            + "\n[setpoints]\nlookahead_ms = 1000\n[watchdogs]\nmax_consecutive_overruns = 0\n";
        let cell = CellConfig::parse(&configs.join(format!("{model}.toml")), &text)
            .unwrap_or_else(|e| panic!("{model}: {e}"));
        let program_path = configs.join(format!("{model}-program.toml"));
        let program = Program::load(&program_path, &cell).unwrap();
        torque_steps += program
            .steps
            .iter()
            .filter(|s| matches!(s, cellrt_runtime::host::program::Step::Torque { .. }))
            .count();
        let before = marked_heap_calls();
        let summary = run(
            &cell,
            RunOptions {
                program: Some(program),
                hook: Some(hook),
                ..RunOptions::default()
            },
        )
        .expect("cell runs");
        assert_eq!(
            summary.outcome,
            Outcome::ProgramCompleted,
            "{model}: {summary:?}"
        );
        assert_eq!(
            marked_heap_calls() - before,
            0,
            "{model}: the RT loop allocated in steady state"
        );
    }
    assert_eq!(LOOPS_EXITED.load(Ordering::Relaxed), MODELS.len() as u64);
    assert!(
        torque_steps >= 4,
        "cst torque steps exercised: {torque_steps}"
    );
}
