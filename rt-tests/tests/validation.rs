//! Argument validation of the benchmarks: clear messages naming the option, as bad input.

use cellrt_rt_tests::compare::CompareOptions;
use cellrt_rt_tests::latency::LatencyOptions;
use cellrt_rt_tests::loopbench::{config_text, program_text, LoopOptions};
use cellrt_rt_tests::BenchError;

fn bad(r: Result<impl std::fmt::Debug, BenchError>, option: &str) {
    match r {
        Err(BenchError::BadInput(msg)) => assert!(msg.starts_with(option), "{msg}"),
        other => panic!("expected bad input for {option}, got {other:?}"),
    }
}

#[test]
fn latency_options() {
    assert!(LatencyOptions::new(1000, 1.0, 80, None).is_ok());
    assert!(LatencyOptions::new(50, 0.1, 1, Some(0)).is_ok());
    assert!(LatencyOptions::new(1_000_000, 1.0, 99, None).is_ok());
    bad(LatencyOptions::new(49, 1.0, 80, None), "--interval");
    bad(LatencyOptions::new(1_000_001, 1.0, 80, None), "--interval");
    bad(LatencyOptions::new(1000, 0.0, 80, None), "--duration");
    bad(LatencyOptions::new(1000, -1.0, 80, None), "--duration");
    bad(LatencyOptions::new(1000, f64::NAN, 80, None), "--duration");
    bad(LatencyOptions::new(1000, 1.0, 0, None), "--priority");
    bad(LatencyOptions::new(1000, 1.0, 100, None), "--priority");
    bad(LatencyOptions::new(1000, 1.0, 80, Some(4096)), "--cpu");
}

#[test]
fn compare_options() {
    assert!(CompareOptions::new(250, 10.0, 80, None, false, 4).is_ok());
    bad(
        CompareOptions::new(250, 1.5, 80, None, false, 4),
        "--duration",
    );
    bad(
        CompareOptions::new(250, 1.0, 80, None, false, 0),
        "--rounds",
    );
    bad(
        CompareOptions::new(20, 1.0, 80, None, false, 1),
        "--interval",
    );
}

#[test]
fn loop_options_and_generated_cell() {
    assert!(LoopOptions::new(256, 250, 1.0, 80, None).is_ok());
    bad(LoopOptions::new(0, 1000, 1.0, 80, None), "--axes");
    bad(LoopOptions::new(257, 1000, 1.0, 80, None), "--axes");
    bad(LoopOptions::new(4, 300, 1.0, 80, None), "--interval");

    // The generated configuration and program validate at every interval, up to 256 axes.
    for interval in [125, 250, 1000, 8000] {
        let o = LoopOptions::new(256, interval, 2.0, 80, None).unwrap();
        let path = std::path::Path::new("bench.toml");
        let cell = cellrt_config::CellConfig::parse(path, &config_text("bench-t", &o))
            .unwrap_or_else(|e| panic!("{interval} µs: {e}"));
        assert_eq!(cell.axes.on_loop().len(), 256);
        cellrt_runtime::host::program::Program::parse(
            std::path::Path::new("p.toml"),
            &program_text(256, 2.0),
            &cell,
        )
        .unwrap_or_else(|e| panic!("{interval} µs: {e}"));
    }
}

#[test]
fn loop_with_je_c_axes() {
    let o = LoopOptions::new(16, 1000, 2.0, 80, None).unwrap();
    bad(o.with_je_c(17), "--je-c");
    let o = o.with_je_c(4).unwrap();
    let path = std::path::Path::new("bench.toml");
    let cell = cellrt_config::CellConfig::parse(path, &config_text("bench-j", &o))
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        (cell.axes.on_loop().len(), cell.axes.on_link().len()),
        (16, 4)
    );
    let transports: Vec<_> = cell
        .axes
        .on_link()
        .iter()
        .map(|a| a.transport.name())
        .collect();
    assert_eq!(
        transports,
        ["cclink-ief-basic", "modbus-tcp", "slmp", "modbus-rtu"]
    );
    let text = cellrt_rt_tests::loopbench::program_text_with_je_c(16, 4, 2.0);
    let p =
        cellrt_runtime::host::program::Program::parse(std::path::Path::new("p.toml"), &text, &cell)
            .unwrap_or_else(|e| panic!("{e}"));
    // Every move step moves the four MR-JE-C axes beside the streamed ones.
    let moves: Vec<_> = p
        .steps
        .iter()
        .filter_map(|s| match s {
            cellrt_runtime::host::program::Step::Move(targets) => {
                let drive = targets
                    .iter()
                    .filter(|t| matches!(t, cellrt_runtime::host::program::AxisMove::Drive(_)))
                    .count();
                Some((targets.len() - drive, drive))
            }
            _ => None,
        })
        .collect();
    assert!(
        !moves.is_empty() && moves.iter().all(|&m| m == (16, 4)),
        "{moves:?}"
    );
}
