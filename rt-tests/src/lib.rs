//! Benchmark harness and end-to-end scenarios: a cyclictest-equivalent wakeup-latency loop
//! ([`latency`]), the side-by-side comparison with Debian's `cyclictest` ([`compare`]), the full
//! cellrt loop with N simulated axes ([`loopbench`]), and their building blocks.

pub mod compare;
pub mod cyclictest;
pub mod error;
pub mod ethercat;
pub mod hist;
pub mod ipc;
pub mod je_c;
pub mod latency;
pub mod livebench;
pub mod loopbench;
pub mod netns;
pub mod plot;
pub mod procscan;
pub mod soak;
pub mod threadcpu;
pub mod tools;

pub use error::BenchError;

/// Writes `value` as pretty JSON to `path`, when given (`--json FILE`).
pub fn write_json<T: serde::Serialize>(
    path: Option<&std::path::Path>,
    value: &T,
) -> Result<(), BenchError> {
    let Some(path) = path else {
        return Ok(());
    };
    let json = serde_json::to_string_pretty(value)
        .map_err(|e| BenchError::failed(format!("cannot encode the JSON report: {e}")))?;
    std::fs::write(path, json + "\n")
        .map_err(|e| BenchError::failed(format!("cannot write {}: {e}", path.display())))
}
